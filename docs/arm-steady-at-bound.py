#!/usr/bin/env python3
"""Where ours ships the Stribeck curve on a random steady joint, does its
Stribeck speed decide how it predicts past the data?

Reads what `CURVES=random SEED=n docs/arm-steady-draws.sh DIR_n BIN` wrote
(each joint's summary, `randomK-1.md`: the parameter table and the models
table) and sorts the joints on which ours shipped `drivetrain Stribeck` by
where its speed `drivetrain.stribeck_speed_m_s` ended:

- on its upper bound, the data's top speed (rule 8; 63 % of the fall shown);
- inside, with the upper end of its 95 % interval at or past the top;
- inside, with its whole interval below the top.

For each group it prints how many joints ours, the tool's Coulomb + viscous
fit (what ours would ship had the curve given way to its rise) and its
Stribeck fit (the speed free past the data) leave above 1.05x and 2x the
best classic held out, and their geometric means. A joint met twice with the
same numbers (one family run on two builds) counts once.

Usage: docs/arm-steady-at-bound.py DIR [DIR ...]
"""
import math
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fit_runs import Run  # noqa: E402

SPEED = re.compile(
    r"^\| `drivetrain\.stribeck_speed_m_s` \| (\S+) \| \S+ \| \[(\S+), (\S+)\] \| \[\S+, (\S+)\] log \| ([^|]*)\|",
    re.M,
)
CLASSICS = ("Coulomb + viscous", "Stribeck", "LuGre")


def joints(dirs):
    seen = set()
    for d in dirs:
        for md in sorted(Path(d).glob("random*-1.md")):
            run = Run(str(md.parent), md.stem) if md.with_suffix(".wall").exists() else None
            if run is None or run.ours is None:
                continue
            m = SPEED.search(run.md)
            if not m or "Stribeck" not in run.rows:
                continue
            value, _lo, hi, top = (float(x) for x in m.groups()[:4])
            held = {k: float(v[6]) for k, v in run.rows.items() if k in CLASSICS or k == "friction-node"}
            key = (md.name, value, held["friction-node"])
            if key in seen:
                continue
            seen.add(key)
            best = min(v for k, v in held.items() if k in CLASSICS)
            if "bound" in m.group(5):
                group = 0
            elif hi >= top:
                group = 1
            else:
                group = 2
            yield group, {k: v / best for k, v in held.items()}


def row(name, ratios):
    if not ratios:
        return f"| {name} | 0 | | | | |"
    gm = math.exp(sum(math.log(x) for x in ratios) / len(ratios))
    return (
        f"| {name} | {len(ratios)} | {sum(x > 1.05 for x in ratios)} | "
        f"{sum(x > 2 for x in ratios)} | {gm:.3f} | {max(ratios):.2f} |"
    )


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    groups = [[], [], []]
    for g, r in joints(sys.argv[1:]):
        groups[g].append(r)
    names = (
        "speed on its bound (the data's top)",
        "inside, its interval reaching the top",
        "inside, its interval below the top",
    )
    print("| joints where ours shipped the Stribeck curve: its speed | model | joints | above 1.05x | above 2x | geometric mean | worst |")
    print("|---|---|---|---|---|---|---|")
    for name, g in zip(names, groups):
        for model, label in (("friction-node", "ours"), ("Coulomb + viscous", "Coulomb + viscous"), ("Stribeck", "Stribeck (speed free)")):
            print(f"| {name} " + row(label, [r[model] for r in g if model in r]))


if __name__ == "__main__":
    main()
