//! The `#[repr(C)]` payloads of the iceoryx2 services and their
//! conversions to the loop's records. Type names are versioned: a peer
//! built with a different layout gets a clean error when its port opens.

use crate::msgs::{EstimateRecord, StatisticsRecord};
use iceoryx2::prelude::*;

/// A velocity or load command.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::Command_v2")]
pub struct CommandPayload {
    /// Sender's stamp, ns.
    pub stamp_ns: u64,
    /// m/s (velocity service) or N (load service).
    pub value: f64,
    /// 1, 2, 3, … per publisher: a gap is a sample lost to a full buffer.
    pub sequence: u64,
}

/// One estimate (the fields of `friction_msgs/FrictionEstimate`).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::FrictionEstimate_v3")]
pub struct EstimatePayload {
    /// The header's stamp, ns.
    pub stamp_ns: u64,
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
    /// wall time of the model step
    pub compute_time_ns: u64,
    /// how long after its deadline the step started (timer mode; catch-up steps are late by design)
    pub late_ns: u64,
    /// Newton iterations of the step
    pub iterations: u32,
    /// REGIME_*
    pub regime: u8,
    /// STATUS_*: the solver's outcome
    pub status: u8,
    /// COMMAND_*: the command's state
    pub command_status: u8,
    /// RANGE_*: where the step's input lies against the calibrated range
    pub calibrated_range: u8,
}

/// Loop statistics (the fields of `friction_msgs/LoopStatistics`).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::LoopStatistics_v6")]
pub struct StatisticsPayload {
    /// The header's stamp, ns.
    pub stamp_ns: u64,
    /// Model steps taken.
    pub steps: u64,
    /// Steps that finished after the next deadline (timer mode).
    pub deadline_misses: u64,
    /// Steps taken late, after their deadline had passed, to keep model time = wall time.
    pub catch_up_steps: u64,
    /// Lost time beyond node.max_catch_up_s, advanced in one variable-length step.
    pub time_jumps: u64,
    /// Steps of the wall clock (NTP) seen; stamps stay monotonic.
    pub clock_jumps: u64,
    /// Commands the transports delivered.
    pub commands_received: u64,
    /// Accepted as the current set point.
    pub commands_applied: u64,
    /// Discarded by a full receive queue before the loop saw them.
    pub commands_overwritten: u64,
    /// Non-finite, beyond limits, or out-of-order stamps (lockstep).
    pub commands_rejected: u64,
    /// Steps taken with a timed-out command.
    pub command_timeouts: u64,
    /// Outputs the loop could not hand to a transport (queue full).
    pub publish_drops: u64,
    /// Outputs a transport's I/O failed to send.
    pub publish_failures: u64,
    /// LoopStatistics that could not be handed over or sent.
    pub statistics_not_sent: u64,
    /// Outputs dropped because the recorder queue was full.
    pub recorder_drops: u64,
    /// Recording files started (split recordings: one per split).
    pub recording_files: u64,
    /// Split files deleted to keep to recording.budget_bytes.
    pub recording_files_deleted: u64,
    /// Messages not recorded because writing had failed (a full disk).
    pub recording_lost: u64,
    /// Snapshot files written.
    pub snapshots: u64,
    /// The time span it holds. In s.
    pub last_snapshot_span_s: f64,
    /// The latest snapshot file ("" before the first). UTF-8, `last_snapshot_len` bytes used.
    pub last_snapshot: [u8; 255],
    /// Bytes of `last_snapshot` used.
    pub last_snapshot_len: u8,
    /// Model step wall time: p50, p99, max, ns.
    pub compute_time_ns: [u64; 3],
    /// Lateness of the step start against its deadline: p50, p99, max, ns.
    pub period_jitter_ns: [u64; 3],
    /// Steps whose solver status was not converged (iteration bound, non-finite, rejected input).
    pub steps_not_converged: u64,
    /// Parameter changes applied while running (ros2 param set).
    pub parameter_updates: u64,
    /// Contacts the loop steps (1 without `contacts`).
    pub contacts: u32,
    /// Index (configured order) of the contact whose step took longest since the previous LoopStatistics.
    pub slowest_contact: u32,
    /// That contact's longest step compute time since the previous LoopStatistics. In ns.
    pub slowest_contact_compute_ns: u64,
    /// Contact steps whose input lay outside the contact's calibrated range (FrictionEstimate RANGE_OUTSIDE).
    pub steps_outside_calibrated_range: u64,
    /// The latest input outside a calibrated range since the previous LoopStatistics: speed forward, speed backward, load or temperature ("" none). Coded: 0 none, 1 speed forward, 2 speed backward, 3 load, 4 temperature.
    pub outside_input: u8,
    /// Its contact (configured order).
    pub outside_contact: u32,
    /// Their unit: m/s, rad/s (a rotary joint's speed: the joint's), N or °C. Coded: 0 m/s, 1 rad/s, 2 N, 3 °C.
    pub outside_unit: u8,
    /// Its value, in its range's units (a joint's speed: the joint's).
    pub outside_value: f64,
    /// The calibrated range it left. Its lower end.
    pub outside_min: f64,
    /// The calibrated range it left. Its upper end.
    pub outside_max: f64,
}

impl From<&StatisticsRecord> for StatisticsPayload {
    fn from(s: &StatisticsRecord) -> Self {
        Self {
            stamp_ns: s.stamp_ns,
            steps: s.steps,
            deadline_misses: s.deadline_misses,
            catch_up_steps: s.catch_up_steps,
            time_jumps: s.time_jumps,
            clock_jumps: s.clock_jumps,
            commands_received: s.commands_received,
            commands_applied: s.commands_applied,
            commands_overwritten: s.commands_overwritten,
            commands_rejected: s.commands_rejected,
            command_timeouts: s.command_timeouts,
            publish_drops: s.publish_drops,
            publish_failures: s.publish_failures,
            statistics_not_sent: s.statistics_not_sent,
            recorder_drops: s.recorder_drops,
            recording_files: s.recording.files,
            recording_files_deleted: s.recording.files_deleted,
            recording_lost: s.recording.lost,
            snapshots: s.recording.snapshots,
            last_snapshot_span_s: s.recording.last_snapshot_span_s,
            last_snapshot: {
                let mut b = [0u8; 255];
                let t = s.recording.last_snapshot.as_str().as_bytes();
                b[..t.len()].copy_from_slice(t);
                b
            },
            last_snapshot_len: s.recording.last_snapshot.as_str().len() as u8,
            compute_time_ns: s.compute_time_ns,
            period_jitter_ns: s.period_jitter_ns,
            steps_not_converged: s.steps_not_converged,
            parameter_updates: s.parameter_updates,
            contacts: s.contacts,
            slowest_contact: s.slowest_contact,
            slowest_contact_compute_ns: s.slowest_contact_compute_ns,
            steps_outside_calibrated_range: s.steps_outside_calibrated_range,
            outside_input: s
                .last_outside
                .map_or(0, |o| crate::msgs::OutsideEvent::input_code(o.input)),
            outside_contact: s.last_outside.map_or(0, |o| o.contact),
            outside_value: s.last_outside.map_or(0.0, |o| o.value),
            outside_min: s.last_outside.map_or(0.0, |o| o.lo),
            outside_max: s.last_outside.map_or(0.0, |o| o.hi),
            outside_unit: s
                .last_outside
                .map_or(0, |o| crate::msgs::OutsideEvent::unit_code(o.unit)),
        }
    }
}

impl From<&StatisticsPayload> for StatisticsRecord {
    fn from(s: &StatisticsPayload) -> Self {
        Self {
            stamp_ns: s.stamp_ns,
            steps: s.steps,
            deadline_misses: s.deadline_misses,
            catch_up_steps: s.catch_up_steps,
            time_jumps: s.time_jumps,
            clock_jumps: s.clock_jumps,
            commands_received: s.commands_received,
            commands_applied: s.commands_applied,
            commands_overwritten: s.commands_overwritten,
            commands_rejected: s.commands_rejected,
            command_timeouts: s.command_timeouts,
            publish_drops: s.publish_drops,
            publish_failures: s.publish_failures,
            statistics_not_sent: s.statistics_not_sent,
            recorder_drops: s.recorder_drops,
            recording: crate::msgs::RecordingStatus {
                files: s.recording_files,
                files_deleted: s.recording_files_deleted,
                lost: s.recording_lost,
                snapshots: s.snapshots,
                last_snapshot: crate::msgs::Note::new(
                    std::str::from_utf8(&s.last_snapshot[..usize::from(s.last_snapshot_len)])
                        .unwrap_or(""),
                ),
                last_snapshot_span_s: s.last_snapshot_span_s,
            },
            compute_time_ns: s.compute_time_ns,
            period_jitter_ns: s.period_jitter_ns,
            steps_not_converged: s.steps_not_converged,
            parameter_updates: s.parameter_updates,
            contacts: s.contacts,
            slowest_contact: s.slowest_contact,
            slowest_contact_compute_ns: s.slowest_contact_compute_ns,
            steps_outside_calibrated_range: s.steps_outside_calibrated_range,
            last_outside: crate::msgs::OutsideEvent::input_of_code(s.outside_input).map(|input| {
                crate::msgs::OutsideEvent {
                    contact: s.outside_contact,
                    input,
                    value: s.outside_value,
                    lo: s.outside_min,
                    hi: s.outside_max,
                    unit: crate::msgs::OutsideEvent::unit_of_code(s.outside_unit),
                }
            }),
        }
    }
}

impl From<&EstimateRecord> for EstimatePayload {
    fn from(e: &EstimateRecord) -> Self {
        Self {
            stamp_ns: e.stamp_ns,
            velocity_m_s: e.velocity_m_s,
            load_n: e.load_n,
            temperature_c: e.temperature_c,
            friction_force_n: e.friction_force_n,
            contact_friction_force_n: e.contact_friction_force_n,
            cof: e.cof,
            h0_m: e.h0_m,
            h_min_m: e.h_min_m,
            hydrodynamic_force_n: e.hydrodynamic_force_n,
            asperity_force_n: e.asperity_force_n,
            asperity_load_share: e.asperity_load_share,
            compute_time_ns: e.compute_time_ns,
            late_ns: e.late_ns,
            iterations: e.iterations,
            regime: e.regime,
            status: e.status,
            command_status: e.command_status,
            calibrated_range: e.calibrated_range,
        }
    }
}

impl From<&EstimatePayload> for EstimateRecord {
    fn from(p: &EstimatePayload) -> Self {
        Self {
            stamp_ns: p.stamp_ns,
            velocity_m_s: p.velocity_m_s,
            load_n: p.load_n,
            temperature_c: p.temperature_c,
            friction_force_n: p.friction_force_n,
            contact_friction_force_n: p.contact_friction_force_n,
            cof: p.cof,
            h0_m: p.h0_m,
            h_min_m: p.h_min_m,
            hydrodynamic_force_n: p.hydrodynamic_force_n,
            asperity_force_n: p.asperity_force_n,
            asperity_load_share: p.asperity_load_share,
            regime: p.regime,
            status: p.status,
            command_status: p.command_status,
            calibrated_range: p.calibrated_range,
            iterations: p.iterations,
            compute_time_ns: p.compute_time_ns,
            late_ns: p.late_ns,
        }
    }
}

/// Most bytes of one joint name in a [`JointStatePayload`].
pub const JOINT_NAME_BYTES: usize = crate::config::MAX_JOINT_NAME_BYTES;

/// A `sensor_msgs/JointState`'s names and velocities (fixed size:
/// [`MAX_CONTACTS`](crate::transport::MAX_CONTACTS) joints of up to
/// [`JOINT_NAME_BYTES`] bytes). `name_count` and `velocity_count` are sent
/// as the sender had them: different counts reject the joints without a
/// velocity, as over ROS 2.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::JointState_v1")]
pub struct JointStatePayload {
    /// The stamp, ns.
    pub stamp_ns: u64,
    /// 1, 2, 3, … per publisher (gaps: samples lost to a full buffer).
    pub sequence: u64,
    /// Names used.
    pub name_count: u32,
    /// Velocities used.
    pub velocity_count: u32,
    /// UTF-8, `name_len[i]` bytes used.
    pub name: [[u8; JOINT_NAME_BYTES]; crate::transport::MAX_CONTACTS],
    /// Bytes of each name used.
    pub name_len: [u8; crate::transport::MAX_CONTACTS],
    /// Velocities, m/s or rad/s, `velocity_count` used.
    pub velocity: [f64; crate::transport::MAX_CONTACTS],
}

impl JointStatePayload {
    /// Joint `i`'s name ("" when not UTF-8: matches no joint).
    pub fn name(&self, i: usize) -> &str {
        let len = usize::from(self.name_len[i]).min(JOINT_NAME_BYTES);
        std::str::from_utf8(&self.name[i][..len]).unwrap_or("")
    }
}

/// Every contact's effort in the configured joint order (the data of the
/// `std_msgs/Float64MultiArray` a ros2_control forward command controller
/// takes).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::JointEfforts_v1")]
pub struct EffortsPayload {
    /// The step's stamp, ns.
    pub stamp_ns: u64,
    /// Efforts used.
    pub len: u32,
    /// Padding (0).
    pub reserved: u32,
    /// N or N·m, `len` used.
    pub effort: [f64; crate::transport::MAX_CONTACTS],
}

/// One contact's estimate (several contacts: one service for all).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::ContactEstimate_v1")]
pub struct ContactEstimatePayload {
    /// Index of the contact in the configured order.
    pub contact: u32,
    /// Padding (0).
    pub reserved: u32,
    /// The estimate.
    pub estimate: EstimatePayload,
}
