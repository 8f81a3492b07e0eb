//! A local run that spent its budget beside a bound, or that crawled
//! toward one: the parameters there held on it and the others fitted (an
//! active-set step).
//!
//! The sine transform s = lo + (hi − lo)(1 + sin u)/2 is stationary at a
//! bound: where the bounded problem's optimum lies on a bound (the cost
//! still falls past it), the Jacobian column of that variable vanishes like
//! cos u while the cost stays curved in u, so Gauss–Newton's model of the
//! cost is flat where it is not and Levenberg–Marquardt crawls toward the
//! bound until its budget ends ("not converged: evaluation limit
//! reached"). On the random steady joints of `docs/arm-steady-draws.sh`
//! that was the end of 16 of 768 fits, each with its Stribeck speed on the
//! data's top speed (rule 8's bound).
//!
//! The step here: the searched parameters within [`NEAR`] of a bound
//! (a fraction of their scaled range) are set on it and held, the others
//! fitted from there by a run on difference Jacobians. The result stands
//! when that run converged, its cost is no higher than the crawl's, and
//! the cost rises when each held parameter is moved [`NEAR`] inward, the
//! others refitted only as the linear and cheap keys are at every point
//! (the bound is active: the first-order condition of the bounded
//! problem, by one-sided differences); else the crawl's end stands as it
//! was.
//!
//! A run does not wait for its budget's end where it sees the crawl: a
//! searched parameter within 5 % of its range of a bound that comes nearer
//! at each of 10 accepted steps ends it (`local_run`'s doc), and the step
//! here holds that parameter too. Where that bound does not hold it (the
//! held fit costs more than the crawl's end, or the cost falls inward) the
//! run is made again from its start without the watch: its path and end
//! are what they were, and the watch has cost the evaluations up to the
//! crawl and the held fit. A fresh run from the crawl's end was tried
//! first and lost optima: its path differs from the one it replaces
//! (stop 80). On EMPS's LuGre fit the
//! given start crawled for 2008 evaluations (+ 11 278 for its Jacobians)
//! to the optimum `fc = 0`; it ends now after 247 (+ 1062) at the same
//! cost.

use super::local_run::{one_run, LocalRun};
use super::options::{JacobianRule, LaterRuns};
use super::problem::Problem;
use super::separable::{Separable, Variables};

/// A searched parameter this close to a bound (a fraction of its scaled
/// range) at a run's end is held on it; the inward probe of the
/// first-order condition is as long.
pub const NEAR: f64 = 1e-3;

/// `run`, or, when it did not converge with searched parameters within
/// [`NEAR`] of a bound or crawling toward one, the fit with those held on
/// their bounds if the bound is active there (see the module's doc). A run
/// that ended crawling toward a bound that does not hold it is replaced by
/// `unwatched`, the same run without the watch (its path as it was, its
/// end settled the same way), the evaluations of both counted.
/// `max_evaluations` is the held fit's budget.
pub fn settle(
    (problem, separable): (&Problem<'_>, Option<&Separable>),
    run: LocalRun,
    unwatched: impl FnOnce() -> LocalRun,
    max_evaluations: usize,
    later: LaterRuns,
    tolerance: (f64, f64),
) -> LocalRun {
    if run.converged || problem.stop.requested() {
        return run;
    }
    let held = |run: &LocalRun| {
        held_on_bounds((problem, separable), run, max_evaluations, later, tolerance)
    };
    if let Some(fitted) = held(&run) {
        return fitted;
    }
    if run.crawling.is_empty() {
        return run;
    }
    let again = unwatched();
    let again = LocalRun {
        evaluations: run.evaluations + again.evaluations,
        jacobian_evaluations: run.jacobian_evaluations + again.jacobian_evaluations,
        ..again
    };
    if again.converged || problem.stop.requested() {
        return again;
    }
    held(&again).unwrap_or(again)
}

/// The fit with `run`'s searched parameters within [`NEAR`] of a bound,
/// and those it crawled toward one with, held on it, when it converged no higher than `run` and the bound is
/// active there.
fn held_on_bounds(
    (problem, separable): (&Problem<'_>, Option<&Separable>),
    run: &LocalRun,
    max_evaluations: usize,
    later: LaterRuns,
    tolerance: (f64, f64),
) -> Option<LocalRun> {
    let vars = Variables::new(problem, separable, &run.x);
    let mut at_bound = run.x.clone();
    let held: Vec<usize> = vars
        .varied()
        .filter(|&i| {
            let p = &problem.params[i];
            let f = p.fraction(run.x[i]);
            let crawled = run.crawling.contains(&i);
            let side = if f < NEAR || (crawled && f < 0.5) {
                0.0
            } else if f > 1.0 - NEAR || crawled {
                1.0
            } else {
                return false;
            };
            at_bound[i] = p.from_fraction(side);
            true
        })
        .collect();
    if held.is_empty() {
        return None;
    }
    let rest = vars.holding(&held, &at_bound);
    let u0 = rest.to_internal(&at_bound);
    let (fitted, _) = one_run(
        rest,
        &u0,
        max_evaluations,
        (JacobianRule::Differences, later),
        &[],
        tolerance,
        false,
    );
    if !fitted.converged || fitted.cost > run.cost || !active(&vars, &held, &fitted) {
        return None;
    }
    let names: Vec<&str> = held
        .iter()
        .map(|&i| problem.params[i].name.as_str())
        .collect();
    Some(LocalRun {
        termination: format!(
            "{} with {} held on its bound (the cost rises inward: the bound is active)",
            fitted.termination,
            names.join(", ")
        ),
        evaluations: run.evaluations + fitted.evaluations,
        jacobian_evaluations: run.jacobian_evaluations + fitted.jacobian_evaluations,
        // Its curvature would lack the held columns: later runs are not
        // stopped inside this optimum's region, they run to their end.
        curvature: None,
        ..fitted
    })
}

/// Whether the cost at `fitted` rises when each `held` parameter alone is
/// moved [`NEAR`] of its range inward from its bound (the linear and cheap
/// keys solved again, the others where they are).
fn active(vars: &Variables<'_, '_>, held: &[usize], fitted: &LocalRun) -> bool {
    let cost_at = |x: &[f64]| {
        let v = vars.holding(held, x);
        v.cost(&v.canonical(x))
    };
    let here = cost_at(&fitted.x);
    held.iter().all(|&i| {
        let p = &vars.problem().params[i];
        let f = p.fraction(fitted.x[i]);
        let mut inward = fitted.x.clone();
        inward[i] = p.from_fraction(if f < 0.5 { NEAR } else { 1.0 - NEAR });
        cost_at(&inward) > here
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::local_run::local_run;
    use crate::fit::problem::{tests_data, Model};
    use crate::fit::series::{Mapping, Series};
    use crate::fit::unknowns::FittedParameter;

    /// A model of two residuals, functions of the two parameters (a, b):
    /// the first two samples' friction less `residuals(a, b)`.
    struct TwoResiduals {
        params: Vec<FittedParameter>,
        residuals: Box<dyn Fn(f64, f64) -> [f64; 2] + Sync>,
    }

    impl Model for TwoResiduals {
        fn label(&self) -> String {
            "two residuals".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.params
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, crate::fit::PredictError> {
            let r = (self.residuals)(x[0], x[1]);
            let mut out = s.friction.clone();
            out[0] -= r[0];
            out[1] -= r[1];
            Ok(out)
        }
    }

    /// Residuals a − target and b − a/2 + c·b² over a ∈ [0.1, 2] (log
    /// scaled), b ∈ [−3, 3]: with `target` 5 the optimum lies past the
    /// bound a = 2, at b solving b − 1 + c·b² = 0.
    fn model(target: f64) -> (TwoResiduals, crate::fit::data::Data) {
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        for k in 0..2 {
            text += &format!("{},0.1,1\n", k as f64 * 0.01);
        }
        let data = tests_data(&text, &Mapping::default());
        let mut a = FittedParameter::new("a", 1.0, 0.1, 2.0);
        a.log = true;
        let params = vec![a, FittedParameter::new("b", 0.0, -3.0, 3.0)];
        let residuals = Box::new(move |a, b| [a - target, b - a / 2.0 + 0.3 * b * b]);
        (TwoResiduals { params, residuals }, data)
    }

    /// Residuals k·(a + b − 4) and b − 6 over a ∈ [0, 10], b ∈ [−10, 10]:
    /// a valley along a + b = 4 whose lowest point (a = −2) lies past the
    /// bound a = 0.
    fn valley(k: f64) -> TwoResiduals {
        TwoResiduals {
            params: vec![
                FittedParameter::new("a", 5.0, 0.0, 10.0),
                FittedParameter::new("b", -1.0, -10.0, 10.0),
            ],
            residuals: Box::new(move |a, b| [k * (a + b - 4.0), b - 6.0]),
        }
    }

    fn crawl(x: Vec<f64>, cost: f64) -> LocalRun {
        LocalRun {
            x,
            cost,
            converged: false,
            termination: "not converged: evaluation limit reached".into(),
            evaluations: 200,
            jacobian_evaluations: 0,
            curvature: None,
            crawling: Vec::new(),
        }
    }

    #[test]
    fn a_run_that_crawled_to_an_active_bound_ends_on_it_converged() {
        let (m, data) = model(5.0);
        let problem = Problem::new(&m, &data, vec![]).unwrap();
        let x = vec![1.9999, 0.5];
        let run = crawl(x.clone(), problem.cost(&x));
        let settled = settle(
            (&problem, None),
            run,
            not_again,
            200,
            LaterRuns::Full,
            (1e-10, 1e-8),
        );
        assert!(settled.converged, "{}", settled.termination);
        assert!(
            settled.termination.contains("a held on its bound"),
            "{}",
            settled.termination
        );
        assert_eq!(settled.x[0], 2.0);
        // b − 1 + 0.3 b² = 0.
        approx::assert_relative_eq!(settled.x[1], (-1.0 + 2.2f64.sqrt()) / 0.6, epsilon = 1e-6);
        assert!(settled.cost < problem.cost(&x));
    }

    #[test]
    fn a_run_near_a_bound_whose_cost_falls_inward_is_left_as_it_ended() {
        // The optimum a = 1.99 lies inside, within NEAR of the bound on a
        // log scale: holding a at 2 is not the optimum, and the probe sees it.
        let (m, data) = model(1.99);
        let problem = Problem::new(&m, &data, vec![]).unwrap();
        let x = vec![1.9995, 0.5];
        let run = crawl(x.clone(), problem.cost(&x));
        let settled = settle(
            (&problem, None),
            run.clone(),
            not_again,
            200,
            LaterRuns::Full,
            (1e-10, 1e-8),
        );
        assert_eq!(settled, run);
    }

    #[test]
    fn a_run_crawling_along_a_valley_toward_an_active_bound_ends_early_and_settles_on_it() {
        let k = 300.0;
        let (_, data) = model(5.0);
        let m = valley(k);
        let problem = Problem::new(&m, &data, vec![]).unwrap();
        let start = [5.0, -1.0];
        let tolerance = (1e-10, 1e-8);
        let run = local_run(
            (&problem, None),
            &start,
            200,
            JacobianRule::Differences,
            &[],
            LaterRuns::Full,
            tolerance,
            true,
        );
        assert_eq!(run.crawling, vec![0], "{}", run.termination);
        assert!(run.termination.contains("crawling toward a bound (a"));
        // Unwatched, the same run walks on to the bound.
        let vars = Variables::new(&problem, None, &start);
        let u0 = vars.to_internal(&start);
        let rules = (JacobianRule::Differences, LaterRuns::Full);
        let (walked, _) = one_run(vars, &u0, 200, rules, &[], tolerance, false);
        let settled = settle(
            (&problem, None),
            run,
            not_again,
            200,
            LaterRuns::Full,
            tolerance,
        );
        assert!(settled.converged, "{}", settled.termination);
        assert!(settled.termination.contains("a held on its bound"));
        assert_eq!(settled.x[0], 0.0);
        // At a = 0: k²(b − 4) + (b − 6) = 0.
        let b = (4.0 * k * k + 6.0) / (k * k + 1.0);
        approx::assert_relative_eq!(settled.x[1], b, epsilon = 1e-9);
        assert!(
            settled.evaluations < walked.evaluations,
            "{} evaluations settled, {} walked",
            settled.evaluations,
            walked.evaluations
        );
    }

    #[test]
    fn a_run_that_crawled_toward_a_bound_that_does_not_hold_it_is_made_again_without_the_watch() {
        // The optimum a = 1.99 lies inside: held at 2 the cost falls inward,
        // so the run is replaced by the same run unwatched (here a stand-in
        // that ended at the optimum), the evaluations of both counted.
        let (m, data) = model(1.99);
        let problem = Problem::new(&m, &data, vec![]).unwrap();
        let x = vec![1.9, 0.5];
        let mut run = crawl(x.clone(), problem.cost(&x));
        run.evaluations = 20;
        run.crawling = vec![0];
        let optimum = vec![1.99, (-1.0 + (1.0f64 + 1.2 * 0.995).sqrt()) / 0.6];
        let unwatched = LocalRun {
            converged: true,
            termination: "converged (cost)".into(),
            evaluations: 30,
            ..crawl(optimum.clone(), problem.cost(&optimum))
        };
        let settled = settle(
            (&problem, None),
            run,
            || unwatched.clone(),
            200,
            LaterRuns::Full,
            (1e-10, 1e-8),
        );
        assert_eq!(settled.x, optimum);
        assert!(settled.converged, "{}", settled.termination);
        assert_eq!(settled.evaluations, 50);
    }

    /// A run that must not be made again.
    fn not_again() -> LocalRun {
        panic!("a run that did not crawl is not made again")
    }
}
