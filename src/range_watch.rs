//! The calibrated-range watch: where each step's input lies against the
//! range a contact was calibrated on (its `calibrated_range`), and what the
//! step publishes while it lies outside (`node.outside_envelope`).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | v | the contact's sliding velocity | m/s |
//! | g | the contact's gain (`contacts.NAME.gain`; 1 for the one contact) | m/rad or – |
//! | u = v / g | the input the range is in: the one contact's velocity command, a joint's velocity | m/s or rad/s |
//! | F_ext | the commanded load | N |
//! | T | the lubricant temperature | °C |
//! | [s_lo, s_hi] | the speeds calibrated in u's direction | m/s or rad/s |
//! | [F_lo, F_hi], [T_lo, T_hi] | the loads and temperatures calibrated | N, °C |
//!
//! Outside is |u| ∉ [s_lo, s_hi] (u ≠ 0; a direction never calibrated is
//! outside from any speed), F_ext ∉ [F_lo, F_hi] or T ∉ [T_lo, T_hi],
//! each judged only where the range gives it. Under `hold` the model runs
//! at the nearest edge: v = g·sign(u)·clamp(|u|, s_lo, s_hi) (0 in a
//! direction never calibrated), clamp(F_ext, F_lo, F_hi), clamp(T, T_lo, T_hi).
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
        /// Its value, in the range's units.
        value: f64,
        /// The range it left.
        lo: f64,
        /// See `lo`.
        hi: f64,
        /// `m/s`, `rad/s`, `N` or `°C`.
        unit: &'static str,
    },
}

impl RangeFlag {
    /// Whether an input lay outside.
    pub fn is_outside(self) -> bool {
        matches!(self, RangeFlag::Outside { .. })
    }

    /// The wire code (`FrictionEstimate.RANGE_*`).
    pub fn code(self) -> u8 {
        use crate::msgs::estimate_constants as codes;
        match self {
            RangeFlag::NotWatched => codes::RANGE_NOT_WATCHED,
            RangeFlag::Inside => codes::RANGE_INSIDE,
            RangeFlag::Outside { .. } => codes::RANGE_OUTSIDE,
        }
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
    /// The contact's gain g: the range's speeds are the contact's ÷ g.
    gain: f64,
}

fn clamp(x: f64, lo: Option<f64>, hi: Option<f64>) -> f64 {
    match (lo, hi) {
        (Some(lo), Some(hi)) => x.clamp(lo, hi),
        _ => x,
    }
}

impl RangeWatch {
    /// A watch of `range` (None: not watched) under `policy`, for a
    /// contact of gain `gain` (1 for the one contact; a joint's contact
    /// slides at `gain` × the joint's speed, the speed its range is in).
    pub fn new(range: Option<CalibratedRange>, policy: OutsideEnvelope, gain: f64) -> Self {
        Self {
            range,
            policy,
            gain,
        }
    }

    /// The watch of resolved contact `c`: a joint's range in the joint's
    /// units through its gain, the one contact's in its own.
    pub fn of_contact(c: &crate::config::ResolvedContact, policy: OutsideEnvelope) -> Self {
        match &c.joint_range {
            Some(r) => Self::new(Some(r.clone()), policy, c.gain),
            None => Self::new(c.config.calibrated_range.clone(), policy, 1.0),
        }
    }

    /// What is published outside.
    pub fn policy(&self) -> OutsideEnvelope {
        self.policy
    }

    /// Change what is published outside (a live parameter change).
    pub fn set_policy(&mut self, policy: OutsideEnvelope) {
        self.policy = policy;
    }

    /// Judge the contact's velocity `v` (m/s), load (N) and temperature
    /// (°C): the input the model runs at and where it lay.
    pub fn watch(&self, v: f64, load_n: f64, temperature_c: f64) -> Watched {
        let Some(r) = &self.range else {
            return Watched {
                velocity_m_s: v,
                load_n,
                flag: RangeFlag::NotWatched,
            };
        };
        let u = v / self.gain;
        let flag = match r.side(u, Some(load_n), Some(temperature_c)) {
            RangeSide::Inside => RangeFlag::Inside,
            RangeSide::Outside {
                input,
                value,
                lo,
                hi,
                unit,
            } => RangeFlag::Outside {
                input,
                value,
                lo,
                hi,
                unit,
            },
        };
        if !(flag.is_outside() && self.policy == OutsideEnvelope::Hold) {
            return Watched {
                velocity_m_s: v,
                load_n,
                flag,
            };
        }
        let speed = match r.speeds(u > 0.0) {
            _ if u == 0.0 => 0.0,
            (Some(lo), Some(hi)) => u.abs().clamp(lo, hi),
            // A direction never calibrated: its nearest calibrated point is rest.
            _ => 0.0,
        };
        Watched {
            velocity_m_s: (self.gain * speed).copysign(v),
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
            training_rms_n: Some(1.0),
            training_samples: 10,
            ..Default::default()
        }
    }

    #[test]
    fn a_contact_without_a_range_is_not_watched_and_runs_at_its_input() {
        let w = RangeWatch::new(None, OutsideEnvelope::Hold, 1.0);
        let x = w.watch(5.0, 1e6, 200.0);
        assert_eq!(x.flag, RangeFlag::NotWatched);
        assert_eq!((x.velocity_m_s, x.load_n), (5.0, 1e6));
        assert_eq!(w.temperature_c(200.0), 200.0);
        assert_eq!(w.published(x.flag, 3.0), 3.0);
    }

    #[test]
    fn warn_runs_the_model_at_the_input_and_flags_the_input_that_left() {
        let w = RangeWatch::new(Some(range()), OutsideEnvelope::Warn, 1.0);
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
                hi: 0.1,
                unit: "m/s"
            }
        );
        assert_eq!(w.published(x.flag, 7.0), 7.0);
    }

    #[test]
    fn hold_runs_the_model_at_the_nearest_edge_of_each_range() {
        let w = RangeWatch::new(Some(range()), OutsideEnvelope::Hold, 1.0);
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
            1.0,
        );
        assert_eq!(one_way.watch(-0.05, 150.0, 30.0).velocity_m_s, 0.0);
        // Inside, hold changes nothing.
        let inside = w.watch(0.05, 150.0, 30.0);
        assert_eq!((inside.velocity_m_s, inside.load_n), (0.05, 150.0));
    }

    #[test]
    fn zero_publishes_no_friction_outside_and_the_model_inside() {
        let w = RangeWatch::new(Some(range()), OutsideEnvelope::Zero, 1.0);
        let x = w.watch(0.05, 500.0, 30.0);
        assert_eq!(x.load_n, 500.0, "zero runs the model at the input");
        assert_eq!(w.published(x.flag, 7.0), 0.0);
        let inside = w.watch(0.05, 150.0, 30.0);
        assert_eq!(w.published(inside.flag, 7.0), 7.0);
    }

    #[test]
    fn a_joints_range_is_judged_in_the_joints_speed_and_held_through_its_gain() {
        let rotary = CalibratedRange {
            speed_forward_min_rad_s: Some(0.0),
            speed_forward_max_rad_s: Some(0.35),
            speed_backward_min_rad_s: Some(0.0),
            speed_backward_max_rad_s: Some(0.35),
            training_rms_n_m: Some(0.05),
            training_samples: 10,
            ..Default::default()
        };
        // Gain 0.02 m/rad: the contact at 0.0314 m/s is the joint at 1.57 rad/s.
        let w = RangeWatch::new(Some(rotary), OutsideEnvelope::Hold, 0.02);
        let x = w.watch(0.0314, 100.0, 40.0);
        assert!(matches!(
            x.flag,
            RangeFlag::Outside { input: "speed forward", unit: "rad/s", value, hi, .. }
                if (value - 1.57).abs() < 1e-12 && hi == 0.35
        ));
        assert_relative_eq!(x.velocity_m_s, 0.02 * 0.35);
        assert_eq!(w.watch(0.005, 100.0, 40.0).flag, RangeFlag::Inside);
    }
}
