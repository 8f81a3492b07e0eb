//! `Model`: one contact's solver, stepped from Python, and `Model.run` over
//! whole numpy series.

use crate::columns::Columns;
use crate::errors;
use friction_node::config::{Config, InputLimits, Origin, OutOfEnvelope, ViscosityLaw};
use friction_node::physics::{Estimate as CoreEstimate, Solver};
use friction_node::range_watch::{RangeFlag, RangeWatch, Watched};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Read a configuration: parameter-file text, or a file, or the built-in
/// default, then `key=value` overrides.
pub fn load_config(
    yaml: Option<&str>,
    path: Option<&str>,
    overrides: &[String],
) -> PyResult<Config> {
    match (yaml, path) {
        (Some(_), Some(_)) => {
            return Err(errors::value(
                "give the configuration as text or as a file, not both",
            ))
        }
        (Some(text), None) => {
            Config::from_yaml(text, &Origin::Text("given to friction_node"), overrides)
        }
        (None, Some(p)) => Config::load(Some(std::path::Path::new(p)), overrides),
        (None, None) => Config::load(None, overrides),
    }
    .map_err(errors::config)
}

/// One step's estimate (the fields of `friction_msgs/FrictionEstimate`),
/// SI units.
#[pyclass(module = "friction_node._core", frozen, get_all)]
#[derive(Clone)]
pub struct Estimate {
    /// Model time at the end of the step, s.
    pub time_s: f64,
    /// sliding velocity of the step
    pub velocity_m_s: f64,
    /// normal load of the step
    pub load_n: f64,
    /// total friction: the contact plus the drivetrain terms, signed like the velocity
    pub friction_force_n: f64,
    /// the lubricated contact alone, signed like the velocity
    pub contact_friction_force_n: f64,
    /// contact friction per unit load: rigid (|F_visc| + (mu_bl + mu_r asinh(|v|/v_a)) F_asp) / F_ext; with pre-sliding |F_c| / F_ext; drivetrain terms excluded
    pub cof: f64,
    /// minimum nominal separation
    pub h0_m: f64,
    /// minimum film thickness
    pub h_min_m: f64,
    /// B * integral of (p - p_amb)
    pub hydrodynamic_force_n: f64,
    /// Greenwood-Williamson contact force
    pub asperity_force_n: f64,
    /// asperity_force_n / load_n
    pub asperity_load_share: f64,
    pub viscous_force_n: f64,
    pub max_pressure_pa: f64,
    /// Newton's last scaled residual.
    pub residual: f64,
    pub iterations: u32,
    pub substeps: u32,
    /// `converged`, `max_iterations`, `non_finite`, `non_finite_input`…
    pub status: &'static str,
    /// `boundary`, `mixed` or `hydrodynamic`.
    pub regime: &'static str,
    /// Where the step's input lay against the configuration's
    /// `calibrated_range`: `not_watched` (none given), `inside` or
    /// `outside` (the friction then as `node.outside_envelope` says).
    pub calibrated_range: &'static str,
}

impl From<&CoreEstimate> for Estimate {
    fn from(e: &CoreEstimate) -> Self {
        Self {
            time_s: e.time,
            velocity_m_s: e.velocity,
            load_n: e.load,
            friction_force_n: e.friction_force,
            contact_friction_force_n: e.contact_friction_force,
            cof: e.cof,
            h0_m: e.h0,
            h_min_m: e.h_min,
            hydrodynamic_force_n: e.hydrodynamic_force,
            asperity_force_n: e.asperity_force,
            asperity_load_share: e.asperity_load_share,
            viscous_force_n: e.viscous_force,
            max_pressure_pa: e.max_pressure,
            residual: e.diagnostics.residual,
            iterations: e.diagnostics.iterations,
            substeps: e.diagnostics.substeps,
            status: e.status.as_str(),
            regime: e.regime.as_str(),
            calibrated_range: RangeFlag::NotWatched.as_str(),
        }
    }
}

impl Estimate {
    /// The estimate of a step whose input `watch` judged as `w`.
    fn watched(e: &CoreEstimate, watch: &RangeWatch, w: &Watched) -> Self {
        Self {
            friction_force_n: watch.published(w.flag, e.friction_force),
            contact_friction_force_n: watch.published(w.flag, e.contact_friction_force),
            calibrated_range: w.flag.as_str(),
            ..Self::from(e)
        }
    }
}

#[pymethods]
impl Estimate {
    fn __repr__(&self) -> String {
        format!(
            "Estimate(time_s={}, velocity_m_s={}, friction_force_n={}, cof={}, h_min_m={:e}, status='{}')",
            self.time_s, self.velocity_m_s, self.friction_force_n, self.cof, self.h_min_m, self.status
        )
    }
}

/// One lubricated contact's model (see the Python wrapper's docstring).
#[pyclass(module = "friction_node._core")]
pub struct Model {
    solver: Solver,
    config: Config,
    temperature_c: f64,
    /// The configuration's calibrated range and `node.outside_envelope`.
    watch: RangeWatch,
}

/// The watch of `config`'s calibrated range.
fn watch_of(config: &Config) -> RangeWatch {
    RangeWatch::new(
        config.calibrated_range.clone(),
        config.node.outside_envelope,
        1.0,
    )
}

/// The values of an optional series, or `default` repeated.
fn series<'a>(
    a: &'a Option<PyReadonlyArray1<'_, f64>>,
    name: &str,
    n: usize,
) -> PyResult<Option<&'a [f64]>> {
    let Some(a) = a else { return Ok(None) };
    let s = a
        .as_slice()
        .map_err(|_| errors::value(format!("{name}: the array is not contiguous")))?;
    if s.len() != n {
        return Err(errors::value(format!(
            "{name} has {} samples, t has {n}: the arrays must have the same length",
            s.len()
        )));
    }
    Ok(Some(s))
}

/// The first sample of `x` the envelope refuses, as a ValueError naming
/// the array and the index (the rule every entry point checks:
/// [`friction_node::config::Envelope`]).
fn check_each(
    name: &str,
    x: &[f64],
    check: impl Fn(f64) -> Result<(), OutOfEnvelope>,
) -> PyResult<()> {
    for (k, v) in x.iter().enumerate() {
        if let Err(e) = check(*v) {
            return Err(errors::value(format!("{name}[{k}]: {e}")));
        }
    }
    Ok(())
}

/// A Python value as the YAML text of a parameter value: bools, integers
/// and floats (non-finite ones as YAML's `.nan`, `.inf`), or text as given.
fn parameter_text(value: &Bound<'_, PyAny>) -> PyResult<String> {
    if let Ok(b) = value.extract::<bool>() {
        return Ok(b.to_string());
    }
    if let Ok(i) = value.extract::<i64>() {
        return Ok(i.to_string());
    }
    if let Ok(x) = value.extract::<f64>() {
        return Ok(if x.is_nan() {
            ".nan".into()
        } else if x.is_infinite() {
            if x > 0.0 { ".inf" } else { "-.inf" }.into()
        } else {
            format!("{x:?}")
        });
    }
    value
        .extract::<String>()
        .map_err(|_| errors::value("a parameter value is a number, a bool or text"))
}

impl Model {
    fn law(&self) -> ViscosityLaw {
        ViscosityLaw::of(&self.config)
    }

    /// The viscosity at `t` °C, or under `node.outside_envelope: hold` at
    /// the calibrated range's nearest temperature; `mu` (the one at `t`)
    /// when the law refuses that.
    fn held_viscosity(&self, t: f64, mu: f64) -> f64 {
        self.law()
            .viscosity_at(self.watch.temperature_c(t))
            .unwrap_or(mu)
    }
}

#[pymethods]
impl Model {
    #[new]
    #[pyo3(signature = (yaml=None, path=None, overrides=Vec::new()))]
    fn new(yaml: Option<&str>, path: Option<&str>, overrides: Vec<String>) -> PyResult<Self> {
        let config = load_config(yaml, path, &overrides)?;
        if !config.contacts.is_empty() {
            return Err(errors::value(format!(
                "the configuration lists {} contacts (`contacts`): a Model is one contact; \
                 create one Model per contact from a configuration without `contacts`",
                config.contacts.0.len()
            )));
        }
        let mut solver = Solver::new(&config.model(), &config.solver_settings())
            .map_err(|e| errors::value(e.to_string()))?;
        solver.initialize_steady(0.0, config.contact.load_n);
        Ok(Self {
            temperature_c: config.lubricant.reference_temperature_c,
            watch: watch_of(&config),
            solver,
            config,
        })
    }

    /// The configured step `solver.dt_s`, s.
    #[getter]
    fn dt(&self) -> f64 {
        self.solver.settings().dt
    }

    /// The configured load `contact.load_n`, N.
    #[getter]
    fn load_n(&self) -> f64 {
        self.config.contact.load_n
    }

    /// The configuration as a complete parameter file.
    fn config_yaml(&self) -> String {
        self.config.to_yaml()
    }

    #[pyo3(signature = (velocity, load=None, dt=None))]
    fn step(&mut self, velocity: f64, load: Option<f64>, dt: Option<f64>) -> PyResult<Estimate> {
        let load = load.unwrap_or(self.config.contact.load_n);
        let limits = InputLimits::of(&self.config);
        limits
            .check_velocity(velocity)
            .and_then(|_| limits.check_load(load))
            .map_err(|e| errors::value(e.to_string()))?;
        let w = self.watch.watch(velocity, load, self.temperature_c);
        let e = match dt {
            Some(dt) => self.solver.step_by(w.velocity_m_s, w.load_n, dt),
            None => self.solver.step(w.velocity_m_s, w.load_n),
        };
        Ok(Estimate::watched(&e, &self.watch, &w))
    }

    #[pyo3(signature = (velocity=0.0, load=None))]
    fn reset(&mut self, velocity: f64, load: Option<f64>) -> PyResult<Estimate> {
        let load = load.unwrap_or(self.config.contact.load_n);
        if !(velocity.is_finite() && load.is_finite() && load > 0.0) {
            return Err(errors::value(format!(
                "reset: velocity {velocity} m/s and load {load} N must be finite, the load positive"
            )));
        }
        Ok(Estimate::from(
            &self.solver.initialize_steady(velocity, load),
        ))
    }

    /// Change a live parameter between steps (the node's and the C API's
    /// `set_parameter`): the key's name, and its value as a number, a bool
    /// or YAML text. The model's tables are rebuilt (this allocates: call it
    /// between steps, not in a real-time loop); the squeeze-film history
    /// and the bristle are kept. Refused, naming the key and the value,
    /// when the key is unknown or read-only, the type is wrong, the value
    /// is out of range, or the grid would change (`solver.cells`).
    fn set_parameter(&mut self, key: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        use friction_node::config::parameters::{declare, set_from_text};
        let text = parameter_text(value)?;
        let new = set_from_text(&self.config, &declare(&self.config), key, &text)
            .map_err(|e| errors::value(e.to_string()))?;
        let law = ViscosityLaw::of(&new);
        let mu = law.viscosity_at(self.temperature_c).map_err(|e| {
            errors::value(format!(
                "parameter `{key}`: the temperature set before no longer holds: {e}"
            ))
        })?;
        let mut prepared = Solver::prepare_model(&new.model(), &new.solver_settings())
            .map_err(|e| errors::value(format!("parameter `{key}`: {e}")))?;
        if !self.solver.fits(&prepared) {
            return Err(errors::value(format!(
                "parameter `{key}`: {}",
                friction_node::physics::ModelMismatch
            )));
        }
        let _ = self.solver.swap_model(&mut prepared);
        self.watch = watch_of(&new);
        self.config = new;
        if law.follows_temperature() {
            self.solver
                .set_liquid_viscosity(self.held_viscosity(self.temperature_c, mu));
        }
        Ok(())
    }

    fn set_temperature(&mut self, temperature_c: f64) -> PyResult<()> {
        let law = self.law();
        let mu = law
            .viscosity_at(temperature_c)
            .map_err(|e| errors::value(e.to_string()))?;
        self.temperature_c = temperature_c;
        if law.follows_temperature() {
            self.solver
                .set_liquid_viscosity(self.held_viscosity(temperature_c, mu));
        }
        Ok(())
    }

    #[pyo3(signature = (t, velocity, load=None, temperature=None))]
    fn run<'py>(
        &mut self,
        py: Python<'py>,
        t: PyReadonlyArray1<'py, f64>,
        velocity: PyReadonlyArray1<'py, f64>,
        load: Option<PyReadonlyArray1<'py, f64>>,
        temperature: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let t = t
            .as_slice()
            .map_err(|_| errors::value("t: the array is not contiguous"))?;
        let n = t.len();
        if n == 0 {
            return Err(errors::value("t is empty"));
        }
        let velocity = Some(velocity);
        let v = series(&velocity, "velocity", n)?.expect("given");
        let load = series(&load, "load", n)?;
        let temperature = series(&temperature, "temperature", n)?;
        if let Some(k) = t.iter().position(|x| !x.is_finite()) {
            return Err(errors::value(format!(
                "t[{k}] = {}: not a finite time",
                t[k]
            )));
        }
        if let Some(k) = (1..n).find(|&k| t[k] <= t[k - 1]) {
            return Err(errors::value(format!(
                "t[{k}] = {} is not after t[{}] = {}: t must increase strictly",
                t[k],
                k - 1,
                t[k - 1]
            )));
        }
        // The envelope `step`, the command line and the node check.
        let limits = InputLimits::of(&self.config);
        let law = self.law();
        check_each("velocity", v, |x| limits.check_velocity(x))?;
        if let Some(l) = load {
            check_each("load", l, |x| limits.check_load(x))?;
        }
        if let Some(tc) = temperature {
            check_each("temperature", tc, |x| law.viscosity_at(x).map(|_| ()))?;
        }
        let default_load = self.config.contact.load_n;
        let follows = temperature.is_some() && law.follows_temperature();
        let solver = &mut self.solver;
        let t_ref = self.temperature_c;
        let temp = |k: usize| temperature.map_or(t_ref, |s| s[k]);
        let f = |k: usize| load.map_or(default_load, |s| s[k]);
        // Checked above: every temperature has its viscosity.
        let mu = |k: usize| law.viscosity_at(temp(k)).unwrap_or(law.mu_ref);
        let mut c = Columns::with_capacity(n);
        // In chunks without the GIL, Python's signals checked between them:
        // Ctrl-C stops a long run within a chunk (~10-50 ms).
        const CHUNK: usize = 10_000;
        let mut k = 0;
        while k < n {
            let end = (k + CHUNK).min(n);
            py.detach(|| {
                for k in k..end {
                    if follows {
                        solver.set_liquid_viscosity(mu(k));
                    }
                    let e = if k == 0 {
                        solver.initialize_steady(v[0], f(0))
                    } else {
                        solver.step_by(v[k], f(k), t[k] - t[k - 1])
                    };
                    c.push(&e, t[k], e.status.as_str(), temp(k));
                }
            });
            py.check_signals()?;
            k = end;
        }
        let (columns, last_t) = (c, temp(n - 1));
        self.temperature_c = last_t;
        columns.into_dict(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "Model(cells={}, dt={} s, load_n={} N)",
            self.config.solver.cells,
            self.solver.settings().dt,
            self.config.contact.load_n
        )
    }
}
