//! The bordered linear solve of one Newton iteration.
//!
//! The Jacobian is tridiagonal in p, bordered by the dense column ∂R/∂h0 and
//! the uniform row ∂G/∂p; one factorisation of the tridiagonal block serves
//! two right-hand sides and a scalar Schur complement gives Δh0: O(N).
//!
//! ## Four independent eliminations
//!
//! The elimination of a tridiagonal system is a chain of dependent
//! divisions, so the sweep is bound by the division's latency, not by the
//! arithmetic. The system is split in two blocks, rows [0, m) and [m, N)
//! with m = N/2 (the SPIKE partition), and each block is factored "twisted"
//! (eliminated from both of its ends towards a meeting row): four chains
//! whose latencies overlap. Dropping the two couplings between the blocks,
//! c_(m−1) (row m−1 to x_m) and a_m (row m to x_(m−1)), each block solves
//! its own part and one spike:
//!
//! ```text
//! A1 v = c_(m−1) e_last ,   A2 u = a_m e_first
//! x1 = y1 − x_m v ,         x2 = y2 − x_(m−1) u
//! x_(m−1) (1 − v_last u_first) = y1_last − v_last y2_first
//! ```
//!
//! The elimination within a block is the Thomas algorithm's, so its
//! stability is the Thomas algorithm's (diagonally dominant rows: the
//! spikes are below one in size and 1 − v_last u_first stays away from 0).

use super::border::{close_border, Border};
use super::work::{Factor, RowColumns, Work};

/// The partition of N rows into two twisted blocks.
#[derive(Debug, Clone, Copy)]
struct Plan {
    /// First row of the second block.
    m: usize,
    /// Meeting rows of the two blocks.
    k1: usize,
    k2: usize,
}

impl Plan {
    /// Meeting rows chosen so that each spike's row (m − 1 and m) starts a
    /// chain; needs N ≥ 4 (so that each block has two rows).
    fn new(n: usize) -> Self {
        let m = n / 2;
        Self {
            m,
            k1: (m - 1) / 2,
            k2: m + (n - m) / 2,
        }
    }
}

/// One elimination chain's running values: multiplier, then the partial
/// solutions for the border column, the residual and the spike.
#[derive(Debug, Clone, Copy, Default)]
struct Chain {
    p: f64,
    z: f64,
    y: f64,
    s: f64,
}

impl Chain {
    /// Eliminate row i, coupled by `fa` to the chain's previous row and by
    /// `fc` to its next (`coupling` = (fa, fc)); the spike's right-hand side
    /// is `srhs` here.
    #[inline(always)]
    fn step(
        &mut self,
        rows: &RowColumns,
        i: usize,
        coupling: (f64, f64),
        srhs: f64,
        f: &mut Factor,
        y: &mut f64,
    ) {
        let (fa, fc) = coupling;
        let inv = 1.0 / (rows.b[i] - fa * self.p);
        self.p = fc * inv;
        self.z = (rows.col[i] - fa * self.z) * inv;
        self.y = (rows.r[i] - fa * self.y) * inv;
        self.s = (srhs - fa * self.s) * inv;
        *f = Factor {
            fa,
            cp: self.p,
            inv_m: inv,
            z: self.z,
            s: self.s,
        };
        *y = self.y;
    }
}

/// Row i of a downward chain from `start` (j-th step) or of an upward chain.
#[inline(always)]
fn down(start: usize, j: usize) -> usize {
    start + j
}

#[inline(always)]
fn up(start: usize, j: usize) -> usize {
    start - j
}

/// The four elimination chains of both blocks, interleaved (block 1 from
/// its top and bottom towards row k1, block 2 likewise towards k2): each
/// row's factor into `fs`, its partial solution into `y`; returns the
/// chains' states at their meeting rows.
#[inline(always)]
fn sweep_chains(rows: &RowColumns, fs: &mut [Factor], y: &mut [f64], pl: Plan) -> [Chain; 4] {
    let (n, m, k1, k2) = (y.len(), pl.m, pl.k1, pl.k2);
    // Chain lengths: block 1 top 0..k1, bottom m−1..k1+1; block 2 top
    // m..k2, bottom n−1..k2+1.
    let lens = [k1, m - 1 - k1, k2 - m, n - 1 - k2];
    let longest = lens.iter().copied().max().unwrap_or(0);
    let mut ch = [Chain::default(); 4];
    // The spikes' right-hand sides start chains 1 and 2.
    let spike_rhs = [0.0, rows.c[m - 1], rows.a[m], 0.0];
    for j in 0..longest {
        if j < lens[0] {
            let i = down(0, j);
            ch[0].step(rows, i, (rows.a[i], rows.c[i]), 0.0, &mut fs[i], &mut y[i]);
        }
        if j < lens[1] {
            let i = up(m - 1, j);
            let srhs = if j == 0 { spike_rhs[1] } else { 0.0 };
            ch[1].step(rows, i, (rows.c[i], rows.a[i]), srhs, &mut fs[i], &mut y[i]);
        }
        if j < lens[2] {
            let i = down(m, j);
            let srhs = if j == 0 { spike_rhs[2] } else { 0.0 };
            ch[2].step(rows, i, (rows.a[i], rows.c[i]), srhs, &mut fs[i], &mut y[i]);
        }
        if j < lens[3] {
            let i = up(n - 1, j);
            ch[3].step(rows, i, (rows.c[i], rows.a[i]), 0.0, &mut fs[i], &mut y[i]);
        }
    }
    ch
}

/// Factor the bordered system and solve it for the Newton direction.
/// Direction into `w.dp`; returns Δh0, or None when the system is singular
/// or non-finite.
#[inline(always)]
pub(crate) fn factor_solve(w: &mut Work) -> Option<f64> {
    if w.banded {
        return super::banded::factor_solve(w);
    }
    let n = w.rows.len();
    let pl = Plan::new(n);
    let (m, k1, k2) = (pl.m, pl.k1, pl.k2);
    let rows = &w.rows;
    let fs = &mut w.factors[..n];
    let y = &mut w.dp[..n];
    let ch = sweep_chains(rows, fs, y, pl);
    // Meeting rows: the block's chains from above (a) and below (c). In the
    // first block the row below the meeting row is dropped at m (c_(m−1) is
    // the spike's), and likewise a_m in the second.
    for (k, top, bottom) in [(k1, ch[0], ch[1]), (k2, ch[2], ch[3])] {
        let (a, c) = (rows.a[k], rows.c[k]);
        let inv = 1.0 / (rows.b[k] - a * top.p - c * bottom.p);
        fs[k] = Factor {
            fa: 0.0,
            cp: 0.0,
            inv_m: inv,
            z: (rows.col[k] - a * top.z - c * bottom.z) * inv,
            s: (-a * top.s - c * bottom.s) * inv,
        };
        y[k] = (rows.r[k] - a * top.y - c * bottom.y) * inv;
    }
    // Back substitution outwards from each meeting row, with the sums of
    // each block's partial solutions.
    let mut sums = [[0.0f64; 3]; 2];
    back_substitute(fs, y, pl, &mut sums, true);
    // The interface unknowns x_(m−1), x_m for both right-hand sides, then
    // the spikes' corrections.
    let (v_last, u_first) = (fs[m - 1].s, fs[m].s);
    let det = 1.0 - v_last * u_first;
    let ym1 = (y[m - 1] - v_last * y[m]) / det;
    let ym = y[m] - u_first * ym1;
    let zm1 = (fs[m - 1].z - v_last * fs[m].z) / det;
    let zm = fs[m].z - u_first * zm1;
    for (f, yi) in fs[..m].iter_mut().zip(y[..m].iter_mut()) {
        *yi -= ym * f.s;
        f.z -= zm * f.s;
    }
    for (f, yi) in fs[m..].iter_mut().zip(y[m..].iter_mut()) {
        *yi -= ym1 * f.s;
        f.z -= zm1 * f.s;
    }
    let [[sy1, sz1, ss1], [sy2, sz2, ss2]] = sums;
    let sy = (sy1 - ym * ss1) + (sy2 - ym1 * ss2);
    let sz = (sz1 - zm * ss1) + (sz2 - zm1 * ss2);
    if !(sz.is_finite() && sy.is_finite() && det.is_finite() && det != 0.0) {
        return None;
    }
    let border = Border {
        balance: w.balance,
        dgdh: w.dgdh,
        c_row: w.c_row,
        g: w.g,
    };
    close_border(border, y, fs.iter().map(|f| f.z), (sy, sz), &mut w.schur)
}

/// Back substitution of both blocks outwards from their meeting rows (four
/// chains interleaved): y always, z and the spike when `all` (a fresh
/// factorisation; with old factors only y changes). Accumulates per block
/// the sums of y, z and the spike.
#[inline(always)]
fn back_substitute(
    fs: &mut [Factor],
    y: &mut [f64],
    pl: Plan,
    sums: &mut [[f64; 3]; 2],
    all: bool,
) {
    let n = y.len();
    let (m, k1, k2) = (pl.m, pl.k1, pl.k2);
    // Outward lengths: block 1 up k1..0, down k1..m−1; block 2 up k2..m,
    // down k2..n−1.
    let lens = [k1, m - 1 - k1, k2 - m, n - 1 - k2];
    let longest = lens.iter().copied().max().unwrap_or(0);
    let seed = |k: usize, fs: &[Factor], y: &[f64]| (fs[k].z, y[k], fs[k].s);
    let mut prev = [
        seed(k1, fs, y),
        seed(k1, fs, y),
        seed(k2, fs, y),
        seed(k2, fs, y),
    ];
    for (b, k) in [(0, k1), (1, k2)] {
        sums[b] = [y[k], fs[k].z, fs[k].s];
    }
    let mut apply =
        |c: usize, i: usize, fs: &mut [Factor], y: &mut [f64], sums: &mut [[f64; 3]; 2]| {
            let f = &mut fs[i];
            let (pz, py, ps) = prev[c];
            y[i] -= f.cp * py;
            if all {
                f.z -= f.cp * pz;
                f.s -= f.cp * ps;
            }
            prev[c] = (f.z, y[i], f.s);
            let b = &mut sums[c / 2];
            b[0] += y[i];
            b[1] += f.z;
            b[2] += f.s;
        };
    for j in 1..=longest {
        if j <= lens[0] {
            apply(0, k1 - j, fs, y, sums);
        }
        if j <= lens[1] {
            apply(1, k1 + j, fs, y, sums);
        }
        if j <= lens[2] {
            apply(2, k2 - j, fs, y, sums);
        }
        if j <= lens[3] {
            apply(3, k2 + j, fs, y, sums);
        }
    }
}

/// Simplified Newton direction: the current residual (rows' r, w.g) with the
/// stored (old) factors, into `w.dbar`. Returns Δh0.
#[inline(always)]
pub(crate) fn direction_with_old_factors(w: &mut Work) -> f64 {
    if w.banded {
        return super::banded::direction_with_old_factors(w);
    }
    let n = w.rows.len();
    let pl = Plan::new(n);
    let (m, k1, k2) = (pl.m, pl.k1, pl.k2);
    let rows = &w.rows;
    let fs = &mut w.factors[..n];
    let y = &mut w.dbar[..n];
    let lens = [k1, m - 1 - k1, k2 - m, n - 1 - k2];
    let longest = lens.iter().copied().max().unwrap_or(0);
    let mut yc = [0.0f64; 4];
    for j in 0..longest {
        let mut go = |c: usize, i: usize, fs: &[Factor], y: &mut [f64]| {
            yc[c] = (rows.r[i] - fs[i].fa * yc[c]) * fs[i].inv_m;
            y[i] = yc[c];
        };
        if j < lens[0] {
            go(0, down(0, j), fs, y);
        }
        if j < lens[1] {
            go(1, up(m - 1, j), fs, y);
        }
        if j < lens[2] {
            go(2, down(m, j), fs, y);
        }
        if j < lens[3] {
            go(3, up(n - 1, j), fs, y);
        }
    }
    for (k, top, bottom) in [(k1, yc[0], yc[1]), (k2, yc[2], yc[3])] {
        y[k] = (rows.r[k] - rows.a[k] * top - rows.c[k] * bottom) * fs[k].inv_m;
    }
    let mut sums = [[0.0f64; 3]; 2];
    back_substitute(fs, y, pl, &mut sums, false);
    let (v_last, u_first) = (fs[m - 1].s, fs[m].s);
    let ym1 = (y[m - 1] - v_last * y[m]) / (1.0 - v_last * u_first);
    let ym = y[m] - u_first * ym1;
    for (f, yi) in fs[..m].iter().zip(y[..m].iter_mut()) {
        *yi -= ym * f.s;
    }
    for (f, yi) in fs[m..].iter().zip(y[m..].iter_mut()) {
        *yi -= ym1 * f.s;
    }
    let [[sy1, _, ss1], [sy2, _, ss2]] = sums;
    let sy = (sy1 - ym * ss1) + (sy2 - ym1 * ss2);
    if w.balance {
        let dh = (-w.g + w.c_row * sy) / w.schur;
        for (v, f) in y.iter_mut().zip(fs.iter()) {
            *v = -*v - f.z * dh;
        }
        dh
    } else {
        for v in y.iter_mut() {
            *v = -*v;
        }
        0.0
    }
}
