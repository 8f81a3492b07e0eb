#!/usr/bin/env bash
# Run every fuzz target for SECONDS (default 900), two at a time, on the
# stable toolchain (RUSTC_BOOTSTRAP=1 lets cargo-fuzz pass its -Z flags).
# Logs go to fuzz/logs/<target>.log; crashes to fuzz/artifacts/<target>/.
set -euo pipefail
cd "$(dirname "$0")"
SECONDS_EACH=${1:-900}
export RUSTC_BOOTSTRAP=1
mkdir -p logs
cargo fuzz build -O
run() {
    local t=$1; shift
    cargo fuzz run -O "$t" "corpus/$t" -- -max_total_time="$SECONDS_EACH" -rss_limit_mb=2048 "$@" \
        > "logs/$t.log" 2>&1 || echo "$t: exit $? (see logs/$t.log)"
    grep -E "^#[0-9]+ +DONE|Done [0-9]+ runs" "logs/$t.log" | tail -2 | sed "s/^/$t: /"
}
run config -max_len=8192 & run set_override -max_len=512 & wait
run signal_csv -max_len=4096 & run cdr -max_len=1024 & wait
run replay -max_len=65536 -timeout=30
