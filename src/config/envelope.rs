//! What inputs the model accepts: one rule, checked by every entry point
//! (the command line's signals, the node's commands, Python, the C API).
//!
//! | quantity | accepted | from |
//! |---|---|---|
//! | velocity v | finite, \|v\| ≤ `node.max_abs_velocity_m_s` | [`InputLimits`] |
//! | load F | finite, in [`node.min_load_n`, `node.max_load_n`] | [`InputLimits`] |
//! | temperature T | finite, in [-60, 300] °C, above Vogel's C, and giving a liquid viscosity in the model's range (1e-5, 100] Pa·s | [`ViscosityLaw`] |
//!
//! The temperature rule is the viscosity's: with `lubricant.viscosity_model:
//! vogel`, μ(T) = μ_ref exp(B/(T − C) − B/(T_ref − C)) has no value at or
//! below C and leaves any range the model can solve long before it (at
//! C + 1 °C the SAE 30 oil is ~10⁴⁰⁰ times its reference viscosity), so a
//! temperature is accepted only where the viscosity it gives is one the
//! configuration itself would accept for `lubricant.viscosity_pa_s`. μ(T)
//! is monotone in T, so a signal whose smallest and largest values pass,
//! passes everywhere between.
//!
//! Every check returns an [`OutOfEnvelope`] that names the quantity, the
//! value and what is allowed; it holds numbers only, so a check allocates
//! nothing (the C API's step calls it).

use super::Config;
use crate::physics::ViscosityModel;
use crate::text::Num;

/// The temperatures any lubricant model accepts, °C.
pub const TEMPERATURE_RANGE_C: (f64, f64) = (-60.0, 300.0);
/// The liquid viscosities the model accepts, Pa·s (open below, closed
/// above), for `lubricant.viscosity_pa_s` and for the viscosity a
/// temperature gives.
pub const VISCOSITY_RANGE_PA_S: (f64, f64) = (1e-5, 100.0);

/// An input outside what the model accepts.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum OutOfEnvelope {
    /// A velocity beyond the limit.
    #[error("velocity {} m/s: a velocity must be finite with |v| ≤ node.max_abs_velocity_m_s = {} m/s", Num(*.value), Num(*.max))]
    Velocity {
        /// The velocity given, m/s.
        value: f64,
        /// `node.max_abs_velocity_m_s`.
        max: f64,
    },
    /// A load outside the limits.
    #[error("load {} N: a load must be finite and lie in [node.min_load_n, node.max_load_n] = [{}, {}] N", Num(*.value), Num(*.min), Num(*.max))]
    Load {
        /// The load given, N.
        value: f64,
        /// `node.min_load_n`.
        min: f64,
        /// `node.max_load_n`.
        max: f64,
    },
    /// A temperature outside the model's range.
    #[error("temperature {} °C: a temperature must be finite and lie in [{}, {}] °C", Num(*.value), Num(TEMPERATURE_RANGE_C.0), Num(TEMPERATURE_RANGE_C.1))]
    TemperatureRange {
        /// The temperature given, °C.
        value: f64,
    },
    /// A temperature where Vogel's law has no value.
    #[error("temperature {} °C is at or below Vogel's C = {} °C (lubricant.vogel_c_c): the viscosity law has no value there", Num(*.value), Num(*.c_c))]
    BelowVogelC {
        /// The temperature given, °C.
        value: f64,
        /// `lubricant.vogel_c_c`, °C.
        c_c: f64,
    },
    /// A temperature whose viscosity is outside the model's range.
    #[error("temperature {} °C gives a liquid viscosity of {} Pa·s (lubricant.viscosity_model: vogel), outside the model's ({}, {}] Pa·s", Num(*.value), Num(*.viscosity), Num(VISCOSITY_RANGE_PA_S.0), Num(VISCOSITY_RANGE_PA_S.1))]
    Viscosity {
        /// The temperature given, °C.
        value: f64,
        /// The viscosity it gives, Pa·s.
        viscosity: f64,
    },
}

/// The velocity and load commands a configuration accepts (`node.*`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InputLimits {
    /// `node.max_abs_velocity_m_s`.
    pub max_abs_velocity_m_s: f64,
    /// `node.min_load_n`.
    pub min_load_n: f64,
    /// `node.max_load_n`.
    pub max_load_n: f64,
}

impl InputLimits {
    /// The limits of `config`.
    pub fn of(config: &Config) -> Self {
        Self {
            max_abs_velocity_m_s: config.node.max_abs_velocity_m_s,
            min_load_n: config.node.min_load_n,
            max_load_n: config.node.max_load_n,
        }
    }

    /// Whether velocity `v` (m/s) is accepted.
    pub fn check_velocity(&self, v: f64) -> Result<(), OutOfEnvelope> {
        if v.is_finite() && v.abs() <= self.max_abs_velocity_m_s {
            Ok(())
        } else {
            Err(OutOfEnvelope::Velocity {
                value: v,
                max: self.max_abs_velocity_m_s,
            })
        }
    }

    /// Whether load `f` (N) is accepted.
    pub fn check_load(&self, f: f64) -> Result<(), OutOfEnvelope> {
        if f.is_finite() && f >= self.min_load_n && f <= self.max_load_n {
            Ok(())
        } else {
            Err(OutOfEnvelope::Load {
                value: f,
                min: self.min_load_n,
                max: self.max_load_n,
            })
        }
    }
}

/// How one contact's liquid viscosity follows the temperature, and which
/// temperatures it accepts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViscosityLaw {
    /// Constant or Vogel.
    pub model: ViscosityModel,
    /// μ at `t_ref_c`, Pa·s.
    pub mu_ref: f64,
    /// °C.
    pub t_ref_c: f64,
}

impl ViscosityLaw {
    /// The law of `config`'s lubricant.
    pub fn of(config: &Config) -> Self {
        Self {
            model: config.viscosity_model(),
            mu_ref: config.lubricant.viscosity_pa_s,
            t_ref_c: config.lubricant.reference_temperature_c,
        }
    }

    /// Whether the viscosity changes with the temperature at all.
    pub fn follows_temperature(&self) -> bool {
        self.model != ViscosityModel::Constant
    }

    /// μ at `t_c` °C (μ_ref with a constant viscosity), or why `t_c` is
    /// not accepted (see the module documentation).
    pub fn viscosity_at(&self, t_c: f64) -> Result<f64, OutOfEnvelope> {
        let (lo, hi) = TEMPERATURE_RANGE_C;
        if !(t_c.is_finite() && (lo..=hi).contains(&t_c)) {
            return Err(OutOfEnvelope::TemperatureRange { value: t_c });
        }
        if let ViscosityModel::Vogel(v) = self.model {
            if t_c <= v.c_c {
                return Err(OutOfEnvelope::BelowVogelC {
                    value: t_c,
                    c_c: v.c_c,
                });
            }
        }
        let mu = self.model.viscosity(self.mu_ref, self.t_ref_c, t_c);
        let (mu_lo, mu_hi) = VISCOSITY_RANGE_PA_S;
        if mu.is_finite() && mu > mu_lo && mu <= mu_hi {
            Ok(mu)
        } else {
            Err(OutOfEnvelope::Viscosity {
                value: t_c,
                viscosity: mu,
            })
        }
    }

    /// Check every temperature between `lo` and `hi` °C (a signal's range):
    /// the ends suffice, μ(T) being monotone.
    pub fn check_span(&self, lo: f64, hi: f64) -> Result<(), OutOfEnvelope> {
        self.viscosity_at(lo)?;
        self.viscosity_at(hi)?;
        Ok(())
    }
}

/// Everything a single-contact configuration accepts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    /// Velocity and load limits.
    pub limits: InputLimits,
    /// The viscosity against temperature.
    pub viscosity: ViscosityLaw,
}

impl Envelope {
    /// The envelope of `config`.
    pub fn of(config: &Config) -> Self {
        Self {
            limits: InputLimits::of(config),
            viscosity: ViscosityLaw::of(config),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn vogel() -> Config {
        let mut c = Config::default();
        c.lubricant.viscosity_model = super::super::ViscosityModelKind::Vogel;
        c
    }

    #[test]
    fn a_vogel_law_refuses_temperatures_at_or_below_c_and_where_the_viscosity_leaves_the_models_range(
    ) {
        let law = ViscosityLaw::of(&vogel());
        let c = law.t_ref_c;
        assert_relative_eq!(
            law.viscosity_at(c).unwrap(),
            law.mu_ref,
            max_relative = 1e-12
        );
        // The cases: -99 (below C = -96), -96 (C itself), -96.5.
        for t in [-99.0, -96.0, -96.5] {
            assert!(
                matches!(
                    law.viscosity_at(t),
                    Err(OutOfEnvelope::TemperatureRange { .. })
                ),
                "{t}"
            );
        }
        let mut cfg = vogel();
        cfg.lubricant.vogel_c_c = -40.0;
        let law = ViscosityLaw::of(&cfg);
        assert!(matches!(
            law.viscosity_at(-40.0),
            Err(OutOfEnvelope::BelowVogelC { .. })
        ));
        // Just above C the viscosity is astronomically large: refused.
        let e = law.viscosity_at(-39.9).unwrap_err();
        assert!(matches!(e, OutOfEnvelope::Viscosity { .. }), "{e}");
        assert!(e.to_string().contains("outside the model's"), "{e}");
        for t in [300.1, f64::NAN, f64::INFINITY] {
            assert!(law.viscosity_at(t).is_err(), "{t}");
        }
        assert!(law.viscosity_at(150.0).is_ok());
        // So thin at 300 °C with this C that it leaves the range too.
        assert!(matches!(
            law.viscosity_at(300.0),
            Err(OutOfEnvelope::Viscosity { .. })
        ));
    }

    #[test]
    fn a_constant_viscosity_accepts_every_temperature_of_the_range_and_no_other() {
        let law = ViscosityLaw::of(&Config::default());
        assert!(!law.follows_temperature());
        assert_eq!(law.viscosity_at(-60.0).unwrap(), law.mu_ref);
        assert!(law.viscosity_at(-60.1).is_err());
        assert!(law.check_span(0.0, 300.0).is_ok());
        assert!(law.check_span(0.0, 300.5).is_err());
    }

    #[test]
    fn velocity_and_load_limits_name_the_value_and_the_keys() {
        let l = InputLimits::of(&Config::default());
        assert!(l.check_velocity(10.0).is_ok());
        let e = l.check_velocity(50.0).unwrap_err().to_string();
        assert!(
            e.contains("50 m/s") && e.contains("node.max_abs_velocity_m_s = 10"),
            "{e}"
        );
        assert!(l.check_velocity(f64::NAN).is_err());
        let e = l.check_load(0.5).unwrap_err().to_string();
        assert!(e.contains("0.5 N") && e.contains("node.min_load_n"), "{e}");
    }
}
