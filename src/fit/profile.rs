//! The cheap keys fitted at every point of the costly ones (variable
//! projection with a nonlinear inner problem; Golub & Pereyra 2003, §4):
//! the default, `--cheap-keys profiled`.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | θ | the costly parameters: a change of one needs a film solve | theirs |
//! | c | the cheap parameters: a change recomposes the friction along the kept film | theirs |
//! | f | c as fractions of their scaled bounds (0 … 1; log-scaled where the bounds are) | 1 |
//! | r(θ, c) | the residuals on the fitted samples (the linear keys solved) | N |
//! | J | ∂r/∂f at fixed θ, by forward differences | N |
//! | c*(θ) | argmin over the box of ‖r(θ, c)‖², from the last accepted point's c | theirs |
//!
//! The local runs search θ alone on the profiled residuals r(θ, c*(θ)).
//! Every point θ costs one film solve; the inner fit of c at it only
//! recomposes the friction along that film. A pair the data hardly
//! separate (a bristle's stiffness and damping, a boundary friction and
//! its rate) is then walked by recompositions, not by film solves. At
//! c*(θ) the gradient in c is zero (or points out of the box), and the
//! profiled cost's gradient in θ is the joint cost's (Kaufman 1975): a
//! stationary point of the profile is one of the joint problem.
//!
//! A cheap key that bends the curve at a speed (a Stribeck speed, an
//! activation speed) has several optima of its own, one per place the data
//! give the bend: a run's first inner fit also starts it at three places
//! of its range and keeps the best (`Variables::evaluate_first`); the
//! later points follow that basin. Without it, on the lead screw's
//! faster-speed split (b) the film with the Stribeck curve ended at
//! training RMS 6.86e-5 N·m where the joint search reaches 1.38e-5 (the
//! bend at 0.2 rad/s instead of 4.1); with it, the same optimum as the
//! joint search from each of three starts, with 47–80 film solves against
//! 133–261. On the EMPS record's 10-key bench: the joint search's optimum
//! with 44 film solves instead of 335.
//!
//! The runs' Jacobian in θ is not a difference of two inner fits (each
//! stopped within `Problem::cheap_ftol`, their difference is noise once
//! θ's step is small, and the runs crawled on it): each column is taken
//! with c held at c*(θ) and projected out of the span of the free cheap
//! keys' columns there ([`project_out_cheap`]), the variable-projection
//! Jacobian of Golub & Pereyra (1973). On the EMPS record's `--fit auto`
//! the last film trial took 12 s instead of 13–20, the whole calibration
//! 50 s instead of 57–64, with the same choices and held-out error.
//!
//! The inner fit is a Levenberg–Marquardt on f with the bounds kept
//! exactly: each step minimises ‖r + J d‖² + λ Σ_j (J_jᵀJ_j) d_j² over the
//! box 0 ≤ f + d ≤ 1 (the linear keys' exact box solver, `box_qp.rs`), so
//! a key at its bound stays there in one step instead of creeping to it
//! under the sine transform.

use super::box_qp::box_minimum;
use super::problem::Problem;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// What the inner fit needs of the local runs' variables.
pub(super) trait CheapFit: Sync {
    /// The problem.
    fn problem(&self) -> &Problem<'_>;
    /// The cheap keys fitted (indices into the problem's parameters).
    fn keys(&self) -> &[usize];
    /// The residuals at the whole point `x` with the linear keys solved,
    /// and the point.
    fn solved_at(&self, x: Vec<f64>) -> (Vec<f64>, Vec<f64>);
}

/// Forward-difference step, as a fraction of a key's scaled range.
const STEP: f64 = 1e-6;
/// Most inner iterations (Jacobians).
const MAX_ITERATIONS: usize = 100;
/// An accepted step that lowers the cost by less than `Problem::cheap_ftol`
/// (this fraction of the runs' `ftol`) ends the inner fit: 1e-12 for a
/// final fit (`ftol` 1e-10), 1e-8 for a selection's trial (1e-6), whose
/// inner fits along a ridge the data hardly resolve (a bristle's stiffness
/// and damping) otherwise crawl on at 1e-12.
pub(super) const INNER_FTOL: f64 = 1e-2;
/// So does one shorter than this, in fractions of the ranges.
const STEP_TOLERANCE: f64 = 1e-10;
/// Singular values of the cheap keys' (unit) columns' Gram matrix below
/// this are taken as zero when a costly column is projected out of their
/// span (a pair the data cannot separate at all).
const PROJECTION_RCOND: f64 = 1e-10;
/// Levenberg–Marquardt damping: first value, and its factors on an
/// accepted and a rejected step.
const DAMPING: (f64, f64, f64) = (1e-3, 1.0 / 3.0, 4.0);
/// The damping's floor, and the value at which a step is given up (the
/// model is flat).
const DAMPING_MIN: f64 = 1e-12;
const DAMPING_MAX: f64 = 1e12;

fn half_sum(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|v| v * v).sum::<f64>()
}

/// The residuals at the whole point `x` with `inner`'s parameters (the
/// cheap ones) fitted from their values in `x`, and the whole point they
/// belong to.
pub(super) fn fit_cheap(inner: &dyn CheapFit, x: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let problem = inner.problem();
    let (mut r, mut x) = inner.solved_at(x.to_vec());
    let mut cost = half_sum(&r);
    if !cost.is_finite() || problem.stop.requested() {
        return (r, x);
    }
    let mut lambda = DAMPING.0;
    for _ in 0..MAX_ITERATIONS {
        let f = fractions(inner, &x);
        let Some(linear) = Linearised::at(inner, &x, &f, &r) else {
            break;
        };
        // Steps from this Jacobian, the damping raised until one lowers
        // the cost (or the step is too short to matter).
        let done = loop {
            let d = linear.step(&f, lambda);
            if d.iter().all(|v| v.abs() < STEP_TOLERANCE) {
                break true;
            }
            let trial: Vec<f64> = f.iter().zip(&d).map(|(a, b)| a + b).collect();
            let (rt, xt) = inner.solved_at(with_fractions(inner, &x, &trial));
            let ct = half_sum(&rt);
            if ct < cost {
                let small = cost - ct < problem.cheap_ftol * cost;
                (r, x, cost) = (rt, xt, ct);
                lambda = (lambda * DAMPING.1).max(DAMPING_MIN);
                break small;
            }
            lambda *= DAMPING.2;
            if lambda > DAMPING_MAX {
                break true;
            }
        };
        if done || problem.stop.requested() {
            break;
        }
    }
    (r, x)
}

/// The cheap keys of `inner` at `x`, as fractions of their ranges.
fn fractions(inner: &dyn CheapFit, x: &[f64]) -> Vec<f64> {
    let params = &inner.problem().params;
    inner
        .keys()
        .iter()
        .map(|i| params[*i].fraction(x[*i]))
        .collect()
}

/// `x` with the cheap keys of `inner` set at fractions `f`.
fn with_fractions(inner: &dyn CheapFit, x: &[f64], f: &[f64]) -> Vec<f64> {
    let params = &inner.problem().params;
    let mut y = x.to_vec();
    for (i, fj) in inner.keys().iter().zip(f) {
        y[*i] = params[*i].from_fraction(*fj);
    }
    y
}

/// The residuals' linear model at a point: ψ_j = J_j / ‖J_j‖, the norms
/// ‖J_j‖, ψᵀψ and ψᵀr.
struct Linearised {
    norms: Vec<f64>,
    gram: DMatrix<f64>,
    b: DVector<f64>,
}

/// The columns of J for the cheap keys `which` (indices into `f`) by
/// forward differences at `x` (fractions `f`, residuals `r`; backward at
/// an upper bound), side by side, each scaled to unit norm, and their
/// norms. A key that does not move the residuals keeps a column of zeros
/// and a unit norm.
fn cheap_columns(
    inner: &dyn CheapFit,
    x: &[f64],
    f: &[f64],
    r: &[f64],
    which: &[usize],
) -> (Vec<Vec<f64>>, Vec<f64>) {
    // The columns side by side: a run's outer Jacobian often has one
    // column (the film's one key), so this is where the cores work.
    which
        .par_iter()
        .map(|&j| {
            let h = if f[j] + STEP <= 1.0 { STEP } else { -STEP };
            let mut g = f.to_vec();
            g[j] += h;
            let (rj, _) = inner.solved_at(with_fractions(inner, x, &g));
            let col: Vec<f64> = rj.iter().zip(r).map(|(a, b)| (a - b) / h).collect();
            let norm = dot(&col, &col).sqrt();
            let norm = if norm.is_finite() && norm > 0.0 {
                norm
            } else {
                1.0
            };
            (col.iter().map(|v| v / norm).collect(), norm)
        })
        .unzip()
}

/// The profiled residuals' Jacobian from `columns`: differences of the
/// residuals in the searched (costly) variables taken with the cheap keys
/// held at `x`, their fit c*(θ) (residuals `r`), each projected out of the
/// span of the columns of the cheap keys inside their box there. With the
/// implicit function theorem (Gauss–Newton), dc*/dθ = −J_c⁺ J_θ on those
/// keys, so d r(θ, c*(θ))/dθ = (I − J_c J_c⁺) J_θ (Golub & Pereyra 1973):
/// the exact gradient at c*, the profile's own curvature (a ridge between
/// a costly and a cheap key is flat in it), and no noise from where the
/// inner fits stopped (the difference of two inner fits, each stopped
/// within `Problem::cheap_ftol`, is noise when θ's step is small). A key
/// at a bound is held there, as the inner fit holds it.
pub(super) fn project_out_cheap(
    inner: &dyn CheapFit,
    x: &[f64],
    r: &[f64],
    columns: &mut [Vec<f64>],
) {
    let f = fractions(inner, x);
    let free: Vec<usize> = (0..f.len()).filter(|&j| f[j] > 0.0 && f[j] < 1.0).collect();
    if free.is_empty() || columns.iter().all(|c| c.iter().all(|v| *v == 0.0)) {
        return;
    }
    let (psi, _) = cheap_columns(inner, x, &f, r, &free);
    let psi: Vec<Vec<f64>> = psi
        .into_iter()
        .filter(|c| c.iter().any(|v| *v != 0.0))
        .collect();
    if psi.is_empty() {
        return;
    }
    let k = psi.len();
    let svd = DMatrix::from_fn(k, k, |a, c| dot(&psi[a], &psi[c])).svd(true, true);
    for col in columns.iter_mut() {
        let b = DVector::from_fn(k, |a, _| dot(&psi[a], col));
        let Ok(a) = svd.solve(&b, PROJECTION_RCOND) else {
            continue;
        };
        for (aj, p) in a.iter().zip(&psi) {
            col.iter_mut().zip(p).for_each(|(c, v)| *c -= aj * v);
        }
    }
}

impl Linearised {
    /// J by forward differences at `x` (fractions `f`, residuals `r`;
    /// backward at an upper bound). None when no key moves the residuals.
    fn at(inner: &dyn CheapFit, x: &[f64], f: &[f64], r: &[f64]) -> Option<Self> {
        let every: Vec<usize> = (0..f.len()).collect();
        let (columns, norms) = cheap_columns(inner, x, f, r, &every);
        if norms.iter().all(|n| *n == 1.0) {
            return None;
        }
        let k = columns.len();
        Some(Self {
            gram: DMatrix::from_fn(k, k, |a, c| dot(&columns[a], &columns[c])),
            b: DVector::from_fn(k, |a, _| dot(&columns[a], r)),
            norms,
        })
    }

    /// The step d in fractions minimising ‖r + J d‖² + λ Σ_j ‖J_j‖² d_j²
    /// over the box 0 ≤ f + d ≤ 1.
    fn step(&self, f: &[f64], lambda: f64) -> Vec<f64> {
        let mut gram = self.gram.clone();
        for j in 0..f.len() {
            gram[(j, j)] = 1.0 + lambda;
        }
        let boxed: Vec<(f64, f64)> = f
            .iter()
            .zip(&self.norms)
            .map(|(fj, n)| (-fj * n, (1.0 - fj) * n))
            .collect();
        box_minimum(&gram, &self.b, &boxed)
            .iter()
            .zip(&self.norms)
            .map(|(y, n)| y / n)
            .collect()
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::local_run::local_run;
    use crate::fit::options::{JacobianRule, LaterRuns};
    use crate::fit::problem::{tests_data, Model};
    use crate::fit::separable::Variables;
    use crate::fit::series::{Mapping, Series};
    use crate::fit::unknowns::FittedParameter;
    use crate::fit::PredictError;
    use approx::assert_relative_eq;
    use std::sync::Mutex;

    /// Friction = a v + k (1 − e^(−|v|/s)) sgn v: `a` costly (a change of it
    /// needs a whole simulation), `s` and `k` cheap; the costly values
    /// every prediction was asked at are kept.
    struct Film {
        params: Vec<FittedParameter>,
        costly_seen: Mutex<Vec<u64>>,
    }

    impl Film {
        fn new(k_hi: f64) -> Self {
            Film {
                params: vec![
                    FittedParameter::new("a", 1.0, 0.1, 10.0),
                    FittedParameter::new("s", 0.1, 0.01, 1.0),
                    FittedParameter::new("k", 0.5, 0.0, k_hi),
                ],
                costly_seen: Mutex::new(Vec::new()),
            }
        }
        /// How many distinct values of the costly key were simulated.
        fn solves(&self) -> usize {
            let mut seen = self.costly_seen.lock().unwrap().clone();
            seen.sort_unstable();
            seen.dedup();
            seen.len()
        }
    }

    impl Model for Film {
        fn label(&self) -> String {
            "film".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.params
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, PredictError> {
            self.costly_seen.lock().unwrap().push(x[0].to_bits());
            let (a, speed, k) = (x[0], x[1], x[2]);
            Ok(s.velocity
                .iter()
                .map(|v| a * v + k * (1.0 - (-v.abs() / speed).exp()) * v.signum())
                .collect())
        }
        fn costly_parameters(&self) -> Option<Vec<usize>> {
            Some(vec![0])
        }
    }

    /// Samples of a = 2, s = 0.3, k = 1.5 over ±1.5 m/s.
    fn data() -> crate::fit::data::Data {
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        for i in 0..200 {
            let v = 1.5 * (i as f64 * 0.05).sin();
            let f = 2.0 * v + 1.5 * (1.0 - (-v.abs() / 0.3).exp()) * v.signum();
            text += &format!("{},{v},{f}\n", i as f64 * 0.01);
        }
        tests_data(&text, &Mapping::default())
    }

    /// The fitted point and the distinct costly values simulated.
    fn fit(profiled: bool) -> (Vec<f64>, usize) {
        let model = Film::new(5.0);
        let data = data();
        let mut problem = Problem::new(&model, &data, vec![]).unwrap();
        problem.profile_cheap = profiled;
        let run = local_run(
            (&problem, None),
            &problem.start(),
            200,
            JacobianRule::Secant,
            &[],
            LaterRuns::Full,
            (1e-10, 1e-8),
            true,
        );
        assert!(run.converged, "{}", run.termination);
        (run.x, model.solves())
    }

    #[test]
    fn profiling_the_cheap_keys_reaches_the_joint_optimum_with_fewer_costly_simulations() {
        let (profiled, profiled_solves) = fit(true);
        let (searched, searched_solves) = fit(false);
        for (x, truth) in [(&profiled, [2.0, 0.3, 1.5]), (&searched, [2.0, 0.3, 1.5])] {
            for (v, t) in x.iter().zip(truth) {
                assert_relative_eq!(*v, t, max_relative = 1e-5);
            }
        }
        assert!(
            profiled_solves < searched_solves,
            "profiled {profiled_solves} costly simulations, searched {searched_solves}"
        );
    }

    /// At the costly key a, the cheap keys s and k fitted tightly there:
    /// the relative distances of the column taken with them held, before
    /// and after its projection, from the central difference of the
    /// profiled residuals r(a, c*(a)) (each side fitted again), and the
    /// relative error of the projected column's gradient Jᵀr against the
    /// profiled cost's central difference.
    fn projected_column_errors(a: f64) -> (f64, f64, f64) {
        let model = Film::new(5.0);
        let data = data();
        let mut problem = Problem::new(&model, &data, vec![]).unwrap();
        problem.profile_cheap = true;
        problem.cheap_ftol = 1e-16;
        let start = [a, 0.2, 1.0];
        let vars = Variables::new(&problem, None, &start);
        let profiled = |a: f64| {
            let mut x = start.to_vec();
            x[0] = a;
            fit_cheap(&vars.cheap_at(&x).unwrap(), &x)
        };
        let (r, x) = profiled(a);
        let h = 1e-4;
        let (rp, _) = profiled(a + h);
        let (rm, _) = profiled(a - h);
        let exact: Vec<f64> = rp
            .iter()
            .zip(&rm)
            .map(|(p, m)| (p - m) / (2.0 * h))
            .collect();
        let mut held = x.clone();
        held[0] += 1e-7;
        let (rh, _) = CheapFit::solved_at(&vars, held);
        let column: Vec<f64> = rh.iter().zip(&r).map(|(a, b)| (a - b) / 1e-7).collect();
        let mut projected = vec![column.clone()];
        project_out_cheap(&vars.cheap_at(&x).unwrap(), &x, &r, &mut projected);
        let distance = |a: &[f64]| {
            let d: Vec<f64> = a.iter().zip(&exact).map(|(p, q)| p - q).collect();
            dot(&d, &d).sqrt() / dot(&exact, &exact).sqrt()
        };
        let slope = (half_sum(&rp) - half_sum(&rm)) / (2.0 * h);
        let gradient = (dot(&projected[0], &r) - slope).abs() / slope.abs();
        (distance(&column), distance(&projected[0]), gradient)
    }

    #[test]
    fn near_the_optimum_the_projected_jacobian_is_the_derivative_of_the_profiled_residuals() {
        // Small residuals (the data are the model's at a = 2: the
        // Gauss–Newton limit): the projected column is the profile's
        // derivative, to an error that falls with the residuals (1.6 % at
        // a = 1.98, 18 % at 1.7); the column before it is not (a and k both
        // raise the friction with the speed, so c* moves with a).
        let (held, projected, gradient) = projected_column_errors(1.999);
        assert!(projected < 2e-3, "{projected}");
        assert!(held > 0.05, "{held}");
        assert!(gradient < 1e-3, "{gradient}");
    }

    #[test]
    fn far_from_the_optimum_the_projected_jacobians_gradient_is_the_profiled_costs() {
        // Large residuals: the column carries the Gauss–Newton error of
        // dc*/da, but Jᵀr, what the runs descend on, is exact at c*.
        let (_, _, gradient) = projected_column_errors(1.7);
        assert!(gradient < 1e-3, "{gradient}");
    }

    #[test]
    fn a_cheap_key_whose_optimum_lies_past_its_bound_ends_on_the_bound() {
        // k's best value 1.5 lies past its upper bound 1.2: the inner fit
        // puts it on the bound exactly, with a and s at their optimum for it.
        let model = Film::new(1.2);
        let data = data();
        let mut problem = Problem::new(&model, &data, vec![]).unwrap();
        problem.profile_cheap = true;
        let start = [2.0, 0.1, 0.5];
        let vars = Variables::new(&problem, None, &start);
        let inner = vars.cheap_at(&start).expect("s and k are profiled");
        assert_eq!(CheapFit::keys(&inner), &[1, 2]);
        let (r, x) = fit_cheap(&inner, &start);
        assert_eq!(x[2], 1.2);
        assert_eq!(x[0], 2.0, "the costly key is held");
        assert_relative_eq!(half_sum(&r), problem.cost(&x), max_relative = 1e-12);
        // Nothing near it fits better: s moved either way, k inside.
        for (ds, dk) in [(1.001, 1.0), (0.999, 1.0), (1.0, 0.999)] {
            let y = [x[0], x[1] * ds, x[2] * dk];
            assert!(problem.cost(&y) > half_sum(&r));
        }
    }
}
