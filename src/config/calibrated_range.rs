//! `calibrated_range` (top level for the one contact, or
//! `contacts.NAME.calibrated_range`): where a fitted file was calibrated.
//!
//! `fit` writes it beside the parameters: the speeds the training data
//! held in each direction, the loads and temperatures where they were
//! inputs, a time series' largest acceleration, and the training error
//! with the number of samples behind it. Outside it the parameters are an
//! extrapolation, not evidence. A configuration without it (hand-written)
//! is not watched.
//!
//! The range is in the units of what the node receives for the contact:
//! the one contact's velocity command (m/s, N); under `contacts.NAME`, its
//! joint's `JointState` velocity and effort — `*_rad_s` keys and
//! `training_rms_n_m` for a rotary joint, `*_m_s` and `training_rms_n` for
//! a linear axis (the contact slides at `gain` × the joint's speed). The
//! load is the contact's load command in N, the temperature the sump's.
//!
//! ```yaml
//! calibrated_range:
//!   speed_forward_min_m_s: 0.0     # |v| of the samples moving forward: smallest …
//!   speed_forward_max_m_s: 0.05    # … and largest
//!   speed_backward_min_m_s: 0.0    # the same backward (magnitudes)
//!   speed_backward_max_m_s: 0.05
//!   load_min_n: 500.0              # only where the load was an input
//!   load_max_n: 2000.0
//!   training_rms_n: 1.2            # the training error, N
//!   training_samples: 25000
//! contacts:
//!   elbow:
//!     joint: elbow
//!     gain: 0.02
//!     calibrated_range:            # a rotary joint's: rad/s, N·m
//!       speed_forward_min_rad_s: 0.0
//!       speed_forward_max_rad_s: 0.35
//!       training_rms_n_m: 0.05
//!       training_samples: 4000
//! ```

use super::ConfigError;
use crate::text::Num;
use serde::{Deserialize, Serialize};

/// Where a fitted configuration was calibrated (the units of the
/// contact's input: see the module's doc).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibratedRange {
    /// Smallest |v| of the training samples moving forward (v > 0), m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_forward_min_m_s: Option<f64>,
    /// Largest |v| of the training samples moving forward, m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_forward_max_m_s: Option<f64>,
    /// Smallest |v| of the training samples moving backward (v < 0), m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_backward_min_m_s: Option<f64>,
    /// Largest |v| of the training samples moving backward, m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_backward_max_m_s: Option<f64>,
    /// A rotary joint's: smallest |ω| moving forward, rad/s (instead of
    /// the m/s keys).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_forward_min_rad_s: Option<f64>,
    /// A rotary joint's: largest |ω| moving forward, rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_forward_max_rad_s: Option<f64>,
    /// A rotary joint's: smallest |ω| moving backward, rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_backward_min_rad_s: Option<f64>,
    /// A rotary joint's: largest |ω| moving backward, rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_backward_max_rad_s: Option<f64>,
    /// Smallest training load, N (where the load was an input).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_min_n: Option<f64>,
    /// Largest training load, N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load_max_n: Option<f64>,
    /// Lowest training temperature, °C (where it was an input).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_min_c: Option<f64>,
    /// Highest training temperature, °C.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub temperature_max_c: Option<f64>,
    /// A time series' largest |dv/dt| between samples, m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceleration_max_m_s2: Option<f64>,
    /// A rotary joint's time series: largest |dω/dt|, rad/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acceleration_max_rad_s2: Option<f64>,
    /// The training RMS error, N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub training_rms_n: Option<f64>,
    /// A rotary joint's training RMS error, N·m (instead of `training_rms_n`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub training_rms_n_m: Option<f64>,
    /// The number of training samples behind it.
    pub training_samples: u64,
}

/// Where an input lies against a calibrated range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RangeSide {
    /// Inside every range given.
    Inside,
    /// Outside: the input's name, its value and the range it left.
    Outside {
        /// `speed forward`, `speed backward`, `load`, `temperature`.
        input: &'static str,
        /// The value, in the range's units.
        value: f64,
        /// The range it left.
        lo: f64,
        /// See `lo`.
        hi: f64,
        /// `m/s`, `rad/s`, `N` or `°C`.
        unit: &'static str,
    },
}

/// One range of a [`CalibratedRange`]: (name, key stem, key unit suffix,
/// unit, lo, hi).
type Pair = (
    &'static str,
    &'static str,
    &'static str,
    &'static str,
    Option<f64>,
    Option<f64>,
);

/// One range of a [`CalibratedRange`]: both ends or neither, finite, not
/// negative (but a temperature), not inverted; errors name the key
/// `prefix.stem_{min,max}_suffix`.
fn check_pair(
    prefix: &str,
    stem: &str,
    suffix: &str,
    lo: Option<f64>,
    hi: Option<f64>,
) -> Result<(), ConfigError> {
    let key = |end: &str| format!("{prefix}.{stem}_{end}_{suffix}");
    let bad = |key: String, value: String, range: &str| ConfigError::OutOfRange {
        key,
        value,
        range: range.into(),
    };
    match (lo, hi) {
        (None, None) => Ok(()),
        (Some(_), None) => Err(bad(
            key("max"),
            "missing".into(),
            "given with its min (a range is a pair)",
        )),
        (None, Some(_)) => Err(bad(
            key("min"),
            "missing".into(),
            "given with its max (a range is a pair)",
        )),
        (Some(lo), Some(hi)) => {
            for (end, v) in [("min", lo), ("max", hi)] {
                let negative = stem != "temperature" && v < 0.0;
                if !v.is_finite() || negative {
                    return Err(bad(
                        key(end),
                        Num(v).to_string(),
                        "a finite number, not negative",
                    ));
                }
            }
            if lo > hi {
                return Err(bad(
                    key("min"),
                    Num(lo).to_string(),
                    &format!("at most its max {} (the range is inverted)", Num(hi)),
                ));
            }
            Ok(())
        }
    }
}

impl CalibratedRange {
    /// Whether the speeds are a rotary joint's (rad/s keys given).
    pub fn is_rotary(&self) -> bool {
        [
            self.speed_forward_min_rad_s,
            self.speed_forward_max_rad_s,
            self.speed_backward_min_rad_s,
            self.speed_backward_max_rad_s,
            self.acceleration_max_rad_s2,
            self.training_rms_n_m,
        ]
        .iter()
        .any(Option::is_some)
    }

    /// The speeds' unit: `rad/s` or `m/s`.
    pub fn speed_unit(&self) -> &'static str {
        if self.is_rotary() {
            "rad/s"
        } else {
            "m/s"
        }
    }

    /// The training error's unit: `N·m` or `N`.
    pub fn force_unit(&self) -> &'static str {
        if self.is_rotary() {
            "N·m"
        } else {
            "N"
        }
    }

    /// The speed range in one direction, in [`Self::speed_unit`].
    pub fn speeds(&self, forward: bool) -> (Option<f64>, Option<f64>) {
        match (self.is_rotary(), forward) {
            (false, true) => (self.speed_forward_min_m_s, self.speed_forward_max_m_s),
            (false, false) => (self.speed_backward_min_m_s, self.speed_backward_max_m_s),
            (true, true) => (self.speed_forward_min_rad_s, self.speed_forward_max_rad_s),
            (true, false) => (self.speed_backward_min_rad_s, self.speed_backward_max_rad_s),
        }
    }

    /// The largest acceleration, in [`Self::speed_unit`] per second.
    pub fn acceleration_max(&self) -> Option<f64> {
        self.acceleration_max_rad_s2.or(self.acceleration_max_m_s2)
    }

    /// The training RMS error, in [`Self::force_unit`].
    pub fn training_rms(&self) -> Option<f64> {
        self.training_rms_n_m.or(self.training_rms_n)
    }

    /// A joint's range in its contact's own units: the contact slides at
    /// `gain` × the joint's speed and pushes the joint with `gain` × its
    /// friction, so speeds and accelerations × `gain` (m/s), the training
    /// error ÷ `gain` (N); loads and temperatures as they are. (The one
    /// contact's range, gain 1, is unchanged.)
    pub fn in_contact_units(&self, gain: f64) -> CalibratedRange {
        let g = |x: Option<f64>| x.map(|v| gain * v);
        let (f, b) = (self.speeds(true), self.speeds(false));
        CalibratedRange {
            speed_forward_min_m_s: g(f.0),
            speed_forward_max_m_s: g(f.1),
            speed_backward_min_m_s: g(b.0),
            speed_backward_max_m_s: g(b.1),
            speed_forward_min_rad_s: None,
            speed_forward_max_rad_s: None,
            speed_backward_min_rad_s: None,
            speed_backward_max_rad_s: None,
            acceleration_max_m_s2: g(self.acceleration_max()),
            acceleration_max_rad_s2: None,
            training_rms_n: self.training_rms().map(|e| e / gain),
            training_rms_n_m: None,
            ..self.clone()
        }
    }

    /// The ranges as [`Pair`]s, the speeds in their unit.
    fn pairs(&self) -> [Pair; 4] {
        let (suffix, unit) = if self.is_rotary() {
            ("rad_s", "rad/s")
        } else {
            ("m_s", "m/s")
        };
        let (f, b) = (self.speeds(true), self.speeds(false));
        [
            ("speed forward", "speed_forward", suffix, unit, f.0, f.1),
            ("speed backward", "speed_backward", suffix, unit, b.0, b.1),
            ("load", "load", "n", "N", self.load_min_n, self.load_max_n),
            (
                "temperature",
                "temperature",
                "c",
                "°C",
                self.temperature_min_c,
                self.temperature_max_c,
            ),
        ]
    }

    /// A rotary key given with an m/s one (a range is in one unit), or
    /// outside a joint's range (`joint` false: the one contact's range is in
    /// m/s): the offending key.
    fn unit_error(&self, prefix: &str, joint: bool) -> Option<ConfigError> {
        let linear = [
            ("speed_forward_min_m_s", self.speed_forward_min_m_s),
            ("speed_forward_max_m_s", self.speed_forward_max_m_s),
            ("speed_backward_min_m_s", self.speed_backward_min_m_s),
            ("speed_backward_max_m_s", self.speed_backward_max_m_s),
            ("acceleration_max_m_s2", self.acceleration_max_m_s2),
            ("training_rms_n", self.training_rms_n),
        ];
        let rotary = [
            ("speed_forward_min_rad_s", self.speed_forward_min_rad_s),
            ("speed_forward_max_rad_s", self.speed_forward_max_rad_s),
            ("speed_backward_min_rad_s", self.speed_backward_min_rad_s),
            ("speed_backward_max_rad_s", self.speed_backward_max_rad_s),
            ("acceleration_max_rad_s2", self.acceleration_max_rad_s2),
            ("training_rms_n_m", self.training_rms_n_m),
        ];
        let given = |keys: &[(&'static str, Option<f64>)]| {
            keys.iter()
                .find(|(_, v)| v.is_some())
                .map(|(k, v)| (*k, v.unwrap_or_default()))
        };
        let (Some((key, value)), l) = (given(&rotary), given(&linear)) else {
            return None;
        };
        let range = if !joint {
            "only in a joint's range (contacts.NAME.calibrated_range): the one contact's range is in m/s and N".to_string()
        } else if let Some((other, _)) = l {
            format!("not with `{other}`: a range is in one unit, rad/s and N·m for a rotary joint, m/s and N for a linear one")
        } else {
            return None;
        };
        Some(ConfigError::OutOfRange {
            key: format!("{prefix}.{key}"),
            value: Num(value).to_string(),
            range,
        })
    }

    /// Each range given as a pair, finite and not inverted, speeds and
    /// loads not negative, at least one speed range, in one unit (rad/s
    /// only in a joint's range, `joint`); the training error finite and not
    /// negative, at least one sample. Errors name the key, below `prefix`
    /// (`calibrated_range` or `contacts.NAME.calibrated_range`).
    pub fn validate(&self, prefix: &str, joint: bool) -> Result<(), ConfigError> {
        if let Some(e) = self.unit_error(prefix, joint) {
            return Err(e);
        }
        let bad = |key: String, value: String, range: &str| ConfigError::OutOfRange {
            key,
            value,
            range: range.into(),
        };
        for (_, stem, suffix, _, lo, hi) in self.pairs() {
            check_pair(prefix, stem, suffix, lo, hi)?;
        }
        let speed_suffix = if self.is_rotary() { "rad_s" } else { "m_s" };
        if self.speeds(true).1.is_none() && self.speeds(false).1.is_none() {
            return Err(bad(
                format!("{prefix}.speed_forward_max_{speed_suffix}"),
                "missing".into(),
                "a speed range in at least one direction",
            ));
        }
        let accel_key = if self.is_rotary() {
            "acceleration_max_rad_s2"
        } else {
            "acceleration_max_m_s2"
        };
        if let Some(a) = self.acceleration_max() {
            if !(a.is_finite() && a >= 0.0) {
                return Err(bad(
                    format!("{prefix}.{accel_key}"),
                    Num(a).to_string(),
                    "a finite number, not negative",
                ));
            }
        }
        let rms_key = if self.is_rotary() {
            "training_rms_n_m"
        } else {
            "training_rms_n"
        };
        match self.training_rms() {
            None => {
                return Err(bad(
                    format!("{prefix}.{rms_key}"),
                    "missing".into(),
                    "the training error (a range says how well it was fitted)",
                ))
            }
            Some(e) if !(e.is_finite() && e >= 0.0) => {
                return Err(bad(
                    format!("{prefix}.{rms_key}"),
                    Num(e).to_string(),
                    "a finite number, not negative",
                ))
            }
            Some(_) => {}
        }
        if self.training_samples == 0 {
            return Err(bad(
                format!("{prefix}.training_samples"),
                "0".into(),
                "at least 1",
            ));
        }
        Ok(())
    }

    /// Where velocity `v` (in [`Self::speed_unit`]), load (N) and
    /// temperature (°C) lie: the first input outside its range, or inside.
    /// A speed is judged in its direction's range; a direction the
    /// training data never moved in is outside from any speed above zero.
    /// Allocates nothing.
    pub fn side(&self, v: f64, load_n: Option<f64>, temperature_c: Option<f64>) -> RangeSide {
        let [fwd, bwd, load, temp] = self.pairs();
        let (name, _, _, unit, lo, hi) = if v > 0.0 { fwd } else { bwd };
        let speed = v.abs();
        if speed > 0.0 {
            match (lo, hi) {
                (Some(lo), Some(hi)) if speed < lo || speed > hi => {
                    return RangeSide::Outside {
                        input: name,
                        value: speed,
                        lo,
                        hi,
                        unit,
                    }
                }
                (None, _) | (_, None) => {
                    return RangeSide::Outside {
                        input: name,
                        value: speed,
                        lo: 0.0,
                        hi: 0.0,
                        unit,
                    }
                }
                _ => {}
            }
        }
        for ((input, _, _, unit, lo, hi), value) in [(load, load_n), (temp, temperature_c)] {
            if let (Some(lo), Some(hi), Some(x)) = (lo, hi, value) {
                if x < lo || x > hi {
                    return RangeSide::Outside {
                        input,
                        value: x,
                        lo,
                        hi,
                        unit,
                    };
                }
            }
        }
        RangeSide::Inside
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn range() -> CalibratedRange {
        CalibratedRange {
            speed_forward_min_m_s: Some(0.001),
            speed_forward_max_m_s: Some(0.05),
            speed_backward_min_m_s: Some(0.002),
            speed_backward_max_m_s: Some(0.04),
            load_min_n: Some(500.0),
            load_max_n: Some(2000.0),
            training_rms_n: Some(1.5),
            training_samples: 100,
            ..Default::default()
        }
    }

    #[test]
    fn each_direction_is_judged_in_its_own_speed_range_and_the_load_in_its_own() {
        let r = range();
        assert_eq!(r.side(0.03, Some(1000.0), None), RangeSide::Inside);
        assert_eq!(r.side(0.0, None, None), RangeSide::Inside);
        // 0.045 m/s: inside forward, outside backward.
        assert_eq!(r.side(0.045, None, None), RangeSide::Inside);
        assert!(matches!(
            r.side(-0.045, None, None),
            RangeSide::Outside { input: "speed backward", hi, .. } if hi == 0.04
        ));
        assert!(matches!(
            r.side(0.01, Some(3000.0), None),
            RangeSide::Outside { input: "load", value, .. } if value == 3000.0
        ));
        // A direction never trained is outside from any speed.
        let one_way = CalibratedRange {
            speed_backward_min_m_s: None,
            speed_backward_max_m_s: None,
            ..range()
        };
        assert!(matches!(
            one_way.side(-0.01, None, None),
            RangeSide::Outside {
                input: "speed backward",
                ..
            }
        ));
    }

    #[test]
    fn an_empty_inverted_or_non_finite_range_is_an_error_naming_its_key() {
        let e = |r: CalibratedRange| {
            r.validate("calibrated_range", false)
                .unwrap_err()
                .to_string()
        };
        assert!(range().validate("calibrated_range", false).is_ok());
        let inverted = CalibratedRange {
            load_min_n: Some(3000.0),
            ..range()
        };
        assert!(e(inverted).contains("calibrated_range.load_min_n"));
        let nan = CalibratedRange {
            speed_forward_max_m_s: Some(f64::NAN),
            ..range()
        };
        assert!(e(nan).contains("calibrated_range.speed_forward_max_m_s"));
        let half = CalibratedRange {
            temperature_min_c: Some(20.0),
            ..range()
        };
        assert!(e(half).contains("calibrated_range.temperature_max_c"));
        let empty = CalibratedRange {
            training_rms_n: Some(1.0),
            training_samples: 10,
            ..Default::default()
        };
        assert!(e(empty).contains("speed_forward_max_m_s"));
        let none = CalibratedRange {
            training_samples: 0,
            ..range()
        };
        assert!(e(none).contains("calibrated_range.training_samples"));
    }

    #[test]
    fn a_rotary_joints_range_is_in_rad_s_and_only_a_joint_may_have_one() {
        let rotary = CalibratedRange {
            speed_forward_min_rad_s: Some(0.0),
            speed_forward_max_rad_s: Some(0.35),
            training_rms_n_m: Some(0.05),
            training_samples: 10,
            ..Default::default()
        };
        assert!(rotary
            .validate("contacts.elbow.calibrated_range", true)
            .is_ok());
        assert_eq!((rotary.speed_unit(), rotary.force_unit()), ("rad/s", "N·m"));
        assert!(matches!(
            rotary.side(1.57, None, None),
            RangeSide::Outside { input: "speed forward", hi, unit: "rad/s", .. } if hi == 0.35
        ));
        let e = rotary
            .validate("calibrated_range", false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("calibrated_range.speed_forward_min_rad_s"),
            "{e}"
        );
        assert!(e.contains("only in a joint's range"), "{e}");
        let mixed = CalibratedRange {
            speed_backward_min_m_s: Some(0.0),
            speed_backward_max_m_s: Some(0.1),
            ..rotary.clone()
        };
        let e = mixed
            .validate("contacts.elbow.calibrated_range", true)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("speed_backward_min_m_s") && e.contains("one unit"),
            "{e}"
        );
        let no_error = CalibratedRange {
            training_rms_n_m: None,
            speed_forward_max_rad_s: Some(0.35),
            ..rotary
        };
        let e = no_error
            .validate("contacts.elbow.calibrated_range", true)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("contacts.elbow.calibrated_range.training_rms_n_m"),
            "{e}"
        );
    }
}
