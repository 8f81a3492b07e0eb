//! One Levenberg–Marquardt run (MINPACK's, from the `levenberg-marquardt`
//! crate) on the problem's unbounded variables, the Jacobian by forward
//! differences of whole simulations run in parallel; on a budget stop, the
//! parameters that were still moving.

use super::problem::Problem;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};
use rayon::prelude::*;

/// The result of one local run.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalRun {
    /// Where it ended.
    pub x: Vec<f64>,
    /// ½ Σ r², N².
    pub cost: f64,
    /// Whether it met a convergence test.
    pub converged: bool,
    /// How it ended, in words.
    pub termination: String,
    /// Residual evaluations it used.
    pub evaluations: usize,
}

/// Forward-difference step in the unbounded variable.
const FD_STEP: f64 = 1e-4;

struct Lm<'p, 'a> {
    problem: &'p Problem<'a>,
    u: DVector<f64>,
    r: DVector<f64>,
    /// Every point evaluated: (cost, u), for what was still moving when a
    /// run stops on its budget.
    trail: Vec<(f64, Vec<f64>)>,
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Lm<'_, '_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
        let x = self.problem.from_internal(u.as_slice());
        self.r = DVector::from_vec(self.problem.residuals(&x));
        self.trail
            .push((0.5 * self.r.norm_squared(), u.as_slice().to_vec()));
    }

    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        // None ends the run (TerminationReason::User) when a stop is asked.
        (!self.problem.stop.requested()).then(|| self.r.clone())
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        if self.problem.stop.requested() {
            return None;
        }
        let n = self.u.len();
        let columns: Vec<Vec<f64>> = (0..n)
            .into_par_iter()
            .map(|j| {
                let mut u = self.u.clone();
                u[j] += FD_STEP;
                let x = self.problem.from_internal(u.as_slice());
                self.problem
                    .residuals(&x)
                    .iter()
                    .zip(self.r.iter())
                    .map(|(a, b)| (a - b) / FD_STEP)
                    .collect()
            })
            .collect();
        let m = self.r.len();
        Some(DMatrix::from_fn(m, n, |i, j| columns[j][i]))
    }
}

/// One Levenberg–Marquardt run from `x0`.
pub fn local_run(problem: &Problem<'_>, x0: &[f64], max_evaluations: usize) -> LocalRun {
    let u0 = DVector::from_vec(problem.to_internal(x0));
    let n = u0.len();
    let mut lm = Lm {
        problem,
        u: u0.clone(),
        r: DVector::zeros(0),
        trail: Vec::new(),
    };
    lm.set_params(&u0);
    let patience = max_evaluations.div_ceil(n + 1).max(1);
    let (lm, report) = LevenbergMarquardt::new()
        .with_ftol(1e-10)
        .with_xtol(1e-8)
        .with_gtol(1e-10)
        .with_patience(patience)
        .minimize(lm);
    let converged = report.termination.was_successful()
        || matches!(
            report.termination,
            TerminationReason::NoImprovementPossible(_)
        );
    let x = problem.from_internal(lm.u.as_slice());
    let cost = 0.5 * lm.r.norm_squared();
    let mut termination = termination_text(&report.termination);
    if matches!(report.termination, TerminationReason::LostPatience) {
        let moving = still_moving(problem, &lm.trail);
        if !moving.is_empty() {
            termination.push_str(&format!("; still moving: {}", moving.join(", ")));
        }
    }
    LocalRun {
        x,
        cost,
        converged,
        termination,
        evaluations: report.number_of_evaluations,
    }
}

/// The parameters that moved by more than 0.1 % of their scaled range
/// between the best point of the first three quarters of a run and the
/// best point of all of it: what a larger budget would still change.
fn still_moving(problem: &Problem<'_>, trail: &[(f64, Vec<f64>)]) -> Vec<String> {
    let best = |t: &[(f64, Vec<f64>)]| {
        t.iter()
            .filter(|(c, _)| c.is_finite())
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, u)| problem.from_internal(u))
    };
    let early = trail.len() * 3 / 4;
    let (Some(a), Some(b)) = (best(&trail[..early.max(1).min(trail.len())]), best(trail)) else {
        return Vec::new();
    };
    problem
        .params
        .iter()
        .zip(a.iter().zip(&b))
        .filter(|(p, (x, y))| (p.fraction(**x) - p.fraction(**y)).abs() > 1e-3)
        .map(|(p, _)| p.name.clone())
        .collect()
}

fn termination_text(t: &TerminationReason) -> String {
    match t {
        TerminationReason::Converged { ftol, xtol } => match (ftol, xtol) {
            (true, true) => "converged (cost and step)".into(),
            (true, false) => "converged (cost)".into(),
            _ => "converged (step)".into(),
        },
        TerminationReason::Orthogonal => "converged (gradient)".into(),
        TerminationReason::ResidualsZero => "converged (zero residual)".into(),
        TerminationReason::NoImprovementPossible(w) => {
            format!("converged to machine precision ({w})")
        }
        TerminationReason::LostPatience => "not converged: evaluation limit reached".into(),
        // Our residuals and Jacobian return None only when a stop is asked.
        TerminationReason::User(_) => "stopped on request".into(),
        other => format!("not converged: {other:?}"),
    }
}
