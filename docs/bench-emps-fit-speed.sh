#!/usr/bin/env bash
# Fit speed on a real record, side by side: the EMPS ball screw's
# DATA_EMPS.csv (25 s at 1 kHz), the 8 configuration keys of
# docs/bench-fit-speed.sh and the two input maps the record needs (the
# drive's mass M and a force offset), `contact.load_n` set to 100 N, every
# later run walked to its end (`--later-runs full`). Each binary given is
# run ROUNDS times (default 2), alternating, so that the machine's load
# falls on all alike; prints wall time, simulations (film solves) and
# training RMS of each run.
#
# Usage: docs/bench-emps-fit-speed.sh OUT_DIR BINARY [BINARY...]
#   e.g. docs/bench-emps-fit-speed.sh out/emps-speed /tmp/old/friction-node target/release/friction-node
# EXTRA="--linear-keys searched" adds arguments to every fit.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:?usage: docs/bench-emps-fit-speed.sh OUT_DIR BINARY [BINARY...]}
shift
[ $# -ge 1 ] || { echo "name at least one binary" >&2; exit 2; }
mkdir -p "$OUT"
D=data/emps-ball-screw
KEYS=contact.boundary_friction,lubricant.viscosity_pa_s,drivetrain.coulomb_n,drivetrain.viscous_n_s_m,contact.presliding_stiffness_n_m,contact.presliding_damping_n_s_m,drivetrain.quadratic_n_s2_m2,contact.boundary_friction_rate,m,off
for round in $(seq 1 "${ROUNDS:-2}"); do
  k=0
  for bin in "$@"; do
    k=$((k + 1))
    log="$OUT/run-$k-$round"
    start=$(date +%s.%N)
    # shellcheck disable=SC2086
    "$bin" fit "$D/DATA_EMPS.csv" --time t --velocity 'ddt(qm)' --smooth 0.01 \
      --friction '35.15 * vir - m * ddt(ddt(qm)) - off' --map m=95 --map off=0 \
      --bounds m=50:150 --bounds off=-20:20 --set contact.load_n=100 \
      --fit "$KEYS" --later-runs full ${EXTRA:-} \
      --out "$log.yaml" > "$log.md" 2> "$log.log" || true
    end=$(date +%s.%N)
    echo "round $round, $bin: wall $(python3 -c "print(round($end - $start, 1))") s; $(grep -E '^[0-9]+ simulations' "$log.md" | sed 's/, [0-9.]* ms each.*//'); $(grep -m1 '^training RMS' "$log.md" | cut -d, -f1)"
  done
done
