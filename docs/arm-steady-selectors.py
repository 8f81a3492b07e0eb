#!/usr/bin/env python3
"""How well can any rule choose between a steady curve's two classic shapes?

Reads the random joints that `CURVES=random SEED=n docs/arm-steady-draws.sh
DIR_n` wrote (each joint's training and held-out CSV and the curve it was
made from) and, in NumPy, fits both classic shapes to each joint's training
points:

- Coulomb + viscous, tau = f_c sgn w + b w, b >= 0 (linear least squares);
- Stribeck, tau = sgn w (f_c + (f_s - f_c) exp(-(w/w_s)^2)) + b w, b >= 0,
  w_s within the data's speeds (top/1000 to top, as `--fit auto`'s
  drivetrain Stribeck term): variable projection, the global optimum over
  w_s on a log grid refined by golden section.

Then it chooses one shape per joint by each rule below and prints, per rule,
how many joints it leaves above 1.05x and 2x the better of the two shapes'
held-out RMS (an oracle: it is chosen after the fact, by the held-out
error). The rules read the training points only, but for "the generating
form", which reads the curve the joint was made from.

Two rules aim at the prediction past the data rather than the fit inside:
- the focused information criterion (Claeskens & Hjort 2003), focused on
  the friction at top..2 top both ways: Coulomb + viscous is the narrow
  model, its bias estimated by its prediction's difference from the
  Stribeck curve's, the variances by the delta method with the Stribeck
  fit's noise variance; the shape with the lower estimated mean squared
  error there is chosen;
- the Stribeck curve only where its speed ends inside the data (below 0.9
  of the top speed): a curve whose speed sits at the data's top shows no
  bend that it can be told apart by.

And rule 7c (stop 90): each classic shape also with its viscous part
bent, b sgn w |w/w90|^d (d in 0.2-1 on a grid, w90 = 90 deg/s), as a
rolling bearing's viscous moment grows with (nu n)^(2/3) (Palmgren); the
simplest of the four shapes (by their parameter count: 2, 3, 4, 5) within
t of the lowest AICc, a bent one only where d's 95 % (Wald) interval
excludes 1 (rule 9c). Its ratio is still to the better of the two classic
shapes, so it can fall below 1.

Usage: docs/arm-steady-selectors.py DIR [DIR ...]    (NumPy)
"""
import math
import sys
from pathlib import Path

import numpy as np


def load(path):
    d = np.loadtxt(path, delimiter=",", skiprows=1)
    return d[:, 0], d[:, 1]


def lsq(a, y):
    """Least squares with the last coefficient (the viscous b) kept >= 0."""
    c = np.linalg.lstsq(a, y, rcond=None)[0]
    if c[-1] < 0:
        c = np.r_[np.linalg.lstsq(a[:, :-1], y, rcond=None)[0], 0.0]
    return c


def cv_design(w):
    return np.c_[np.sign(w), w]


def st_design(w, ws):
    return np.c_[np.sign(w), np.sign(w) * np.exp(-((w / ws) ** 2)), w]


def sse(a, y, c):
    r = a @ c - y
    return float(r @ r)


def stribeck(w, y, lo, hi, grid=None):
    """The Stribeck fit: (w_s, coefficients, SSE). With `grid` the descent
    starts at the grid point nearest `start` instead (a warm start)."""
    g = np.exp(np.linspace(math.log(lo), math.log(hi), 200)) if grid is None else grid
    prof = [(sse(st_design(w, v), y, c), v, c) for v in g for c in [lsq(st_design(w, v), y)]]
    best = min(prof, key=lambda p: p[0])
    a, b = math.log(best[1]) - 0.03, math.log(best[1]) + 0.03
    a, b = max(a, math.log(lo)), min(b, math.log(hi))
    f = lambda lv: sse(st_design(w, math.exp(lv)), y, lsq(st_design(w, math.exp(lv)), y))
    for _ in range(60):
        m1, m2 = a + (b - a) * 0.382, a + (b - a) * 0.618
        if f(m1) < f(m2):
            b = m2
        else:
            a = m1
    ws = math.exp((a + b) / 2)
    c = lsq(st_design(w, ws), y)
    return ws, c, sse(st_design(w, ws), y, c)


def aicc(s, n, k):
    return n * math.log(s / n) + 2 * k + 2 * k * (k + 1) / (n - k - 1)


def folds(w, count=4):
    """`--fit auto`'s folds of a steady curve: contiguous speed ranges."""
    order = sorted(range(len(w)), key=lambda k: abs(w[k]))
    f = np.zeros(len(w), dtype=int)
    for rank, k in enumerate(order):
        f[k] = rank * count // len(w)
    return f


def fold_mse(w, y, top, ws_all, warm):
    """Each fold's mean squared error, both shapes refitted without it: the
    Stribeck speed descended from the fit on all points (warm) or the fold's
    own global optimum (cold)."""
    grid = np.exp(np.linspace(math.log(top / 1000), math.log(top), 400))
    f = folds(w)
    es, ev = [], []
    for k in range(4):
        tr, te = f != k, f == k
        ss = np.array([sse(st_design(w[tr], v), y[tr], lsq(st_design(w[tr], v), y[tr])) for v in grid])
        i = int(np.argmin(abs(np.log(grid) - math.log(ws_all))))
        if warm:
            while True:
                j = min((x for x in (i - 1, i, i + 1) if 0 <= x < len(grid)), key=lambda x: ss[x])
                if j == i:
                    break
                i = j
        else:
            i = int(np.argmin(ss))
        c = lsq(st_design(w[tr], grid[i]), y[tr])
        es.append(float(np.mean((st_design(w[te], grid[i]) @ c - y[te]) ** 2)))
        cc = lsq(cv_design(w[tr]), y[tr])
        ev.append(float(np.mean((cv_design(w[te]) @ cc - y[te]) ** 2)))
    return np.array(es), np.array(ev)


def st_jacobian(w, ws, c):
    """The Stribeck prediction's derivatives in (f_c, f_s - f_c, w_s, b)."""
    s, e = np.sign(w), np.exp(-((w / ws) ** 2))
    return np.c_[s, s * e, c[1] * s * e * 2 * w**2 / ws**3, w]


def fic(w, cc, ws, cs, ss):
    """Focused information criterion at top..2 top: (Coulomb + viscous'
    estimated mean squared error there, the Stribeck curve's)."""
    n, top = len(w), abs(w).max()
    s2 = ss / (n - 4)
    cw = s2 * np.linalg.pinv(st_jacobian(w, ws, cs).T @ st_jacobian(w, ws, cs))
    cn = s2 * np.linalg.pinv(cv_design(w).T @ cv_design(w))
    f = np.linspace(top, 2 * top, 8)
    f = np.r_[f, -f]
    gw, gn = st_jacobian(f, ws, cs), cv_design(f)
    vw = np.einsum("ij,jk,ik->i", gw, cw, gw)
    vn = np.einsum("ij,jk,ik->i", gn, cn, gn)
    bias2 = (gn @ cc - st_design(f, ws) @ cs) ** 2
    return float((np.maximum(bias2 - (vw - vn), 0) + vn).mean()), float(vw.mean())


W90 = math.radians(90.0)
BENDS = np.linspace(0.2, 1.0, 33)


def bent_cv(w, d):
    return np.c_[np.sign(w), np.sign(w) * (abs(w) / W90) ** d]


def bent_st(w, ws, d):
    return np.c_[np.sign(w), np.sign(w) * np.exp(-((w / ws) ** 2)), np.sign(w) * (abs(w) / W90) ** d]


def bent_fits(w, y, top):
    """Both classic shapes with the viscous part bent: ((SSE, d, whether
    d's 95 % Wald interval excludes 1) of Coulomb + bent viscous, (SSE,
    w_s, d, the same) of Stribeck + bent viscous), each the best on its
    grid."""
    cv = min(((sse(bent_cv(w, d), y, lsq(bent_cv(w, d), y)), d) for d in BENDS), key=lambda t: t[0])
    st = min(((sse(bent_st(w, v, d), y, lsq(bent_st(w, v, d), y)), v, d)
              for v in np.exp(np.linspace(math.log(top / 1000), math.log(top), 60)) for d in BENDS[::2]),
             key=lambda t: t[0])
    n, u, sg = len(w), abs(w) / W90, np.sign(w)

    def shown(jac, s, k, d):
        c = s / (n - k) * np.linalg.pinv(jac.T @ jac)
        return d + 1.96 * math.sqrt(max(c[-1, -1], 0.0)) < 1.0

    c1 = lsq(bent_cv(w, cv[1]), y)
    jv = np.c_[sg, sg * u ** cv[1], c1[1] * sg * u ** cv[1] * np.log(u)]
    c2 = lsq(bent_st(w, st[1], st[2]), y)
    e, d2 = np.exp(-((w / st[1]) ** 2)), st[2]
    js = np.c_[sg, sg * e, c2[1] * sg * e * 2 * w**2 / st[1] ** 3, sg * u ** d2, c2[2] * sg * u ** d2 * np.log(u)]
    return (cv[0], cv[1], shown(jv, cv[0], 3, cv[1])), (st[0], st[1], st[2], shown(js, st[0], 5, d2))


def joint(train, validate, made):
    w, y = load(train)
    wv, yv = load(validate)
    n, top = len(w), abs(w).max()
    cc = lsq(cv_design(w), y)
    ws, cs, ss = stribeck(w, y, top / 1000, top)
    rms = lambda p: float(np.sqrt(np.mean((p - yv) ** 2)))
    j = {
        "held_v": rms(cv_design(wv) @ cc),
        "held_s": rms(st_design(wv, ws) @ cs),
        "aicc_v": aicc(sse(cv_design(w), y, cc), n, 2),
        "aicc_s": aicc(ss, n, 4),
        "made_s": made[1] != made[0],
        "pred_v": cv_design(wv) @ cc,
        "pred_s": st_design(wv, ws) @ cs,
        "yv": yv,
        "fic": fic(w, cc, ws, cs, ss),
        "ws_inside": ws < 0.9 * top,
    }
    (sv_b, d_v, shown_v), (ss_b, ws_b, d_s, shown_s) = bent_fits(w, y, top)
    j["held_vb"] = rms(bent_cv(wv, d_v) @ lsq(bent_cv(w, d_v), y))
    j["held_sb"] = rms(bent_st(wv, ws_b, d_s) @ lsq(bent_st(w, ws_b, d_s), y))
    j["aicc_vb"] = aicc(sv_b, n, 3) if shown_v else math.inf
    j["aicc_sb"] = aicc(ss_b, n, 5) if shown_s else math.inf
    j["cv_warm"] = fold_mse(w, y, top, ws, True)
    j["cv_cold"] = fold_mse(w, y, top, ws, False)
    return j


def main(dirs):
    joints = []
    for d in map(Path, dirs):
        for line in open(d / "random-curves.txt"):
            name, fc, fs, _, _ = line.split()
            joints.append(joint(d / f"{name}-1-train.csv", d / f"{name}-1-validate.csv", (float(fc), float(fs))))
    print(f"{len(joints)} joints; ratio = the chosen shape's held-out RMS / the better shape's\n")
    print("| rule | above 1.05x | above 2x | geometric mean |")
    print("|---|---|---|---|")

    def row(label, held):
        r = [h / min(j["held_v"], j["held_s"]) for h, j in zip(held, joints)]
        gm = math.exp(sum(map(math.log, r)) / len(r))
        print(f"| {label} | {sum(x > 1.05 for x in r)} | {sum(x > 2 for x in r)} | {gm:.3f} |")

    pick = lambda choose: [j["held_s"] if choose(j) else j["held_v"] for j in joints]
    row("always Coulomb + viscous", pick(lambda j: False))
    row("always Stribeck", pick(lambda j: True))
    row("the generating form (reads the truth)", pick(lambda j: j["made_s"]))
    for t in (0, 2, 4, 7, 10, 14):
        row(f"Stribeck when its AICc is lower by more than {t}", pick(lambda j, t=t: j["aicc_s"] < j["aicc_v"] - t))
    row("lower focused information criterion at top..2 top", pick(lambda j: j["fic"][1] < j["fic"][0]))
    row("Stribeck when its AICc is lower by more than 2 and its speed below 0.9 top",
        pick(lambda j: j["aicc_s"] < j["aicc_v"] - 2 and j["ws_inside"]))
    for kind in ("warm", "cold"):
        row(f"lower CV on the 4 speed ranges, fold refits {kind}",
            pick(lambda j, k=kind: j[f"cv_{k}"][0].mean() < j[f"cv_{k}"][1].mean()))
    held = []
    for j in joints:
        x = max(min((j["aicc_v"] - j["aicc_s"]) / 2, 50), -50)
        wt = 1 / (1 + math.exp(-x))
        held.append(float(np.sqrt(np.mean((wt * j["pred_s"] + (1 - wt) * j["pred_v"] - j["yv"]) ** 2))))
    row("Akaike-weighted average of the two", held)
    for t in (2, 4):
        held = []
        for j in joints:
            shapes = [(j[f"aicc_{k}"], j[f"held_{k}"]) for k in ("v", "vb", "s", "sb")]
            lowest = min(a for a, _ in shapes)
            held.append(next(h for a, h in shapes if a <= lowest + t))
        row(f"rule 7c: the simplest of the four shapes within {t} of the lowest AICc (bent where d is shown)", held)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
