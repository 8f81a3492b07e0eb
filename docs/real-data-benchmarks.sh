#!/usr/bin/env bash
# The three real recordings in data/, each calibrated with one rule
# (`--fit auto`: the data choose the terms; no contact key and no physical
# bound set by hand; only the input maps a recording needs are named), and
# predicted where the calibration did not look. One table: ours and each
# classic model, with training, cross-validated and held-out error and the
# wall time of the whole calibration.
#
#   O-ring seal        fit 1 + 3 bar, predict 5 + 7 bar (maps: effective area,
#                      sensor offset, preload; the script docs/calibrate-oring-seal.sh)
#   EMPS ball screw    fit DATA_EMPS, predict DATA_EMPS_PULSES (pulses ignored);
#                      friction = 35.15 vir − M q̈ − offset, M and offset fitted maps;
#                      the force smoothed as q̈ is (smooth(smooth(vir)) beside
#                      ddt(ddt(qm)): the parallel filtering of the benchmark's
#                      own IDIM-LS reference)
#   lead screw drive 1 positive direction, steady torque against motor speed
#                      (a) fit every other speed, predict the rest
#                      (b) fit ≤ 100 rpm, predict 120–200 rpm
#
# Usage: docs/real-data-benchmarks.sh [OUT_DIR] [BINARY]   (default: out/real-data)
# SETS="seal emps lead-a lead-b" chooses which to run.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/real-data}
mkdir -p "$OUT"
if [ -z "${2:-}" ]; then cargo build --release --quiet; fi
BIN=${2:-target/release/friction-node}
. docs/bench-lib.sh
SETS=${SETS:-seal emps lead-a lead-b}

# The lead screw's steady curves: drive 1, positive direction, motor speed
# (rad/s) and motor torque (N·m), split two ways.
python3 - "$OUT" <<'PY'
import csv, sys
out = sys.argv[1]
rows = [r for r in csv.DictReader(open("data/lead-screw/steady_state_summary.csv"))
        if r["drive"] == "1" and not r["file_label"].startswith("n")]
rows.sort(key=lambda r: float(r["motor_speed_rad_s"]))
rpm = lambda r: int(r["file_label"])
splits = {
    "a": lambda r: rpm(r) in (2, 20, 40, 60, 80, 100, 140, 180),
    "b": lambda r: rpm(r) <= 100,
}
for name, train in splits.items():
    for part, keep in (("train", train), ("validate", lambda r, t=train: not t(r))):
        with open(f"{out}/lead-{name}-{part}.csv", "w") as f:
            f.write("velocity_rad_s,friction_nm\n")
            for r in rows:
                if keep(r):
                    f.write(f"{r['motor_speed_rad_s']},{float(r['motor_torque_mNm']) / 1000}\n")
PY

run() {
    local name=$1
    shift
    timed "$name" "$BIN" fit "$@" --baselines --out "$OUT/$name.yaml" --report "$OUT/$name-report"
}

for set in $SETS; do
    case $set in
    seal)
        D=data/oring-seal
        run seal "$D/O-ring257_1bar.csv" "$D/O-ring257_3bar.csv" \
            --validate "$D/O-ring257_5bar.csv" --validate "$D/O-ring257_7bar.csv" \
            --config launch-config/oring-seal.yaml \
            --columns t_ms,laser_v,p_raw_v,f_raw_v,x_mm,p_bar,force_n --skip 15 --delimiter whitespace \
            --time 't_ms / 1000' --velocity 'ddt(x_mm) / 1000' \
            --friction 'force_n - p_bar * 1e5 * a_eff - f_off' --load '12.1 * p_bar + f0' \
            --map a_eff=5.1875e-4 --map f_off=0 --map f0=90 \
            --bounds a_eff=4.8e-4:5.6e-4 --bounds f_off=-5:5 --bounds f0=10:400 \
            --fit auto,a_eff,f_off,f0 ;;
    emps)
        D=data/emps-ball-screw
        run emps "$D/DATA_EMPS.csv" --validate "$D/DATA_EMPS_PULSES.csv" \
            --time t --velocity 'ddt(qm)' --smooth 0.01 \
            --friction '35.15 * smooth(smooth(vir)) - m * ddt(ddt(qm)) - off' \
            --map m=95 --map off=0 --bounds m=50:150 --bounds off=-20:20 \
            --fit auto,m,off ;;
    lead-a|lead-b)
        s=${set#lead-}
        run "$set" "$OUT/lead-$s-train.csv" --validate "$OUT/lead-$s-validate.csv" --rotary --fit auto ;;
    esac
done

python3 - "$OUT" $SETS <<'PY'
import sys
sys.path.insert(0, "docs")
from fit_runs import Run
out, sets = sys.argv[1], sys.argv[2:]
labels = {"seal": "O-ring seal (5 + 7 bar from 1 + 3)", "emps": "EMPS (pulses record)",
          "lead-a": "lead screw (a) every other speed", "lead-b": "lead screw (b) faster speeds"}
print("| recording | model | terms / parameters | training RMS | CV RMS | held-out RMS | held-out / friction | fit | wall (s) |")
print("|---|---|---|---|---|---|---|---|---|")
for s in sets:
    run = Run(out, s)
    unit = "N·m" if s.startswith("lead") else "N"
    if not run.rows:
        print(f"| {labels[s]} | — | failed: {run.failure()} | | | | | | {run.wall} |")
        continue
    for c in run.rows.values():
        model, n, params, fit, train, cv, held, rel = c[:8]
        ours = model == "friction-node"
        what = run.chosen if (ours and run.chosen) else f"{n} parameters"
        fitted = "converged" if fit == "converged" else "not converged"
        print(f"| {labels[s]} | {model} | {what} | {train} {unit} | {cv} {unit} | {held} {unit} | {rel} | {fitted} | {run.wall if ours else ''} |")
    if run.verdict:
        print(f"| {labels[s]} | | {run.verdict.replace('|', '/')} | | | | | | |")
PY
