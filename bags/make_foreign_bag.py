#!/usr/bin/env python3
"""Write bags/foreign_joint_states.mcap with an independent MCAP writer
(mcap + mcap-ros2-support), to prove that bags friction-node did not write
replay.

The bag looks like a recording from a robot with a linear axis:

  /joint_states         sensor_msgs/msg/JointState  500 Hz, joints
                        base_yaw, slider, gripper; the slider moves
                        v = 0.6 sin(2π·1 Hz·t) m/s (header stamps set)
  /cmd_vel              geometry_msgs/msg/TwistStamped  100 Hz, linear.x =
                        the same slider velocity (a second candidate, so
                        replay must be told which topic to use)
  /slider/normal_load   std_msgs/msg/Float64  10 Hz, 5762 N, 4000 N from 1 s
  /diagnostics_text     std_msgs/msg/String  1 Hz (not usable by replay)

Chunks of 16 kB so that a truncated copy still holds whole chunks.
Deterministic: fixed stamps, no wall clock.

Usage: make_foreign_bag.py OUT.mcap [--seconds S]
"""
import argparse
import math

from mcap_ros2.writer import Writer

TIME = "int32 sec\nuint32 nanosec\n"
HEADER = "builtin_interfaces/Time stamp\nstring frame_id\n"
SEP = "=" * 80 + "\n"


def with_header(main: str) -> str:
    return main + SEP + "MSG: std_msgs/Header\n" + HEADER + SEP + "MSG: builtin_interfaces/Time\n" + TIME


JOINT_STATE = with_header(
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n"
)
TWIST_STAMPED = (
    "std_msgs/Header header\ngeometry_msgs/Twist twist\n"
    + SEP
    + "MSG: geometry_msgs/Twist\nVector3 linear\nVector3 angular\n"
    + SEP
    + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
    + SEP
    + "MSG: std_msgs/Header\n"
    + HEADER
    + SEP
    + "MSG: builtin_interfaces/Time\n"
    + TIME
)

T0_NS = 1_700_000_000_000_000_000  # an arbitrary epoch stamp


def stamp(t_ns: int) -> dict:
    return {"sec": t_ns // 1_000_000_000, "nanosec": t_ns % 1_000_000_000}


def velocity(t: float) -> float:
    return 0.6 * math.sin(2.0 * math.pi * t)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--seconds", type=float, default=2.0)
    args = ap.parse_args()
    with open(args.out, "wb") as f:
        w = Writer(f, chunk_size=16 * 1024)
        js = w.register_msgdef("sensor_msgs/msg/JointState", JOINT_STATE)
        tw = w.register_msgdef("geometry_msgs/msg/TwistStamped", TWIST_STAMPED)
        fl = w.register_msgdef("std_msgs/msg/Float64", "float64 data\n")
        st = w.register_msgdef("std_msgs/msg/String", "string data\n")
        period_ns = 2_000_000  # 500 Hz
        steps = int(round(args.seconds * 1e9 / period_ns))
        x = 0.0
        for k in range(steps + 1):
            t_ns = k * period_ns
            t = t_ns / 1e9
            now = T0_NS + t_ns
            v = velocity(t)
            x += v * period_ns / 1e9
            if k % 50 == 0:
                load = 5762.0 if t < 1.0 else 4000.0
                w.write_message("/slider/normal_load", fl, {"data": load}, log_time=now, publish_time=now, sequence=k)
            if k % 500 == 0:
                w.write_message(
                    "/diagnostics_text", st, {"data": f"axis ok at {t:.1f} s"}, log_time=now, publish_time=now
                )
            # Log time a little after the stamp, as a real recorder sees it.
            w.write_message(
                "/joint_states",
                js,
                {
                    "header": {"stamp": stamp(now), "frame_id": ""},
                    "name": ["base_yaw", "slider", "gripper"],
                    "position": [0.1 * t, x, 0.02],
                    "velocity": [0.1, v, 0.0],
                    "effort": [0.0, 0.0, 0.0],
                },
                log_time=now + 150_000,
                publish_time=now + 100_000,
                sequence=k,
            )
            if k % 5 == 0:
                w.write_message(
                    "/cmd_vel",
                    tw,
                    {
                        "header": {"stamp": stamp(now), "frame_id": "slider"},
                        "twist": {"linear": {"x": v, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}},
                    },
                    log_time=now + 120_000,
                    publish_time=now + 80_000,
                    sequence=k // 5,
                )
        w.finish()


if __name__ == "__main__":
    main()
