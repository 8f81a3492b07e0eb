//! The global phase and the distinct optima.
//!
//! A seeded Latin hypercube over the scaled bounds (each parameter's range
//! cut into as many strata as there are points, one point per stratum) is
//! scored by one simulation per point, in parallel. Local runs start from
//! the given start and from the best global points that are not close to a
//! start already taken; their end points, sorted by cost and with
//! near-duplicates merged, are the distinct optima.

use super::local_run::{local_run, Found, LocalRun};
use super::options::Options;
use super::problem::Problem;
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

/// Global phase, local runs, distinct optima (best first; never empty).
pub fn search(problem: &Problem<'_>, options: &Options) -> Vec<LocalRun> {
    let x0 = problem.start();
    let mut starts = vec![x0.clone()];
    // Extra starts (a nested model's optimum) run whatever the count.
    let clamp = |x: &[f64]| -> Vec<f64> {
        problem
            .params
            .iter()
            .zip(x)
            .map(|(p, v)| v.clamp(p.lo, p.hi))
            .collect()
    };
    let extra: Vec<Vec<f64>> = options
        .extra_starts
        .iter()
        .filter(|x| x.len() == problem.params.len())
        .map(|x| clamp(x))
        .collect();
    let wanted = options.starts + extra.len();
    starts.extend(extra);
    if options.global_points > 0 && options.starts > 1 {
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
    }
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
        local_run(
            problem,
            x,
            options.max_evaluations,
            options.jacobian,
            earlier,
            (options.ftol, options.xtol),
        )
    };
    // The given start first; then the other starts side by side, each
    // stopping when it comes to the first one's optimum (the same for
    // every run, so the outcome does not depend on which ends first).
    let mut runs: Vec<LocalRun> = Vec::new();
    if !problem.stop.requested() {
        let first = run_from(&starts[0], &[]);
        say(0, &first);
        runs.push(first);
    }
    let found: Vec<Found> = runs
        .iter()
        .filter_map(|r| {
            r.curvature.clone().map(|curvature| Found {
                u: problem.to_internal(&r.x),
                cost: r.cost,
                curvature,
            })
        })
        .collect();
    let others: Vec<Option<LocalRun>> = starts
        .par_iter()
        .enumerate()
        .skip(1)
        .map(|(k, x)| {
            if problem.stop.requested() || runs.is_empty() {
                return None;
            }
            let run = run_from(x, &found);
            say(k, &run);
            Some(run)
        })
        .collect();
    runs.extend(others.into_iter().flatten());
    runs.sort_by(|a, b| a.cost.total_cmp(&b.cost));
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
        let cost = problem.cost(&x0);
        distinct.push(LocalRun {
            x: x0,
            cost,
            converged: false,
            termination: "stopped before any local run".into(),
            evaluations: 1,
            jacobian_evaluations: 0,
            curvature: None,
        });
    }
    distinct
}

#[cfg(test)]
mod tests {
    use super::*;

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
