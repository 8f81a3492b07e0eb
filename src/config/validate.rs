//! Validation: the physical range of every key and the ROS 2 naming rules,
//! one small function per section. Errors name the key, the value and the
//! allowed range (or the rule broken).

use super::{Config, ConfigError, FluxKind, MethodKind};
use crate::physics::terms::{End, Interval};
use crate::text::Num;

/// The documented range of one numeric key (see [`key_ranges`]).
#[derive(Debug, Clone, PartialEq)]
pub struct KeyRange {
    /// The dotted key.
    pub key: String,
    /// Its valid values.
    pub range: Interval,
}

impl std::fmt::Display for KeyRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", IntervalText(self.range))
    }
}

/// An interval as users read it: `[lo, hi)`, the numbers as [`Num`]
/// writes them (every range in errors, parameter descriptions and the
/// README's table of the terms' keys).
pub struct IntervalText(pub Interval);

impl std::fmt::Display for IntervalText {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (open, lo) = match self.0.lo {
            End::Closed(v) => ('[', v),
            End::Open(v) => ('(', v),
        };
        let (close, hi) = match self.0.hi {
            End::Closed(v) => (']', v),
            End::Open(v) => (')', v),
        };
        write!(f, "{open}{}, {}{close}", Num(lo), Num(hi))
    }
}

thread_local! {
    static COLLECT: std::cell::RefCell<Option<Vec<KeyRange>>> = const { std::cell::RefCell::new(None) };
}

/// The range of every numeric key that [`Config::validate`] checks, as it
/// checks them on the default configuration (ranges that depend on another
/// key are given at its default value).
pub fn key_ranges() -> Vec<KeyRange> {
    COLLECT.with(|c| *c.borrow_mut() = Some(Vec::new()));
    let _ = Config::default().validate();
    let mut v = COLLECT.with(|c| c.borrow_mut().take()).unwrap_or_default();
    let mut seen = std::collections::HashSet::new();
    v.retain(|r| seen.insert(r.key.clone()));
    v
}

fn check(key: &str, value: f64, lo: End, hi: End) -> Result<(), ConfigError> {
    let range = Interval { lo, hi };
    COLLECT.with(|c| {
        if let Some(v) = c.borrow_mut().as_mut() {
            v.push(KeyRange {
                key: key.to_string(),
                range,
            });
        }
    });
    if range.contains(value) {
        return Ok(());
    }
    Err(ConfigError::OutOfRange {
        key: key.to_string(),
        value: format!("{value}"),
        range: IntervalText(range).to_string(),
    })
}

/// (lo, hi]
pub(super) fn oc(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Open(lo), End::Closed(hi))
}

/// [lo, hi]
pub(super) fn cc(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Closed(lo), End::Closed(hi))
}

/// [lo, hi)
pub(super) fn co(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Closed(lo), End::Open(hi))
}

/// (lo, hi)
pub(super) fn oo(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Open(lo), End::Open(hi))
}

impl Config {
    /// Physical ranges of every key, and ROS 2 names.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_contact()?;
        self.validate_texture()?;
        self.validate_lubricant()?;
        self.validate_roughness()?;
        self.validate_solver()?;
        self.validate_node()?;
        self.validate_ros()?;
        self.validate_iceoryx2()?;
        self.validate_recording()?;
        if let Some(r) = &self.calibrated_range {
            r.validate("calibrated_range", false)?;
        }
        self.validate_contacts()
    }

    pub(super) fn validate_contact(&self) -> Result<(), ConfigError> {
        let c = &self.contact;
        oc("contact.length_m", c.length_m, 1e-4, 10.0)?;
        oc("contact.width_m", c.width_m, 1e-4, 10.0)?;
        cc("contact.mass_kg", c.mass_kg, 0.0, 1e6)?;
        oc("contact.load_n", c.load_n, 0.0, 1e9)?;
        cc("contact.profile_depth_m", c.profile_depth_m, 0.0, 1e-3)?;
        cc("contact.min_film_m", c.min_film_m, 0.0, 1e-3)?;
        self.validate_terms()
    }

    /// Every friction term's key against the range its term declares
    /// (`physics::terms`: the catalogue is the one list of them).
    pub(super) fn validate_terms(&self) -> Result<(), ConfigError> {
        use crate::physics::terms::configured_catalogue as catalogue;
        let tree = serde_norway::to_value(self).expect("a configuration serializes");
        for k in catalogue() {
            let v = k
                .key
                .split('.')
                .try_fold(&tree, |t, part| t.get(part))
                .and_then(serde_norway::Value::as_f64)
                .unwrap_or(f64::NAN);
            check(k.key, v, k.lo, k.hi)?;
        }
        Ok(())
    }

    pub(super) fn validate_texture(&self) -> Result<(), ConfigError> {
        let t = &self.texture;
        let n = t.pocket_start_m.len();
        for (key, len) in [
            ("texture.pocket_width_m", t.pocket_width_m.len()),
            ("texture.pocket_depth_m", t.pocket_depth_m.len()),
        ] {
            if len != n {
                return Err(ConfigError::InvalidValue {
                    key: key.into(),
                    message: format!("has {len} entries but texture.pocket_start_m has {n}"),
                });
            }
        }
        let length = self.contact.length_m;
        for i in 0..n {
            let (s, w, d) = (
                t.pocket_start_m[i],
                t.pocket_width_m[i],
                t.pocket_depth_m[i],
            );
            co(&format!("texture.pocket_start_m[{i}]"), s, 0.0, length)?;
            oc(&format!("texture.pocket_width_m[{i}]"), w, 0.0, length - s)?;
            cc(&format!("texture.pocket_depth_m[{i}]"), d, 0.0, 1e-3)?;
        }
        Ok(())
    }

    pub(super) fn validate_lubricant(&self) -> Result<(), ConfigError> {
        let l = &self.lubricant;
        let (mu_lo, mu_hi) = super::envelope::VISCOSITY_RANGE_PA_S;
        oc("lubricant.viscosity_pa_s", l.viscosity_pa_s, mu_lo, mu_hi)?;
        let (t_lo, t_hi) = super::envelope::TEMPERATURE_RANGE_C;
        cc(
            "lubricant.reference_temperature_c",
            l.reference_temperature_c,
            t_lo,
            t_hi,
        )?;
        oc("lubricant.vogel_b_c", l.vogel_b_c, 0.0, 1e5)?;
        cc(
            "lubricant.vogel_c_c",
            l.vogel_c_c,
            -273.15,
            l.reference_temperature_c - 1.0,
        )?;
        cc("lubricant.density_kg_m3", l.density_kg_m3, 100.0, 3e4)?;
        oc(
            "lubricant.gas_viscosity_pa_s",
            l.gas_viscosity_pa_s,
            1e-7,
            1e-2,
        )?;
        oo(
            "lubricant.gas_density_kg_m3",
            l.gas_density_kg_m3,
            1e-4,
            l.density_kg_m3,
        )?;
        oc(
            "lubricant.ambient_pressure_pa",
            l.ambient_pressure_pa,
            0.0,
            1e9,
        )?;
        oc(
            "lubricant.saturation_pressure_pa",
            l.saturation_pressure_pa,
            0.0,
            1e9,
        )?;
        co(
            "lubricant.vapour_pressure_pa",
            l.vapour_pressure_pa,
            0.0,
            l.saturation_pressure_pa,
        )?;
        oo(
            "lubricant.vapour_fraction_at_saturation",
            l.vapour_fraction_at_saturation,
            0.0,
            1.0,
        )?;
        oo(
            "lubricant.vapour_fraction_at_vapour_pressure",
            l.vapour_fraction_at_vapour_pressure,
            l.vapour_fraction_at_saturation,
            1.0,
        )
    }

    pub(super) fn validate_roughness(&self) -> Result<(), ConfigError> {
        let r = &self.roughness;
        oc("roughness.sigma_m", r.sigma_m, 1e-10, 1e-4)?;
        cc(
            "roughness.asperity_density_per_m2",
            r.asperity_density_per_m2,
            0.0,
            1e16,
        )?;
        oc(
            "roughness.asperity_radius_m",
            r.asperity_radius_m,
            1e-9,
            1e-2,
        )?;
        oc(
            "roughness.effective_modulus_pa",
            r.effective_modulus_pa,
            1e5,
            1e13,
        )?;
        if r.flow_factors {
            use crate::physics::flow_factors::{FlowFactors, SUPPORTED_GAMMAS};
            FlowFactors::new(r.lay_gamma, r.sigma_m).map_err(|_| ConfigError::OutOfRange {
                key: "roughness.lay_gamma".into(),
                value: format!("{}", r.lay_gamma),
                range: format!("one of {SUPPORTED_GAMMAS}"),
            })?;
        }
        Ok(())
    }

    pub(super) fn validate_solver(&self) -> Result<(), ConfigError> {
        let s = &self.solver;
        cc("solver.cells", s.cells as f64, 8.0, 65536.0)?;
        oc("solver.dt_s", s.dt_s, 1e-7, 1.0)?;
        // The loop keeps deadlines in integer nanoseconds: the step must be one.
        let ns = s.dt_s * 1e9;
        if (ns - ns.round()).abs() > 1e-3 {
            return Err(ConfigError::InvalidValue {
                key: "solver.dt_s".into(),
                message: format!(
                    "{} s is not a whole number of nanoseconds (deadlines are integer ns)",
                    s.dt_s
                ),
            });
        }
        oc("solver.tolerance", s.tolerance, 1e-14, 1e-1)?;
        cc("solver.max_iterations", s.max_iterations as f64, 1.0, 1e4)?;
        cc("solver.theta1", s.theta1, 0.5, 10.0)?;
        oc("solver.theta2", s.theta2, 0.0, 10.0)?;
        if s.method == MethodKind::Reference && s.flux != FluxKind::Upwind {
            return Err(ConfigError::InvalidValue {
                key: "solver.flux".into(),
                message: format!(
                    "{} is not supported by solver.method: reference (the paper's Picard solver has the upwind flux only); allowed with it: upwind (with solver.method: newton: {})",
                    s.flux.name(),
                    FluxKind::NAMES
                ),
            });
        }
        let r = &s.reference;
        let k = |name: &str| format!("solver.reference.{name}");
        oc(&k("fluid_relaxation"), r.fluid_relaxation, 0.0, 1.0)?;
        oc(
            &k("fluid_relaxation_min"),
            r.fluid_relaxation_min,
            0.0,
            r.fluid_relaxation,
        )?;
        cc(
            &k("max_fluid_iterations"),
            r.max_fluid_iterations as f64,
            1.0,
            1e7,
        )?;
        oc(&k("fluid_tolerance"), r.fluid_tolerance, 1e-14, 1.0)?;
        oc(&k("motion_relaxation"), r.motion_relaxation, 0.0, 1.0)?;
        cc(
            &k("max_motion_iterations"),
            r.max_motion_iterations as f64,
            1.0,
            1e6,
        )?;
        oc(&k("motion_tolerance"), r.motion_tolerance, 1e-14, 1.0)
    }
}
