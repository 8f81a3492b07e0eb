#!/usr/bin/env bash
# The held-back direct-drive arm's split (steady curves in rad/s and N·m,
# fitted at 0.5-20 deg/s, predicting 25-90 deg/s) on many noise draws of
# two Stribeck curves τ(ω) = sgn ω (f_c + (f_s − f_c) e^(−(ω/ω_s)²)) + b ω:
# a peak (f_c 1.2, f_s 1.8 N·m, ω_s 0.05 rad/s, b 2 N·m·s/rad) and a rise
# (1.2, 0.6, 0.1, 1), each speed taken both ways with 1 % noise. Each draw
# is fitted with `--rotary --fit auto --baselines`; prints, per draw, ours'
# and the Stribeck curve's held-out RMS, their ratio (the target: at most
# 1.05) and what ours chose, then the worst ratio.
#
# Usage: docs/arm-steady-draws.sh [OUT_DIR] [BIN]   (default: out/arm-steady-draws)
# DRAWS=20 sets the draws per curve.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/arm-steady-draws}
BIN=${2:-target/release/friction-node}
DRAWS=${DRAWS:-20}
mkdir -p "$OUT"
[ -x "$BIN" ] || cargo build --release --quiet
. docs/bench-lib.sh

python3 - "$OUT" "$DRAWS" <<'PY'
import math, random, sys
out, draws = sys.argv[1], int(sys.argv[2])
train = [0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 13.0, 16.0, 20.0]
validate = [25.0, 35.0, 45.0, 60.0, 75.0, 90.0]
curves = {"peak": (1.2, 1.8, 0.05, 2.0), "rise": (1.2, 0.6, 0.1, 1.0)}
def write(path, speeds, p, seed):
    fc, fs, ws, b = p
    rng = random.Random(seed)
    with open(path, "w") as f:
        f.write("velocity_rad_s,friction_nm\n")
        for deg in speeds:
            for sign in (1.0, -1.0):
                w = sign * math.radians(deg)
                tau = sign * (fc + (fs - fc) * math.exp(-(w / ws) ** 2)) + b * w
                f.write(f"{w},{tau * (1 + rng.gauss(0, 0.01))}\n")
for name, p in curves.items():
    for seed in range(1, draws + 1):
        write(f"{out}/{name}-{seed}-train.csv", train, p, seed)
        write(f"{out}/{name}-{seed}-validate.csv", validate, p, 100 + seed)
PY

for curve in peak rise; do
    for seed in $(seq 1 "$DRAWS"); do
        n=$curve-$seed
        timed "$n" "$BIN" fit "$OUT/$n-train.csv" --validate "$OUT/$n-validate.csv" --rotary \
            --fit auto --baselines --out "$OUT/$n.yaml"
    done
done

python3 - "$OUT" "$DRAWS" <<'PY'
import sys
sys.path.insert(0, "docs")
from fit_runs import Run
out, draws = sys.argv[1], int(sys.argv[2])
print("| draw | ours: held out (N·m) | Stribeck: held out (N·m) | ours / Stribeck | ours chose |")
print("|---|---|---|---|---|")
worst = None
for curve in ("peak", "rise"):
    for seed in range(1, draws + 1):
        run = Run(out, f"{curve}-{seed}")
        ours, st = run.ours, run.rows.get("Stribeck")
        if ours is None or st is None:
            print(f"| {curve}-{seed} | failed: {run.failure()} | | | |")
            continue
        ratio = float(ours[6]) / float(st[6])
        worst = max(worst or ratio, ratio)
        print(f"| {curve}-{seed} | {ours[6]} | {st[6]} | {ratio:.3f} | {run.chosen or '—'} |")
print(f"\nworst ours / Stribeck: {worst:.3f}" if worst else "\nno draw fitted")
PY
