//! One Levenberg–Marquardt run (MINPACK's, from the `levenberg-marquardt`
//! crate) on the problem's unbounded variables; on a budget stop, the
//! parameters that were still moving.
//!
//! The Jacobian is taken by forward differences of whole simulations (one
//! per parameter, run in parallel) or — the default — kept up to date
//! between them by Broyden's secant update (Dennis & Schnabel 1996, §8.1;
//! MINPACK's `hybrd` does the same): after an accepted step du with
//! residual change dr, J ← J + (dr − J du) duᵀ / (duᵀ du), at no
//! simulation's cost. Differences are taken again when the secant model
//! failed (the step before it needed more than one trial) and after as
//! many secant updates as there are parameters; and a run that ended on
//! secant Jacobians is polished by a run on differences from its end
//! point, so the convergence test and the optimum are the exact method's.
//!
//! A searched parameter within `CRAWL_ZONE` (5 % of its range) of a bound
//! whose distance to it fell at each of `CRAWL_STEPS` (10) accepted steps
//! in a row is crawling toward it: the sine transform is stationary at a
//! bound, so where the cost still falls past it each step moves it a fixed
//! fraction of the way left, to the end of the budget (on EMPS's LuGre
//! fit, 3 % of the range to 0.1 % in 800 evaluations). The run ends there,
//! and `bound_polish::settle` holds the parameter on the bound or, where
//! the bound does not hold it, makes the run again without the watch.

use super::earlier_optima::{EarlierOptima, Found, Joined, VALLEY_POINTS};
use super::options::{JacobianRule, LaterRuns};
use super::problem::Problem;
use super::separable::{Separable, Variables};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

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
    /// Simulations its Jacobians took (columns of differences).
    pub jacobian_evaluations: usize,
    /// JᵀJ in the optimiser's variables at (or one step before) its end
    /// point, when its last Jacobian was taken by differences: the
    /// curvature of the cost that defines the optimum's confidence region.
    pub curvature: Option<DMatrix<f64>>,
    /// The searched parameters (indices of the whole point) it ended
    /// crawling toward a bound with (see the module's doc); empty if none.
    pub crawling: Vec<usize>,
}

/// The secant model is kept while the accepted step's actual reduction
/// of the cost is at least this fraction of the reduction it predicted.
const SECANT_TRUST: f64 = 0.25;
/// Secant updates between differences, per parameter.
const SECANT_SPAN: usize = 2;

/// Forward-difference step in the unbounded variable.
const FD_STEP: f64 = 1e-4;

/// Accepted steps in a row that bring a searched parameter nearer a bound
/// within [`CRAWL_ZONE`] and end a run as crawling toward it.
pub(super) const CRAWL_STEPS: usize = 10;

/// How near a bound (a fraction of a parameter's scaled range) a crawl
/// toward it is watched for.
pub(super) const CRAWL_ZONE: f64 = 0.05;

/// The last Jacobian: the accepted point it belongs to, the matrix, and
/// the secant updates since differences were taken.
struct LastJacobian {
    u: DVector<f64>,
    /// The whole point of `u` (the linear parameters solved).
    x: Vec<f64>,
    r: DVector<f64>,
    j: DMatrix<f64>,
    secant_updates: usize,
    /// Whether every column was taken by differences at `u` (else the
    /// costly columns are secant estimates).
    exact: bool,
}

struct Lm<'p, 'a> {
    problem: &'p Problem<'a>,
    /// The searched variables (the linear parameters solved at each point).
    vars: Variables<'p, 'a>,
    u: DVector<f64>,
    /// The whole point of `u`.
    x: Vec<f64>,
    r: DVector<f64>,
    /// Every point evaluated: (cost, whole point), for what was still
    /// moving when a run stops on its budget.
    trail: Vec<(f64, Vec<f64>)>,
    rule: JacobianRule,
    /// Per variable, whether a change of it alone needs a whole simulation
    /// (None: all cost the same).
    costly: Option<Vec<bool>>,
    last: Mutex<Option<LastJacobian>>,
    /// Residual evaluations since the last Jacobian.
    trials: AtomicUsize,
    /// Simulations the differences took.
    jacobian_evaluations: AtomicUsize,
    /// Optima of earlier runs, and which one this run came to.
    earlier: EarlierOptima<'p>,
    /// Whether a crawl along a bound ends the run.
    watch_crawl: bool,
    /// Per searched variable: its distance to the nearer bound at the last
    /// accepted point (a fraction of its range) and the accepted steps in a
    /// row that brought it nearer inside [`CRAWL_ZONE`].
    approach: Mutex<Vec<(f64, usize)>>,
    /// Whether the run ended crawling toward a bound.
    crawled: AtomicBool,
}

impl<'p, 'a> Lm<'p, 'a> {
    /// A run from `u0` (its residuals not yet taken).
    fn new(
        vars: Variables<'p, 'a>,
        u0: &DVector<f64>,
        (rule, later): (JacobianRule, LaterRuns),
        earlier: &'p [Found],
        watch_crawl: bool,
    ) -> Self {
        Lm {
            problem: vars.problem(),
            costly: vars.costly(),
            vars,
            u: u0.clone(),
            x: Vec::new(),
            r: DVector::zeros(0),
            trail: Vec::new(),
            rule,
            last: Mutex::new(None),
            trials: AtomicUsize::new(0),
            jacobian_evaluations: AtomicUsize::new(0),
            earlier: EarlierOptima::new(earlier, later),
            watch_crawl,
            approach: Mutex::new(Vec::new()),
            crawled: AtomicBool::new(false),
        }
    }

    /// At an accepted point: whether a searched parameter has now come
    /// nearer a bound inside [`CRAWL_ZONE`] at [`CRAWL_STEPS`] accepted
    /// steps in a row.
    fn crawling(&self) -> bool {
        if !self.watch_crawl {
            return false;
        }
        let searched = self.vars.searched();
        let mut approach = self.approach.lock().unwrap_or_else(|p| p.into_inner());
        approach.resize(searched.len(), (f64::INFINITY, 0));
        let mut crawled = false;
        for (&i, (last, steps)) in searched.iter().zip(approach.iter_mut()) {
            let d = bound_distance(self.problem, i, self.x[i]);
            *steps = if d < CRAWL_ZONE && d < *last {
                *steps + 1
            } else {
                0
            };
            *last = d;
            crawled |= *steps >= CRAWL_STEPS;
        }
        self.crawled.store(crawled, Ordering::Relaxed);
        crawled
    }

    /// The searched parameters crawling toward a bound.
    fn crawlers(&self) -> Vec<usize> {
        let approach = self.approach.lock().unwrap_or_else(|p| p.into_inner());
        self.vars
            .searched()
            .iter()
            .zip(approach.iter())
            .filter(|(_, (_, steps))| *steps >= CRAWL_STEPS)
            .map(|(&i, _)| i)
            .collect()
    }

    /// The Jacobian by forward differences: every column, or the columns
    /// `only` marks (the others zero). Profiled, each column is taken
    /// with the cheap keys held at the point's fit and projected out of
    /// their span (`profile::project_out_cheap`), not by a second inner fit.
    fn differences(&self, only: Option<&[bool]>) -> DMatrix<f64> {
        let n = self.u.len();
        let taken = |j: usize| only.is_none_or(|o| o[j]);
        let mut columns: Vec<Vec<f64>> = (0..n)
            .into_par_iter()
            .map(|j| {
                if !taken(j) {
                    return vec![0.0; self.r.len()];
                }
                let mut u = self.u.clone();
                u[j] += FD_STEP;
                self.vars
                    .evaluate_held(u.as_slice(), &self.x)
                    .iter()
                    .zip(self.r.iter())
                    .map(|(a, b)| (a - b) / FD_STEP)
                    .collect()
            })
            .collect();
        if let Some(inner) = self.vars.cheap_at(&self.x) {
            super::profile::project_out_cheap(&inner, &self.x, self.r.as_slice(), &mut columns);
        }
        let count = (0..n).filter(|j| taken(*j)).count();
        self.jacobian_evaluations
            .fetch_add(count, Ordering::Relaxed);
        let m = self.r.len();
        DMatrix::from_fn(m, n, |i, j| columns[j][i])
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Lm<'_, '_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        // After a rejected last trial the optimiser goes back to the last
        // accepted point: the point of the last Jacobian, whose residuals
        // are kept.
        let back = self
            .last
            .get_mut()
            .unwrap_or_else(|p| p.into_inner())
            .as_ref()
            .filter(|l| l.u == *u)
            .map(|l| (l.r.clone(), l.x.clone()));
        self.u.copy_from(u);
        if let Some((r, x)) = back {
            self.r = r;
            self.x = x;
            return;
        }
        // A profiled point's cheap keys are fitted from the last accepted
        // point's (the run's start at first).
        let (r, x) = {
            let last = self.last.lock().unwrap_or_else(|p| p.into_inner());
            match last.as_ref() {
                Some(l) => self.vars.evaluate_near(u.as_slice(), &l.x),
                None if !self.x.is_empty() => self.vars.evaluate_near(u.as_slice(), &self.x),
                None => self.vars.evaluate_first(u.as_slice()),
            }
        };
        self.r = DVector::from_vec(r);
        let cost = 0.5 * self.r.norm_squared();
        self.trail.push((cost, x.clone()));
        self.x = x;
        self.trials.fetch_add(1, Ordering::Relaxed);
        self.earlier.check_region(self.problem, u.as_slice(), cost);
    }

    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        // None ends the run (TerminationReason::User) when a stop is asked
        // or the run came to an earlier optimum.
        (!self.problem.stop.requested() && self.earlier.joined().is_none()).then(|| self.r.clone())
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        if self.problem.stop.requested() || self.earlier.joined().is_some() || self.crawling() {
            return None;
        }
        self.trials.store(0, Ordering::Relaxed);
        let mut last = self.last.lock().unwrap_or_else(|p| p.into_inner());
        let n = self.u.len();
        let mut partial = None;
        if let (JacobianRule::Secant, Some(l)) = (self.rule, last.as_mut()) {
            let du = &self.u - &l.u;
            let dd = du.norm_squared();
            let predicted = &l.r + &l.j * &du;
            let (old, now) = (l.r.norm_squared(), self.r.norm_squared());
            let ratio = (old - now) / (old - predicted.norm_squared());
            if dd > 0.0 {
                let miss = &self.r - predicted;
                let updated = &l.j + miss * du.transpose() / dd;
                if ratio >= SECANT_TRUST && l.secant_updates < SECANT_SPAN * n {
                    l.j = updated;
                    l.secant_updates += 1;
                    l.u.copy_from(&self.u);
                    l.x.clone_from(&self.x);
                    l.r.copy_from(&self.r);
                    return Some(l.j.clone());
                }
                // The secant model failed one step after an exact
                // refresh: the cheap columns are taken anew, the costly
                // ones keep their secant estimates (updated by this step);
                // the next refresh is exact again, as is one after the
                // secant span (the whole matrix has drifted).
                if l.exact && ratio < SECANT_TRUST {
                    partial = self.costly.as_deref().map(|c| (c, updated));
                }
            }
        }
        let cost = 0.5 * self.r.norm_squared();
        if self
            .earlier
            .check_valley(&self.vars, self.u.as_slice(), cost)
        {
            return None;
        }
        let (j, exact) = match partial {
            Some((costly, mut j)) => {
                let cheap: Vec<bool> = costly.iter().map(|c| !c).collect();
                let fresh = self.differences(Some(&cheap));
                for (k, take) in cheap.iter().enumerate() {
                    if *take {
                        j.set_column(k, &fresh.column(k));
                    }
                }
                (j, false)
            }
            None => (self.differences(None), true),
        };
        *last = Some(LastJacobian {
            u: self.u.clone(),
            x: self.x.clone(),
            r: self.r.clone(),
            j: j.clone(),
            secant_updates: 0,
            exact,
        });
        Some(j)
    }
}

/// One Levenberg–Marquardt run from `x0` with `rule`'s Jacobians (a
/// secant run is polished on differences), `separable`'s parameters solved
/// at every point; it stops early when it comes to one of the `earlier`
/// optima (inside its confidence region, or, with `later` =
/// [`LaterRuns::Valley`], in its valley). With `watch_crawl` a crawl
/// toward a bound ends it (see the module's doc).
#[allow(clippy::too_many_arguments)]
pub fn local_run(
    (problem, separable): (&Problem<'_>, Option<&Separable>),
    x0: &[f64],
    max_evaluations: usize,
    rule: JacobianRule,
    earlier: &[Found],
    later: LaterRuns,
    tolerance: (f64, f64),
    watch_crawl: bool,
) -> LocalRun {
    let vars = |x: &[f64]| Variables::new(problem, separable, x);
    // A start is moved off its bounds (the sine transform is stationary
    // there).
    let u0 = vars(x0).to_internal(x0);
    let (first, ended_early) = one_run(
        vars(x0),
        &u0,
        max_evaluations,
        (rule, later),
        earlier,
        tolerance,
        watch_crawl,
    );
    // The budget bounds the whole run: a secant run that spent it is not
    // polished (it did not converge).
    let left = max_evaluations.saturating_sub(first.evaluations);
    if rule == JacobianRule::Differences || ended_early || !first.converged || left < 2 {
        return first;
    }
    // The polish: the exact method from where the secant run ended (moved
    // off a bound as a start is), on the budget that is left.
    let u1 = vars(&first.x).to_internal(&first.x);
    let (polish, _) = one_run(
        vars(&first.x),
        &u1,
        left,
        (JacobianRule::Differences, later),
        earlier,
        tolerance,
        watch_crawl,
    );
    LocalRun {
        evaluations: first.evaluations + polish.evaluations,
        jacobian_evaluations: first.jacobian_evaluations + polish.jacobian_evaluations,
        ..polish
    }
}

/// One run; true when it ended early (a stop, or an earlier optimum).
/// With `watch_crawl` a crawl along a bound ends it (see the module's
/// doc).
pub(super) fn one_run(
    vars: Variables<'_, '_>,
    u0: &[f64],
    max_evaluations: usize,
    rules: (JacobianRule, LaterRuns),
    earlier: &[Found],
    (ftol, xtol): (f64, f64),
    watch_crawl: bool,
) -> (LocalRun, bool) {
    let problem = vars.problem();
    let u0 = DVector::from_column_slice(u0);
    let n = u0.len();
    if n == 0 {
        return (solved_run(&vars), problem.stop.requested());
    }
    let mut lm = Lm::new(vars, &u0, rules, earlier, watch_crawl);
    lm.set_params(&u0);
    let patience = max_evaluations.div_ceil(n + 1).max(1);
    let (lm, report) = LevenbergMarquardt::new()
        .with_ftol(ftol)
        .with_xtol(xtol)
        .with_gtol(1e-10)
        .with_patience(patience)
        .minimize(lm);
    // Valley tests are counted with the Jacobians' simulations: both are
    // simulations besides the optimiser's own evaluations.
    let jacobian_evaluations =
        lm.jacobian_evaluations.load(Ordering::Relaxed) + lm.earlier.valley_evaluations();
    let evaluations = (report.number_of_evaluations, jacobian_evaluations);
    let crawling = if lm.crawled.load(Ordering::Relaxed) {
        lm.crawlers()
    } else {
        Vec::new()
    };
    let curvature = curvature(lm.last.into_inner().unwrap_or_else(|p| p.into_inner()));
    if let Some(how) = lm.earlier.joined() {
        return (joined_run(earlier, how, &lm.x, &lm.r, evaluations), true);
    }
    let crawled = !crawling.is_empty();
    let converged = !crawled
        && (report.termination.was_successful()
            || matches!(
                report.termination,
                TerminationReason::NoImprovementPossible(_)
            ));
    let mut termination = if crawled {
        crawl_text(problem, &crawling)
    } else {
        termination_text(&report.termination)
    };
    if matches!(report.termination, TerminationReason::LostPatience) {
        let moving = still_moving(problem, &lm.trail);
        if !moving.is_empty() {
            termination.push_str(&format!("; still moving: {}", moving.join(", ")));
        }
    }
    let run = LocalRun {
        x: lm.x.clone(),
        cost: 0.5 * lm.r.norm_squared(),
        converged,
        termination,
        evaluations: evaluations.0,
        jacobian_evaluations,
        curvature,
        crawling,
    };
    (run, problem.stop.requested())
}

/// A parameter's distance to its nearer bound, a fraction of its scaled
/// range.
pub(super) fn bound_distance(problem: &Problem<'_>, i: usize, x: f64) -> f64 {
    let f = problem.params[i].fraction(x);
    f.min(1.0 - f)
}

/// How a run that crawled toward a bound ended, naming the parameters.
fn crawl_text(problem: &Problem<'_>, crawling: &[usize]) -> String {
    let names: Vec<&str> = crawling
        .iter()
        .map(|&i| problem.params[i].name.as_str())
        .collect();
    format!(
        "not converged: crawling toward a bound ({} nearer it at each of {CRAWL_STEPS} steps)",
        names.join(", ")
    )
}

/// JᵀJ of the last Jacobian by differences, in the canonical variables:
/// at the end point, or at the accepted point before it when the last
/// step met the convergence test (the curvature hardly changes over that
/// step). None when the last Jacobian was a secant update.
fn curvature(last: Option<LastJacobian>) -> Option<DMatrix<f64>> {
    let l = last.filter(|l| l.secant_updates == 0 && l.exact)?;
    // A column taken on a fold where cos u < 0 changes sign.
    let mut j = l.j;
    for (k, u) in l.u.iter().enumerate() {
        if u.cos() < 0.0 {
            j.column_mut(k).neg_mut();
        }
    }
    Some(j.transpose() * &j)
}

/// A run with nothing to search (every parameter solved): its one point.
fn solved_run(vars: &Variables<'_, '_>) -> LocalRun {
    let (r, x) = vars.evaluate(&[]);
    LocalRun {
        x,
        cost: 0.5 * r.iter().map(|v| v * v).sum::<f64>(),
        converged: true,
        termination: "converged (every parameter solved as a linear one)".into(),
        evaluations: 1,
        jacobian_evaluations: 0,
        curvature: None,
        crawling: Vec::new(),
    }
}

/// A run that came to an earlier optimum (`how`), standing at the whole
/// point `x` with residuals `r` after `(evaluations, jacobian_evaluations)`.
fn joined_run(
    earlier: &[Found],
    how: Joined,
    x: &[f64],
    r: &DVector<f64>,
    (evaluations, jacobian_evaluations): (usize, usize),
) -> LocalRun {
    let (x, cost, termination) = match how {
        // Where it stopped: the point that came to optimum k.
        Joined::Region(k) => (
            x.to_vec(),
            0.5 * r.norm_squared(),
            format!("came to optimum {} of an earlier run", k + 1),
        ),
        // Its end is that optimum: a straight way down leads there.
        Joined::Valley(k) => (
            earlier[k].x.clone(),
            earlier[k].cost,
            format!(
                "in the valley of optimum {} of an earlier run (from cost {:.4e} the cost \
                 falls at every one of {VALLEY_POINTS} points on the straight line to it)",
                k + 1,
                0.5 * r.norm_squared()
            ),
        ),
    };
    LocalRun {
        x,
        cost,
        converged: true,
        termination,
        evaluations,
        jacobian_evaluations,
        curvature: None,
        crawling: Vec::new(),
    }
}

/// The parameters that moved by more than 0.1 % of their scaled range
/// between the best point of the first three quarters of a run and the
/// best point of all of it (the trail's whole points): what a larger
/// budget would still change.
fn still_moving(problem: &Problem<'_>, trail: &[(f64, Vec<f64>)]) -> Vec<String> {
    let best = |t: &[(f64, Vec<f64>)]| {
        t.iter()
            .filter(|(c, _)| c.is_finite())
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, x)| x.clone())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::problem::{tests_data, Model};
    use crate::fit::series::{Mapping, Series};
    use crate::fit::unknowns::FittedParameter;
    use crate::fit::PredictError;
    use approx::assert_relative_eq;

    /// Friction = a² v + b: `a` costly (a change of it needs a whole
    /// simulation), `b` cheap.
    struct Costly(Vec<FittedParameter>);

    impl Model for Costly {
        fn label(&self) -> String {
            "costly".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.0
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, PredictError> {
            Ok(s.velocity.iter().map(|v| x[0] * x[0] * v + x[1]).collect())
        }
        fn costly_parameters(&self) -> Option<Vec<usize>> {
            Some(vec![0])
        }
    }

    #[test]
    fn a_secant_model_that_fails_after_an_exact_jacobian_is_refreshed_in_its_cheap_columns_alone() {
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        for k in 0..20 {
            let v = (k as f64 * 0.4).sin();
            text += &format!("{},{v},{}\n", k as f64 * 0.01, 4.0 * v + 1.0);
        }
        let data = tests_data(&text, &Mapping::default());
        let model = Costly(vec![
            FittedParameter::new("a", 1.0, 0.0, 10.0),
            FittedParameter::new("b", 0.0, -5.0, 5.0),
        ]);
        let problem = Problem::new(&model, &data, vec![]).unwrap();
        assert_eq!(problem.costly(), Some(vec![true, false]));
        let vars = Variables::new(&problem, None, &[1.0, 0.0]);
        let u0 = DVector::from_vec(vars.to_internal(&[1.0, 0.0]));
        let mut lm = Lm::new(
            vars,
            &u0,
            (JacobianRule::Secant, LaterRuns::Full),
            &[],
            true,
        );
        lm.set_params(&u0);
        let columns = |lm: &Lm| lm.jacobian_evaluations.load(Ordering::Relaxed);
        let exact = lm.jacobian().unwrap();
        assert_eq!(columns(&lm), 2, "the first Jacobian takes every column");
        // A step in the costly key that the tangent says lowers the cost
        // (a from 1 towards 2.2) but that goes to a = 4.4, where a² is far
        // from its tangent: the cost rises, the secant model failed.
        let mut u1 = u0.clone();
        u1[0] += 0.8;
        lm.set_params(&u1);
        let partial = lm.jacobian().unwrap();
        assert_eq!(columns(&lm), 3, "only the cheap column is taken anew");
        let fresh = lm.differences(None);
        assert_relative_eq!(partial.column(1), fresh.column(1), epsilon = 1e-12);
        // The costly column is the secant's: (r₁ − r₀) / du, not the
        // tangent at either end.
        let r0 = DVector::from_vec(lm.vars.evaluate(u0.as_slice()).0);
        let secant = (&lm.r - r0) / 0.8;
        assert_relative_eq!(partial.column(0), secant.column(0), max_relative = 1e-9);
        assert!((partial.column(0) - fresh.column(0)).norm() > 0.1 * fresh.column(0).norm());
        assert!((partial.column(0) - exact.column(0)).norm() > 0.1 * exact.column(0).norm());
        // Not exact: it gives no curvature for a confidence region.
        let last = lm.last.lock().unwrap().take();
        assert!(!last.as_ref().unwrap().exact);
        assert!(curvature(last).is_none());
    }

    #[test]
    fn a_jacobian_rule_is_named_on_the_command_line() {
        assert_eq!(JacobianRule::parse("secant"), Ok(JacobianRule::Secant));
        assert_eq!(
            JacobianRule::parse("differences"),
            Ok(JacobianRule::Differences)
        );
        assert!(JacobianRule::parse("broyden")
            .unwrap_err()
            .contains("secant or differences"));
    }
}
