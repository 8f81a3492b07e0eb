//! Statistics at the optimum, from the Jacobian in scaled coordinates.
//!
//! | symbol | meaning |
//! |---|---|
//! | J | ∂r/∂s, residuals against scaled parameters (ln p or p), by differences |
//! | σ² | Σr² / (m − n): residual variance, m fitted samples, n parameters |
//! | C₀ | σ² (JᵀJ)⁻¹: covariance of s for independent residuals |
//! | S_b | Σ_{t∈b} J_tᵀ r_t: the score of batch b |
//! | C_B | B/(B − n) (JᵀJ)⁻¹ (Σ_b S_b S_bᵀ) (JᵀJ)⁻¹: covariance of s from B batches |
//! | C_jj | C₀_jj, or max(C₀_jj, C_B_jj) where a time series is fitted |
//! | SE(p) | p·√C_jj on the log scale, √C_jj on the linear scale |
//! | 95 % interval | s ± 1.96 √C_jj, mapped back to p |
//! | ρ_ij | C₀_ij / √(C₀_ii C₀_jj) |
//!
//! **Correlated residuals.** The samples of a time series are consecutive
//! at a high rate: what no model has (a ripple, a drive's dynamics, the
//! filter that made the friction) leaves residuals that are alike for
//! hundreds of samples, and C₀, which counts every sample as news, is then
//! far too narrow (±0.5 % on a Stribeck speed that 40 000 samples of a
//! rippled joint did not pin, `docs/fit-auto-judged.md`, stop 88). Where
//! a time series is fitted, its residuals are cut into [`BATCHES`]
//! contiguous batches and the covariance is estimated from the batches'
//! scores, the sandwich of batch means (the long-run covariance of
//! Newey–West's heteroskedasticity and autocorrelation consistent
//! estimators, with batches for the kernel): each batch is about
//! independent of the others when the residuals' memory is shorter than
//! a batch. A steady curve's points are each a batch of their own (they
//! are separate steady states). A variance is never taken below C₀'s:
//! with tens of batches C_B is itself noisy, and positively correlated
//! residuals only widen it. Rules 9 and 9b (`admission.rs`) read these
//! intervals: a term is admitted, or a bend shown, only on what the
//! samples' independent information tells.
//!
//! ρ stays C₀'s, a property of the design J: a pair with |ρ| > 0.95 is
//! not separately identifiable from these data whatever the noise; a
//! parameter at a bound has no meaningful standard error.

use super::problem::Problem;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::ops::Range;

/// Correlations above this are flagged.
pub const CORRELATION_FLAG: f64 = 0.95;

/// Contiguous batches a time series' residuals are cut into for its
/// covariance: the 10–30 of the batch-means literature, a few more so that
/// B − n stays well above zero for the ten-odd keys a fit may have.
pub const BATCHES: usize = 32;

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
    /// Batches the standard errors were estimated from (a time series'
    /// [`BATCHES`] each, a steady point one); 0: independent residuals
    /// (only steady curves were fitted).
    pub batches: usize,
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
    let cov = &inv * sigma2;
    // A rank-deficient fit has no finite error to estimate.
    let (variance, batches) = if rank_deficient {
        (vec![f64::INFINITY; n], 0)
    } else {
        variances(jac, r0, &inv, sigma2, problem.fitted_by_source())
    };
    let mut standard_error = Vec::with_capacity(n);
    let mut interval95 = Vec::with_capacity(n);
    for (j, p) in problem.params.iter().enumerate() {
        let se_s = variance[j].max(0.0).sqrt();
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
        batches,
    }
}

/// Each scaled parameter's variance C_jj (see the module's table) and the
/// batches it was estimated from (0: C₀'s alone, every source a steady
/// curve or too few batches for the parameters). `inv` is (JᵀJ)⁻¹.
fn variances(
    jac: &DMatrix<f64>,
    r0: &[f64],
    inv: &DMatrix<f64>,
    sigma2: f64,
    fitted_by_source: &[(usize, bool)],
) -> (Vec<f64>, usize) {
    let n = jac.ncols();
    let independent = (0..n).map(|j| sigma2 * inv[(j, j)]);
    match batches(fitted_by_source) {
        Some(b) if b.len() > n => {
            let long_run = batch_covariance(jac, r0, inv, &b);
            let v = independent
                .enumerate()
                .map(|(j, c)| c.max(long_run[(j, j)]))
                .collect();
            (v, b.len())
        }
        _ => (independent.collect(), 0),
    }
}

/// The residuals' batches (index ranges) where some source is a time
/// series: each time series cut into [`BATCHES`] contiguous batches (fewer
/// when it has fewer samples), each steady point a batch of its own. None
/// when every source is a steady curve (C₀ holds).
fn batches(fitted_by_source: &[(usize, bool)]) -> Option<Vec<Range<usize>>> {
    if fitted_by_source.iter().all(|(_, steady)| *steady) {
        return None;
    }
    let mut out = Vec::new();
    let mut at = 0;
    for &(len, steady) in fitted_by_source {
        if steady {
            out.extend((at..at + len).map(|k| k..k + 1));
        } else {
            out.extend(contiguous(len, BATCHES).map(|r| at + r.start..at + r.end));
        }
        at += len;
    }
    Some(out)
}

/// `parts` contiguous ranges covering 0..len, as equal as the length
/// allows (one per index when there are fewer indices; none when len is 0).
pub(super) fn contiguous(len: usize, parts: usize) -> impl Iterator<Item = Range<usize>> {
    let b = parts.min(len);
    (0..b).map(move |i| i * len / b..(i + 1) * len / b)
}

/// C_B: the covariance of the scaled parameters from the batches' scores,
/// B/(B − n) (JᵀJ)⁻¹ (Σ_b S_b S_bᵀ) (JᵀJ)⁻¹ (see the module's table).
/// `inv` is (JᵀJ)⁻¹; `batches` has more than n batches.
fn batch_covariance(
    jac: &DMatrix<f64>,
    r0: &[f64],
    inv: &DMatrix<f64>,
    batches: &[Range<usize>],
) -> DMatrix<f64> {
    let n = jac.ncols();
    let mut meat = DMatrix::<f64>::zeros(n, n);
    let mut score = DVector::<f64>::zeros(n);
    for b in batches {
        score.fill(0.0);
        for t in b.clone() {
            for j in 0..n {
                score[j] += jac[(t, j)] * r0[t];
            }
        }
        meat.ger(1.0, &score, &score, 1.0);
    }
    let b = batches.len() as f64;
    inv * meat * inv * (b / (b - n as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The variance of a mean estimated from `r` (J a column of ones, the
    /// residuals `r` about it) as one time series, and its batches.
    fn mean_variance(r: &[f64]) -> (f64, usize) {
        let m = r.len();
        let jac = DMatrix::from_element(m, 1, 1.0);
        let inv = DMatrix::from_element(1, 1, 1.0 / m as f64);
        let sigma2 = r.iter().map(|x| x * x).sum::<f64>() / (m - 1) as f64;
        let (v, b) = variances(&jac, r, &inv, sigma2, &[(m, false)]);
        (v[0], b)
    }

    #[test]
    fn a_time_series_is_cut_into_contiguous_batches_and_a_steady_point_is_a_batch_of_its_own() {
        assert_eq!(batches(&[(10, true), (5, true)]), None);
        let b = batches(&[(3, true), (100, false)]).unwrap();
        assert_eq!(b.len(), 3 + BATCHES);
        assert_eq!(&b[..3], &[0..1, 1..2, 2..3]);
        assert_eq!(b[3].start, 3);
        assert_eq!(b.last().unwrap().end, 103);
        assert!(b.windows(2).all(|w| w[0].end == w[1].start));
        assert!(b[3..].iter().all(|r| (3..=4).contains(&r.len())), "{b:?}");
        // Fewer samples than batches: each sample its own.
        assert_eq!(batches(&[(5, false)]).unwrap().len(), 5);
    }

    #[test]
    fn residuals_alike_over_each_batch_count_as_one_sample_per_batch() {
        // 32 batches of L = 50 samples, each batch at +1 or −1: the mean's
        // variance is 1/(B − 1), not the 1/(m − 1) of independent samples.
        let l = 50;
        let r: Vec<f64> = (0..BATCHES * l)
            .map(|t| if (t / l) % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let (v, b) = mean_variance(&r);
        assert_eq!(b, BATCHES);
        assert_relative_eq!(v, 1.0 / (BATCHES as f64 - 1.0), max_relative = 1e-12);
        let independent = 1.0 / (r.len() as f64 - 1.0);
        assert_relative_eq!(
            v / independent,
            (r.len() - 1) as f64 / 31.0,
            max_relative = 1e-12
        );
    }

    #[test]
    fn residuals_that_cancel_within_each_batch_keep_the_variance_of_independent_samples() {
        // Alternating ±1: every batch's score is zero, C_B = 0, and the
        // variance is never taken below C₀'s.
        let r: Vec<f64> = (0..BATCHES * 50)
            .map(|t| if t % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let (v, _) = mean_variance(&r);
        assert_relative_eq!(v, 1.0 / (r.len() as f64 - 1.0), max_relative = 1e-12);
    }

    #[test]
    fn only_steady_curves_keep_the_variance_of_independent_samples() {
        let r = [1.0, 1.0, -1.0, -1.0, 1.0, 1.0];
        let jac = DMatrix::from_element(6, 1, 1.0);
        let inv = DMatrix::from_element(1, 1, 1.0 / 6.0);
        let (v, b) = variances(&jac, &r, &inv, 1.2, &[(6, true)]);
        assert_eq!(b, 0);
        assert_relative_eq!(v[0], 0.2, max_relative = 1e-12);
    }
}
