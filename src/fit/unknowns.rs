//! Fitted parameters: their bounds, their scale and how they reach the
//! configuration.
//!
//! A parameter is a numeric configuration key (`roughness.sigma_m`, any
//! key of the parameter file whose value is a real number) or a map
//! coefficient of the input expressions (`k` in `--load 'k * p_bar'`). The
//! optimiser works on the scaled value s: ln p when both bounds are
//! positive (a positive physical quantity is fitted in relative terms),
//! p otherwise; and on an unbounded u with s = lo + (hi − lo)(1 + sin u)/2.

use super::FitError;
use crate::config::{Config, ConfigError};
use crate::physics::terms::FitScale;
use serde_norway::Value;

/// What the command line asked for one fitted parameter.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParamSpec {
    /// The dotted configuration key (or map coefficient).
    pub name: String,
    /// `--bounds NAME=LO:HI`.
    pub bounds: Option<(f64, f64)>,
    /// `--start NAME=VALUE` (default: the configuration's value, or the
    /// map coefficient's `--map` value).
    pub start: Option<f64>,
    /// Under `--fit auto`: a bound or start for a key that the selection
    /// may choose, not named in `--fit`. It is used if its term is chosen,
    /// and fits nothing by itself.
    pub if_chosen: bool,
}

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct FittedParameter {
    /// The dotted key (or map coefficient).
    pub name: String,
    /// The starting value.
    pub start: f64,
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
    /// Fitted on ln p.
    pub log: bool,
}

/// A start this close to a bound (as a fraction of the scaled range) is
/// moved inside: the sine transform is stationary at its bounds.
const START_MARGIN: f64 = 0.02;

/// The keys that place a bend of the friction curve at a speed (a Stribeck
/// speed, a boundary film's activation speed): such a key has as many
/// optima as the data have places to bend the curve, and one start finds
/// one of them.
pub const BEND_SPEED_KEYS: [&str; 2] = [
    "drivetrain.stribeck_speed_m_s",
    "contact.boundary_activation_speed_m_s",
];

impl FittedParameter {
    /// This parameter started at `v`, kept inside its bounds (clear of
    /// them by the start margin, where the sine transform is stationary);
    /// the bounds do not move.
    pub fn warm(&mut self, v: f64) {
        if v.is_finite() {
            let f = self.fraction(v.clamp(self.lo, self.hi));
            self.start = self.from_fraction(f.clamp(START_MARGIN, 1.0 - START_MARGIN));
        }
    }

    /// A parameter on `[lo, hi]`, on the log scale when `lo > 0`.
    pub fn new(name: &str, start: f64, lo: f64, hi: f64) -> Self {
        Self {
            name: name.to_string(),
            start,
            lo,
            hi,
            log: lo > 0.0,
        }
    }

    /// `p` on the scale the optimiser sees (ln p for a log parameter).
    pub fn scaled(&self, p: f64) -> f64 {
        if self.log {
            p.ln()
        } else {
            p
        }
    }

    /// The value of scaled `s`.
    pub fn unscaled(&self, s: f64) -> f64 {
        if self.log {
            s.exp()
        } else {
            s
        }
    }

    /// The bounds on the scaled axis.
    pub fn scaled_bounds(&self) -> (f64, f64) {
        (self.scaled(self.lo), self.scaled(self.hi))
    }

    /// Position of `p` within the scaled bounds, 0 … 1.
    pub fn fraction(&self, p: f64) -> f64 {
        let (a, b) = self.scaled_bounds();
        ((self.scaled(p) - a) / (b - a)).clamp(0.0, 1.0)
    }

    /// The value at position `f` (0 … 1) within the scaled bounds.
    pub fn from_fraction(&self, f: f64) -> f64 {
        let (a, b) = self.scaled_bounds();
        self.unscaled(a + (b - a) * f.clamp(0.0, 1.0))
            .clamp(self.lo, self.hi)
    }

    /// The unbounded variable of `p` (a start at a bound is moved inside).
    /// It is shifted by a whole period of the sine: MINPACK sizes its first
    /// step by the norm of the variables, so a start in the middle of every
    /// range (all u = 0) would take steps of 1e-16 and stop at once.
    pub fn to_internal(&self, p: f64) -> f64 {
        let f = self.fraction(p).clamp(START_MARGIN, 1.0 - START_MARGIN);
        (2.0 * f - 1.0).asin() + std::f64::consts::TAU
    }

    /// The unbounded variable of `p` on its canonical fold (in
    /// [2π − π/2, 2π + π/2]), a value at a bound kept there: where the
    /// point of a run's end is compared with other runs' points.
    pub fn to_canonical(&self, p: f64) -> f64 {
        (2.0 * self.fraction(p) - 1.0).asin() + std::f64::consts::TAU
    }

    /// The value of the optimiser's unbounded variable `u` (see `to_internal`).
    pub fn from_internal(&self, u: f64) -> f64 {
        self.from_fraction(0.5 * (1.0 + u.sin()))
    }

    /// Whether `p` sits at a bound (within 0.1 % of the scaled range).
    pub fn at_bound(&self, p: f64) -> bool {
        let f = self.fraction(p);
        !(1e-3..=1.0 - 1e-3).contains(&f)
    }
}

/// Scales of the data, for default bounds of terms that start at zero.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DataScale {
    /// max |F|, N.
    pub friction_n: f64,
    /// max |v|, m/s.
    pub velocity_m_s: f64,
    /// Smallest load, N.
    pub load_min_n: f64,
    /// The contact's stiffness through the data's reversals, N/m (None:
    /// no reversal; see [`super::reversals`]).
    pub reversal_stiffness_n_m: Option<f64>,
}

impl DataScale {
    /// The scales of the data (m/s or rad/s, N or N·m) on the contact
    /// behind gain `gain` (m/s, N), whose smallest load is `load_min_n`:
    /// v = g ẋ, F = F_data / g, k = k_data / g².
    pub fn through_gain(&self, gain: f64, load_min_n: f64) -> Self {
        Self {
            friction_n: self.friction_n / gain,
            velocity_m_s: self.velocity_m_s * gain,
            load_min_n,
            reversal_stiffness_n_m: self.reversal_stiffness_n_m.map(|k| k / (gain * gain)),
        }
    }
}

/// The configuration as a tree of keys, to read and set numeric keys by
/// their dotted name.
#[derive(Debug, Clone)]
pub struct ConfigKeys {
    tree: Value,
}

fn lookup<'a>(tree: &'a Value, key: &str) -> Option<&'a Value> {
    key.split('.').try_fold(tree, |node, part| match node {
        Value::Mapping(m) => m.get(part),
        _ => None,
    })
}

fn lookup_mut<'a>(tree: &'a mut Value, key: &str) -> Option<&'a mut Value> {
    key.split('.').try_fold(tree, |node, part| match node {
        Value::Mapping(m) => m.get_mut(part),
        _ => None,
    })
}

/// The dotted names of every real-valued key under `tree` (prefixed by
/// `prefix`), into `out`.
fn numeric_keys(tree: &Value, prefix: &str, out: &mut Vec<String>) {
    match tree {
        Value::Mapping(m) => {
            for (k, v) in m {
                if let Some(k) = k.as_str() {
                    let name = if prefix.is_empty() {
                        k.to_string()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    numeric_keys(v, &name, out);
                }
            }
        }
        Value::Number(n) if n.is_f64() => out.push(prefix.to_string()),
        _ => {}
    }
}

impl ConfigKeys {
    /// The key tree of `config`.
    pub fn new(config: &Config) -> Self {
        Self {
            tree: serde_norway::to_value(config).expect("a configuration serializes"),
        }
    }

    /// The value of a real-valued key; names what is wrong otherwise.
    pub fn value(&self, key: &str) -> Result<f64, FitError> {
        let err = |message: String| FitError::Key {
            key: key.to_string(),
            message,
        };
        match lookup(&self.tree, key) {
            None => {
                let mut keys = Vec::new();
                numeric_keys(&self.tree, "", &mut keys);
                let hint =
                    crate::config::nearest_key::nearest(key, keys.iter().map(String::as_str))
                        .map_or_else(String::new, |k| format!(": did you mean `{k}`?"));
                Err(err(format!(
                    "is not a key of the configuration (see launch-config/default.yaml){hint}"
                )))
            }
            Some(Value::Number(n)) if n.is_f64() => Ok(n.as_f64().expect("f64")),
            Some(Value::Number(n)) => Err(err(format!(
                "is an integer setting ({n}), not a continuous parameter"
            ))),
            Some(Value::Mapping(_)) => Err(err("is a section, not a number".into())),
            Some(v) => Err(err(format!(
                "is not numeric (its value is {})",
                serde_norway::to_string(v).unwrap_or_default().trim()
            ))),
        }
    }

    /// The configuration with `keys` set to `values`, validated.
    pub fn with(&self, keys: &[String], values: &[f64]) -> Result<Config, ConfigError> {
        let mut tree = self.tree.clone();
        for (k, v) in keys.iter().zip(values) {
            if let Some(slot) = lookup_mut(&mut tree, k) {
                *slot = Value::Number((*v).into());
            }
        }
        let config: Config =
            serde_norway::from_value(tree).map_err(|e| ConfigError::InvalidValue {
                key: keys.join(","),
                message: e.to_string(),
            })?;
        config.validate()?;
        Ok(config)
    }

    fn valid(&self, key: &str, v: f64) -> Result<(), ConfigError> {
        self.with(&[key.to_string()], &[v]).map(|_| ())
    }

    /// Resolve a `--fit` key: its start, its bounds (given, checked against
    /// the key's valid range, or a decade either side of the start, shrunk
    /// into the valid range), its scale.
    pub fn parameter(
        &self,
        spec: &ParamSpec,
        scale: &DataScale,
    ) -> Result<FittedParameter, FitError> {
        let key = spec.name.as_str();
        let current = self.value(key)?;
        // A pre-sliding stiffness that is off (0) starts at the data's
        // stiffness through its reversals.
        let data_start = if key.ends_with("presliding_stiffness_n_m") && current == 0.0 {
            scale.reversal_stiffness_n_m
        } else {
            None
        };
        let implied = spec.start.or(data_start).unwrap_or(current);
        let (lo, hi) = match spec.bounds {
            Some((lo, hi)) => {
                check_bounds(key, lo, hi)?;
                for v in [lo, hi] {
                    self.valid(key, v).map_err(|e| FitError::Bounds {
                        key: key.into(),
                        message: format!("{v} is outside the key's valid range: {e}"),
                    })?;
                }
                (lo, hi)
            }
            None => self.default_bounds(key, implied, scale)?,
        };
        let start = start_within(spec, implied, (lo, hi));
        if let Some(s) = spec.start {
            self.valid(key, s).map_err(|e| FitError::Key {
                key: key.into(),
                message: format!("--start {s} is not valid: {e}"),
            })?;
        }
        check_start(key, start, (lo, hi))?;
        Ok(FittedParameter::new(key, start, lo, hi))
    }

    fn default_bounds(
        &self,
        key: &str,
        start: f64,
        scale: &DataScale,
    ) -> Result<(f64, f64), FitError> {
        // A speed or a stiffness: its physical range, from the data's
        // scales, whatever its start.
        if let Some(range) =
            crate::physics::terms::term_key(key).and_then(|k| physical_range(k, scale))
        {
            return Ok(range);
        }
        if start > 0.0 {
            let shrink = |factor: f64| -> f64 {
                // start·factor^(2^-k), the first that is valid.
                let mut f = factor;
                for _ in 0..30 {
                    if self.valid(key, start * f).is_ok() {
                        return start * f;
                    }
                    f = f.sqrt();
                }
                start
            };
            let (lo, hi) = (shrink(0.1), shrink(10.0));
            if lo < hi {
                return Ok((lo, hi));
            }
        }
        // Terms that are off by default: bounds from the data's scales, as
        // each term declares them (physics::terms).
        let hi = match crate::physics::terms::term_key(key) {
            Some(k) => match k.fit {
                FitScale::Data {
                    factor,
                    speed_power,
                    per_load,
                    symmetric,
                } => {
                    let v = scale.velocity_m_s.max(1e-9);
                    let mut h = factor * scale.friction_n / v.powi(speed_power);
                    if per_load {
                        h /= scale.load_min_n.max(1e-9);
                    }
                    let h = h.min(k.hi.value());
                    if symmetric && h > 0.0 && h.is_finite() {
                        return Ok((-h, h));
                    }
                    Some(h)
                }
                FitScale::FromStart | FitScale::Speed { .. } | FitScale::Stiffness { .. } => None,
            },
            None => None,
        };
        match hi {
            Some(h) if h > 0.0 && h.is_finite() => Ok((0.0, h)),
            _ => Err(FitError::Bounds {
                key: key.into(),
                message: format!(
                    "starts at {start}: give its range with --bounds {key}=LO:HI (the fit then starts inside it; --start {key}=V to choose where)"
                ),
            }),
        }
    }
}

/// The range of a speed or a stiffness key from the data's scales, kept
/// inside the key's valid range (None: another kind of key, or data that
/// give no scale).
fn physical_range(k: &crate::physics::terms::TermKey, scale: &DataScale) -> Option<(f64, f64)> {
    let (lo, hi) = match k.fit {
        FitScale::Speed { lo, hi } => (lo * scale.velocity_m_s, hi * scale.velocity_m_s),
        FitScale::Stiffness { x_lo, x_hi } => (scale.friction_n / x_hi, scale.friction_n / x_lo),
        _ => return None,
    };
    let inside = |v: f64| {
        let (a, b) = (k.lo.value(), k.hi.value());
        // An open end is kept a part in a million inside.
        let a = if matches!(k.lo, crate::physics::terms::End::Open(_)) {
            a + 1e-6 * a.abs().max(f64::MIN_POSITIVE)
        } else {
            a
        };
        v.clamp(a, b)
    };
    let (lo, hi) = (inside(lo), inside(hi));
    (lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi).then_some((lo, hi))
}

/// Bounds must be finite and increasing.
pub fn check_bounds(key: &str, lo: f64, hi: f64) -> Result<(), FitError> {
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(FitError::Bounds {
            key: key.into(),
            message: format!("{lo}:{hi} must be finite numbers"),
        });
    }
    if lo >= hi {
        return Err(FitError::Bounds {
            key: key.into(),
            message: format!("{lo}:{hi} is inverted or empty (LO must be below HI)"),
        });
    }
    Ok(())
}

/// A map coefficient as a fitted parameter: `--bounds` or, for a positive
/// start, a decade either side.
pub fn map_parameter(spec: &ParamSpec, map_start: f64) -> Result<FittedParameter, FitError> {
    let key = spec.name.as_str();
    let implied = spec.start.unwrap_or(map_start);
    let (lo, hi) = match spec.bounds {
        Some((lo, hi)) => {
            check_bounds(key, lo, hi)?;
            (lo, hi)
        }
        None if implied > 0.0 => (implied / 10.0, implied * 10.0),
        None => {
            let start = implied;
            return Err(FitError::Bounds {
                key: key.into(),
                message: format!(
                "the map coefficient starts at {start}: give its range with --bounds {key}=LO:HI (the fit then starts inside it; --start {key}=V to choose where)"
            ),
            });
        }
    };
    let start = start_within(spec, implied, (lo, hi));
    check_start(key, start, (lo, hi))?;
    Ok(FittedParameter::new(key, start, lo, hi))
}

/// The start of a fitted parameter: the `--start` given, else the start
/// the configuration (or the data) implies when it lies within the bounds,
/// else a point inside them: their geometric mean when both are positive
/// (scale parameters), their midpoint otherwise. So `--bounds` alone is
/// enough for a key that is off (0) by default.
fn start_within(spec: &ParamSpec, implied: f64, (lo, hi): (f64, f64)) -> f64 {
    match spec.start {
        Some(s) => s,
        None if (lo..=hi).contains(&implied) => implied,
        None if lo > 0.0 => (lo * hi).sqrt(),
        None => 0.5 * (lo + hi),
    }
}

/// An explicit start must lie within the bounds.
fn check_start(key: &str, start: f64, (lo, hi): (f64, f64)) -> Result<(), FitError> {
    if (lo..=hi).contains(&start) {
        return Ok(());
    }
    Err(FitError::Bounds {
        key: key.into(),
        message: format!(
            "--start {start} lies outside [{lo}, {hi}] (give a start inside --bounds {key}=LO:HI, or leave --start out to start inside them)"
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const SCALE: DataScale = DataScale {
        friction_n: 100.0,
        velocity_m_s: 0.5,
        load_min_n: 1000.0,
        reversal_stiffness_n_m: None,
    };

    fn spec(name: &str) -> ParamSpec {
        ParamSpec {
            name: name.into(),
            ..Default::default()
        }
    }

    #[test]
    fn the_sine_transform_round_trips_inside_the_bounds_on_the_log_scale() {
        let p = FittedParameter::new("roughness.sigma_m", 5e-6, 5e-7, 5e-5);
        assert!(p.log);
        for v in [6e-7, 5e-6, 4e-5] {
            assert_relative_eq!(p.from_internal(p.to_internal(v)), v, max_relative = 1e-12);
        }
        // The geometric middle is the middle of the scaled range.
        assert_relative_eq!(p.fraction(5e-6), 0.5, epsilon = 1e-12);
        assert!(p.at_bound(5e-7) && !p.at_bound(5e-6));
        // Any u maps inside the bounds.
        for u in [-100.0, -1.0, 0.0, 3.0, 1e6] {
            let v = p.from_internal(u);
            assert!((p.lo..=p.hi).contains(&v));
        }
    }

    #[test]
    fn keys_resolve_to_their_value_and_a_decade_either_side_inside_the_valid_range() {
        let keys = ConfigKeys::new(&Config::default());
        let p = keys.parameter(&spec("roughness.sigma_m"), &SCALE).unwrap();
        assert_relative_eq!(p.start, 5e-6);
        assert_relative_eq!(p.lo, 5e-7, max_relative = 1e-12);
        assert_relative_eq!(p.hi, 5e-5, max_relative = 1e-12);
        // boundary_friction 0.3: valid up to 2, so hi shrinks below 3.
        let p = keys
            .parameter(&spec("contact.boundary_friction"), &SCALE)
            .unwrap();
        assert!(p.hi <= 2.0 && p.hi > 0.3, "{p:?}");
        // Drivetrain terms start at 0: bounds from the data.
        let p = keys
            .parameter(&spec("drivetrain.viscous_n_s_m"), &SCALE)
            .unwrap();
        assert_eq!((p.lo, p.hi, p.log), (0.0, 400.0, false));
        // The boundary film's rate: up to twice the data's friction
        // coefficient (100 N over 1000 N) per e-fold; its activation speed
        // from 1e-4 of the data's top speed (0.5 m/s) to the top speed.
        let p = keys
            .parameter(&spec("contact.boundary_friction_rate"), &SCALE)
            .unwrap();
        assert_eq!((p.lo, p.log), (0.0, false));
        assert_relative_eq!(p.hi, 0.2, max_relative = 1e-12);
        let p = keys
            .parameter(&spec("contact.boundary_activation_speed_m_s"), &SCALE)
            .unwrap();
        assert_relative_eq!(p.lo, 5e-5, max_relative = 1e-12);
        assert_relative_eq!(p.hi, 0.5, max_relative = 1e-12);
        assert!(p.log);
        // The Stribeck speed: from 1e-3 of the top speed to the top speed,
        // where the data still show 63 % of the fall.
        let p = keys
            .parameter(&spec("drivetrain.stribeck_speed_m_s"), &SCALE)
            .unwrap();
        assert_relative_eq!(p.lo, 5e-4, max_relative = 1e-12);
        assert_relative_eq!(p.hi, 0.5, max_relative = 1e-12);
        let c = keys.with(&["roughness.sigma_m".into()], &[3.5e-6]).unwrap();
        assert_eq!(c.roughness.sigma_m, 3.5e-6);
    }

    #[test]
    fn bad_keys_and_bounds_are_named() {
        let keys = ConfigKeys::new(&Config::default());
        let e = |s: ParamSpec| keys.parameter(&s, &SCALE).unwrap_err().to_string();
        assert!(
            e(spec("roughness.sigma")).contains("not a key"),
            "{}",
            e(spec("roughness.sigma"))
        );
        assert!(e(spec("solver.cells")).contains("integer"));
        assert!(e(spec("contact.profile")).contains("not numeric"));
        assert!(e(spec("contact")).contains("section"));
        let with = |lo, hi| ParamSpec {
            bounds: Some((lo, hi)),
            ..spec("contact.boundary_friction")
        };
        assert!(e(with(0.5, 0.1)).contains("inverted"));
        let m = e(with(0.1, 3.0));
        assert!(
            m.contains("outside the key's valid range") && m.contains("[0, 2]"),
            "{m}"
        );
        let m = e(ParamSpec {
            start: Some(0.05),
            ..with(0.1, 1.0)
        });
        assert!(m.contains("outside [0.1, 1]"), "{m}");
        let m = map_parameter(&spec("c0"), 0.0).unwrap_err().to_string();
        assert!(m.contains("--bounds c0=LO:HI"), "{m}");
    }

    #[test]
    fn following_the_advice_for_a_key_at_zero_gives_a_fit_that_starts_inside_the_bounds() {
        // A key off by default with no data scale: the advice names --bounds.
        let keys = ConfigKeys::new(&Config::default());
        let m = keys
            .parameter(&spec("contact.min_film_m"), &SCALE)
            .unwrap_err()
            .to_string();
        assert!(m.contains("--bounds contact.min_film_m=LO:HI"), "{m}");
        // Doing exactly that works (before: "the start 0 lies outside").
        let p = keys
            .parameter(
                &ParamSpec {
                    bounds: Some((1e-7, 1e-5)),
                    ..spec("contact.min_film_m")
                },
                &SCALE,
            )
            .unwrap();
        assert_relative_eq!(p.start, 1e-6, max_relative = 1e-12);
        // The same for a map coefficient, and a bound through zero starts mid-way.
        let c = |lo, hi| {
            map_parameter(
                &ParamSpec {
                    bounds: Some((lo, hi)),
                    ..spec("c0")
                },
                0.0,
            )
        };
        assert_eq!(c(-2.0, 4.0).unwrap().start, 0.0);
        assert_relative_eq!(c(1.0, 100.0).unwrap().start, 10.0, max_relative = 1e-12);
    }
}
