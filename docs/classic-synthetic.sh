#!/usr/bin/env bash
# --fit auto on records made by the classic models themselves: Coulomb +
# viscous, Stribeck with the static level above the Coulomb level and below
# it (a rise that saturates), and LuGre. Each record is the point-to-point
# motion of docs/point-to-point-motion.py (10 s at 1 kHz) with 1 % white
# noise; the last 30 % is held out. Prints, per record: the noise (what the
# generating model's training RMS is), ours' training RMS and its ratio to
# the noise, ours' and the generating classic's held-out RMS as the tool
# fits them, and what --fit auto chose.
#
# Usage: docs/classic-synthetic.sh [OUT_DIR] [BIN]   (default: out/classic-synthetic)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/classic-synthetic}
BIN=${2:-target/release/friction-node}
. docs/bench-lib.sh
mkdir -p "$OUT"
[ -x "$BIN" ] || cargo build --release --quiet
python3 docs/point-to-point-motion.py "$OUT/motion.csv" 10

# The generators: F(v) in N for v in m/s; LuGre integrated with 20
# explicit sub-steps per sample (σ0 |v| / g · dt ≤ 0.02 per sub-step).
python3 - "$OUT" <<'PY'
import csv, math, random, sys
out = sys.argv[1]
rows = list(csv.DictReader(open(f"{out}/motion.csv")))
t = [float(r["t_s"]) for r in rows]
v = [float(r["v"]) for r in rows]
sgn = lambda x: (x > 0) - (x < 0)

def stribeck(fc, fs, vs, b):
    return lambda x: sgn(x) * (fc + (fs - fc) * math.exp(-(x / vs) ** 2)) + b * x

def lugre(fc, fs, vs, b, s0, s1):
    z, out_f = 0.0, []
    for k, x in enumerate(v):
        dt = t[k] - t[k - 1] if k else 1e-3
        h = dt / 20
        for _ in range(20):
            g = (fc + (fs - fc) * math.exp(-(x / vs) ** 2)) / s0
            dz = x - abs(x) * z / g
            z += h * dz
        out_f.append(s0 * z + s1 * dz + b * x)
    return out_f

cases = {
    "coulomb-viscous": [stribeck(200.0, 200.0, 0.01, 2000.0)(x) for x in v],
    "stribeck-peak": [stribeck(200.0, 320.0, 0.01, 2000.0)(x) for x in v],
    "stribeck-rise": [stribeck(200.0, 80.0, 0.02, 500.0)(x) for x in v],
    "lugre": lugre(200.0, 320.0, 0.01, 2000.0, 1e6, 2000.0),
}
random.seed(17)
for name, f in cases.items():
    rms = math.sqrt(sum(x * x for x in f) / len(f))
    noise = [random.gauss(0, 0.01 * rms) for _ in f]
    with open(f"{out}/{name}.csv", "w") as fh:
        fh.write("t_s,velocity_m_s,friction_n\n")
        for a, b, c, e in zip(t, v, f, noise):
            fh.write(f"{a},{b},{c + e}\n")
    n_train = int(0.7 * len(f))
    tr = noise[:n_train]
    with open(f"{out}/{name}.noise", "w") as fh:
        fh.write(f"{math.sqrt(sum(e * e for e in tr) / len(tr))}\n")
PY

for name in coulomb-viscous stribeck-peak stribeck-rise lugre; do
    timed "$name" "$BIN" fit "$OUT/$name.csv" --holdout 0.3 --set solver.cells=32 --fit auto \
        --baselines --out "$OUT/$name.yaml"
done

python3 - "$OUT" <<'PY'
import sys
sys.path.insert(0, "docs")
from fit_runs import Run
out = sys.argv[1]
gen = {"coulomb-viscous": "Coulomb + viscous", "stribeck-peak": "Stribeck",
       "stribeck-rise": "Stribeck", "lugre": "LuGre"}
print("| record | noise (generator's training RMS) | ours: training RMS | ours / noise | ours: held-out RMS | generator's classic, as fitted: held-out RMS | ours chose | wall (s) |")
print("|---|---|---|---|---|---|---|---|")
for name, classic in gen.items():
    run = Run(out, name)
    noise = float(open(f"{out}/{name}.noise").read())
    if run.ours is None:
        print(f"| {name} | {noise:.4g} N | failed: {run.failure()} | | | | | {run.wall} |")
        continue
    ours, cl = run.ours, run.rows.get(classic)
    print(f"| {name} | {noise:.4g} N | {ours[4]} N | {float(ours[4]) / noise:.3f} | {ours[6]} N | "
          f"{classic}: {cl[6] if cl else '—'} N | {run.chosen or '—'} | {run.wall} |")
PY
