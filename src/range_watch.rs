//! The calibrated-range watch: where each step's input lies against the
//! range a contact was calibrated on (its `calibrated_range`), and what the
//! step publishes while it lies outside (`node.outside_envelope`).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | v | the commanded sliding velocity | m/s |
//! | F_ext | the commanded load | N |
//! | T | the lubricant temperature | °C |
//! | [s_lo, s_hi] | the speeds calibrated in v's direction | m/s |
//! | [F_lo, F_hi], [T_lo, T_hi] | the loads and temperatures calibrated | N, °C |
//!
//! Outside is |v| ∉ [s_lo, s_hi] (v ≠ 0; a direction never calibrated is
//! outside from any speed), F_ext ∉ [F_lo, F_hi] or T ∉ [T_lo, T_hi],
//! each judged only where the range gives it. Under `hold` the model runs
//! at the nearest edge: sign(v)·clamp(|v|, s_lo, s_hi) (0 in a direction
//! never calibrated), clamp(F_ext, F_lo, F_hi), clamp(T, T_lo, T_hi).
//! Under `zero` the model runs at the input, and the friction published is
//! 0. The acceleration a time series was calibrated at is reported by
//! `fit`, not watched here: a commanded velocity carries no measured
//! acceleration. Allocates nothing.

use crate::config::{CalibratedRange, OutsideEnvelope, RangeSide};

/// Where one step's input lay.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum RangeFlag {
    /// The contact has no calibrated range: nothing is judged.
    #[default]
    NotWatched,
    /// Every input inside its range.
    Inside,
    /// An input outside: which, its value and the range it left.
    Outside {
        /// `speed forward`, `speed backward`, `load`, `temperature`.
        input: &'static str,
        /// Its value (contact units).
        value: f64,
        /// The range it left.
        lo: f64,
        /// See `lo`.
        hi: f64,
    },
}

impl RangeFlag {
    /// Whether an input lay outside.
    pub fn is_outside(self) -> bool {
        matches!(self, RangeFlag::Outside { .. })
    }

    /// `not_watched`, `inside` or `outside` (Python, CSV).
    pub fn as_str(self) -> &'static str {
        match self {
            RangeFlag::NotWatched => "not_watched",
            RangeFlag::Inside => "inside",
            RangeFlag::Outside { .. } => "outside",
        }
    }
}

/// One step's input as the watch passes it to the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Watched {
    /// The velocity the model runs at, m/s (clamped under `hold`).
    pub velocity_m_s: f64,
    /// The load the model runs at, N (clamped under `hold`).
    pub load_n: f64,
    /// Where the input (before any clamp) lay.
    pub flag: RangeFlag,
}

/// One contact's watch.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeWatch {
    range: Option<CalibratedRange>,
    policy: OutsideEnvelope,
}

fn clamp(x: f64, lo: Option<f64>, hi: Option<f64>) -> f64 {
    match (lo, hi) {
        (Some(lo), Some(hi)) => x.clamp(lo, hi),
        _ => x,
    }
}

impl RangeWatch {
    /// A watch of `range` (None: not watched) under `policy`.
    pub fn new(range: Option<CalibratedRange>, policy: OutsideEnvelope) -> Self {
        Self { range, policy }
    }

    /// Whether the contact has a calibrated range.
    pub fn is_watched(&self) -> bool {
        self.range.is_some()
    }

    /// What is published outside.
    pub fn policy(&self) -> OutsideEnvelope {
        self.policy
    }

    /// Change what is published outside (a live parameter change).
    pub fn set_policy(&mut self, policy: OutsideEnvelope) {
        self.policy = policy;
    }

    /// Judge velocity `v` (m/s), load (N) and temperature (°C): the input
    /// the model runs at and where it lay.
    pub fn watch(&self, v: f64, load_n: f64, temperature_c: f64) -> Watched {
        let Some(r) = &self.range else {
            return Watched {
                velocity_m_s: v,
                load_n,
                flag: RangeFlag::NotWatched,
            };
        };
        let flag = match r.side(v, Some(load_n), Some(temperature_c)) {
            RangeSide::Inside => RangeFlag::Inside,
            RangeSide::Outside {
                input,
                value,
                lo,
                hi,
            } => RangeFlag::Outside {
                input,
                value,
                lo,
                hi,
            },
        };
        if !(flag.is_outside() && self.policy == OutsideEnvelope::Hold) {
            return Watched {
                velocity_m_s: v,
                load_n,
                flag,
            };
        }
        let (lo, hi) = if v > 0.0 {
            (r.speed_forward_min_m_s, r.speed_forward_max_m_s)
        } else {
            (r.speed_backward_min_m_s, r.speed_backward_max_m_s)
        };
        let speed = match (lo, hi) {
            _ if v == 0.0 => 0.0,
            (Some(lo), Some(hi)) => v.abs().clamp(lo, hi),
            // A direction never calibrated: its nearest calibrated point is rest.
            _ => 0.0,
        };
        Watched {
            velocity_m_s: speed.copysign(v),
            load_n: clamp(load_n, r.load_min_n, r.load_max_n),
            flag,
        }
    }

    /// The temperature the viscosity follows: clamped to the range under
    /// `hold`, else as given.
    pub fn temperature_c(&self, temperature_c: f64) -> f64 {
        match &self.range {
            Some(r) if self.policy == OutsideEnvelope::Hold => {
                clamp(temperature_c, r.temperature_min_c, r.temperature_max_c)
            }
            _ => temperature_c,
        }
    }

    /// The friction published for a step whose input lay at `flag`: 0
    /// outside under `zero`, else the model's `friction`.
    pub fn published(&self, flag: RangeFlag, friction: f64) -> f64 {
        if flag.is_outside() && self.policy == OutsideEnvelope::Zero {
            0.0
        } else {
            friction
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn range() -> CalibratedRange {
        CalibratedRange {
            speed_forward_min_m_s: Some(0.01),
            speed_forward_max_m_s: Some(0.1),
            speed_backward_min_m_s: Some(0.02),
            speed_backward_max_m_s: Some(0.08),
            load_min_n: Some(100.0),
            load_max_n: Some(200.0),
            temperature_min_c: Some(20.0),
            temperature_max_c: Some(40.0),
            training_rms_n: 1.0,
            training_samples: 10,
            ..Default::default()
        }
    }

    #[test]
    fn a_contact_without_a_range_is_not_watched_and_runs_at_its_input() {
        let w = RangeWatch::new(None, OutsideEnvelope::Hold);
        let x = w.watch(5.0, 1e6, 200.0);
        assert_eq!(x.flag, RangeFlag::NotWatched);
        assert_eq!((x.velocity_m_s, x.load_n), (5.0, 1e6));
        assert_eq!(w.temperature_c(200.0), 200.0);
        assert_eq!(w.published(x.flag, 3.0), 3.0);
    }

    #[test]
    fn warn_runs_the_model_at_the_input_and_flags_the_input_that_left() {
        let w = RangeWatch::new(Some(range()), OutsideEnvelope::Warn);
        let inside = w.watch(0.05, 150.0, 30.0);
        assert_eq!(inside.flag, RangeFlag::Inside);
        let x = w.watch(0.3, 150.0, 30.0);
        assert_eq!(x.velocity_m_s, 0.3);
        assert_eq!(
            x.flag,
            RangeFlag::Outside {
                input: "speed forward",
                value: 0.3,
                lo: 0.01,
                hi: 0.1
            }
        );
        assert_eq!(w.published(x.flag, 7.0), 7.0);
    }

    #[test]
    fn hold_runs_the_model_at_the_nearest_edge_of_each_range() {
        let w = RangeWatch::new(Some(range()), OutsideEnvelope::Hold);
        let fast_back = w.watch(-0.5, 150.0, 30.0);
        assert_relative_eq!(fast_back.velocity_m_s, -0.08);
        assert!(fast_back.flag.is_outside());
        let slow = w.watch(0.001, 50.0, 30.0);
        assert_relative_eq!(slow.velocity_m_s, 0.01);
        assert_relative_eq!(slow.load_n, 100.0);
        assert_relative_eq!(w.temperature_c(80.0), 40.0);
        // A direction never calibrated: the nearest calibrated point is rest.
        let one_way = RangeWatch::new(
            Some(CalibratedRange {
                speed_backward_min_m_s: None,
                speed_backward_max_m_s: None,
                ..range()
            }),
            OutsideEnvelope::Hold,
        );
        assert_eq!(one_way.watch(-0.05, 150.0, 30.0).velocity_m_s, 0.0);
        // Inside, hold changes nothing.
        let inside = w.watch(0.05, 150.0, 30.0);
        assert_eq!((inside.velocity_m_s, inside.load_n), (0.05, 150.0));
    }

    #[test]
    fn zero_publishes_no_friction_outside_and_the_model_inside() {
        let w = RangeWatch::new(Some(range()), OutsideEnvelope::Zero);
        let x = w.watch(0.05, 500.0, 30.0);
        assert_eq!(x.load_n, 500.0, "zero runs the model at the input");
        assert_eq!(w.published(x.flag, 7.0), 0.0);
        let inside = w.watch(0.05, 150.0, 30.0);
        assert_eq!(w.published(inside.flag, 7.0), 7.0);
    }
}
