# Sourced by the benchmark scripts in docs/ (from the repository's root).
#
# timed NAME CMD...: runs CMD with its stdout in $OUT/NAME.md and its stderr
# in $OUT/NAME.log, and writes its wall time (s) to $OUT/NAME.wall. A run that
# fails is recorded (docs/fit_runs.py reports its log's last line), not fatal.
timed() {
    local name=$1 start end
    shift
    start=$(date +%s.%N)
    "$@" > "$OUT/$name.md" 2> "$OUT/$name.log" || true
    end=$(date +%s.%N)
    python3 -c "print(round($end - $start, 1))" > "$OUT/$name.wall"
}
