#!/usr/bin/env bash
# The held-back direct-drive arm's split (steady curves in rad/s and N·m,
# fitted at 0.5-20 deg/s, predicting 25-90 deg/s) on many noise draws of
# two Stribeck curves τ(ω) = sgn ω (f_c + (f_s − f_c) e^(−(ω/ω_s)²)) + b ω:
# a peak (f_c 1.2, f_s 1.8 N·m, ω_s 0.05 rad/s, b 2 N·m·s/rad) and a rise
# (1.2, 0.6, 0.1, 1), each speed taken both ways with 1 % noise. Each draw
# is fitted with `--rotary --fit auto --baselines`; prints, per draw, ours'
# and the Stribeck curve's held-out RMS, their ratio (the target: at most
# 1.05) and what ours chose, then the worst ratio.
#
# CURVES=random instead draws DRAWS Stribeck curves none of the rules was
# developed on (a fresh judge, as the held-back joints are; SEED=2026 picks
# the family): f_c log-uniform in 0.2–5 N·m, f_s / f_c uniform in 0.4–2
# (every third curve 1: Coulomb + viscous), ω_s log-uniform in
# 0.005–0.5 rad/s (below, inside and above the training speeds), b such that
# the viscous part at 90 deg/s is 0.05–3 × f_c (log-uniform); each is
# compared with the best classic's held-out RMS.
#
# WS_MAX=w (with CURVES=random) draws ω_s log-uniform in 0.005–w rad/s
# instead of 0.005–0.5 (the training's top speed is 0.349 rad/s): a judge
# of curves whose Stribeck speed lies well past the data.
#
# OFFSET=x (with CURVES=random) adds to each random joint a level that
# differs by direction, a constant c drawn uniform in ±x·f_c from its own
# generator (a torque sensor's offset: τ + c both ways); the curves and
# noise are those of OFFSET=0.
#
# POWER=p (with CURVES=random) bends each random joint's viscous part:
# b ω₉₀ sgn ω |ω/ω₉₀|^δ, with δ uniform in p–1 from its own generator
# (ω₉₀ = 90 deg/s, so the part at 90 deg/s is that of POWER=1). A rise
# that bends below the line as speed grows, as a film's shear or a
# grease's thinning gives and neither classic has; the curves, offsets
# and noise are those of POWER=1.
#
# SHAPE=q (with CURVES=random) gives each random joint's Stribeck fall its
# own exponent, e^(−|ω/ω_s|^α) with α uniform in q–2 from its own
# generator (both classics' fall is Gaussian, α = 2; measured joints give
# 0.5–2): a shape neither classic nor ours has. The curves, offsets, bends
# and noise are those of SHAPE=2.
#
# Usage: docs/arm-steady-draws.sh [OUT_DIR] [BIN]   (default: out/arm-steady-draws)
# DRAWS=20 sets the draws per curve.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-out/arm-steady-draws}
BIN=${2:-target/release/friction-node}
DRAWS=${DRAWS:-20}
CURVES=${CURVES:-peak rise}
SEED=${SEED:-2026}
OFFSET=${OFFSET:-0}
WS_MAX=${WS_MAX:-0.5}
POWER=${POWER:-1}
SHAPE=${SHAPE:-2}
mkdir -p "$OUT"
[ -x "$BIN" ] || cargo build --release --quiet
. docs/bench-lib.sh

python3 - "$OUT" "$DRAWS" "$CURVES" "$SEED" "$OFFSET" "$WS_MAX" "$POWER" "$SHAPE" <<'PY'
import math, random, sys
out, draws, names, family = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(), int(sys.argv[4])
offset = float(sys.argv[5])
ws_max = float(sys.argv[6])
power = float(sys.argv[7])
shape = float(sys.argv[8])
offsets, powers, shapes = {}, {}, {}
train = [0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 13.0, 16.0, 20.0]
validate = [25.0, 35.0, 45.0, 60.0, 75.0, 90.0]
curves = {"peak": (1.2, 1.8, 0.05, 2.0), "rise": (1.2, 0.6, 0.1, 1.0)}
if names == ["random"]:
    rng = random.Random(family)
    logu = lambda lo, hi: math.exp(rng.uniform(math.log(lo), math.log(hi)))
    curves = {}
    for k in range(1, draws + 1):
        fc = logu(0.2, 5.0)
        ratio = rng.uniform(0.4, 2.0)
        curves[f"random{k}"] = (fc, fc * (1.0 if k % 3 == 0 else ratio), logu(0.005, ws_max),
                                logu(0.05, 3.0) * fc / math.radians(90.0))
    def per_joint(what, draw):
        """Each joint's own value from the family's generator for `what`,
        written to random-{what}s.txt."""
        rng_ = random.Random(f"{family} {what}")
        values = {n: draw(rng_, p) for n, p in curves.items()}
        with open(f"{out}/random-{what}s.txt", "w") as f:
            for n, x in values.items():
                f.write(f"{n} {x:.4g}\n")
        return values
    if offset > 0.0:
        offsets = per_joint("offset", lambda r, p: r.uniform(-offset, offset) * p[0])
    if power < 1.0:
        powers = per_joint("power", lambda r, p: r.uniform(power, 1.0))
    if shape < 2.0:
        shapes = per_joint("shape", lambda r, p: r.uniform(shape, 2.0))
    with open(f"{out}/random-curves.txt", "w") as f:
        for n, (fc, fs, ws, b) in curves.items():
            f.write(f"{n} {fc:.4g} {fs:.4g} {ws:.4g} {b:.4g}\n")
else:
    curves = {n: curves[n] for n in names}
def write(path, speeds, p, seed, c=0.0, delta=1.0, alpha=2.0):
    fc, fs, ws, b = p
    rng = random.Random(seed)
    w90 = math.radians(90.0)
    with open(path, "w") as f:
        f.write("velocity_rad_s,friction_nm\n")
        for deg in speeds:
            for sign in (1.0, -1.0):
                w = sign * math.radians(deg)
                tau = sign * (fc + (fs - fc) * math.exp(-abs(w / ws) ** alpha)) + (b * w if delta == 1.0 else b * w90 * math.copysign(abs(w / w90) ** delta, w)) + c
                f.write(f"{w},{tau * (1 + rng.gauss(0, 0.01))}\n")
for name, p in curves.items():
    for seed in (range(1, draws + 1) if not name.startswith("random") else [1]):
        # Each random joint gets its own noise (until stop 70 every one of
        # them drew seed 1's, so the family's noise was one draw repeated).
        noise = seed if not name.startswith("random") else 1000 * family + int(name[6:])
        c, delta, alpha = offsets.get(name, 0.0), powers.get(name, 1.0), shapes.get(name, 2.0)
        write(f"{out}/{name}-{seed}-train.csv", train, p, noise, c, delta, alpha)
        write(f"{out}/{name}-{seed}-validate.csv", validate, p, 100000 + noise if name.startswith("random") else 100 + seed, c, delta, alpha)
PY

if [ "$CURVES" = random ]; then
    LIST=$(seq -f 'random%g' 1 "$DRAWS"); SEEDS=1
else
    LIST=$CURVES; SEEDS=$(seq 1 "$DRAWS")
fi
for curve in $LIST; do
    for seed in $SEEDS; do
        n=$curve-$seed
        timed "$n" "$BIN" fit "$OUT/$n-train.csv" --validate "$OUT/$n-validate.csv" --rotary \
            --fit auto --baselines --out "$OUT/$n.yaml"
    done
done

python3 - "$OUT" "$DRAWS" $LIST <<'PY'
import sys
sys.path.insert(0, "docs")
from fit_runs import Run
out, draws, names = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
rnd = names[0].startswith("random")
# The classic of the form each random joint was made with (Stribeck when
# f_s != f_c, else Coulomb + viscous), as the tool fits it: what a user
# who knew the joint's form would fit. The best classic is chosen after
# the fact, by its held-out error; this one is not.
form = {}
if rnd:
    for line in open(f"{out}/random-curves.txt"):
        n, fc, fs, _, _ = line.split()
        form[n] = "Stribeck" if float(fs) != float(fc) else "Coulomb + viscous"
print("| draw | ours: held out (N·m) | best classic: held out (N·m) | ours / best | ours chose |")
print("|---|---|---|---|---|")
worst = None
ratios = []
by_form = []
for curve in names:
    for seed in ([1] if rnd else range(1, draws + 1)):
        run = Run(out, f"{curve}-{seed}")
        ours = run.ours
        classic = [(float(c[6]), m) for m, c in run.rows.items() if m != "friction-node"]
        if ours is None or not classic:
            print(f"| {curve}-{seed} | failed: {run.failure()} | | | |")
            continue
        best, label = min(classic)
        ratio = float(ours[6]) / best
        ratios.append(ratio)
        if curve in form and form[curve] in run.rows:
            made = float(run.rows[form[curve]][6])
            by_form.append((float(ours[6]) / made, made / best))
        worst = max(worst or ratio, ratio)
        print(f"| {curve}-{seed} | {ours[6]} | {label} {best:.5g} | {ratio:.3f} | {run.chosen or '—'} |")
print(f"\nworst ours / best classic: {worst:.3f}" if worst else "\nno draw fitted")
if ratios:
    import math, statistics
    print(f"{len(ratios)} draws: median {statistics.median(ratios):.3f}, geometric mean "
          f"{math.exp(sum(map(math.log, ratios)) / len(ratios)):.3f}, above 1.05: "
          f"{sum(r > 1.05 for r in ratios)}, above 2: {sum(r > 2 for r in ratios)}")
if by_form:
    gm = lambda xs: math.exp(sum(map(math.log, xs)) / len(xs))
    for k, what in ((0, "ours / the classic of the joint's own form"),
                    (1, "the classic of the joint's own form / best classic")):
        xs = [r[k] for r in by_form]
        print(f"{what}: geometric mean {gm(xs):.3f}, above 1.05: {sum(x > 1.05 for x in xs)}, "
              f"above 2: {sum(x > 2 for x in xs)}, worst {max(xs):.3f}")
PY
