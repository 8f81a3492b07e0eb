//! Statistics at the optimum, from the Jacobian in scaled coordinates.
//!
//! | symbol | meaning |
//! |---|---|
//! | J | ∂r/∂s, residuals against scaled parameters (ln p or p), by differences |
//! | σ² | Σr² / (m − n): residual variance, m fitted samples, n parameters |
//! | C | σ² (JᵀJ)⁻¹: covariance of s |
//! | SE(p) | p·√C_jj on the log scale, √C_jj on the linear scale |
//! | 95 % interval | s ± 1.96 √C_jj, mapped back to p |
//! | ρ_ij | C_ij / √(C_ii C_jj) |
//!
//! A pair with |ρ| > 0.95 is not separately identifiable from these data;
//! a parameter at a bound has no meaningful standard error.

use super::problem::Problem;
use nalgebra::DMatrix;
use rayon::prelude::*;

/// Correlations above this are flagged.
pub const CORRELATION_FLAG: f64 = 0.95;

/// Statistics of a fit at its best point.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Statistics {
    /// Standard error of each parameter (its own unit).
    pub standard_error: Vec<f64>,
    /// 95 % interval of each parameter.
    pub interval95: Vec<(f64, f64)>,
    /// Correlation matrix, row-major.
    pub correlation: Vec<Vec<f64>>,
    /// Residual standard deviation σ, N.
    pub sigma: f64,
    /// JᵀJ was singular: some parameters do not change the residual at all.
    pub rank_deficient: bool,
    /// Parameters at a bound.
    pub at_bound: Vec<bool>,
}

impl Statistics {
    /// Parameter `j`'s 95 % interval; (NaN, NaN) where it was not
    /// computed (a fit that stopped before its statistics).
    pub fn interval95_of(&self, j: usize) -> (f64, f64) {
        self.interval95
            .get(j)
            .copied()
            .unwrap_or((f64::NAN, f64::NAN))
    }

    /// Parameter `j`'s standard error; NaN where it was not computed.
    pub fn standard_error_of(&self, j: usize) -> f64 {
        self.standard_error.get(j).copied().unwrap_or(f64::NAN)
    }

    /// Pairs (i, j, ρ) with |ρ| above [`CORRELATION_FLAG`].
    pub fn correlated_pairs(&self) -> Vec<(usize, usize, f64)> {
        let n = self.correlation.len();
        let mut out = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                let r = self.correlation[i][j];
                if r.abs() > CORRELATION_FLAG || r.is_nan() {
                    out.push((i, j, r));
                }
            }
        }
        out
    }
}

/// Relative step of the differences, of each scaled range.
const STEP: f64 = 1e-4;

/// The residuals at `x` and their Jacobian in scaled coordinates (central
/// differences, one-sided at a bound).
pub fn jacobian(problem: &Problem<'_>, x: &[f64]) -> (Vec<f64>, DMatrix<f64>) {
    let n = x.len();
    let r0 = problem.residuals(x);
    let m = r0.len();
    let columns: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map(|j| {
            let p = &problem.params[j];
            let (a, b) = p.scaled_bounds();
            let s = p.scaled(x[j]);
            let h = STEP * (b - a);
            let at = |s: f64| {
                let mut y = x.to_vec();
                y[j] = p.unscaled(s).clamp(p.lo, p.hi);
                problem.residuals(&y)
            };
            let (lo, hi) = (
                if s - h >= a { s - h } else { s },
                if s + h <= b { s + h } else { s },
            );
            let (rl, rh) = (
                if lo < s { at(lo) } else { r0.clone() },
                if hi > s { at(hi) } else { r0.clone() },
            );
            rh.iter()
                .zip(&rl)
                .map(|(u, v)| (u - v) / (hi - lo))
                .collect()
        })
        .collect();
    let jac = DMatrix::from_fn(m, n, |i, j| columns[j][i]);
    (r0, jac)
}

/// Statistics at `x` from its residuals `r0` and Jacobian `jac`.
pub fn from_jacobian(
    problem: &Problem<'_>,
    x: &[f64],
    r0: &[f64],
    jac: &DMatrix<f64>,
) -> Statistics {
    let (m, n) = jac.shape();
    let jtj = jac.transpose() * jac;
    let dof = m.saturating_sub(n).max(1) as f64;
    let sigma2 = r0.iter().map(|r| r * r).sum::<f64>() / dof;
    let (inv, rank_deficient) = match jtj.clone().cholesky() {
        Some(c) => (c.inverse(), false),
        None => {
            let tol = 1e-12 * jtj.norm();
            let pinv = jtj
                .pseudo_inverse(tol)
                .unwrap_or_else(|_| DMatrix::from_element(n, n, f64::NAN));
            (pinv, true)
        }
    };
    let cov = inv * sigma2;
    let mut standard_error = Vec::with_capacity(n);
    let mut interval95 = Vec::with_capacity(n);
    for (j, p) in problem.params.iter().enumerate() {
        let se_s = if rank_deficient {
            f64::INFINITY
        } else {
            cov[(j, j)].max(0.0).sqrt()
        };
        let s = p.scaled(x[j]);
        standard_error.push(if p.log { x[j] * se_s } else { se_s });
        interval95.push((p.unscaled(s - 1.96 * se_s), p.unscaled(s + 1.96 * se_s)));
    }
    let correlation = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| cov[(i, j)] / (cov[(i, i)] * cov[(j, j)]).sqrt())
                .collect()
        })
        .collect();
    Statistics {
        standard_error,
        interval95,
        correlation,
        sigma: sigma2.sqrt(),
        rank_deficient,
        at_bound: problem
            .params
            .iter()
            .zip(x)
            .map(|(p, v)| p.at_bound(*v))
            .collect(),
    }
}
