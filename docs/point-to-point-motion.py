"""Point-to-point moves at 1 kHz, the motion of the synthetic fit scripts
(docs/auto-selection-synthetic.sh, docs/bench-fit-speed.sh): moves to a
top speed drawn from 5, 20, 50, 100, 200 mm/s either way, ramps at 2 m/s²,
a flat of 0.2-1 s and a dwell at rest of 0.1-0.4 s, seeded (3), so every
run of a script sees the same motion.

Usage: python3 docs/point-to-point-motion.py OUT.csv DURATION_S
Writes columns t_s, v (m/s).
"""
import random
import sys

out, duration = sys.argv[1], float(sys.argv[2])
random.seed(3)
dt = 1e-3
segs, t = [], 0.0
while t < duration:
    vmax = random.choice([0.005, 0.02, 0.05, 0.1, 0.2]) * random.choice([1, -1])
    ramp = abs(vmax) / 2.0
    flat, dwell = random.uniform(0.2, 1.0), random.uniform(0.1, 0.4)
    segs.append((t, ramp, flat, vmax, dwell))
    t += 2 * ramp + flat + dwell


def v(t):
    for (t0, r, f, vm, d) in segs:
        if t0 <= t < t0 + 2 * r + f + d:
            s = t - t0
            if s < r:
                return vm * s / r
            if s < r + f:
                return vm
            if s < 2 * r + f:
                return vm * (2 * r + f - s) / r
            return 0.0
    return 0.0


with open(out, "w") as fh:
    fh.write("t_s,v\n")
    for k in range(int(duration / dt) + 1):
        fh.write(f"{k*dt:.6f},{v(k*dt):.9f}\n")
