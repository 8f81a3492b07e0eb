#!/usr/bin/env bash
# Regenerate the fixture bags in bags/ (the only way they are made).
#
#   node_lockstep.mcap        recorded by friction-node itself: the README's
#                             demo (v = sin 2πt m/s, 1 kHz) in lockstep over
#                             iceoryx2 for 2 s, shipped default physics.
#   foreign_joint_states.mcap written by an independent writer (Python mcap +
#                             mcap-ros2-support): JointState, TwistStamped,
#                             a load topic and an unrelated String topic.
#
# Run from anywhere: bash bags/regenerate.sh
# Needs: cargo, python3 with `pip install "mcap==1.*" "mcap-ros2-support==0.*"`.
# Regenerate after a deliberate change to the solver's numbers: tests/replay.rs
# checks that the node bag replays within 1e-6 of what was recorded.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet
rm -f bags/node_lockstep.mcap
target/release/friction-node run --demo 2 \
    --config launch-config/lockstep-iceoryx2.yaml \
    --record bags/node_lockstep.mcap --quiet
python3 bags/make_foreign_bag.py bags/foreign_joint_states.mcap --seconds 2
ls -l bags/*.mcap
