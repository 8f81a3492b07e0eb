//! Separable least squares: the parameters the residuals are linear in are
//! solved at every point, not searched (variable projection; Golub &
//! Pereyra 1973, 2003).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | θ | the searched parameters (every other one) | theirs |
//! | c, c₀ | the linear parameters, and their values where the residuals were taken | theirs |
//! | φ_j | the change of every fitted residual per unit of c_j: fixed | N per unit of c_j |
//! | r(θ, c) | the residuals on the fitted samples | N |
//! | [lo_j, hi_j] | c_j's bounds | theirs |
//!
//! A parameter is linear when every residual is affine in it with a slope
//! that no parameter changes: r(θ, c) = r(θ, c₀) + Σ_j φ_j (c_j − c₀_j).
//! Such are the model's [`Model::linear_parameters`] (our drivetrain's
//! viscous and quadratic losses: slopes v and v|v|) — when no fitted map
//! coefficient moves the model's inputs — and the fitted map coefficients
//! that move only the measured friction, affinely (a drive's mass times
//! the measured acceleration, a force offset). Their slopes are taken once
//! per problem, by one difference each across the bound.
//!
//! At every point θ the local runs evaluate, c is set to
//!
//! c*(θ) = argmin_{lo ≤ c ≤ hi} ‖r(θ, c₀) + Φ (c − c₀)‖²,
//!
//! a convex quadratic program in k ≤ [`MAX_LINEAR`] unknowns, solved
//! exactly: the unconstrained minimum when it lies in the box, else the
//! best of the minima on the box's faces (each c_j free, at lo_j or at
//! hi_j: 3ᵏ faces; the box's minimum is one of them). The runs then search
//! θ alone on the reduced residuals r(θ, c*(θ)). The least-squares
//! optimum is the same; what changes is the path: a ridge along which the
//! linear parameters trade against each other (a viscous against a
//! quadratic loss) is no longer walked step by step, and every point costs
//! one simulation as before (the k products Φᵀr are sums over the samples).

use super::problem::{Model, Problem};
use nalgebra::{DMatrix, DVector};

/// At most this many parameters are solved (3ᵏ faces per point); more
/// linear ones are searched.
pub const MAX_LINEAR: usize = 6;

/// Where a profiled key that bends the curve at a speed also starts at a
/// run's first point: fractions of its scaled (log) range, near its slow
/// end, in its middle and near its fast end.
const BEND_PLACES: [f64; 3] = [0.1, 0.5, 0.9];

/// The linear parameters of a problem and their fixed slopes.
#[derive(Debug, Clone)]
pub struct Separable {
    /// Indices (into the problem's parameters) of the solved ones.
    linear: Vec<usize>,
    /// The others: searched.
    searched: Vec<usize>,
    /// Their bounds.
    bounds: Vec<(f64, f64)>,
    /// ψ_j = φ_j / s_j on the fitted samples.
    columns: Vec<Vec<f64>>,
    /// s_j = ‖φ_j‖.
    norms: Vec<f64>,
    /// ψᵀψ (unit diagonal).
    gram: DMatrix<f64>,
}

impl Separable {
    /// The problem's linear parameters and their slopes, taken at the
    /// problem's start (one evaluation, and one more per parameter); None
    /// when it has none, or no prediction at its start.
    pub fn new(problem: &Problem<'_>) -> Option<Self> {
        let candidates = linear_candidates(problem);
        if candidates.is_empty() {
            return None;
        }
        let x0 = problem.start();
        let r0 = problem.try_residuals(&x0)?;
        let mut linear = Vec::new();
        let (mut columns, mut norms, mut bounds) = (Vec::new(), Vec::new(), Vec::new());
        for j in candidates {
            let p = &problem.params[j];
            let far = if x0[j] - p.lo > p.hi - x0[j] {
                p.lo
            } else {
                p.hi
            };
            let step = far - x0[j];
            if step == 0.0 {
                continue;
            }
            let mut x = x0.clone();
            x[j] = far;
            let r = problem.try_residuals(&x)?;
            let phi: Vec<f64> = r.iter().zip(&r0).map(|(a, b)| (a - b) / step).collect();
            let norm = phi.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                continue;
            }
            linear.push(j);
            columns.push(phi.iter().map(|v| v / norm).collect::<Vec<f64>>());
            norms.push(norm);
            bounds.push((p.lo, p.hi));
        }
        if linear.is_empty() {
            return None;
        }
        let k = linear.len();
        let gram = DMatrix::from_fn(k, k, |a, b| dot(&columns[a], &columns[b]));
        let searched = (0..problem.params.len())
            .filter(|i| !linear.contains(i))
            .collect();
        Some(Self {
            linear,
            searched,
            bounds,
            columns,
            norms,
            gram,
        })
    }

    /// Indices of the solved parameters.
    pub fn linear(&self) -> &[usize] {
        &self.linear
    }

    /// Indices of the searched parameters.
    pub fn searched(&self) -> &[usize] {
        &self.searched
    }

    /// The linear parameters of `x` (whose residuals are `r`) set to their
    /// best values in their bounds, and `r` to the residuals there.
    pub fn solve(&self, x: &mut [f64], r: &mut [f64]) {
        let k = self.linear.len();
        let b = DVector::from_iterator(k, self.columns.iter().map(|c| dot(c, r)));
        let boxed: Vec<(f64, f64)> = (0..k)
            .map(|j| {
                let (lo, hi) = self.bounds[j];
                let c = x[self.linear[j]];
                (self.norms[j] * (lo - c), self.norms[j] * (hi - c))
            })
            .collect();
        let y = super::box_qp::box_minimum(&self.gram, &b, &boxed);
        for (j, yj) in y.iter().enumerate() {
            if *yj == 0.0 {
                continue;
            }
            let i = self.linear[j];
            let (lo, hi) = self.bounds[j];
            x[i] = (x[i] + yj / self.norms[j]).clamp(lo, hi);
            for (rk, ck) in r.iter_mut().zip(&self.columns[j]) {
                *rk += yj * ck;
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The parameters of `problem` that are linear with fixed slopes, at most
/// [`MAX_LINEAR`]: the model's own when no fitted map coefficient moves
/// the model's inputs, and the fitted map coefficients that move only the
/// measured friction, affinely, in every training source.
fn linear_candidates(problem: &Problem<'_>) -> Vec<usize> {
    let model: &dyn Model = problem.model;
    let n = model.parameters().len();
    let sources = &problem.data.train;
    let inputs_fixed = problem
        .map_fit
        .iter()
        .all(|(i, _)| sources.iter().all(|s| !s.inputs_read(*i)));
    let mut out = Vec::new();
    if inputs_fixed {
        out.extend(model.linear_parameters());
    }
    for (j, (i, _)) in problem.map_fit.iter().enumerate() {
        if sources
            .iter()
            .all(|s| s.moves_only_the_friction_affinely(*i))
        {
            out.push(n + j);
        }
    }
    out.truncate(MAX_LINEAR);
    out
}

/// The local runs' variables: the searched parameters' unbounded
/// variables u (every parameter's when nothing is solved); the solved
/// ones are set at each point from their values in `reference`. With
/// `Problem::profile_cheap`, the searched ones are the costly parameters
/// alone and the cheap ones are fitted at each point (`profile.rs`).
#[derive(Clone)]
pub struct Variables<'p, 'a> {
    problem: &'p Problem<'a>,
    separable: Option<&'p Separable>,
    /// A whole point: the linear parameters' values the residuals are
    /// taken at before they are solved (any fixed values: the residuals
    /// are affine in them).
    reference: Vec<f64>,
    /// The searched parameters' indices.
    searched: Vec<usize>,
    /// The cheap parameters fitted at each point (the film held), when
    /// the searched ones are the costly ones alone.
    profiled: Vec<usize>,
}

impl<'p, 'a> Variables<'p, 'a> {
    /// The variables of `problem` with `separable`'s parameters solved,
    /// taken from the whole point `x0`.
    pub fn new(problem: &'p Problem<'a>, separable: Option<&'p Separable>, x0: &[f64]) -> Self {
        let all: Vec<usize> = match separable {
            Some(s) => s.searched().to_vec(),
            None => (0..problem.params.len()).collect(),
        };
        let (searched, profiled) = match problem.costly().filter(|_| problem.profile_cheap) {
            Some(c) if all.iter().any(|i| c[*i]) && all.iter().any(|i| !c[*i]) => {
                all.iter().partition(|i| c[**i])
            }
            _ => (all, Vec::new()),
        };
        Self {
            problem,
            separable,
            reference: x0.to_vec(),
            searched,
            profiled,
        }
    }

    /// The variables of the cheap parameters alone at the whole point
    /// `x` (the others held there): the inner fit of a profiled point.
    pub(super) fn cheap_at(&self, x: &[f64]) -> Option<Self> {
        (!self.profiled.is_empty()).then(|| Self {
            problem: self.problem,
            separable: self.separable,
            reference: x.to_vec(),
            searched: self.profiled.clone(),
            profiled: Vec::new(),
        })
    }

    /// These variables with the parameters `held` (indices of the whole
    /// point) no longer searched: held at their values in the whole point
    /// `x`, which becomes the reference.
    pub(super) fn holding(&self, held: &[usize], x: &[f64]) -> Self {
        let keep = |v: &Vec<usize>| v.iter().copied().filter(|i| !held.contains(i)).collect();
        Self {
            problem: self.problem,
            separable: self.separable,
            reference: x.to_vec(),
            searched: keep(&self.searched),
            profiled: keep(&self.profiled),
        }
    }

    /// The indices (in the whole point) of the parameters the optimiser
    /// searches (through the sine transform), profiled ones excluded.
    pub(super) fn searched(&self) -> &[usize] {
        &self.searched
    }

    /// The indices (in the whole point) of the parameters searched,
    /// profiled ones included.
    pub(super) fn varied(&self) -> impl Iterator<Item = usize> + '_ {
        self.searched.iter().chain(&self.profiled).copied()
    }

    /// The problem.
    pub fn problem(&self) -> &'p Problem<'a> {
        self.problem
    }

    /// Per searched variable: whether a change of it alone needs a whole
    /// simulation (None: every one costs the same).
    pub fn costly(&self) -> Option<Vec<bool>> {
        let all = self.problem.costly()?;
        let out: Vec<bool> = self.searched.iter().map(|i| all[*i]).collect();
        (out.iter().any(|c| *c) && out.iter().any(|c| !*c)).then_some(out)
    }

    /// How many variables are searched.
    pub fn len(&self) -> usize {
        self.searched.len()
    }

    /// Whether nothing is searched.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The whole point `x` as the searched variables u.
    pub fn to_internal(&self, x: &[f64]) -> Vec<f64> {
        self.searched
            .iter()
            .map(|i| self.problem.params[*i].to_internal(x[*i]))
            .collect()
    }

    /// The whole point `x` in the searched variables, on their canonical
    /// fold (where distances between runs' points are taken).
    pub fn canonical(&self, x: &[f64]) -> Vec<f64> {
        self.searched
            .iter()
            .map(|i| self.problem.params[*i].to_canonical(x[*i]))
            .collect()
    }

    /// The whole point at u before the linear parameters are solved, the
    /// others taken from `near`.
    fn point(&self, u: &[f64], near: &[f64]) -> Vec<f64> {
        let mut x = near.to_vec();
        for (i, v) in self.searched.iter().zip(u) {
            x[*i] = self.problem.params[*i].from_internal(*v);
        }
        x
    }

    /// The residuals at u, with the linear parameters solved (and the
    /// profiled ones fitted from their values in the reference), and the
    /// whole point they belong to. A point with no prediction gives the
    /// problem's large residuals (nothing is solved there).
    pub fn evaluate(&self, u: &[f64]) -> (Vec<f64>, Vec<f64>) {
        self.evaluate_near(u, &self.reference)
    }

    /// [`Self::evaluate`] at a run's first point: with the profiled
    /// parameters fitted from their values in the reference and, for each
    /// profiled key that bends the curve at a speed
    /// ([`super::unknowns::BEND_SPEED_KEYS`]), from that key at
    /// three places of its range (`BEND_PLACES`) as well; the best of these fits. The
    /// later points follow the basin it chose, warm-started.
    pub fn evaluate_first(&self, u: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut best = self.evaluate(u);
        let x0 = self.point(u, &self.reference);
        let sum = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
        for i in &self.profiled {
            let p = &self.problem.params[*i];
            if !super::unknowns::BEND_SPEED_KEYS.contains(&p.name.as_str()) {
                continue;
            }
            for f in BEND_PLACES {
                let mut near = x0.clone();
                near[*i] = p.from_fraction(f);
                let tried = self.evaluate_near(u, &near);
                if sum(&tried.0) < sum(&best.0) {
                    best = tried;
                }
            }
        }
        best
    }

    /// [`Self::evaluate`] with the profiled parameters fitted from their
    /// values in the whole point `near` (the run's last point).
    pub fn evaluate_near(&self, u: &[f64], near: &[f64]) -> (Vec<f64>, Vec<f64>) {
        if self.profiled.is_empty() {
            return self.solved_at(self.point(u, &self.reference));
        }
        let x = self.point(u, near);
        match self.cheap_at(&x) {
            Some(inner) => super::profile::fit_cheap(&inner, &x),
            None => self.solved_at(x),
        }
    }

    /// The residuals at u with the profiled parameters held at their
    /// values in `near` (not fitted there) and the linear ones solved: a
    /// profiled Jacobian's column before its projection
    /// (`profile::project_out_cheap`). Without profiled parameters,
    /// [`Self::evaluate_near`]'s.
    pub(super) fn evaluate_held(&self, u: &[f64], near: &[f64]) -> Vec<f64> {
        if self.profiled.is_empty() {
            return self.evaluate_near(u, near).0;
        }
        self.solved_at(self.point(u, near)).0
    }

    /// The residuals at the whole point `x` with the linear parameters
    /// solved, and the point.
    pub(super) fn solved_at(&self, mut x: Vec<f64>) -> (Vec<f64>, Vec<f64>) {
        let Some(mut r) = self.problem.try_residuals(&x) else {
            return (self.problem.penalty(), x);
        };
        if let Some(s) = self.separable {
            s.solve(&mut x, &mut r);
        }
        (r, x)
    }

    /// ½ Σ r² at u, the linear parameters solved.
    pub fn cost(&self, u: &[f64]) -> f64 {
        0.5 * self.evaluate(u).0.iter().map(|r| r * r).sum::<f64>()
    }
}

impl super::profile::CheapFit for Variables<'_, '_> {
    fn problem(&self) -> &Problem<'_> {
        self.problem
    }

    fn keys(&self) -> &[usize] {
        &self.searched
    }

    fn solved_at(&self, x: Vec<f64>) -> (Vec<f64>, Vec<f64>) {
        Variables::solved_at(self, x)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::data::Data;
    use crate::fit::options::{LinearKeys, Options};
    use crate::fit::problem::tests_data;
    use crate::fit::series::{Mapping, Series};
    use crate::fit::unknowns::FittedParameter;
    use crate::fit::PredictError;
    use approx::assert_relative_eq;

    /// Friction = a (1 − e^(−|v|/s)) sgn v + b v: `b` linear with a fixed
    /// slope v (declared), `a` linear with a slope that `s` moves (not
    /// declared), `s` nonlinear.
    struct Toy(Vec<FittedParameter>, Vec<usize>);

    impl Model for Toy {
        fn label(&self) -> String {
            "toy".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.0
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, PredictError> {
            let (speed, a, b) = (x[0], x[1], x[2]);
            Ok(s.velocity
                .iter()
                .map(|v| a * (1.0 - (-v.abs() / speed).exp()) * v.signum() + b * v)
                .collect())
        }
        fn linear_parameters(&self) -> Vec<usize> {
            self.1.clone()
        }
    }

    fn toy(declared: Vec<usize>) -> Toy {
        Toy(
            vec![
                FittedParameter::new("s", 0.05, 0.01, 1.0),
                FittedParameter::new("a", 1.0, 0.0, 10.0),
                FittedParameter::new("b", 0.5, 0.0, 10.0),
            ],
            declared,
        )
    }

    /// Data made by s = 0.2, a = 3, b = 2.5, measured with gain 1/g and
    /// offset o (map coefficients), with a deterministic wobble as noise.
    fn data(velocity: &str, coefficients: Vec<(String, f64)>) -> Data {
        let mut text = String::from("t_s,v,f\n");
        for k in 0..200 {
            let v = 0.8 * (k as f64 * 0.07).sin();
            let f = 3.0 * (1.0 - (-v.abs() / 0.2).exp()) * v.signum() + 2.5 * v;
            let noise = 0.01 * (k as f64 * 1.7).cos();
            text += &format!("{},{},{}\n", k as f64 * 0.01, v, f + 0.7 + noise);
        }
        let mapping = Mapping {
            velocity: velocity.into(),
            friction: "f - o".into(),
            coefficients,
            ..Default::default()
        };
        tests_data(&text, &mapping)
    }

    #[test]
    fn the_models_linear_keys_and_an_offset_of_the_friction_are_solved_and_a_gain_of_the_velocity_is_not(
    ) {
        let d = data("v", vec![("o".into(), 0.0)]);
        let model = toy(vec![2]);
        let fit_o = (0, FittedParameter::new("o", 0.0, -5.0, 5.0));
        let p = Problem::new(&model, &d, vec![fit_o]).unwrap();
        let s = Separable::new(&p).unwrap();
        assert_eq!((s.linear(), s.searched()), (&[2, 3][..], &[0, 1][..]));
        // A fitted gain of the velocity moves the model's inputs: the
        // model's slopes are no longer fixed, the offset's still is.
        let d = data("v * g", vec![("g".into(), 1.0), ("o".into(), 0.0)]);
        let fit_g = (0, FittedParameter::new("g", 1.0, 0.5, 2.0));
        let fit_o = (1, FittedParameter::new("o", 0.0, -5.0, 5.0));
        let p = Problem::new(&model, &d, vec![fit_g, fit_o]).unwrap();
        let s = Separable::new(&p).unwrap();
        assert_eq!((s.linear(), s.searched()), (&[4][..], &[0, 1, 2, 3][..]));
    }

    #[test]
    fn the_solved_linear_keys_are_the_least_squares_values_at_the_searched_ones() {
        let d = data("v", vec![("o".into(), 0.0)]);
        let model = toy(vec![2]);
        let p = Problem::new(
            &model,
            &d,
            vec![(0, FittedParameter::new("o", 0.0, -5.0, 5.0))],
        )
        .unwrap();
        let s = Separable::new(&p).unwrap();
        let mut x = vec![0.2, 3.0, 0.5, 0.0];
        let mut r = p.residuals(&x);
        s.solve(&mut x, &mut r);
        // At the generating speed the linear ones are the generator's (to
        // the wobble), and the residuals are the problem's own there.
        assert_relative_eq!(x[2], 2.5, epsilon = 0.01);
        assert_relative_eq!(x[3], 0.7, epsilon = 0.01);
        for (a, b) in r.iter().zip(p.residuals(&x)) {
            assert_relative_eq!(*a, b, epsilon = 1e-12);
        }
        // No other values in the box fit better.
        let cost = |x: &[f64]| p.cost(x);
        let best = cost(&x);
        for (i, h) in [(2, 1e-3), (3, 1e-3)] {
            for sign in [-1.0, 1.0] {
                let mut y = x.clone();
                y[i] += sign * h;
                assert!(cost(&y) >= best, "{i} {sign}");
            }
        }
    }

    #[test]
    fn a_fit_that_solves_the_linear_keys_reaches_the_optimum_of_one_that_searches_them() {
        let d = data("v", vec![("o".into(), 0.0)]);
        let model = toy(vec![2]);
        let fit = |linear_keys| {
            let p = Problem::new(
                &model,
                &d,
                vec![(0, FittedParameter::new("o", 0.0, -5.0, 5.0))],
            )
            .unwrap();
            let options = Options {
                linear_keys,
                ..Default::default()
            };
            let separable = match linear_keys {
                LinearKeys::Solved => Separable::new(&p),
                LinearKeys::Searched => None,
            };
            let runs = crate::fit::multistart::search(&p, separable.as_ref(), &options);
            let sims = p.simulations.load(std::sync::atomic::Ordering::Relaxed);
            (runs[0].x.clone(), runs[0].cost, sims)
        };
        let (xs, cs, solved) = fit(LinearKeys::Solved);
        let (xr, cr, searched) = fit(LinearKeys::Searched);
        assert!(cs <= cr * (1.0 + 1e-9), "solved {cs} searched {cr}");
        for (a, b) in xs.iter().zip(&xr) {
            assert_relative_eq!(*a, *b, max_relative = 1e-4, epsilon = 1e-6);
        }
        assert!(solved < searched, "{solved} simulations against {searched}");
    }
}
