#!/usr/bin/env bash
# Regenerate the fixture bags in bags/ (the only way they are made).
#
#   node_lockstep.mcap        recorded by friction-node itself: the README's
#                             demo (v = sin 2πt m/s, 1 kHz) in lockstep over
#                             iceoryx2 for 2 s, shipped default physics.
#   foreign_joint_states.mcap written by an independent writer (Python mcap +
#                             mcap-ros2-support): JointState, TwistStamped,
#                             a load topic and an unrelated String topic.
#   rosbags_sqlite3/, rosbags_mcap/
#                             rosbag2 directories written by the Python
#                             `rosbags` writer in both storages (sqlite3,
#                             ROS 2 Humble's default, and mcap): JointState
#                             velocity and effort, load, oil temperature and a
#                             friction topic from a `simulate` run (Vogel
#                             viscosity, temperature ramp 20 -> 60 degC).
#
# Run from anywhere: bash bags/regenerate.sh
# Needs: cargo, python3 with
#   pip install "mcap==1.*" "mcap-ros2-support==0.*" "rosbags==0.11.*" numpy
# Regenerate after a deliberate change to the solver's numbers: tests/replay/fidelity.rs
# checks that the node bag replays within 1e-6 of what was recorded.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
rm -f bags/node_lockstep.mcap
target/release/friction-node run --demo 2 \
    --config launch-config/lockstep-iceoryx2.yaml \
    --record bags/node_lockstep.mcap --quiet
python3 bags/make_foreign_bag.py bags/foreign_joint_states.mcap --seconds 2
tmp=$(mktemp -d)
printf 't_s,temperature_c\n0,20\n1,60\n' > "$tmp/ramp.csv"
target/release/friction-node simulate --velocity sine:0,0.5,2 --load const:5762 \
    --temperature "csv:$tmp/ramp.csv" --duration 1 --set solver.dt_s=0.002 \
    --set solver.cells=64 --set lubricant.viscosity_model=vogel --out "$tmp/sim.csv" > /dev/null
python3 bags/make_rosbags_bags.py "$tmp/sim.csv" bags
rm -rf "$tmp"
ls -l bags/*.mcap
