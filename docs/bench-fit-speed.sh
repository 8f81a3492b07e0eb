#!/usr/bin/env bash
# Fit speed, side by side in one run: the shape of issue 42's target (a
# 25 s record at 1 kHz, 8 configuration keys + 2 input maps, contact.load_n
# set), synthetic: point-to-point moves made by `simulate` with every fitted
# term on, 1 % noise, the velocity read 5 % fast and the force offset by
# 5 N (the two maps). Fits it three ways: `--jacobian differences
# --later-runs full` (finite differences at every iteration, every local
# run walked to its end), `--jacobian secant --later-runs full` (the
# defaults), and the opt-in shortcut `--later-runs valley` (later runs stop
# in the first optimum's valley); prints simulations, wall time and
# training RMS of each.
#
# Usage: docs/bench-fit-speed.sh [OUT_DIR] [BINARY]   (default: out/bench-fit-speed)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/bench-fit-speed}
mkdir -p "$OUT"
if [ -z "${2:-}" ]; then cargo build --release --quiet; fi
BIN=${2:-target/release/friction-node}
python3 docs/point-to-point-motion.py "$OUT/vel.csv" 25
"$BIN" simulate --velocity "csv:$OUT/vel.csv@v" --duration 25 --out "$OUT/sim.csv" \
  --set solver.cells=64 --set contact.load_n=2000 \
  --set contact.boundary_friction=0.12 --set lubricant.viscosity_pa_s=0.08 \
  --set drivetrain.coulomb_n=40 --set drivetrain.viscous_n_s_m=300 \
  --set contact.presliding_stiffness_n_m=2e6 --set contact.presliding_damping_n_s_m=3e3 \
  --set drivetrain.quadratic_n_s2_m2=800 --set contact.boundary_friction_rate=0.01 > /dev/null
python3 - "$OUT" <<'PY'
import csv, random, sys
out = sys.argv[1]
random.seed(5)
rows = list(csv.DictReader(open(f"{out}/sim.csv")))
f = [float(x["friction_n"]) for x in rows]
scale = max(abs(x) for x in f)
with open(f"{out}/meas.csv", "w") as fh:
    fh.write("t,v,f\n")
    for x, y in zip(rows, f):
        fh.write(f"{x['t_s']},{float(x['velocity_m_s']) * 1.05},{y + 5 + random.gauss(0, 0.01 * scale)}\n")
PY
for way in ${WAYS:-differences/full secant/full secant/valley}; do
  rule=${way%/*}
  later=${way#*/}
  start=$(date +%s.%N)
  "$BIN" fit "$OUT/meas.csv" --time t --velocity 'v / c' --friction 'f - b' --map c=1 --map b=0 \
    --bounds c=0.5:2 --bounds b=-50:50 --set solver.cells=64 --set contact.load_n=2000 \
    --fit contact.boundary_friction,lubricant.viscosity_pa_s,drivetrain.coulomb_n,drivetrain.viscous_n_s_m,contact.presliding_stiffness_n_m,contact.presliding_damping_n_s_m,drivetrain.quadratic_n_s2_m2,contact.boundary_friction_rate,c,b \
    --jacobian "$rule" --later-runs "$later" --out "$OUT/fitted-$rule-$later.yaml" > "$OUT/$rule-$later.log" 2>&1 || true
  end=$(date +%s.%N)
  echo "$rule, later runs $later: $(grep -E '^[0-9]+ simulations' "$OUT/$rule-$later.log"); $(grep -E '^training RMS' "$OUT/$rule-$later.log" | cut -d, -f1); wall $(python3 -c "print(round($end - $start, 1))") s"
done
