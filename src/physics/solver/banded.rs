//! The bordered linear solve when the rows are pentadiagonal (a MUSCL
//! Couette flux, `flux.rs`): row i couples p_(i−2) … p_(i+2) (one of the
//! outer diagonals is zero, by the sign of v), bordered by the dense column
//! ∂R/∂h0 and the uniform row ∂G/∂p as in `bordered.rs`.
//!
//! Banded LU without pivoting, one sweep down and one up: O(N), with the
//! same Schur complement for Δh0 as the tridiagonal solve:
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

use super::work::{BandFactor, Work};

/// Factor the bordered pentadiagonal system and solve it for the Newton
/// direction. Direction into `w.dp`; returns Δh0, or None when the system
/// is singular or non-finite.
#[inline(always)]
pub(crate) fn factor_solve(w: &mut Work) -> Option<f64> {
    let n = w.rows.len();
    let rows = &w.rows;
    let fs = &mut w.band[..n];
    let y = &mut w.dp[..n];
    let (mut f1, mut f2) = (BandFactor::default(), BandFactor::default());
    let (mut y1, mut y2) = (0.0, 0.0);
    for i in 0..n {
        // Row i minus l2 × U-row (i−2) minus l1 × U-row (i−1).
        let l2 = rows.a2[i] * f2.inv_d;
        let a = rows.a[i] - l2 * f2.u1;
        let b = rows.b[i] - l2 * f2.u2;
        let l1 = a * f1.inv_d;
        let d = b - l1 * f1.u1;
        let inv_d = 1.0 / d;
        let f = BandFactor {
            l2,
            l1,
            inv_d,
            u1: rows.c[i] - l1 * f1.u2,
            u2: rows.c2[i],
            z: rows.col[i] - l2 * f2.z - l1 * f1.z,
        };
        let yi = rows.r[i] - l2 * y2 - l1 * y1;
        fs[i] = f;
        y[i] = yi;
        (f2, f1) = (f1, f);
        (y2, y1) = (y1, yi);
    }
    let (sy, sz) = back_substitute(fs, y, true);
    if !(sy.is_finite() && sz.is_finite()) {
        return None;
    }
    if !w.balance {
        for v in y.iter_mut() {
            *v = -*v;
        }
        return Some(0.0);
    }
    w.schur = w.dgdh - w.c_row * sz;
    if !(w.schur.is_finite() && w.schur != 0.0) {
        return None;
    }
    let dh = (-w.g + w.c_row * sy) / w.schur;
    for (v, f) in y.iter_mut().zip(fs.iter()) {
        *v = -*v - f.z * dh;
    }
    Some(dh)
}

/// The upward sweep: y (and z when `all`, a fresh factorisation) from the
/// forward-eliminated values; returns their sums.
#[inline(always)]
fn back_substitute(fs: &mut [BandFactor], y: &mut [f64], all: bool) -> (f64, f64) {
    let (mut y1, mut y2, mut z1, mut z2) = (0.0, 0.0, 0.0, 0.0);
    let (mut sy, mut sz) = (0.0, 0.0);
    for (f, yi) in fs.iter_mut().zip(y.iter_mut()).rev() {
        *yi = (*yi - f.u1 * y1 - f.u2 * y2) * f.inv_d;
        (y2, y1) = (y1, *yi);
        sy += *yi;
        if all {
            f.z = (f.z - f.u1 * z1 - f.u2 * z2) * f.inv_d;
            (z2, z1) = (z1, f.z);
            sz += f.z;
        }
    }
    (sy, sz)
}

/// Simplified Newton direction: the current residual with the stored (old)
/// factors, into `w.dbar`. Returns Δh0.
#[inline(always)]
pub(crate) fn direction_with_old_factors(w: &mut Work) -> f64 {
    let n = w.rows.len();
    let fs = &mut w.band[..n];
    let y = &mut w.dbar[..n];
    let (mut y1, mut y2) = (0.0, 0.0);
    for ((f, yi), r) in fs.iter().zip(y.iter_mut()).zip(&w.rows.r[..n]) {
        *yi = r - f.l2 * y2 - f.l1 * y1;
        (y2, y1) = (y1, *yi);
    }
    let (sy, _) = back_substitute(fs, y, false);
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
