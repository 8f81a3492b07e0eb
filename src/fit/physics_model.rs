//! Our model as a predictor: the configuration with the fitted keys set,
//! run over a series.
//!
//! - A time series is simulated on the solver's fixed step `solver.dt_s`
//!   from the state its start implies: a series that starts at rest (its
//!   first speed within two sample intervals' change of zero) starts, as
//!   `simulate` does, from the steady state at rest one sample interval
//!   before its first sample, the velocity ramped from 0 to the first
//!   sample's (film at rest, pre-sliding bristle undeflected); any other
//!   from the steady state of its first sample (steady sliding). The
//!   inputs (velocity, load, temperature) are interpolated linearly between
//!   samples, and the friction is read at the sample times by linear
//!   interpolation between steps. With `lubricant.viscosity_model: vogel`
//!   and a temperature the viscosity follows it every step.
//! - A steady curve is solved point by point with the steady solver, each
//!   point warm-started from the previous one.
//!
//! **The film once per film.** Every friction term but the soft width acts
//! after the film ([`crate::physics::terms::acts_after_the_film`]): the
//! pressure, the gap and the film's forces do not depend on it. A
//! prediction keeps its film trace — per solver step the inputs of the
//! friction's composition (velocity, load, the film's viscous and asperity
//! forces) — and a prediction whose values differ from a kept one's only in
//! such keys, on the same inputs, recomposes the friction along that trace
//! ([`FrictionTerms::friction`], the pre-sliding bristle advanced step by
//! step as the solver advances it) instead of solving the film again. The
//! result is the full simulation's, bit for bit (tested); a fit whose
//! Jacobian columns are mostly term keys solves the film about once per
//! Jacobian instead of once per column.

use super::problem::Model;
use super::series::{mix, Series};
use super::unknowns::{ConfigKeys, DataScale, FittedParameter, ParamSpec};
use super::{FitError, PredictError};
use crate::config::{Config, ViscosityLaw};
use crate::physics::terms::{acts_after_the_film, BristleMove, FrictionTerms, TermStates};
use crate::physics::{Estimate, Solver, Status, ViscosityModel};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// The physics model with some configuration keys fitted.
pub struct PhysicsModel {
    keys: ConfigKeys,
    names: Vec<String>,
    params: Vec<FittedParameter>,
    /// The gain g through which the data's axis drives the contact: the
    /// data's velocity times g is the contact's speed, the contact's
    /// friction times g the data's (a joint's lever arm, m; 1: the data
    /// are the contact's own).
    gain: f64,
    /// The film traces kept (shared by the models of one calibration:
    /// every set of keys `--fit auto` tries on the same film reuses it).
    traces: Arc<FilmTraces>,
    /// This model's own film solves.
    solves: AtomicUsize,
    /// What the film of this model's base configuration is, and what its
    /// terms are: a prediction looks its film up and composes its friction
    /// without building a configuration.
    base: FilmBase,
}

/// A model's base: the fingerprint of its base configuration's film, its
/// fitted keys that the film depends on (index and base value), and its
/// friction terms.
struct FilmBase {
    fingerprint: u64,
    film_params: Vec<(usize, u64)>,
    terms: FrictionTerms,
}

/// The film traces of a calibration, newest last, and the film solves so
/// far.
#[derive(Default)]
pub struct FilmTraces {
    kept: Mutex<Vec<Arc<FilmTrace>>>,
    solves: AtomicUsize,
}

impl FilmTraces {
    /// Film solves so far: the predictions that could not recompose the
    /// friction along a kept trace.
    pub fn solves(&self) -> usize {
        self.solves.load(Ordering::Relaxed)
    }
}

/// The keys the friction is linear in, with slopes that depend on the
/// inputs alone ([`Model::linear_parameters`]).
const LINEAR_KEYS: [&str; 2] = ["drivetrain.viscous_n_s_m", "drivetrain.quadratic_n_s2_m2"];

/// Film traces kept: enough for the sources of one Jacobian's base point
/// and the film columns beside it.
const TRACES_KEPT: usize = 16;

/// A fingerprint of what the film depends on in `config`: the
/// configuration with every friction term off but the soft width (its
/// model and solver settings), and the load a series without its own runs
/// at.
fn film_fingerprint(config: &Config) -> u64 {
    let mut m = config.model();
    let off = FrictionTerms::default();
    for k in crate::physics::terms::catalogue() {
        if acts_after_the_film(k.key) {
            let default = off.get(k.key).expect("a listed term has its keys");
            m.terms.set(k.key, default);
        }
    }
    let text = format!(
        "{m:?} {:?} {:?} {}",
        config.solver_settings(),
        config.lubricant,
        config.contact.load_n.to_bits()
    );
    name_hash(&text)
}

/// One film solution along a series: per solver step (the first the steady
/// start), the inputs of the friction's composition.
struct FilmTrace {
    /// The fingerprint of the configuration the film depends on (every key
    /// but those acting after the film) and of the gain.
    film_key: u64,
    /// The fingerprint of the series' inputs.
    inputs: u64,
    /// A steady curve (each step its own steady state) or a time series.
    steady: bool,
    /// Per step: velocity (m/s), load (N), the film's viscous and asperity
    /// forces (N).
    steps: Vec<[f64; 4]>,
    /// Per step, its time (s; a steady curve: unused).
    times: Vec<f64>,
    /// The time series' sampling onto the data (see [`transient`]).
    sampling: Option<Sampling>,
}

/// Where a time series' samples fall between the solver's steps.
#[derive(Clone, Copy)]
struct Sampling {
    /// The solver's step, s.
    dt: f64,
    /// Whether the series starts at rest (its first sample is not the
    /// steady start's).
    at_rest: bool,
}

impl FilmTrace {
    fn record(e: &Estimate) -> [f64; 4] {
        [e.velocity, e.load, e.viscous_force, e.asperity_force]
    }

    /// The friction at the series' samples with `terms` on this film.
    fn compose(&self, terms: &FrictionTerms, s: &Series) -> Vec<f64> {
        let mut states = TermStates::default();
        let mut friction = |st: &[f64; 4], how: BristleMove| {
            terms
                .friction((st[0], st[1]), (st[2], st[3]), &mut states, how)
                .1
        };
        if self.steady {
            return self
                .steps
                .iter()
                .map(|st| friction(st, BristleMove::Steady))
                .collect();
        }
        let sampling = self.sampling.expect("a time series is sampled");
        let f0 = friction(&self.steps[0], BristleMove::Steady);
        let mut forces = vec![f0];
        forces.extend(
            self.steps[1..]
                .iter()
                .map(|st| friction(st, BristleMove::Step(sampling.dt))),
        );
        onto_samples(s, &self.times, &forces, sampling)
    }
}

/// The friction at the samples of `s` from the friction `forces` at the
/// steps' `times` (the first the start): linear interpolation between
/// steps, as the solver's run is read.
fn onto_samples(s: &Series, times: &[f64], forces: &[f64], sampling: Sampling) -> Vec<f64> {
    let n = s.len();
    let mut out = vec![f64::NAN; n];
    let (mut t_prev, mut f_prev) = (times[0], forces[0]);
    let mut k = 0;
    if !sampling.at_rest {
        out[0] = forces[0];
        k = 1;
    }
    for (&t, &f) in times.iter().zip(forces).skip(1) {
        while k < n && s.t[k] <= t + 1e-12 * sampling.dt {
            let w = ((s.t[k] - t_prev) / (t - t_prev)).clamp(0.0, 1.0);
            out[k] = f_prev + w * (f - f_prev);
            k += 1;
        }
        (t_prev, f_prev) = (t, f);
    }
    for o in out.iter_mut().skip(k) {
        *o = f_prev;
    }
    out
}

impl PhysicsModel {
    /// `specs` must name real-valued keys of `base`.
    pub fn new(base: &Config, specs: &[ParamSpec], scale: &DataScale) -> Result<Self, FitError> {
        let keys = ConfigKeys::new(base);
        let params = specs
            .iter()
            .map(|s| keys.parameter(s, scale))
            .collect::<Result<Vec<_>, _>>()?;
        let film_params = params
            .iter()
            .enumerate()
            .filter(|(_, p)| !acts_after_the_film(&p.name))
            .map(|(i, p)| Ok((i, keys.value(&p.name)?.to_bits())))
            .collect::<Result<Vec<_>, FitError>>()?;
        let base = FilmBase {
            fingerprint: film_fingerprint(base),
            film_params,
            terms: base.model().terms,
        };
        Ok(Self {
            names: params.iter().map(|p| p.name.clone()).collect(),
            keys,
            params,
            gain: 1.0,
            traces: Arc::new(FilmTraces::default()),
            solves: AtomicUsize::new(0),
            base,
        })
    }

    /// The model driven through gain `gain` (see `contact_scale.rs`).
    pub fn with_gain(self, gain: f64) -> Self {
        Self { gain, ..self }
    }

    /// Start every fitted key named in `values` at its value there (kept
    /// inside its bounds, which do not move).
    pub fn warm(&mut self, values: &[(String, f64)]) {
        for q in &mut self.params {
            if let Some((_, v)) = values.iter().find(|(n, _)| *n == q.name) {
                q.warm(*v);
            }
        }
    }

    /// The gain (1: the data are the contact's own).
    pub fn gain(&self) -> f64 {
        self.gain
    }

    /// Number of fitted configuration keys.
    pub fn parameters_len(&self) -> usize {
        self.params.len()
    }

    /// The configuration at parameter values `x`.
    pub fn config(&self, x: &[f64]) -> Result<Config, crate::config::ConfigError> {
        self.keys.with(&self.names, x)
    }

    /// This model's film solves so far: its predictions that could not
    /// recompose the friction along a kept film trace.
    pub fn film_solves(&self) -> usize {
        self.solves.load(Ordering::Relaxed)
    }

    /// The film traces this model keeps.
    pub fn traces(&self) -> Arc<FilmTraces> {
        self.traces.clone()
    }

    /// The model keeping its film traces in `traces` (shared with others
    /// on the same data).
    pub fn with_traces(self, traces: Arc<FilmTraces>) -> Self {
        Self { traces, ..self }
    }

    /// The fingerprint of the film at values `x`: the base's, the gain, and
    /// the fitted keys the film depends on that differ from the base (a
    /// model that does not fit such a key, and one at its base value, name
    /// the same film).
    fn film_key(&self, x: &[f64]) -> u64 {
        let mut h = mix(self.base.fingerprint, self.gain.to_bits());
        for (i, base) in &self.base.film_params {
            let bits = x[*i].to_bits();
            if bits != *base {
                h = mix(mix(h, *i as u64 ^ name_hash(&self.names[*i])), bits);
            }
        }
        h
    }

    /// The friction terms at values `x`: the base's with every fitted term
    /// key set.
    fn terms_at(&self, x: &[f64]) -> FrictionTerms {
        let mut t = self.base.terms;
        for (name, v) in self.names.iter().zip(x) {
            t.set(name, *v);
        }
        t
    }

    /// The contact's friction at the samples of `s` (the data's series;
    /// the contact's speed is the data's times the gain) at values `x`:
    /// recomposed along a kept film trace when one matches, else solved,
    /// its trace kept. The contact's series is built only for a solve (a
    /// trace's film key holds the gain, its inputs the data's).
    fn run(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, PredictError> {
        let film_key = self.film_key(x);
        let inputs = s.inputs_fingerprint();
        let lock = || self.traces.kept.lock().unwrap_or_else(|p| p.into_inner());
        let kept = lock()
            .iter()
            .find(|t| t.inputs == inputs && t.film_key == film_key)
            .cloned();
        if let Some(trace) = kept {
            return Ok(trace.compose(&self.terms_at(x), s));
        }
        let config = &self
            .config(x)
            .map_err(|e| PredictError::Parameters(e.to_string()))?;
        self.traces.solves.fetch_add(1, Ordering::Relaxed);
        self.solves.fetch_add(1, Ordering::Relaxed);
        let scaled;
        let contact = if self.gain == 1.0 {
            s
        } else {
            scaled = Series {
                velocity: s.velocity.iter().map(|w| self.gain * w).collect(),
                ..s.clone()
            };
            &scaled
        };
        let (out, trace) = if s.steady {
            steady(config, contact)?
        } else {
            transient(config, contact)?
        };
        let mut traces = lock();
        if traces.len() >= TRACES_KEPT {
            traces.remove(0);
        }
        traces.push(Arc::new(FilmTrace {
            film_key,
            inputs,
            ..trace
        }));
        Ok(out)
    }
}

/// A key name's hash (FNV-1a on its bytes).
fn name_hash(name: &str) -> u64 {
    name.bytes()
        .fold(0xcbf2_9ce4_8422_2325, |h, b| mix(h, u64::from(b)))
}

impl Model for PhysicsModel {
    fn label(&self) -> String {
        "friction-node".into()
    }

    fn parameters(&self) -> &[FittedParameter] {
        &self.params
    }

    fn film_solves(&self) -> Option<usize> {
        Some(self.solves.load(Ordering::Relaxed))
    }

    /// The drivetrain's viscous and quadratic losses: b v + c_q v |v| is
    /// added to the friction beside everything else (outside the bristle,
    /// after the film), so the prediction is linear in b and c_q with the
    /// slopes v and v |v| (through the gain), whatever the other keys.
    fn costly_parameters(&self) -> Option<Vec<usize>> {
        Some(self.base.film_params.iter().map(|(i, _)| *i).collect())
    }

    fn linear_parameters(&self) -> Vec<usize> {
        self.names
            .iter()
            .enumerate()
            .filter(|(_, n)| LINEAR_KEYS.contains(&n.as_str()))
            .map(|(i, _)| i)
            .collect()
    }

    fn predict(&self, x: &[f64], series: &Series) -> Result<Vec<f64>, PredictError> {
        let mut f = self.run(x, series)?;
        if self.gain != 1.0 {
            f.iter_mut().for_each(|f| *f *= self.gain);
        }
        Ok(f)
    }
}

/// Linear interpolation in a sampled signal with a moving cursor (times
/// are asked in increasing order).
struct Cursor<'a> {
    t: &'a [f64],
    y: &'a [f64],
    j: usize,
}

impl<'a> Cursor<'a> {
    fn new(t: &'a [f64], y: &'a [f64]) -> Self {
        Self { t, y, j: 0 }
    }

    fn at(&mut self, t: f64) -> f64 {
        let n = self.t.len();
        while self.j + 2 < n && self.t[self.j + 1] <= t {
            self.j += 1;
        }
        let (t0, t1) = (self.t[self.j], self.t[self.j + 1]);
        let w = ((t - t0) / (t1 - t0)).clamp(0.0, 1.0);
        self.y[self.j] + w * (self.y[self.j + 1] - self.y[self.j])
    }
}

fn follows_temperature(config: &Config, s: &Series) -> bool {
    s.temperature.is_some() && config.viscosity_model() != ViscosityModel::Constant
}

/// The liquid viscosity at `t_c` °C by the configuration's law, or why
/// these parameters give none there (the rule of every entry point).
fn viscosity(law: &ViscosityLaw, t_c: f64) -> Result<f64, PredictError> {
    law.viscosity_at(t_c)
        .map_err(|e| PredictError::Viscosity(e.to_string()))
}

/// Where a simulated series starts (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Start {
    /// The time the simulation starts, s.
    t: f64,
    /// The first sample's time and velocity, s and m/s.
    first: (f64, f64),
    /// Whether it starts at rest (one sample interval before the first sample).
    at_rest: bool,
}

impl Start {
    fn of(s: &Series) -> Self {
        let (t, v) = (&s.t, &s.velocity);
        let first = (t[0], v[0]);
        let at_rest =
            v[0] == 0.0 || (t.len() >= 2 && t[1] > t[0] && v[0].abs() <= 2.0 * (v[1] - v[0]).abs());
        let start = if at_rest && t.len() >= 2 {
            t[0] - (t[1] - t[0])
        } else {
            t[0]
        };
        Self {
            t: start,
            first,
            at_rest,
        }
    }

    /// The steady velocity the solver starts from, m/s.
    fn initial_velocity(&self) -> f64 {
        if self.at_rest {
            0.0
        } else {
            self.first.1
        }
    }

    /// The velocity at `t`: ramped from rest before the first sample.
    fn velocity(&self, t: f64, v_at: &mut Cursor) -> f64 {
        let (t1, v1) = self.first;
        if self.at_rest && t < t1 {
            v1 * ((t - self.t) / (t1 - self.t)).clamp(0.0, 1.0)
        } else {
            v_at.at(t)
        }
    }
}

/// The friction at the samples of time series `s` and its film trace (the
/// caller fills in the trace's keys).
fn transient(config: &Config, s: &Series) -> Result<(Vec<f64>, FilmTrace), PredictError> {
    let settings = config.solver_settings();
    let dt = settings.dt;
    let mut solver =
        Solver::new(&config.model(), &settings).map_err(|e| PredictError::Solver(e.to_string()))?;
    let n = s.len();
    let start = Start::of(s);
    let t0 = start.t;
    let steps = ((s.t[n - 1] - t0) / dt).ceil() as u64;
    let default_load = vec![config.contact.load_n; n];
    let load = s.load.as_deref().unwrap_or(&default_load);
    let follows = follows_temperature(config, s);
    let law = ViscosityLaw::of(config);
    let mut v_at = Cursor::new(&s.t, &s.velocity);
    let mut f_at = Cursor::new(&s.t, load);
    let mut temp_at = s.temperature.as_deref().map(|y| Cursor::new(&s.t, y));
    if follows {
        let temp = temp_at.as_mut().expect("follows").at(t0);
        solver.set_liquid_viscosity(viscosity(&law, temp)?);
    }
    let first = solver.initialize_steady(start.initial_velocity(), f_at.at(t0));
    let len = usize::try_from(steps).unwrap_or(0).saturating_add(1);
    let (mut trace, mut times, mut forces) = (
        Vec::with_capacity(len),
        Vec::with_capacity(len),
        Vec::with_capacity(len),
    );
    trace.push(FilmTrace::record(&first));
    times.push(t0);
    forces.push(first.friction_force);
    // Parameters that make the inputs unreachable (a load the contact cannot
    // carry) leave the solver at its iteration bound step after step, each
    // at the cost of its fallbacks: such a run is no prediction.
    const STUCK_STEPS: u32 = 50;
    let mut stuck = 0u32;
    for step in 1..=steps {
        let t = t0 + step as f64 * dt;
        if follows {
            let temp = temp_at.as_mut().expect("follows").at(t);
            solver.set_liquid_viscosity(viscosity(&law, temp)?);
        }
        let e = solver.step(start.velocity(t, &mut v_at), f_at.at(t));
        if !e.friction_force.is_finite()
            || !matches!(e.status, Status::Converged | Status::MaxIterations)
        {
            return Err(PredictError::Step {
                t_s: t,
                status: e.status.as_str(),
                iterations: e.diagnostics.iterations,
            });
        }
        stuck = if e.status == Status::MaxIterations {
            stuck + 1
        } else {
            0
        };
        if stuck >= STUCK_STEPS {
            return Err(PredictError::Stuck {
                steps: STUCK_STEPS,
                t_s: t,
            });
        }
        trace.push(FilmTrace::record(&e));
        times.push(t);
        forces.push(e.friction_force);
    }
    let sampling = Sampling {
        dt,
        at_rest: start.at_rest,
    };
    let out = onto_samples(s, &times, &forces, sampling);
    Ok((
        out,
        FilmTrace {
            film_key: 0,
            inputs: 0,
            steady: false,
            steps: trace,
            times,
            sampling: Some(sampling),
        },
    ))
}

/// The friction at the points of steady curve `s` and its film trace.
fn steady(config: &Config, s: &Series) -> Result<(Vec<f64>, FilmTrace), PredictError> {
    let mut solver = Solver::new(&config.model(), &config.solver_settings())
        .map_err(|e| PredictError::Solver(e.to_string()))?;
    let follows = follows_temperature(config, s);
    let law = ViscosityLaw::of(config);
    let mut trace = Vec::with_capacity(s.len());
    let out = (0..s.len())
        .map(|k| {
            if follows {
                let temp = s.temperature.as_ref().expect("follows")[k];
                solver.set_liquid_viscosity(viscosity(&law, temp)?);
            }
            let e = solver.steady(s.velocity[k], s.load_at(k, config.contact.load_n));
            if e.status.is_converged() && e.friction_force.is_finite() {
                trace.push(FilmTrace::record(&e));
                Ok(e.friction_force)
            } else {
                Err(PredictError::Steady {
                    velocity_m_s: s.velocity[k],
                    status: e.status.as_str(),
                })
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((
        out,
        FilmTrace {
            film_key: 0,
            inputs: 0,
            steady: true,
            steps: trace,
            times: Vec::new(),
            sampling: None,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn series(t: Vec<f64>, v: Vec<f64>, steady: bool) -> Series {
        let n = t.len();
        Series {
            name: "s".into(),
            steady,
            friction: vec![0.0; n],
            t,
            velocity: v,
            load: None,
            temperature: None,
            fit: vec![true; n],
        }
    }

    #[test]
    fn a_transient_prediction_on_the_step_grid_equals_the_solver_run_directly() {
        let mut config = Config::default();
        config.solver.cells = 64;
        let t: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-3).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.3 * (6.0 * t).sin() + 0.05).collect();
        let s = series(t.clone(), v.clone(), false);
        let got = transient(&config, &s).unwrap().0;
        let mut solver = Solver::new(&config.model(), &config.solver_settings()).unwrap();
        let first = solver.initialize_steady(v[0], config.contact.load_n);
        assert_eq!(got[0], first.friction_force);
        for k in 1..t.len() {
            let e = solver.step(v[k], config.contact.load_n);
            assert_relative_eq!(got[k], e.friction_force, max_relative = 1e-9);
        }
    }

    #[test]
    fn the_fit_recomposes_a_term_added_to_the_list_as_the_solver_computes_it() {
        // physics/terms/test_term.rs: a term added in its file and one line
        // of the list. The fit sets its key on the terms and recomposes the
        // friction along the kept film, with the bristle carrying it.
        let mut config = Config::default();
        config.solver.cells = 32;
        config.contact.presliding_stiffness_n_m = 5e7;
        let t: Vec<f64> = (0..=150).map(|k| k as f64 * 1e-3).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.02 * (20.0 * t).sin()).collect();
        let s = series(t.clone(), v.clone(), false);
        let (_, trace) = transient(&config, &s).unwrap();
        let mut terms = config.model().terms;
        assert!(terms.set("probe.drag_n", 40.0));
        let got = trace.compose(&terms, &s);
        let mut model = config.model();
        model.terms.probe.drag = 40.0;
        let mut solver = Solver::new(&model, &config.solver_settings()).unwrap();
        let first = solver.initialize_steady(v[0], config.contact.load_n);
        assert_relative_eq!(got[0], first.friction_force, max_relative = 1e-9);
        for k in 1..t.len() {
            let e = solver.step(v[k], config.contact.load_n);
            assert_relative_eq!(
                got[k],
                e.friction_force,
                max_relative = 1e-9,
                epsilon = 1e-9
            );
        }
    }

    #[test]
    fn a_series_that_starts_at_rest_is_predicted_as_simulate_ran_it() {
        // simulate starts at rest at t = 0 and writes its first row at t = dt:
        // with the bristle on, a start in steady sliding would begin it fully
        // deflected (the biased fit).
        let mut config = Config::default();
        config.solver.cells = 32;
        config.contact.presliding_stiffness_n_m = 5e7;
        let dt = config.solver.dt_s;
        let mut solver = Solver::new(&config.model(), &config.solver_settings()).unwrap();
        solver.initialize_steady(0.0, config.contact.load_n);
        let (mut t, mut v, mut f) = (Vec::new(), Vec::new(), Vec::new());
        for k in 1..=300 {
            let tk = k as f64 * dt;
            let vk = 0.05 * (std::f64::consts::TAU * tk).sin();
            f.push(solver.step(vk, config.contact.load_n).friction_force);
            t.push(tk);
            v.push(vk);
        }
        let s = series(t, v, false);
        assert!(Start::of(&s).at_rest);
        let got = transient(&config, &s).unwrap().0;
        for (g, e) in got.iter().zip(&f) {
            assert_relative_eq!(g, e, max_relative = 1e-9);
        }
    }

    #[test]
    fn a_series_in_motion_starts_in_steady_sliding_and_one_at_zero_speed_at_rest() {
        let moving = series(vec![0.0, 1e-3, 2e-3], vec![0.05, 0.0502, 0.0504], false);
        assert!(!Start::of(&moving).at_rest);
        assert_eq!(Start::of(&moving).t, 0.0);
        let resting = series(vec![1.0, 1.001], vec![0.0, 0.0], false);
        let start = Start::of(&resting);
        assert!(start.at_rest);
        assert_relative_eq!(start.t, 0.999, max_relative = 1e-12);
    }

    /// A model of `keys` (each with its bounds and start) on `config`.
    fn model_of(config: &Config, keys: &[(&str, f64, f64, f64)]) -> PhysicsModel {
        let specs: Vec<ParamSpec> = keys
            .iter()
            .map(|(k, lo, hi, start)| ParamSpec {
                name: k.to_string(),
                bounds: Some((*lo, *hi)),
                start: Some(*start),
                if_chosen: false,
            })
            .collect();
        let scale = DataScale {
            friction_n: 1e3,
            velocity_m_s: 0.1,
            load_min_n: 1e3,
            reversal_stiffness_n_m: None,
        };
        PhysicsModel::new(config, &specs, &scale).unwrap()
    }

    #[test]
    fn a_change_of_keys_that_act_after_the_film_recomposes_its_trace_bit_for_bit() {
        let mut config = Config::default();
        config.solver.cells = 32;
        let keys = [
            ("lubricant.viscosity_pa_s", 0.01, 1.0, 0.0564),
            ("contact.boundary_friction", 0.01, 1.0, 0.3),
            ("contact.presliding_stiffness_n_m", 1e5, 1e9, 2e6),
            ("contact.presliding_damping_n_s_m", 0.0, 1e5, 10.0),
            ("contact.boundary_friction_rate", 0.0, 0.5, 0.01),
            ("drivetrain.coulomb_n", 0.0, 1e3, 40.0),
            ("drivetrain.viscous_n_s_m", 0.0, 1e4, 300.0),
            ("drivetrain.quadratic_n_s2_m2", 0.0, 1e4, 800.0),
            ("drivetrain.coulomb_asymmetry_n", -100.0, 100.0, 5.0),
        ];
        // A time series through reversals (at rest at its start) and a
        // steady curve.
        let t: Vec<f64> = (1..=400).map(|k| k as f64 * 1e-3).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.05 * (9.0 * t).sin()).collect();
        let curve = series(vec![0.0, 1.0, 2.0, 3.0], vec![0.01, -0.05, 0.2, 1.0], true);
        for s in [series(t, v, false), curve] {
            let model = model_of(&config, &keys);
            let x0: Vec<f64> = keys.iter().map(|k| k.3).collect();
            model.predict(&x0, &s).unwrap();
            assert_eq!(model.film_solves(), 1);
            // Every term key moved: recomposed, not solved.
            let x1 = vec![0.0564, 0.2, 5e6, 300.0, 0.02, 10.0, 900.0, 100.0, -20.0];
            let recomposed = model.predict(&x1, &s).unwrap();
            assert_eq!(model.film_solves(), 1, "recomposed along the kept film");
            let fresh = model_of(&config, &keys);
            let solved = fresh.predict(&x1, &s).unwrap();
            assert_eq!(fresh.film_solves(), 1);
            for (a, b) in recomposed.iter().zip(&solved) {
                assert_eq!(a.to_bits(), b.to_bits(), "{a} vs {b}");
            }
            // The viscosity moves the film: solved again.
            let mut x2 = x1.clone();
            x2[0] = 0.1;
            model.predict(&x2, &s).unwrap();
            assert_eq!(model.film_solves(), 2);
        }
        // The soft width acts on the film: not a key after it.
        assert!(!acts_after_the_film("contact.width_load_exponent"));
        assert!(acts_after_the_film("contact.boundary_friction"));
    }

    #[test]
    fn the_friction_is_linear_in_the_viscous_and_quadratic_losses_with_slopes_no_other_key_moves() {
        let mut config = Config::default();
        config.solver.cells = 32;
        let keys = [
            ("lubricant.viscosity_pa_s", 0.01, 1.0, 0.0564),
            ("contact.presliding_stiffness_n_m", 1e5, 1e9, 2e6),
            ("drivetrain.coulomb_n", 0.0, 1e3, 40.0),
            ("drivetrain.viscous_n_s_m", 0.0, 1e4, 300.0),
            ("drivetrain.quadratic_n_s2_m2", 0.0, 1e4, 800.0),
        ];
        let t: Vec<f64> = (1..=300).map(|k| k as f64 * 1e-3).collect();
        let v: Vec<f64> = t.iter().map(|t| 0.05 * (9.0 * t).sin()).collect();
        let curve = series(vec![0.0, 1.0, 2.0, 3.0], vec![0.01, -0.05, 0.2, 1.0], true);
        let model = model_of(&config, &keys);
        assert_eq!(model.linear_parameters(), vec![3, 4]);
        for s in [series(t, v, false), curve] {
            // The slope of each linear key at two points that differ in
            // every other key (the film included), and at twice the step.
            let slope = |x: &[f64], i: usize, h: f64| -> Vec<f64> {
                let mut moved = x.to_vec();
                moved[i] += h;
                let a = model.predict(x, &s).unwrap();
                let b = model.predict(&moved, &s).unwrap();
                b.iter().zip(&a).map(|(b, a)| (b - a) / h).collect()
            };
            let x0 = [0.0564, 2e6, 40.0, 300.0, 800.0];
            let x1 = [0.2, 3e7, 10.0, 50.0, 20.0];
            for i in [3, 4] {
                let reference = slope(&x0, i, 100.0);
                let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(scale > 0.0);
                for other in [slope(&x1, i, 100.0), slope(&x0, i, 200.0)] {
                    for (a, b) in other.iter().zip(&reference) {
                        assert_relative_eq!(*a, *b, epsilon = 1e-9 * scale);
                    }
                }
            }
        }
    }

    #[test]
    fn every_term_key_can_be_set_on_the_terms_as_the_configuration_sets_it() {
        let base = Config::default();
        let keys = ConfigKeys::new(&base);
        for k in crate::physics::terms::configured_catalogue() {
            let mut t = base.model().terms;
            let v = keys.value(k.key).unwrap();
            let moved = if v == 0.0 { 0.25 } else { v * 0.75 };
            assert!(t.set(k.key, moved), "{}", k.key);
            let c = keys.with(&[k.key.to_string()], &[moved]).unwrap();
            assert_eq!(t, c.model().terms, "{}", k.key);
        }
        assert!(!base.model().terms.set("lubricant.viscosity_pa_s", 0.1));
    }

    #[test]
    fn the_films_fingerprint_ignores_exactly_the_keys_that_act_after_the_film() {
        let mut config = Config::default();
        config.contact.width_load_exponent = 0.5;
        let base = film_fingerprint(&config);
        let keys = ConfigKeys::new(&config);
        for k in crate::physics::terms::configured_catalogue() {
            let v = keys.value(k.key).unwrap();
            let moved = if v == 0.0 { 0.5 } else { v * 0.9 };
            let c = keys.with(&[k.key.to_string()], &[moved]).unwrap();
            assert_eq!(
                film_fingerprint(&c) == base,
                acts_after_the_film(k.key),
                "{}",
                k.key
            );
        }
        let mut viscous = config.clone();
        viscous.lubricant.viscosity_pa_s *= 2.0;
        assert_ne!(film_fingerprint(&viscous), base);
        // The load a series without its own runs at.
        let mut loaded = config.clone();
        loaded.contact.load_n *= 2.0;
        assert_ne!(film_fingerprint(&loaded), base);
        // A model that fits the viscosity names the base film at its base
        // value, as one that does not fit it.
        let fits = model_of(&config, &[("lubricant.viscosity_pa_s", 0.01, 1.0, 0.0564)]);
        let not = model_of(&config, &[("contact.boundary_friction", 0.01, 1.0, 0.3)]);
        assert_eq!(fits.film_key(&[0.0564]), not.film_key(&[0.3]));
        assert_ne!(fits.film_key(&[0.06]), not.film_key(&[0.3]));
    }

    #[test]
    fn a_steady_prediction_is_the_steady_solver_point_by_point() {
        let mut config = Config::default();
        config.solver.cells = 64;
        let v = vec![0.01, 0.1, 1.0];
        let s = series(vec![0.0, 1.0, 2.0], v.clone(), true);
        let got = steady(&config, &s).unwrap().0;
        let mut solver = Solver::new(&config.model(), &config.solver_settings()).unwrap();
        for (k, v) in v.iter().enumerate() {
            let e = solver.steady(*v, config.contact.load_n);
            assert_relative_eq!(got[k], e.friction_force, max_relative = 1e-9);
        }
    }
}
