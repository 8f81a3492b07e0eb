//! The bordered linear solve when the rows are pentadiagonal (a MUSCL
//! Couette flux, `flux.rs`): row i couples p_(i−2) … p_(i+2) (one of the
//! outer diagonals is zero, by the sign of v), bordered by the dense column
//! ∂R/∂h0 and the uniform row ∂G/∂p as in `bordered.rs`.
//!
//! Banded elimination without pivoting, "twisted" like `bordered.rs`: rows
//! above the meeting row k = N/2 are eliminated downwards (LU), rows below
//! it upwards (UL), so two chains of dependent divisions overlap instead of
//! one running N long. With v ≥ 0 the rows hold (a2, a, b, c): the
//! downward chain keeps the band, and so does the upward one (eliminating
//! c_j with row j + 1 changes only a_j and b_j). With v < 0 the rows hold
//! (a, b, c, c2), which is the same shape read from the last row to the
//! first; the solve runs on that reversed order. Then the same Schur
//! complement for Δh0 as the tridiagonal solve:
//!
//! ```text
//! A y = R ,  A z = ∂R/∂h0 ,  S = ∂G/∂h0 − c Σ z ,
//! Δh0 = (−G + c Σ y) / S ,   Δp = −y − z Δh0
//! ```
//!
//! The upwind part of the Jacobian is an M-matrix (diagonally dominant by
//! columns); the limited slope adds at most half the upwind cell's Couette
//! derivative off the diagonal, so the pivots stay those of a dominant
//! matrix and no pivoting is needed (a zero or non-finite pivot gives None,
//! as in `bordered.rs`).

use super::border::{close_border, Border};
use super::work::{BandFactor, RowColumns, Work};

/// Row i of the system in solve order (reversed when v < 0), as
/// (two left, left, diagonal, right, border column, residual).
#[inline(always)]
fn row<const REV: bool>(rows: &RowColumns, n: usize, i: usize) -> [f64; 6] {
    if REV {
        let j = n - 1 - i;
        [
            rows.c2[j],
            rows.c[j],
            rows.b[j],
            rows.a[j],
            rows.col[j],
            rows.r[j],
        ]
    } else {
        [
            rows.a2[i],
            rows.a[i],
            rows.b[i],
            rows.c[i],
            rows.col[i],
            rows.r[i],
        ]
    }
}

/// Storage index of solve-order row i.
#[inline(always)]
fn at<const REV: bool>(n: usize, i: usize) -> usize {
    if REV {
        n - 1 - i
    } else {
        i
    }
}

/// Factor the bordered pentadiagonal system and solve it for the Newton
/// direction. Direction into `w.dp`; returns Δh0, or None when the system
/// is singular or non-finite.
#[inline(always)]
pub(crate) fn factor_solve(w: &mut Work) -> Option<f64> {
    w.band_reversed = w.rows.reversed;
    let (sy, sz) = if w.band_reversed {
        factor::<true>(w)
    } else {
        factor::<false>(w)
    };
    if !(sy.is_finite() && sz.is_finite()) {
        return None;
    }
    let border = Border {
        balance: w.balance,
        dgdh: w.dgdh,
        c_row: w.c_row,
        g: w.g,
    };
    let y = &mut w.dp[..w.rows.len()];
    close_border(border, y, w.band_z.iter().copied(), (sy, sz), &mut w.schur)
}

/// The two eliminations and the meeting row; y into `w.dp`, z into
/// `w.band_z` (storage order). Returns (Σ y, Σ z).
#[inline(always)]
fn factor<const REV: bool>(w: &mut Work) -> (f64, f64) {
    let n = w.rows.len();
    let k = n / 2;
    let rows = &w.rows;
    let fs = &mut w.band[..n];
    let y = &mut w.dp[..n];
    let z = &mut w.band_z[..n];
    // Downward (rows 0..k): running (1/d, c, y, z) of the two rows above.
    let (mut t1, mut t2) = ([0.0f64; 4], [0.0f64; 4]);
    // Upward (rows n−1..k+1): running (1/b', a', a2, y', z') of the row below.
    let mut u1 = [0.0f64; 5];
    let up_len = n - 1 - k;
    for j in 0..k.max(up_len) {
        if j < k {
            let i = j;
            let [ra2, ra, rb, rc, rcol, rr] = row::<REV>(rows, n, i);
            let l2 = ra2 * t2[0];
            let l1 = (ra - l2 * t2[1]) * t1[0];
            let inv = 1.0 / (rb - l1 * t1[1]);
            let yi = rr - l2 * t2[2] - l1 * t1[2];
            let zi = rcol - l2 * t2[3] - l1 * t1[3];
            fs[i] = BandFactor {
                l2,
                l1,
                inv_d: inv,
                u1: rc,
                u2: 0.0,
            };
            y[at::<REV>(n, i)] = yi;
            z[at::<REV>(n, i)] = zi;
            t2 = t1;
            t1 = [inv, rc, yi, zi];
        }
        if j < up_len {
            let i = n - 1 - j;
            let [ra2, ra, rb, rc, rcol, rr] = row::<REV>(rows, n, i);
            let mu = rc * u1[0];
            let inv = 1.0 / (rb - mu * u1[1]);
            let a = ra - mu * u1[2];
            let yi = rr - mu * u1[3];
            let zi = rcol - mu * u1[4];
            fs[i] = BandFactor {
                l2: 0.0,
                l1: mu,
                inv_d: inv,
                u1: a,
                u2: ra2,
            };
            y[at::<REV>(n, i)] = yi;
            z[at::<REV>(n, i)] = zi;
            u1 = [inv, a, ra2, yi, zi];
        }
    }
    // The meeting row: its right neighbour from the row below, its two
    // left ones from the rows above.
    let [ra2, ra, rb, rc, rcol, rr] = row::<REV>(rows, n, k);
    let mu = rc * u1[0];
    let (b, a) = (rb - mu * u1[1], ra - mu * u1[2]);
    let l2 = ra2 * t2[0];
    let l1 = (a - l2 * t2[1]) * t1[0];
    let inv = 1.0 / (b - l1 * t1[1]);
    y[at::<REV>(n, k)] = (rr - mu * u1[3] - l2 * t2[2] - l1 * t1[2]) * inv;
    z[at::<REV>(n, k)] = (rcol - mu * u1[4] - l2 * t2[3] - l1 * t1[3]) * inv;
    fs[k] = BandFactor {
        l2,
        l1,
        inv_d: inv,
        u1: 0.0,
        u2: mu,
    };
    back_substitute::<REV>(fs, y, Some(z), k)
}

/// From the meeting row outwards: x_i = (y_i − u1 x_(i+1)) / d_i above it,
/// x_j = (y'_j − a'_j x_(j−1) − a2_j x_(j−2)) / b'_j below it, for y and,
/// when given, z: up to four independent chains interleaved. Returns
/// (Σ y, Σ z).
#[inline(always)]
fn back_substitute<const REV: bool>(
    fs: &[BandFactor],
    y: &mut [f64],
    mut z: Option<&mut [f64]>,
    k: usize,
) -> (f64, f64) {
    let n = y.len();
    let kk = at::<REV>(n, k);
    let y_k = y[kk];
    let z_k = z.as_ref().map_or(0.0, |z| z[kk]);
    let (mut sy, mut sz) = (y_k, z_k);
    // Above: the row below's x; below: the two rows above's (x_(k−1) is
    // the above chain's first, set at j = 0 before the below chain reads it).
    let (mut ya, mut za) = (y_k, z_k);
    let (mut yb, mut zb) = ([y_k, 0.0], [z_k, 0.0]);
    for j in 0..k.max(n - 1 - k) {
        if j < k {
            let i = k - 1 - j;
            let (f, s) = (&fs[i], at::<REV>(n, i));
            ya = (y[s] - f.u1 * ya) * f.inv_d;
            y[s] = ya;
            sy += ya;
            if let Some(z) = z.as_deref_mut() {
                za = (z[s] - f.u1 * za) * f.inv_d;
                z[s] = za;
                sz += za;
            }
            if j == 0 {
                (yb[1], zb[1]) = (ya, za);
            }
        }
        if k + 1 + j < n {
            let i = k + 1 + j;
            let (f, s) = (&fs[i], at::<REV>(n, i));
            let yi = (y[s] - f.u1 * yb[0] - f.u2 * yb[1]) * f.inv_d;
            y[s] = yi;
            yb = [yi, yb[0]];
            sy += yi;
            if let Some(z) = z.as_deref_mut() {
                let zi = (z[s] - f.u1 * zb[0] - f.u2 * zb[1]) * f.inv_d;
                z[s] = zi;
                zb = [zi, zb[0]];
                sz += zi;
            }
        }
    }
    (sy, sz)
}

/// Simplified Newton direction: the current residual with the stored (old)
/// factors, into `w.dbar`. Returns Δh0.
#[inline(always)]
pub(crate) fn direction_with_old_factors(w: &mut Work) -> f64 {
    let sy = if w.band_reversed {
        old_factors::<true>(w)
    } else {
        old_factors::<false>(w)
    };
    let y = &mut w.dbar[..w.rows.len()];
    if w.balance {
        let dh = (-w.g + w.c_row * sy) / w.schur;
        for (v, z) in y.iter_mut().zip(&w.band_z) {
            *v = -*v - z * dh;
        }
        dh
    } else {
        for v in y.iter_mut() {
            *v = -*v;
        }
        0.0
    }
}

/// y = A⁻¹ r with the stored factors, into `w.dbar`; returns Σ y.
#[inline(always)]
fn old_factors<const REV: bool>(w: &mut Work) -> f64 {
    let n = w.rows.len();
    let k = n / 2;
    let fs = &w.band[..n];
    let r = &w.rows.r[..n];
    let y = &mut w.dbar[..n];
    let (mut y1, mut y2) = (0.0, 0.0);
    for (i, f) in fs[..k].iter().enumerate() {
        let yi = r[at::<REV>(n, i)] - f.l2 * y2 - f.l1 * y1;
        y[at::<REV>(n, i)] = yi;
        (y2, y1) = (y1, yi);
    }
    let mut yb = 0.0;
    for i in (k + 1..n).rev() {
        yb = r[at::<REV>(n, i)] - fs[i].l1 * yb;
        y[at::<REV>(n, i)] = yb;
    }
    let f = &fs[k];
    y[at::<REV>(n, k)] = (r[at::<REV>(n, k)] - f.u2 * yb - f.l2 * y2 - f.l1 * y1) * f.inv_d;
    back_substitute::<REV>(fs, y, None, k).0
}

#[cfg(test)]
mod banded_tests {
    //! The banded bordered solve equals a dense solve of the same system.
    use super::super::work::Work;
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::{DMatrix, DVector};
    use proptest::prelude::*;

    /// The dense (N + 1)² matrix of the bordered system in `w` and its
    /// right-hand side.
    fn dense(w: &Work) -> (DMatrix<f64>, DVector<f64>) {
        let n = w.rows.len();
        let r = &w.rows;
        let mut m = DMatrix::zeros(n + 1, n + 1);
        let mut rhs = DVector::zeros(n + 1);
        for i in 0..n {
            m[(i, i)] = r.b[i];
            if i >= 1 {
                m[(i, i - 1)] = r.a[i];
            }
            if i >= 2 {
                m[(i, i - 2)] = r.a2[i];
            }
            if i + 1 < n {
                m[(i, i + 1)] = r.c[i];
            }
            if i + 2 < n {
                m[(i, i + 2)] = r.c2[i];
            }
            m[(i, n)] = r.col[i];
            m[(n, i)] = w.c_row;
            rhs[i] = -r.r[i];
        }
        m[(n, n)] = w.dgdh;
        rhs[n] = -w.g;
        (m, rhs)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Diagonally dominant pentadiagonal rows with one outer diagonal
        /// (either side), a border: the banded solve, fresh and with old
        /// factors, equals nalgebra's LU.
        #[test]
        fn the_banded_bordered_solve_equals_a_dense_solve(
            n in 4usize..40,
            seed in prop::collection::vec(-1.0..1.0f64, 240),
            lower in any::<bool>(),
        ) {
            let mut w = Work::new(n);
            let s = |k: usize| seed[k % seed.len()];
            for i in 0..n {
                let outer = 0.4 * s(5 * i);
                w.rows.a[i] = if i > 0 { -1.0 + 0.3 * s(5 * i + 1) } else { 0.0 };
                w.rows.c[i] = if i + 1 < n { -0.5 + 0.3 * s(5 * i + 2) } else { 0.0 };
                w.rows.a2[i] = if lower && i >= 2 { outer } else { 0.0 };
                w.rows.c2[i] = if !lower && i + 2 < n { outer } else { 0.0 };
                w.rows.b[i] = 3.0 + s(5 * i + 3);
                w.rows.col[i] = s(5 * i + 4);
                w.rows.r[i] = s(7 * i + 11);
            }
            w.rows.reversed = !lower;
            w.c_row = -0.7;
            w.dgdh = 5.0;
            w.g = 0.3;
            w.balance = true;
            let (m, rhs) = dense(&w);
            let x = m.lu().solve(&rhs).expect("a regular matrix");
            let dh = factor_solve(&mut w).expect("a regular system");
            assert_relative_eq!(dh, x[n], epsilon = 1e-12, max_relative = 1e-9);
            for i in 0..n {
                assert_relative_eq!(w.dp[i], x[i], epsilon = 1e-12, max_relative = 1e-9);
            }
            // Old factors, same residual: the same direction.
            let dhb = direction_with_old_factors(&mut w);
            assert_relative_eq!(dhb, dh, epsilon = 1e-12, max_relative = 1e-9);
            for i in 0..n {
                assert_relative_eq!(w.dbar[i], w.dp[i], epsilon = 1e-12, max_relative = 1e-9);
            }
        }
    }
}
