//! The optima earlier local runs found, and when a later run has come to
//! one of them and may stop.
//!
//! A run that enters the 95 % joint confidence region of an optimum an
//! earlier run found (within it by that optimum's curvature JᵀJ, and its
//! cost within ½ s² χ²₀.₉₅(n) of that optimum's) stops there: going on could only find that optimum again, or a point
//! the data cannot tell from it (kept among the distinct optima when it
//! lies apart).
//!
//! With the valley test on (our model's fits; `--later-runs valley`, the
//! default), a run that is not the first also asks, before it takes
//! differences, whether it already sits in the valley of an earlier
//! optimum u₁ (the hill–valley test of Ursem 2000, made monotone): the
//! cost at `VALLEY_POINTS` evenly spaced points of the straight line from
//! its point u to u₁ (in the unbounded variables) falls at every point,
//! c(u) ≥ c(u + ⅕(u₁ − u)) ≥ … ≥ c₁. Then a descent from u has a straight
//! way down to u₁ with no hill on it, and the run stops there ("in the
//! valley of optimum 1") for a few simulations instead of the dozens of
//! Jacobians it would take to walk down. A line with a rise on it
//! (another valley between) lets the run go on; it asks again once its
//! cost has fallen tenfold since the last time. The test is evidence, not
//! proof: from a start far up the slopes most straight lines fall, and a
//! better optimum whose basin holds such a start would be missed;
//! `--later-runs full` walks every run to its end. The first run (no
//! earlier optimum) is the same either way.

use super::options::LaterRuns;
use super::problem::Problem;
use super::separable::Variables;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The optimiser's variables u on their canonical fold: the variables are
/// periodic (x = x(sin u)), so a run that went over a bound stands at
/// the same point as asin(sin u) + 2π; distances between runs' points
/// are taken there.
pub fn canonical(u: &[f64]) -> Vec<f64> {
    u.iter()
        .map(|v| v.sin().asin() + std::f64::consts::TAU)
        .collect()
}

/// An optimum found by an earlier run: its point in the optimiser's
/// variables (canonical) and whole, its cost and the curvature JᵀJ there
/// (in the canonical variables).
#[derive(Debug, Clone)]
pub struct Found {
    /// The point, unbounded variables (the searched parameters').
    pub u: Vec<f64>,
    /// The whole point, every parameter.
    pub x: Vec<f64>,
    /// ½Σr² there.
    pub cost: f64,
    /// JᵀJ there.
    pub curvature: DMatrix<f64>,
}

/// The 95 % quantile of χ² with `n` degrees of freedom (Wilson–Hilferty:
/// 2.5 % low at n = 1, within 1 % from n = 3).
pub fn chi_square_95(n: usize) -> f64 {
    let n = n.max(1) as f64;
    let a = 2.0 / (9.0 * n);
    n * (1.0 - a + 1.644_853_626_951_472_6 * a.sqrt()).powi(3)
}

/// Interior points of the valley test's line.
pub const VALLEY_POINTS: usize = 4;
/// A run asks the valley test again once its cost has fallen by this
/// factor since the last time.
const VALLEY_RETEST: f64 = 10.0;

/// How a run came to an earlier optimum.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Joined {
    /// Inside its 95 % confidence region.
    Region(usize),
    /// On a straight line down to it with no rise (the valley test).
    Valley(usize),
}

/// A run's view of the earlier optima: which one it came to, and the
/// valley tests it asked.
pub struct EarlierOptima<'p> {
    /// Optima of earlier runs.
    earlier: &'p [Found],
    /// Whether the valley test is asked.
    later: LaterRuns,
    /// The earlier optimum this run came to.
    joined: Mutex<Option<Joined>>,
    /// The cost at the last valley test (none yet: infinite).
    valley_cost: Mutex<f64>,
    /// Simulations the valley tests took.
    valley_evaluations: AtomicUsize,
}

impl<'p> EarlierOptima<'p> {
    /// The optima `earlier`, the valley test asked when `later` says so.
    pub fn new(earlier: &'p [Found], later: LaterRuns) -> Self {
        EarlierOptima {
            earlier,
            later,
            joined: Mutex::new(None),
            valley_cost: Mutex::new(f64::INFINITY),
            valley_evaluations: AtomicUsize::new(0),
        }
    }

    /// The earlier optima.
    pub fn found(&self) -> &'p [Found] {
        self.earlier
    }

    /// The earlier optimum the run came to, and how.
    pub fn joined(&self) -> Option<Joined> {
        *self.joined.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Record that the run came to an earlier optimum (the first record
    /// stays).
    fn join(&self, how: Joined) {
        let mut j = self.joined.lock().unwrap_or_else(|p| p.into_inner());
        if j.is_none() {
            *j = Some(how);
        }
    }

    /// Simulations the valley tests took.
    pub fn valley_evaluations(&self) -> usize {
        self.valley_evaluations.load(Ordering::Relaxed)
    }

    /// Record it when the point `u` (cost `cost`) of a run on `problem`
    /// has entered an earlier optimum's confidence region (`joins`).
    pub fn check_region(&self, problem: &Problem<'_>, u: &[f64], cost: f64) {
        if let Some(k) = self.joins(problem, u, cost) {
            self.join(Joined::Region(k));
        }
    }

    /// Whether the run at `u` (cost `cost`) sits in an earlier optimum's
    /// valley (`valley`); recorded when it does.
    pub fn check_valley(&self, vars: &Variables<'_, '_>, u: &[f64], cost: f64) -> bool {
        let k = self.valley(vars, u, cost);
        if let Some(k) = k {
            self.join(Joined::Valley(k));
        }
        k.is_some()
    }

    /// The earlier optimum whose 95 % joint confidence region this point
    /// (u, its cost) has entered: dᵀ JᵀJ d ≤ s² χ²₀.₉₅(n), d = u − u₁ and
    /// s² = 2c₁/(m − n) the residual variance at that optimum (the region
    /// of the linearised model), with the cost itself within ½ s² χ²₀.₉₅(n)
    /// of c₁. The data cannot tell such a point from that optimum; going
    /// on could only find it again, or a point that fits as well.
    fn joins(&self, problem: &Problem<'_>, u: &[f64], cost: f64) -> Option<usize> {
        let n = problem.params.len();
        let dof = problem.fitted_samples().saturating_sub(n).max(1) as f64;
        let chi2 = chi_square_95(n);
        self.earlier.iter().position(|f| {
            let s2 = 2.0 * f.cost / dof;
            let u = canonical(u);
            let d = DVector::from_iterator(u.len(), u.iter().zip(&f.u).map(|(a, b)| a - b));
            let q = (d.transpose() * &f.curvature * &d)[(0, 0)];
            q <= s2 * chi2 && cost <= f.cost + 0.5 * s2 * chi2
        })
    }

    /// The earlier optimum whose valley the point `u` (cost `cost`) is in: the cost
    /// falls at every one of `VALLEY_POINTS` evenly spaced points of the
    /// straight line to it. Asked once the cost has fallen `VALLEY_RETEST`
    /// times since the last asking (the first time always).
    fn valley(&self, vars: &Variables<'_, '_>, u: &[f64], cost: f64) -> Option<usize> {
        {
            let mut last = self.valley_cost.lock().unwrap_or_else(|p| p.into_inner());
            if self.later != LaterRuns::Valley
                || self.earlier.is_empty()
                || !cost.is_finite()
                || cost * VALLEY_RETEST > *last
            {
                return None;
            }
            *last = cost;
        }
        self.earlier
            .iter()
            .position(|f| f.cost <= cost && self.falls_to(vars, u, cost, f))
    }

    /// Whether the cost falls at every interior point of the straight
    /// line from `u` (cost `cost`) to `f`, and on to `f`.
    fn falls_to(&self, vars: &Variables<'_, '_>, u: &[f64], cost: f64, f: &Found) -> bool {
        let from = canonical(u);
        let costs: Vec<f64> = (1..=VALLEY_POINTS)
            .into_par_iter()
            .map(|k| {
                let t = k as f64 / (VALLEY_POINTS + 1) as f64;
                let u: Vec<f64> = from
                    .iter()
                    .zip(&f.u)
                    .map(|(a, b)| a + t * (b - a))
                    .collect();
                vars.cost(&u)
            })
            .collect();
        self.valley_evaluations
            .fetch_add(VALLEY_POINTS, Ordering::Relaxed);
        let line: Vec<f64> = std::iter::once(cost)
            .chain(costs)
            .chain(std::iter::once(f.cost))
            .collect();
        line.windows(2).all(|w| w[1].is_finite() && w[1] <= w[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn the_chi_square_quantile_matches_the_tables() {
        // χ²₀.₉₅: 3.841 (1), 11.070 (5), 18.307 (10), 31.410 (20).
        assert_relative_eq!(chi_square_95(1), 3.841, max_relative = 0.03);
        for (n, q) in [(3, 7.815), (5, 11.070), (10, 18.307), (20, 31.410)] {
            assert_relative_eq!(chi_square_95(n), q, max_relative = 0.01);
        }
    }

    #[test]
    fn a_point_past_a_bound_stands_where_its_fold_puts_it() {
        // x depends on sin u: u and π − u are the same point, as are u and
        // u + 2π.
        let u = [0.3, -1.2];
        let v = [std::f64::consts::PI - 0.3, -1.2 + std::f64::consts::TAU];
        for (a, b) in canonical(&u).iter().zip(canonical(&v)) {
            assert_relative_eq!(*a, b, epsilon = 1e-12);
        }
    }
}
