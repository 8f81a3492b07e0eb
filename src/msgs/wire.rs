//! ROS 2 wire types: serde structs in the `.msg` field order (CDR needs
//! exactly that). `msg/msg/*.msg` is the source of truth for the project's
//! own types; a test checks these structs against it.

use serde::{Deserialize, Serialize};

/// `builtin_interfaces/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Time {
    pub sec: i32,
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
    pub stamp: Time,
    pub frame_id: String,
}

/// `std_msgs/Float64`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Float64 {
    pub data: f64,
}

/// `geometry_msgs/Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vector3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    pub linear: Vector3,
    pub angular: Vector3,
}

/// `geometry_msgs/TwistStamped`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TwistStamped {
    pub header: Header,
    pub twist: Twist,
}

/// `sensor_msgs/JointState`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct JointState {
    pub header: Header,
    pub name: Vec<String>,
    pub position: Vec<f64>,
    pub velocity: Vec<f64>,
    pub effort: Vec<f64>,
}

/// `std_msgs/MultiArrayDimension`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiArrayDimension {
    pub label: String,
    pub size: u32,
    pub stride: u32,
}

/// `std_msgs/MultiArrayLayout`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiArrayLayout {
    pub dim: Vec<MultiArrayDimension>,
    pub data_offset: u32,
}

/// `std_msgs/Float64MultiArray`: the joint efforts, one per configured
/// joint in order (one dimension labelled `joints`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Float64MultiArray {
    pub layout: MultiArrayLayout,
    pub data: Vec<f64>,
}

/// `std_msgs/Empty`. On the wire an empty structure carries one byte (as
/// rosidl generates it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Empty {
    pub structure_needs_at_least_one_member: u8,
}

/// `sensor_msgs/Temperature` (°C).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Temperature {
    pub header: Header,
    pub temperature: f64,
    pub variance: f64,
}

/// Constants of `friction_msgs/FrictionEstimate`.
pub mod estimate_constants {
    pub const REGIME_BOUNDARY: u8 = 0;
    pub const REGIME_MIXED: u8 = 1;
    pub const REGIME_HYDRODYNAMIC: u8 = 2;
    pub const STATUS_CONVERGED: u8 = 0;
    pub const STATUS_MAX_ITERATIONS: u8 = 1;
    pub const STATUS_NON_FINITE: u8 = 2;
    pub const STATUS_NON_FINITE_INPUT: u8 = 3;
    pub const STATUS_INPUT_OUT_OF_RANGE: u8 = 6;
    pub const COMMAND_FRESH: u8 = 0;
    pub const COMMAND_HELD: u8 = 1;
    pub const COMMAND_TIMED_OUT: u8 = 2;
    pub const COMMAND_REJECTED: u8 = 3;
    /// Status codes of bags written before `command_status` existed.
    pub const LEGACY_STATUS_COMMAND_TIMEOUT: u8 = 4;
    pub const LEGACY_STATUS_COMMAND_REJECTED: u8 = 5;
}

/// `friction_msgs/FrictionEstimate`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrictionEstimate {
    pub header: Header,
    pub velocity_m_s: f64,
    pub load_n: f64,
    pub temperature_c: f64,
    pub friction_force_n: f64,
    pub contact_friction_force_n: f64,
    pub cof: f64,
    pub h0_m: f64,
    pub h_min_m: f64,
    pub hydrodynamic_force_n: f64,
    pub asperity_force_n: f64,
    pub asperity_load_share: f64,
    pub regime: u8,
    pub status: u8,
    pub command_status: u8,
    pub iterations: u32,
    pub compute_time_ns: u64,
    pub late_ns: u64,
}

/// `friction_msgs/FrictionEstimate` as bags recorded it before
/// `command_status` existed (`legacy/FrictionEstimateV1.msg`): read by replay.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrictionEstimateV1 {
    pub header: Header,
    pub velocity_m_s: f64,
    pub load_n: f64,
    pub friction_force_n: f64,
    pub cof: f64,
    pub h0_m: f64,
    pub h_min_m: f64,
    pub hydrodynamic_force_n: f64,
    pub asperity_force_n: f64,
    pub asperity_load_share: f64,
    pub regime: u8,
    pub status: u8,
    pub iterations: u32,
    pub compute_time_ns: u64,
}

/// `friction_msgs/FilmProfile`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FilmProfile {
    pub header: Header,
    pub dx_m: f64,
    pub h_m: Vec<f64>,
    pub p_pa: Vec<f64>,
}

/// `friction_msgs/LoopStatistics`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LoopStatistics {
    pub header: Header,
    pub steps: u64,
    pub deadline_misses: u64,
    pub catch_up_steps: u64,
    pub time_jumps: u64,
    pub clock_jumps: u64,
    pub commands_received: u64,
    pub commands_applied: u64,
    pub commands_overwritten: u64,
    pub commands_rejected: u64,
    pub command_timeouts: u64,
    pub publish_drops: u64,
    pub publish_failures: u64,
    pub statistics_not_sent: u64,
    pub recorder_drops: u64,
    pub recording_files: u64,
    pub recording_files_deleted: u64,
    pub recording_lost: u64,
    pub snapshots: u64,
    pub last_snapshot: String,
    pub last_snapshot_span_s: f64,
    pub compute_time_p50_ns: u64,
    pub compute_time_p99_ns: u64,
    pub compute_time_max_ns: u64,
    pub period_jitter_p50_ns: u64,
    pub period_jitter_p99_ns: u64,
    pub period_jitter_max_ns: u64,
    pub steps_not_converged: u64,
    pub parameter_updates: u64,
    pub contacts: u32,
    pub slowest_contact: u32,
    pub slowest_contact_compute_ns: u64,
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
