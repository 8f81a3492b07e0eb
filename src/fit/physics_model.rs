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

use super::film_run::{steady, transient, FilmTrace};
use super::problem::Model;
use super::series::{mix, Series};
use super::unknowns::{ConfigKeys, DataScale, FittedParameter, ParamSpec};
use super::{FitError, PredictError};
use crate::config::Config;
use crate::physics::terms::{acts_after_the_film, FrictionTerms};
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

/// The viscous rise's exponent: fitted, the viscous key is no longer
/// linear with a fixed slope.
const BENT_KEY: &str = "drivetrain.viscous_exponent";

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
    /// trace's film key holds the gain, its inputs the data's; `inputs`
    /// is `s`'s `Series::inputs_fingerprint`).
    fn run(&self, x: &[f64], s: &Series, inputs: u64) -> Result<Vec<f64>, PredictError> {
        let film_key = self.film_key(x);
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
        // A fitted exponent makes the viscous rise F_v depend on it as well as on b.
        let bent = self.names.iter().any(|n| n == BENT_KEY);
        self.names
            .iter()
            .enumerate()
            .filter(|(_, n)| LINEAR_KEYS.contains(&n.as_str()))
            .filter(|(_, n)| !(bent && n.as_str() == LINEAR_KEYS[0]))
            .map(|(i, _)| i)
            .collect()
    }

    fn predict(&self, x: &[f64], series: &Series) -> Result<Vec<f64>, PredictError> {
        self.predict_fingerprinted(x, series, series.inputs_fingerprint())
    }

    fn predict_fingerprinted(
        &self,
        x: &[f64],
        series: &Series,
        inputs: u64,
    ) -> Result<Vec<f64>, PredictError> {
        let mut f = self.run(x, series, inputs)?;
        if self.gain != 1.0 {
            f.iter_mut().for_each(|f| *f *= self.gain);
        }
        Ok(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::film_run::tests::series;

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

    use approx::assert_relative_eq;

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
    fn a_fitted_viscous_exponent_makes_the_viscous_slope_depend_on_it_so_the_viscous_key_is_not_linear(
    ) {
        let mut config = Config::default();
        config.solver.cells = 32;
        config.drivetrain.viscous_reference_speed_m_s = 1.0;
        let keys = [
            ("drivetrain.viscous_n_s_m", 0.0, 1e4, 300.0),
            ("drivetrain.viscous_exponent", 0.1, 1.0, 1.0),
            ("drivetrain.quadratic_n_s2_m2", 0.0, 1e4, 800.0),
        ];
        let model = model_of(&config, &keys);
        assert_eq!(model.linear_parameters(), vec![2]);
        // The slope of b at v = 0.5 m/s: v_b |v/v_b|^δ, 0.5 straight and
        // 0.5^0.5 with δ = 0.5.
        let s = series(vec![0.0, 1.0], vec![0.5, 0.5], true);
        let at = |x: &[f64]| model.predict(x, &s).unwrap()[1];
        let slope = |d: f64| (at(&[400.0, d, 0.0]) - at(&[300.0, d, 0.0])) / 100.0;
        assert_relative_eq!(slope(1.0), 0.5, max_relative = 1e-6);
        assert_relative_eq!(slope(0.5), 0.5f64.sqrt(), max_relative = 1e-6);
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
}
