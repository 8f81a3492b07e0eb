#!/usr/bin/env python3
"""Write rosbag2 directories with the Python `rosbags` writer (an
independent implementation of rosbag2), one per storage:

  OUT/rosbags_sqlite3/   metadata.yaml + rosbags_sqlite3.db3 (sqlite3,
                         ROS 2 Humble's default storage)
  OUT/rosbags_mcap/      metadata.yaml + rosbags_mcap.mcap

Both hold the same messages, taken from a `friction-node simulate` CSV
(its t_s, velocity_m_s, load_n, friction_n columns) and a temperature ramp:

  /joint_states          sensor_msgs/msg/JointState, every row; joints
                         `spindle` (still) and `slider` (the velocity);
                         header stamps set
  /slider/normal_load    std_msgs/msg/Float64, every 10th row
  /oil_temperature       sensor_msgs/msg/Temperature, every 10th row,
                         20 -> 60 degC over the run
  /slider/friction       std_msgs/msg/Float64, every row: the simulated
                         friction (what a force sensor would record)

Deterministic: stamps come from the CSV, no wall clock.

Usage: make_rosbags_bags.py SIM.csv OUT_DIR
"""
import argparse
import csv
import shutil
from pathlib import Path

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

T0_NS = 1_700_000_000_000_000_000


def temperature_c(t: float, duration: float) -> float:
    return 20.0 + 40.0 * t / duration


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("sim_csv")
    ap.add_argument("out_dir")
    a = ap.parse_args()
    rows = []
    with open(a.sim_csv, newline="") as f:
        for r in csv.DictReader(f):
            rows.append((float(r["t_s"]), float(r["velocity_m_s"]), float(r["load_n"]), float(r["friction_n"])))
    duration = rows[-1][0] or 1.0
    ts = get_typestore(Stores.ROS2_HUMBLE)
    JointState = ts.types["sensor_msgs/msg/JointState"]
    Header = ts.types["std_msgs/msg/Header"]
    Time = ts.types["builtin_interfaces/msg/Time"]
    Float64 = ts.types["std_msgs/msg/Float64"]
    Temperature = ts.types["sensor_msgs/msg/Temperature"]
    import numpy as np

    for storage, name in [(StoragePlugin.SQLITE3, "rosbags_sqlite3"), (StoragePlugin.MCAP, "rosbags_mcap")]:
        path = Path(a.out_dir) / name
        if path.exists():
            shutil.rmtree(path)
        with Writer(path, version=9, storage_plugin=storage) as w:
            js = w.add_connection("/joint_states", JointState.__msgtype__, typestore=ts)
            load = w.add_connection("/slider/normal_load", Float64.__msgtype__, typestore=ts)
            temp = w.add_connection("/oil_temperature", Temperature.__msgtype__, typestore=ts)
            fric = w.add_connection("/slider/friction", Float64.__msgtype__, typestore=ts)
            for k, (t, v, l, fr) in enumerate(rows):
                t_ns = T0_NS + round(t * 1e9)
                header = Header(stamp=Time(sec=t_ns // 10**9, nanosec=t_ns % 10**9), frame_id="base")
                m = JointState(
                    header=header,
                    name=["spindle", "slider"],
                    position=np.array([0.0, 0.0]),
                    velocity=np.array([0.0, v]),
                    effort=np.array([0.0, fr]),
                )
                w.write(js, t_ns, ts.serialize_cdr(m, JointState.__msgtype__))
                w.write(fric, t_ns, ts.serialize_cdr(Float64(data=fr), Float64.__msgtype__))
                if k % 10 == 0:
                    w.write(load, t_ns, ts.serialize_cdr(Float64(data=l), Float64.__msgtype__))
                    tm = Temperature(header=header, temperature=temperature_c(t, duration), variance=0.0)
                    w.write(temp, t_ns, ts.serialize_cdr(tm, Temperature.__msgtype__))
        print(f"wrote {path} ({len(rows)} rows)")


if __name__ == "__main__":
    main()
