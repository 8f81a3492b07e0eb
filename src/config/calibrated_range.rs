//! `calibrated_range` (top level for the one contact, or
//! `contacts.NAME.calibrated_range`): where a fitted file was calibrated.
//!
//! `fit` writes it beside the parameters: the speeds the training data
//! held in each direction, the loads and temperatures where they were
//! inputs, a time series' largest acceleration, and the training error
//! with the number of samples behind it. Outside it the parameters are an
//! extrapolation, not evidence. A configuration without it (hand-written)
//! is not watched. Every value is in the contact's units (a joint's: its
//! speed × `gain`, its torque ÷ `gain`), as every other key of a contact.
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
//! ```

use super::ConfigError;
use crate::text::Num;
use serde::{Deserialize, Serialize};

/// Where a fitted configuration was calibrated (contact units).
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
    /// The training RMS error, N.
    pub training_rms_n: f64,
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
        /// The value, in the contact's units.
        value: f64,
        /// The range it left.
        lo: f64,
        /// See `lo`.
        hi: f64,
    },
}

impl CalibratedRange {
    /// The ranges as (name, key stem, lo, hi), each given pair.
    fn pairs(&self) -> [(&'static str, &'static str, Option<f64>, Option<f64>); 4] {
        [
            (
                "speed forward",
                "speed_forward",
                self.speed_forward_min_m_s,
                self.speed_forward_max_m_s,
            ),
            (
                "speed backward",
                "speed_backward",
                self.speed_backward_min_m_s,
                self.speed_backward_max_m_s,
            ),
            ("load", "load", self.load_min_n, self.load_max_n),
            (
                "temperature",
                "temperature",
                self.temperature_min_c,
                self.temperature_max_c,
            ),
        ]
    }

    /// Each range given as a pair, finite and not inverted, speeds and
    /// loads not negative, at least one speed range; the training error
    /// finite and not negative, at least one sample. Errors name the key,
    /// below `prefix` (`calibrated_range` or
    /// `contacts.NAME.calibrated_range`).
    pub fn validate(&self, prefix: &str) -> Result<(), ConfigError> {
        let suffix = |stem: &str, end: &str| match stem {
            "load" => format!("{prefix}.load_{end}_n"),
            "temperature" => format!("{prefix}.temperature_{end}_c"),
            _ => format!("{prefix}.{stem}_{end}_m_s"),
        };
        let bad = |key: String, value: String, range: &str| ConfigError::OutOfRange {
            key,
            value,
            range: range.into(),
        };
        for (_, stem, lo, hi) in self.pairs() {
            match (lo, hi) {
                (None, None) => {}
                (Some(_), None) => {
                    return Err(bad(
                        suffix(stem, "max"),
                        "missing".into(),
                        "given with its min (a range is a pair)",
                    ))
                }
                (None, Some(_)) => {
                    return Err(bad(
                        suffix(stem, "min"),
                        "missing".into(),
                        "given with its max (a range is a pair)",
                    ))
                }
                (Some(lo), Some(hi)) => {
                    for (end, v) in [("min", lo), ("max", hi)] {
                        let negative = stem != "temperature" && v < 0.0;
                        if !v.is_finite() || negative {
                            return Err(bad(
                                suffix(stem, end),
                                Num(v).to_string(),
                                "a finite number, not negative",
                            ));
                        }
                    }
                    if lo > hi {
                        return Err(bad(
                            suffix(stem, "min"),
                            Num(lo).to_string(),
                            &format!("at most its max {} (the range is inverted)", Num(hi)),
                        ));
                    }
                }
            }
        }
        if self.speed_forward_max_m_s.is_none() && self.speed_backward_max_m_s.is_none() {
            return Err(bad(
                format!("{prefix}.speed_forward_max_m_s"),
                "missing".into(),
                "a speed range in at least one direction",
            ));
        }
        if let Some(a) = self.acceleration_max_m_s2 {
            if !(a.is_finite() && a >= 0.0) {
                return Err(bad(
                    format!("{prefix}.acceleration_max_m_s2"),
                    Num(a).to_string(),
                    "a finite number, not negative",
                ));
            }
        }
        if !(self.training_rms_n.is_finite() && self.training_rms_n >= 0.0) {
            return Err(bad(
                format!("{prefix}.training_rms_n"),
                Num(self.training_rms_n).to_string(),
                "a finite number, not negative",
            ));
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

    /// Where velocity `v` (m/s), load (N) and temperature (°C) lie: the
    /// first input outside its range, or inside. A speed is judged in its
    /// direction's range; a direction the training data never moved in is
    /// outside from any speed above zero. Allocates nothing.
    pub fn side(&self, v: f64, load_n: Option<f64>, temperature_c: Option<f64>) -> RangeSide {
        let [fwd, bwd, load, temp] = self.pairs();
        let (name, lo, hi) = if v > 0.0 {
            (fwd.0, fwd.2, fwd.3)
        } else {
            (bwd.0, bwd.2, bwd.3)
        };
        let speed = v.abs();
        if speed > 0.0 {
            match (lo, hi) {
                (Some(lo), Some(hi)) if speed < lo || speed > hi => {
                    return RangeSide::Outside {
                        input: name,
                        value: speed,
                        lo,
                        hi,
                    }
                }
                (None, _) | (_, None) => {
                    return RangeSide::Outside {
                        input: name,
                        value: speed,
                        lo: 0.0,
                        hi: 0.0,
                    }
                }
                _ => {}
            }
        }
        for ((input, _, lo, hi), value) in [(load, load_n), (temp, temperature_c)] {
            if let (Some(lo), Some(hi), Some(x)) = (lo, hi, value) {
                if x < lo || x > hi {
                    return RangeSide::Outside {
                        input,
                        value: x,
                        lo,
                        hi,
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
            training_rms_n: 1.5,
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
        let e = |r: CalibratedRange| r.validate("calibrated_range").unwrap_err().to_string();
        assert!(range().validate("calibrated_range").is_ok());
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
            training_rms_n: 1.0,
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
}
