#!/usr/bin/env bash
# Regenerate docs/figures/ and docs/claims.md from `friction-node study all`
# at the paper's settings (N = 256, 1 ms steps, 3 cycles per case).
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cargo run --release -- study all --out "$out"
rm -rf docs/figures && mkdir -p docs/figures
for f in "$out"/*/*.svg "$out"/*/summary.csv; do
    study=$(basename "$(dirname "$f")")
    cp "$f" "docs/figures/${study}_$(basename "$f")"
done
cp "$out/claims.md" docs/claims.md
echo "docs/figures and docs/claims.md regenerated"
