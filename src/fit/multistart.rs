//! The global phase and the distinct optima.
//!
//! A seeded Latin hypercube over the scaled bounds (each parameter's range
//! cut into as many strata as there are points, one point per stratum) is
//! scored by one simulation per point, in parallel. Local runs start from
//! the given start and from the best global points that are not close to a
//! start already taken; their end points, sorted by cost and with
//! near-duplicates merged, are the distinct optima.

use super::earlier_optima::Found;
use super::local_run::{local_run, LocalRun};
use super::options::Options;
use super::problem::Problem;
use super::separable::{Separable, Variables};
use rand::rngs::StdRng;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

/// `points` points in the unit cube of dimension `dims`, one per stratum of
/// every coordinate.
pub fn latin_hypercube(points: usize, dims: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = StdRng::seed_from_u64(seed);
    let mut out = vec![Vec::with_capacity(dims); points];
    for _ in 0..dims {
        let mut strata: Vec<usize> = (0..points).collect();
        strata.shuffle(&mut rng);
        for (point, s) in out.iter_mut().zip(strata) {
            point.push((s as f64 + rng.random::<f64>()) / points as f64);
        }
    }
    out
}

/// Largest per-parameter distance in fractions of the scaled ranges.
fn distance(problem: &Problem<'_>, a: &[f64], b: &[f64]) -> f64 {
    problem
        .params
        .iter()
        .zip(a.iter().zip(b))
        .map(|(p, (x, y))| (p.fraction(*x) - p.fraction(*y)).abs())
        .fold(0.0, f64::max)
}

/// Starts closer than this (fraction of the range) are the same start.
const DISTINCT_START: f64 = 0.1;
/// Optima closer than this are the same optimum.
const DISTINCT_OPTIMUM: f64 = 0.02;

/// Global phase, local runs (`separable`'s parameters solved at every
/// point), distinct optima (best first; never empty).
pub fn search(
    problem: &Problem<'_>,
    separable: Option<&Separable>,
    options: &Options,
) -> Vec<LocalRun> {
    let starts = starts(problem, options);
    let runs = local_runs((problem, separable), options, &starts);
    let mut distinct: Vec<LocalRun> = Vec::new();
    for r in runs {
        if distinct
            .iter()
            .all(|d| distance(problem, &d.x, &r.x) > DISTINCT_OPTIMUM)
        {
            distinct.push(r);
        }
    }
    if distinct.is_empty() {
        // Stopped before any local run: the start, unrefined.
        let x0 = problem.start();
        let cost = problem.cost(&x0);
        distinct.push(LocalRun {
            x: x0,
            cost,
            converged: false,
            termination: "stopped before any local run".into(),
            evaluations: 1,
            jacobian_evaluations: 0,
            curvature: None,
            crawling: Vec::new(),
        });
    }
    distinct
}

/// The local runs' starts: the given start, the extra starts (a nested
/// model's optimum, whatever the count), then the best points of the
/// global phase that are not close to a start already taken.
fn starts(problem: &Problem<'_>, options: &Options) -> Vec<Vec<f64>> {
    let clamp = |x: &[f64]| -> Vec<f64> {
        problem
            .params
            .iter()
            .zip(x)
            .map(|(p, v)| v.clamp(p.lo, p.hi))
            .collect()
    };
    let given = match &options.start {
        Some(x) if x.len() == problem.params.len() => clamp(x),
        _ => problem.start(),
    };
    let mut starts = vec![given];
    let extra: Vec<Vec<f64>> = options
        .extra_starts
        .iter()
        .filter(|x| x.len() == problem.params.len())
        .map(|x| clamp(x))
        .collect();
    let wanted = options.starts + extra.len();
    starts.extend(extra);
    if options.global_points == 0 || options.starts <= 1 {
        return starts;
    }
    let cube = latin_hypercube(options.global_points, problem.params.len(), options.seed);
    let mut scored: Vec<(f64, Vec<f64>)> = cube
        .par_iter()
        .map(|f| {
            if problem.stop.requested() {
                return (f64::INFINITY, Vec::new());
            }
            let x: Vec<f64> = problem
                .params
                .iter()
                .zip(f)
                .map(|(p, v)| p.from_fraction(*v))
                .collect();
            (problem.cost(&x), x)
        })
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    options.say(&format!(
        "global phase: {} points (seed {}), best cost {:.4e}",
        scored.len(),
        options.seed,
        scored[0].0
    ));
    for (_, x) in scored {
        if starts.len() >= wanted || x.is_empty() {
            break;
        }
        if starts
            .iter()
            .all(|s| distance(problem, s, &x) > DISTINCT_START)
        {
            starts.push(x);
        }
    }
    starts
}

/// The local runs from `starts`, best first: the given start first; then
/// the other starts side by side, each stopping when it comes to the
/// first one's optimum (the same for every run, so the outcome does not
/// depend on which ends first).
fn local_runs(
    (problem, separable): (&Problem<'_>, Option<&Separable>),
    options: &Options,
    starts: &[Vec<f64>],
) -> Vec<LocalRun> {
    let total = starts.len();
    let say = |k: usize, run: &LocalRun| {
        options.say(&format!(
            "local run {}/{total} ({}): cost {:.4e}, {} evaluations + {} for Jacobians, {}",
            k + 1,
            if k == 0 {
                "given start"
            } else {
                "global point"
            },
            run.cost,
            run.evaluations,
            run.jacobian_evaluations,
            run.termination
        ));
    };
    let run_from = |x: &Vec<f64>, earlier: &[Found]| {
        let run = |watch_crawl: bool| {
            local_run(
                (problem, separable),
                x,
                options.max_evaluations,
                options.jacobian,
                earlier,
                options.later_runs,
                (options.ftol, options.xtol),
                watch_crawl,
            )
        };
        super::bound_polish::settle(
            (problem, separable),
            run(true),
            || run(false),
            options.max_evaluations,
            options.later_runs,
            (options.ftol, options.xtol),
        )
    };
    let mut runs: Vec<LocalRun> = Vec::new();
    if problem.stop.requested() {
        return runs;
    }
    let first = run_from(&starts[0], &[]);
    say(0, &first);
    let found: Vec<Found> = first
        .curvature
        .clone()
        .map(|curvature| Found {
            u: Variables::new(problem, separable, &first.x).canonical(&first.x),
            x: first.x.clone(),
            cost: first.cost,
            curvature,
        })
        .into_iter()
        .collect();
    runs.push(first);
    let others: Vec<Option<LocalRun>> = starts
        .par_iter()
        .enumerate()
        .skip(1)
        .map(|(k, x)| {
            if problem.stop.requested() {
                return None;
            }
            let run = run_from(x, &found);
            say(k, &run);
            Some(run)
        })
        .collect();
    runs.extend(others.into_iter().flatten());
    runs.sort_by(|a, b| a.cost.total_cmp(&b.cost));
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::data::Data;
    use crate::fit::options::LaterRuns;
    use crate::fit::problem::{tests_data, Model};
    use crate::fit::series::{Mapping, Series};
    use crate::fit::unknowns::FittedParameter;

    /// Two valleys in one parameter a ∈ [−3, 3]: residuals a² − 1 and
    /// 0.3 (a + 1), so ½Σr² has its best optimum at a = −1 (cost 0), a
    /// worse one at a = 0.953 (cost 0.176) and a hill between them at
    /// a = 0.047 (cost 0.547).
    struct TwoValleys(Vec<FittedParameter>);

    impl Model for TwoValleys {
        fn label(&self) -> String {
            "two valleys".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.0
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, crate::fit::PredictError> {
            let a = x[0];
            let mut out = s.friction.clone();
            out[0] -= a * a - 1.0;
            out[1] -= 0.3 * (a + 1.0);
            Ok(out)
        }
    }

    fn two_valleys() -> (TwoValleys, Data) {
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        for k in 0..8 {
            text += &format!("{},0.1,1\n", k as f64 * 0.01);
        }
        let data = tests_data(&text, &Mapping::default());
        // The given start, a = 2, lies in the worse valley.
        let model = TwoValleys(vec![FittedParameter::new("a", 2.0, -3.0, 3.0)]);
        (model, data)
    }

    /// The distinct optima and the simulations of a search from a = 2
    /// with `other` as a second start.
    fn runs_from(other: Option<f64>, later_runs: LaterRuns) -> (Vec<LocalRun>, usize) {
        let (model, data) = two_valleys();
        let problem = Problem::new(&model, &data, vec![]).unwrap();
        let options = Options {
            starts: 1,
            global_points: 0,
            extra_starts: other.map(|a| vec![a]).into_iter().collect(),
            later_runs,
            ..Default::default()
        };
        let runs = search(&problem, None, &options);
        let simulations = problem
            .simulations
            .load(std::sync::atomic::Ordering::Relaxed);
        (runs, simulations)
    }

    #[test]
    fn a_later_run_in_the_valley_of_the_first_optimum_stops_there_for_a_few_simulations() {
        let (alone, first_run) = runs_from(None, LaterRuns::Valley);
        let (valley, with_valley) = runs_from(Some(2.5), LaterRuns::Valley);
        let (full, _) = runs_from(Some(2.5), LaterRuns::Full);
        // One distinct optimum every way: the first run's, a = 0.953.
        assert_eq!((alone.len(), valley.len(), full.len()), (1, 1, 1));
        approx::assert_relative_eq!(valley[0].x[0], 0.9528, epsilon = 1e-3);
        approx::assert_relative_eq!(valley[0].x[0], full[0].x[0], epsilon = 1e-9);
        // The later run cost its start and the valley test's points, and
        // nothing more: it stopped there.
        assert_eq!(
            with_valley,
            first_run + 1 + crate::fit::earlier_optima::VALLEY_POINTS
        );
    }

    #[test]
    fn a_later_run_with_a_hill_on_its_line_to_the_first_optimum_walks_to_the_better_one() {
        // From a = −2.5 the straight line to a = 0.953 crosses a = −1 and
        // the hill at 0.047: the valley test sees the rise, the run goes
        // on and finds the better optimum.
        let (runs, _) = runs_from(Some(-2.5), LaterRuns::Valley);
        assert_eq!(runs.len(), 2, "{runs:?}");
        approx::assert_relative_eq!(runs[0].x[0], -1.0, epsilon = 1e-4);
        assert!(runs[0].cost < 1e-8, "{}", runs[0].cost);
        assert!(!runs[0].termination.contains("valley"));
        approx::assert_relative_eq!(runs[1].x[0], 0.9528, epsilon = 1e-3);
    }

    #[test]
    fn a_latin_hypercube_puts_one_point_in_every_stratum_and_repeats_with_its_seed() {
        let a = latin_hypercube(10, 3, 7);
        for d in 0..3 {
            let mut strata: Vec<usize> = a.iter().map(|p| (p[d] * 10.0) as usize).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..10).collect::<Vec<_>>());
        }
        assert_eq!(a, latin_hypercube(10, 3, 7));
        assert_ne!(a, latin_hypercube(10, 3, 8));
    }
}
