#!/usr/bin/env bash
# --fit auto on synthetic data made with a known subset of terms: does the
# selection choose that subset (or one the data cannot tell from it)?
# Five cases, each a 10 s point-to-point record at 1 kHz (N = 32) with 1 %
# noise, made by `simulate` with the terms listed on; the fit starts from
# the default configuration. Prints truth and choice per case.
#
# Usage: docs/auto-selection-synthetic.sh [OUT_DIR]   (default: out/auto-selection)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/auto-selection}
mkdir -p "$OUT"
cargo build --release --quiet
BIN=target/release/friction-node
python3 docs/point-to-point-motion.py "$OUT/motion.csv" 10
COMMON=(--set solver.cells=32 --set contact.load_n=2000)
case_run() {
    local name=$1 truth=$2; shift 2
    "$BIN" simulate --velocity "csv:$OUT/motion.csv@v" --duration 10 --out "$OUT/$name-clean.csv" "${COMMON[@]}" "$@" > /dev/null
    python3 - "$OUT/$name-clean.csv" "$OUT/$name.csv" <<'PY'
import csv, random, sys
random.seed(11)
rows = list(csv.DictReader(open(sys.argv[1])))
f = [float(r["friction_n"]) for r in rows]
rms = (sum(x * x for x in f) / len(f)) ** 0.5
with open(sys.argv[2], "w") as fh:
    fh.write("t_s,velocity_m_s,friction_n\n")
    for r, x in zip(rows, f):
        fh.write(f"{r['t_s']},{r['velocity_m_s']},{x + random.gauss(0, 0.01 * rms)}\n")
PY
    local chosen
    chosen=$("$BIN" fit "$OUT/$name.csv" "${COMMON[@]}" --fit auto --out "$OUT/$name.yaml" 2>/dev/null | grep '^Chosen:' | sed 's/\. Stopped:.*//; s/^Chosen: //' || true)
    echo "| $name | $truth | $chosen |"
}
echo "| case | terms in the data (besides boundary friction) | chosen by --fit auto |"
echo "|---|---|---|"
case_run film "film" --set lubricant.viscosity_pa_s=0.3
case_run viscous "drivetrain viscous" --set drivetrain.viscous_n_s_m=2000
case_run presliding "pre-sliding" --set contact.presliding_stiffness_n_m=2e6
case_run rate "boundary rate" --set contact.boundary_friction_rate=0.03
case_run mixed "pre-sliding, drivetrain viscous, drivetrain quadratic" --set contact.presliding_stiffness_n_m=2e6 --set drivetrain.viscous_n_s_m=2000 --set drivetrain.quadratic_n_s2_m2=5000
