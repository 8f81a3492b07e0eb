#!/usr/bin/env python3
"""Do the fit's 95 % intervals hold the truth? On the draws of
docs/joint-series-draws.sh the joint is known: for every draw whose chosen
set holds a viscous rise, the generator's slope b (the `.params` file)
against ours on the joint (the report's parameter table, its "on the
joint" column, with the standard error scaled alike), as z = (ours − b)/SE.
A 95 % interval should hold b in about 19 draws of 20.

Usage: docs/interval-coverage.py OUT_DIR...   (each a joint-series-draws.sh
output directory, or a directory of them)
"""
import glob
import os
import re
import sys

KEY = "drivetrain.viscous_n_s_m"


def on_joint(md):
    """(value on the joint, its standard error) of KEY, or None."""
    for line in open(md, encoding="utf-8"):
        if line.startswith(f"| `{KEY}` |"):
            c = [x.strip() for x in line.strip().strip("|").split("|")]
            value, se = float(c[1]), float(c[2])
            joint = re.match(r"([-0-9.e+]+)", c[6]) if len(c) > 6 else None
            if not joint or value == 0:
                return None
            scale = float(joint.group(1)) / value
            return value * scale, se * scale
    return None


def true_slope(params):
    cells = [x.strip() for x in open(params, encoding="utf-8").read().strip().strip("|").split("|")]
    return float(cells[4])


def main(dirs):
    rows = []
    for d in dirs:
        for md in sorted(glob.glob(os.path.join(d, "**", "d*.md"), recursive=True)):
            params = md[:-3] + ".params"
            if not os.path.exists(params):
                continue
            got = on_joint(md)
            if got is None:
                continue
            b = true_slope(params)
            rows.append((os.path.basename(md)[:-3], got[0], got[1], b, (got[0] - b) / got[1]))
    if not rows:
        sys.exit("no report with a viscous rise and its .params file found")
    print("| draw | ours: b on the joint | std. error | the joint's b | z |")
    print("|---|---|---|---|---|")
    for name, v, se, b, z in rows:
        print(f"| {name} | {v:.4g} | {se:.3g} | {b:.4g} | {z:+.1f} |")
    inside = sum(abs(r[4]) < 1.96 for r in rows)
    print(f"\nthe joint's b inside ours' 95 % interval: {inside} of {len(rows)} draws")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
