//! ROS 2 wire types: serde structs in the `.msg` field order (CDR needs
//! exactly that). `msg/msg/*.msg` is the source of truth for the project's
//! own types; a test checks these structs against it.

use serde::{Deserialize, Serialize};

/// `builtin_interfaces/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: i32,
    /// Nanoseconds within the second.
    pub nanosec: u32,
}

impl Time {
    /// The latest time `builtin_interfaces/Time` can hold (`sec` is int32 in
    /// ROS 2: 2038-01-19T03:14:07.999999999Z), ns.
    pub const MAX_NS: u64 = i32::MAX as u64 * 1_000_000_000 + 999_999_999;

    /// From ns since the epoch. Saturates at [`Time::MAX_NS`] instead of
    /// wrapping; [`Time::fits`] tells whether it had to.
    pub fn from_ns(ns: u64) -> Self {
        let ns = ns.min(Self::MAX_NS);
        Self {
            sec: i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX),
            nanosec: u32::try_from(ns % 1_000_000_000).unwrap_or(999_999_999),
        }
    }

    /// Whether `ns` is representable (no saturation in [`Time::from_ns`]).
    pub fn fits(ns: u64) -> bool {
        ns <= Self::MAX_NS
    }

    /// Nanoseconds (negative times map to 0).
    pub fn to_ns(self) -> u64 {
        if self.sec < 0 {
            return 0;
        }
        self.sec as u64 * 1_000_000_000 + u64::from(self.nanosec.min(999_999_999))
    }
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Header {
    /// When the data was valid.
    pub stamp: Time,
    /// The frame it refers to.
    pub frame_id: String,
}

/// `std_msgs/Float64`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Float64 {
    /// The value.
    pub data: f64,
}

/// `geometry_msgs/Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vector3 {
    /// X component.
    pub x: f64,
    /// Y component.
    pub y: f64,
    /// Z component.
    pub z: f64,
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity (m/s; the slider's is `x`).
    pub linear: Vector3,
    /// Angular velocity, rad/s.
    pub angular: Vector3,
}

/// `geometry_msgs/TwistStamped`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TwistStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The velocity.
    pub twist: Twist,
}

/// `sensor_msgs/JointState`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointState {
    /// Stamp and frame.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions, one per name (may be empty).
    pub position: Vec<f64>,
    /// Velocities, one per name (m/s or rad/s).
    pub velocity: Vec<f64>,
    /// Efforts, one per name (N or N·m).
    pub effort: Vec<f64>,
}

/// `std_msgs/MultiArrayDimension`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiArrayDimension {
    /// The dimension's name.
    pub label: String,
    /// Its length.
    pub size: u32,
    /// Elements per step along it.
    pub stride: u32,
}

/// `std_msgs/MultiArrayLayout`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiArrayLayout {
    /// The dimensions.
    pub dim: Vec<MultiArrayDimension>,
    /// Elements before the first.
    pub data_offset: u32,
}

/// `std_msgs/Float64MultiArray`: the joint efforts, one per configured
/// joint in order (one dimension labelled `joints`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Float64MultiArray {
    /// The layout.
    pub layout: MultiArrayLayout,
    /// The values.
    pub data: Vec<f64>,
}

/// `std_msgs/Empty`. On the wire an empty structure carries one byte (as
/// rosidl generates it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Empty {
    /// Padding (ROS 2 gives empty messages one byte).
    pub structure_needs_at_least_one_member: u8,
}

/// `sensor_msgs/Temperature` (°C).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Temperature {
    /// Stamp and frame.
    pub header: Header,
    /// Temperature, °C.
    pub temperature: f64,
    /// Its variance (0: unknown).
    pub variance: f64,
}

/// Constants of `friction_msgs/FrictionEstimate`.
pub mod estimate_constants {
    /// Asperities carry >= 95 % of the load.
    pub const REGIME_BOUNDARY: u8 = 0;
    /// Film and asperities share the load.
    pub const REGIME_MIXED: u8 = 1;
    /// Asperities carry <= 5 % of the load.
    pub const REGIME_HYDRODYNAMIC: u8 = 2;
    /// The step converged.
    pub const STATUS_CONVERGED: u8 = 0;
    /// The solver hit its iteration bound; last iterate kept.
    pub const STATUS_MAX_ITERATIONS: u8 = 1;
    /// The solver produced a non-finite value; previous state kept.
    pub const STATUS_NON_FINITE: u8 = 2;
    /// The solver was handed a non-finite input; last good estimate reported.
    pub const STATUS_NON_FINITE_INPUT: u8 = 3;
    /// An input outside the physical envelope; last good estimate reported.
    pub const STATUS_INPUT_OUT_OF_RANGE: u8 = 6;
    /// A velocity command arrived for this step.
    pub const COMMAND_FRESH: u8 = 0;
    /// No new command since the previous step; the last one held.
    pub const COMMAND_HELD: u8 = 1;
    /// The last command is older than the timeout; held or ramped to zero.
    pub const COMMAND_TIMED_OUT: u8 = 2;
    /// A command since the previous step was rejected (non-finite, beyond limits, out of order).
    pub const COMMAND_REJECTED: u8 = 3;
    /// The contact's configuration has no calibrated_range (hand-written parameters).
    pub const RANGE_NOT_WATCHED: u8 = 0;
    /// The step's speed, load and temperature lie inside the range the contact was calibrated on.
    pub const RANGE_INSIDE: u8 = 1;
    /// An input lies outside it: the friction is as node.outside_envelope says (warn: the
    /// model's; hold: the model's at the nearest edge; zero: 0).
    pub const RANGE_OUTSIDE: u8 = 2;
    /// Status codes of bags written before `command_status` existed.
    pub const LEGACY_STATUS_COMMAND_TIMEOUT: u8 = 4;
    /// Status 5 in bags written before command_status existed: the command was rejected.
    pub const LEGACY_STATUS_COMMAND_REJECTED: u8 = 5;
}

/// `friction_msgs/FrictionEstimate`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrictionEstimate {
    /// Stamp: the step's deadline in wall time (timer mode) or the command's stamp (lockstep).
    pub header: Header,
    /// sliding velocity of the step
    pub velocity_m_s: f64,
    /// normal load of the step
    pub load_n: f64,
    /// lubricant temperature of the step (the reference temperature when none is measured)
    pub temperature_c: f64,
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
    /// REGIME_*
    pub regime: u8,
    /// STATUS_*: the solver's outcome
    pub status: u8,
    /// COMMAND_*: the command's state
    pub command_status: u8,
    /// RANGE_*: where the step's input lies against the calibrated range
    pub calibrated_range: u8,
    /// Newton iterations of the step
    pub iterations: u32,
    /// wall time of the model step
    pub compute_time_ns: u64,
    /// how long after its deadline the step started (timer mode; catch-up steps are late by design)
    pub late_ns: u64,
}

/// `friction_msgs/FrictionEstimate` as bags recorded it before
/// `command_status` existed (`legacy/FrictionEstimateV1.msg`): read by replay.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrictionEstimateV1 {
    /// Stamp: the step's deadline in wall time (timer mode) or the command's stamp (lockstep).
    pub header: Header,
    /// Sliding velocity of the step (m/s).
    pub velocity_m_s: f64,
    /// Normal load of the step (N).
    pub load_n: f64,
    /// Total friction: the contact plus the drivetrain terms, signed like the velocity (N).
    pub friction_force_n: f64,
    /// contact friction per unit load: rigid (|F_visc| + (mu_bl + mu_r asinh(|v|/v_a)) F_asp) / F_ext; with pre-sliding |F_c| / F_ext; drivetrain terms excluded
    pub cof: f64,
    /// Minimum nominal separation (m).
    pub h0_m: f64,
    /// Minimum film thickness (m).
    pub h_min_m: f64,
    /// B * integral of (p - p_amb), N.
    pub hydrodynamic_force_n: f64,
    /// Greenwood-Williamson contact force (N).
    pub asperity_force_n: f64,
    /// asperity_force_n / load_n.
    pub asperity_load_share: f64,
    /// REGIME_*.
    pub regime: u8,
    /// STATUS_*: the solver's outcome.
    pub status: u8,
    /// Newton iterations of the step.
    pub iterations: u32,
    /// Wall time of the model step (ns).
    pub compute_time_ns: u64,
}

/// `friction_msgs/FilmProfile`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FilmProfile {
    /// Stamp: the step's deadline in wall time (timer mode) or the command's stamp (lockstep).
    pub header: Header,
    /// Cell width; cell i is centred at x = (i + 0.5) * dx_m.
    pub dx_m: f64,
    /// Film thickness at the cell centres (m).
    pub h_m: Vec<f64>,
    /// Absolute fluid pressure at the cell centres (Pa).
    pub p_pa: Vec<f64>,
}

/// `friction_msgs/LoopStatistics`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LoopStatistics {
    /// Stamp: the step's deadline in wall time (timer mode) or the command's stamp (lockstep).
    pub header: Header,
    /// model steps taken
    pub steps: u64,
    /// steps that finished after the next deadline (timer mode)
    pub deadline_misses: u64,
    /// steps taken late, after their deadline had passed, to keep model time = wall time
    pub catch_up_steps: u64,
    /// lost time beyond node.max_catch_up_s, advanced in one variable-length step
    pub time_jumps: u64,
    /// steps of the wall clock (NTP) seen; stamps stay monotonic
    pub clock_jumps: u64,
    /// commands the transports delivered
    pub commands_received: u64,
    /// accepted as the current set point
    pub commands_applied: u64,
    /// discarded by a full receive queue before the loop saw them
    pub commands_overwritten: u64,
    /// non-finite, beyond limits, or out-of-order stamps (lockstep)
    pub commands_rejected: u64,
    /// steps taken with a timed-out command
    pub command_timeouts: u64,
    /// outputs the loop could not hand to a transport (queue full)
    pub publish_drops: u64,
    /// outputs a transport's I/O failed to send
    pub publish_failures: u64,
    /// LoopStatistics that could not be handed over or sent
    pub statistics_not_sent: u64,
    /// outputs dropped because the recorder queue was full
    pub recorder_drops: u64,
    /// recording files started (split recordings: one per split)
    pub recording_files: u64,
    /// split files deleted to keep to recording.budget_bytes
    pub recording_files_deleted: u64,
    /// messages not recorded because writing had failed (a full disk)
    pub recording_lost: u64,
    /// snapshot files written
    pub snapshots: u64,
    /// the latest snapshot file ("" before the first)
    pub last_snapshot: String,
    /// the time span it holds
    pub last_snapshot_span_s: f64,
    /// model step wall time
    pub compute_time_p50_ns: u64,
    /// Model step wall time, p99 (ns).
    pub compute_time_p99_ns: u64,
    /// Model step wall time, max (ns).
    pub compute_time_max_ns: u64,
    /// lateness of the step start against its deadline (timer mode)
    pub period_jitter_p50_ns: u64,
    /// Lateness of the step start, p99 (ns).
    pub period_jitter_p99_ns: u64,
    /// Lateness of the step start, max (ns).
    pub period_jitter_max_ns: u64,
    /// steps whose solver status was not converged (iteration bound, non-finite, rejected input)
    pub steps_not_converged: u64,
    /// parameter changes applied while running (ros2 param set)
    pub parameter_updates: u64,
    /// contacts the loop steps (1 without `contacts`)
    pub contacts: u32,
    /// index (configured order) of the contact whose step took longest since the previous LoopStatistics
    pub slowest_contact: u32,
    /// that contact's longest step compute time since the previous LoopStatistics
    pub slowest_contact_compute_ns: u64,
    /// contact steps whose input lay outside the contact's calibrated range (FrictionEstimate RANGE_OUTSIDE)
    pub steps_outside_calibrated_range: u64,
    /// the latest input outside a calibrated range since the previous LoopStatistics: speed forward, speed backward, load or temperature ("" none)
    pub outside_input: String,
    /// its contact (configured order)
    pub outside_contact: u32,
    /// its value, in its range's units (a joint's speed: the joint's)
    pub outside_value: f64,
    /// the calibrated range it left
    pub outside_min: f64,
    /// See `outside_min`.
    pub outside_max: f64,
    /// their unit: m/s, rad/s (a rotary joint's speed: the joint's), N or °C
    pub outside_unit: String,
}

#[cfg(feature = "ros2")]
mod ros2_impls {
    use super::*;
    impl ros2_client::Message for Time {}
    impl ros2_client::Message for Header {}
    impl ros2_client::Message for Float64 {}
    impl ros2_client::Message for TwistStamped {}
    impl ros2_client::Message for JointState {}
    impl ros2_client::Message for Float64MultiArray {}
    impl ros2_client::Message for Temperature {}
    impl ros2_client::Message for Empty {}
    impl ros2_client::Message for FrictionEstimate {}
    impl ros2_client::Message for FilmProfile {}
    impl ros2_client::Message for LoopStatistics {}
}
