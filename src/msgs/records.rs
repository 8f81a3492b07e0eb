//! Heap-free records the loop produces (Copy), and their conversions to and
//! from the wire types.

use super::types::{msg_fields, FRICTION_ESTIMATE, FRICTION_ESTIMATE_V1, FRICTION_ESTIMATE_V2};
use super::wire::{
    estimate_constants as codes, FrictionEstimate, FrictionEstimateV1, Header, LoopStatistics, Time,
};
use crate::physics::{Estimate, Regime, Status};

/// One estimate as the loop produces it (Copy, no heap).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EstimateRecord {
    /// The step's stamp (the header's), ns.
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

/// The wire code of a regime (`REGIME_*`).
pub fn regime_code(r: Regime) -> u8 {
    match r {
        Regime::Boundary => codes::REGIME_BOUNDARY,
        Regime::Mixed => codes::REGIME_MIXED,
        Regime::Hydrodynamic => codes::REGIME_HYDRODYNAMIC,
    }
}

/// The wire code of a solver status (`STATUS_*`).
pub fn status_code(s: Status) -> u8 {
    match s {
        Status::Converged => codes::STATUS_CONVERGED,
        Status::MaxIterations => codes::STATUS_MAX_ITERATIONS,
        Status::NonFinite => codes::STATUS_NON_FINITE,
        Status::NonFiniteInput => codes::STATUS_NON_FINITE_INPUT,
        Status::InputOutOfRange => codes::STATUS_INPUT_OUT_OF_RANGE,
    }
}

/// Name of a solver status code (logs, CSV).
pub fn status_name(code: u8) -> &'static str {
    match code {
        codes::STATUS_CONVERGED => "converged",
        codes::STATUS_MAX_ITERATIONS => "max_iterations",
        codes::STATUS_NON_FINITE => "non_finite",
        codes::STATUS_NON_FINITE_INPUT => "non_finite_input",
        codes::STATUS_INPUT_OUT_OF_RANGE => "input_out_of_range",
        _ => "unknown",
    }
}

/// Name of a calibrated-range code (CSV, Python): `not_watched`,
/// `inside`, `outside`.
pub fn range_name(code: u8) -> &'static str {
    match code {
        codes::RANGE_NOT_WATCHED => "not_watched",
        codes::RANGE_INSIDE => "inside",
        codes::RANGE_OUTSIDE => "outside",
        _ => "unknown",
    }
}

/// Name of a command status code (logs, CSV).
pub fn command_status_name(code: u8) -> &'static str {
    match code {
        codes::COMMAND_FRESH => "fresh",
        codes::COMMAND_HELD => "held",
        codes::COMMAND_TIMED_OUT => "timed_out",
        codes::COMMAND_REJECTED => "rejected",
        _ => "unknown",
    }
}

impl EstimateRecord {
    /// The record of a core estimate; the node's fields (temperature,
    /// drivetrain, command status, lateness) are set by the caller
    /// (temperature 0 °C until then: records compare equal, unlike NaN).
    pub fn from_estimate(e: &Estimate, stamp_ns: u64, compute_time_ns: u64) -> Self {
        Self {
            stamp_ns,
            velocity_m_s: e.velocity,
            load_n: e.load,
            temperature_c: 0.0,
            friction_force_n: e.friction_force,
            contact_friction_force_n: e.contact_friction_force,
            cof: e.cof,
            h0_m: e.h0,
            h_min_m: e.h_min,
            hydrodynamic_force_n: e.hydrodynamic_force,
            asperity_force_n: e.asperity_force,
            asperity_load_share: e.asperity_load_share,
            regime: regime_code(e.regime),
            status: status_code(e.status),
            command_status: codes::COMMAND_FRESH,
            calibrated_range: codes::RANGE_NOT_WATCHED,
            iterations: e.diagnostics.iterations,
            compute_time_ns,
            late_ns: 0,
        }
    }

    /// The wire message, stamped with `frame_id`.
    pub fn to_wire(&self, frame_id: &str) -> FrictionEstimate {
        FrictionEstimate {
            header: Header {
                stamp: Time::from_ns(self.stamp_ns),
                frame_id: frame_id.to_string(),
            },
            velocity_m_s: self.velocity_m_s,
            load_n: self.load_n,
            temperature_c: self.temperature_c,
            friction_force_n: self.friction_force_n,
            contact_friction_force_n: self.contact_friction_force_n,
            cof: self.cof,
            h0_m: self.h0_m,
            h_min_m: self.h_min_m,
            hydrodynamic_force_n: self.hydrodynamic_force_n,
            asperity_force_n: self.asperity_force_n,
            asperity_load_share: self.asperity_load_share,
            regime: self.regime,
            status: self.status,
            command_status: self.command_status,
            calibrated_range: self.calibrated_range,
            iterations: self.iterations,
            compute_time_ns: self.compute_time_ns,
            late_ns: self.late_ns,
        }
    }

    /// The record of a wire message.
    pub fn from_wire(m: &FrictionEstimate) -> Self {
        Self {
            stamp_ns: m.header.stamp.to_ns(),
            velocity_m_s: m.velocity_m_s,
            load_n: m.load_n,
            temperature_c: m.temperature_c,
            friction_force_n: m.friction_force_n,
            contact_friction_force_n: m.contact_friction_force_n,
            cof: m.cof,
            h0_m: m.h0_m,
            h_min_m: m.h_min_m,
            hydrodynamic_force_n: m.hydrodynamic_force_n,
            asperity_force_n: m.asperity_force_n,
            asperity_load_share: m.asperity_load_share,
            regime: m.regime,
            status: m.status,
            command_status: m.command_status,
            calibrated_range: m.calibrated_range,
            iterations: m.iterations,
            compute_time_ns: m.compute_time_ns,
            late_ns: m.late_ns,
        }
    }

    /// A record of the layout before `command_status`: its single status
    /// carried the command flags (4 timeout, 5 rejected), now split.
    pub fn from_wire_v1(m: &FrictionEstimateV1) -> Self {
        let (status, command_status) = match m.status {
            codes::LEGACY_STATUS_COMMAND_TIMEOUT => {
                (codes::STATUS_CONVERGED, codes::COMMAND_TIMED_OUT)
            }
            codes::LEGACY_STATUS_COMMAND_REJECTED => {
                (codes::STATUS_CONVERGED, codes::COMMAND_REJECTED)
            }
            s => (s, codes::COMMAND_FRESH),
        };
        Self {
            stamp_ns: m.header.stamp.to_ns(),
            velocity_m_s: m.velocity_m_s,
            load_n: m.load_n,
            temperature_c: f64::NAN,
            friction_force_n: m.friction_force_n,
            contact_friction_force_n: m.friction_force_n,
            cof: m.cof,
            h0_m: m.h0_m,
            h_min_m: m.h_min_m,
            hydrodynamic_force_n: m.hydrodynamic_force_n,
            asperity_force_n: m.asperity_force_n,
            asperity_load_share: m.asperity_load_share,
            regime: m.regime,
            status,
            command_status,
            calibrated_range: codes::RANGE_NOT_WATCHED,
            iterations: m.iterations,
            compute_time_ns: m.compute_time_ns,
            late_ns: 0,
        }
    }
}

fn top_fields(schema_text: &str) -> Vec<(String, String)> {
    msg_fields(schema_text.split("\n====").next().unwrap_or(""))
}

/// The layouts `FrictionEstimate` was recorded in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum EstimateLayout {
    /// Before `command_status` (`legacy/FrictionEstimateV1.msg`).
    V1,
    /// Before `calibrated_range` (`legacy/FrictionEstimateV2.msg`): the
    /// same bytes (the new field sits in what was padding), read as
    /// `RANGE_NOT_WATCHED`.
    V2,
    /// Today's `msg/msg/FrictionEstimate.msg`.
    #[default]
    Current,
}

impl EstimateLayout {
    /// The layout of a recorded `ros2msg` schema text, or an error naming
    /// its fields.
    pub fn of_schema(schema_text: &str) -> Result<Self, String> {
        let got = top_fields(schema_text);
        for (layout, t) in [
            (Self::Current, &FRICTION_ESTIMATE),
            (Self::V2, &FRICTION_ESTIMATE_V2),
            (Self::V1, &FRICTION_ESTIMATE_V1),
        ] {
            if got == msg_fields(t.definition) {
                return Ok(layout);
            }
        }
        Err(format!(
            "fields {:?} are neither those of friction_msgs/msg/FrictionEstimate nor of an earlier layout",
            got.iter().map(|(_, n)| n.as_str()).collect::<Vec<_>>()
        ))
    }
}

/// Whether a `ros2msg` schema text is that of `FrictionEstimate`, in the
/// current layout or an earlier one.
pub fn check_estimate_schema(schema_text: &str) -> Result<(), String> {
    EstimateLayout::of_schema(schema_text).map(|_| ())
}

/// Decode a recorded `FrictionEstimate` of `layout`.
pub fn decode_estimate(
    bytes: &[u8],
    layout: EstimateLayout,
) -> Result<EstimateRecord, super::CdrError> {
    match layout {
        EstimateLayout::V1 => {
            super::from_cdr::<FrictionEstimateV1>(bytes).map(|m| EstimateRecord::from_wire_v1(&m))
        }
        EstimateLayout::V2 => super::from_cdr::<FrictionEstimate>(bytes).map(|m| EstimateRecord {
            calibrated_range: codes::RANGE_NOT_WATCHED,
            ..EstimateRecord::from_wire(&m)
        }),
        EstimateLayout::Current => {
            super::from_cdr::<FrictionEstimate>(bytes).map(|m| EstimateRecord::from_wire(&m))
        }
    }
}

/// A short text held inline (Copy, no heap): a path in the statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Note {
    len: u8,
    bytes: [u8; 255],
}

impl Default for Note {
    fn default() -> Self {
        Self {
            len: 0,
            bytes: [0; 255],
        }
    }
}

impl Note {
    /// The text, cut at 255 bytes (on a character boundary).
    pub fn new(s: &str) -> Self {
        let mut end = s.len().min(255);
        while !s.is_char_boundary(end) {
            end -= 1;
        }
        let mut n = Self::default();
        n.bytes[..end].copy_from_slice(&s.as_bytes()[..end]);
        n.len = end as u8;
        n
    }

    /// The text held.
    pub fn as_str(&self) -> &str {
        std::str::from_utf8(&self.bytes[..usize::from(self.len)]).unwrap_or("")
    }
}

/// What the recorder reports into the loop statistics.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RecordingStatus {
    /// Recording files started (split recordings: one per split).
    pub files: u64,
    /// Split files deleted to keep to recording.budget_bytes.
    pub files_deleted: u64,
    /// Messages not recorded because writing had failed (a full disk).
    pub lost: u64,
    /// Snapshot files written.
    pub snapshots: u64,
    /// The latest snapshot file ("" before the first).
    pub last_snapshot: Note,
    /// The time span it holds. In s.
    pub last_snapshot_span_s: f64,
}

/// Loop statistics as the loop produces them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StatisticsRecord {
    /// When the statistics were taken (the header's stamp), ns.
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
    /// The recorder's counters.
    pub recording: RecordingStatus,
    /// Wall time of the model step (ns).
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
    /// The latest step outside a calibrated range since the previous
    /// statistics (`/diagnostics` names it).
    pub last_outside: Option<OutsideEvent>,
}

/// A contact's input outside its calibrated range (Copy, no heap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutsideEvent {
    /// The contact (configured order).
    pub contact: u32,
    /// The input: `speed forward`, `speed backward`, `load`, `temperature`.
    pub input: &'static str,
    /// Its value, in the range's units (a joint's speed: the joint's).
    pub value: f64,
    /// The range it left: lowest …
    pub lo: f64,
    /// … and highest.
    pub hi: f64,
    /// `m/s`, `rad/s`, `N` or `°C`.
    pub unit: &'static str,
}

impl OutsideEvent {
    /// The inputs a calibrated range watches, by their code (1-based; 0 is none).
    pub const INPUTS: [&'static str; 4] =
        ["speed forward", "speed backward", "load", "temperature"];

    /// The code of an input name (0 for a name not watched).
    pub fn input_code(input: &str) -> u8 {
        Self::INPUTS
            .iter()
            .position(|i| *i == input)
            .map_or(0, |k| k as u8 + 1)
    }

    /// The input of a code (None for 0 or an unknown code).
    pub fn input_of_code(code: u8) -> Option<&'static str> {
        Self::INPUTS.get(usize::from(code).checked_sub(1)?).copied()
    }

    /// The units of a range's inputs, by their code (0-based).
    pub const UNITS: [&'static str; 4] = ["m/s", "rad/s", "N", "°C"];

    /// The code of a unit (0, m/s, for one not listed).
    pub fn unit_code(unit: &str) -> u8 {
        Self::UNITS.iter().position(|u| *u == unit).unwrap_or(0) as u8
    }

    /// The unit of a code (m/s for an unknown one).
    pub fn unit_of_code(code: u8) -> &'static str {
        Self::UNITS.get(usize::from(code)).copied().unwrap_or("m/s")
    }
}

impl StatisticsRecord {
    /// The wire message, stamped with `frame_id`.
    pub fn to_wire(&self, frame_id: &str) -> LoopStatistics {
        LoopStatistics {
            header: Header {
                stamp: Time::from_ns(self.stamp_ns),
                frame_id: frame_id.to_string(),
            },
            steps: self.steps,
            deadline_misses: self.deadline_misses,
            catch_up_steps: self.catch_up_steps,
            time_jumps: self.time_jumps,
            clock_jumps: self.clock_jumps,
            commands_received: self.commands_received,
            commands_applied: self.commands_applied,
            commands_overwritten: self.commands_overwritten,
            commands_rejected: self.commands_rejected,
            command_timeouts: self.command_timeouts,
            publish_drops: self.publish_drops,
            publish_failures: self.publish_failures,
            statistics_not_sent: self.statistics_not_sent,
            recorder_drops: self.recorder_drops,
            recording_files: self.recording.files,
            recording_files_deleted: self.recording.files_deleted,
            recording_lost: self.recording.lost,
            snapshots: self.recording.snapshots,
            last_snapshot: self.recording.last_snapshot.as_str().to_string(),
            last_snapshot_span_s: self.recording.last_snapshot_span_s,
            compute_time_p50_ns: self.compute_time_ns[0],
            compute_time_p99_ns: self.compute_time_ns[1],
            compute_time_max_ns: self.compute_time_ns[2],
            period_jitter_p50_ns: self.period_jitter_ns[0],
            period_jitter_p99_ns: self.period_jitter_ns[1],
            period_jitter_max_ns: self.period_jitter_ns[2],
            steps_not_converged: self.steps_not_converged,
            parameter_updates: self.parameter_updates,
            contacts: self.contacts,
            slowest_contact: self.slowest_contact,
            slowest_contact_compute_ns: self.slowest_contact_compute_ns,
            steps_outside_calibrated_range: self.steps_outside_calibrated_range,
            outside_input: self
                .last_outside
                .map_or(String::new(), |o| o.input.to_string()),
            outside_contact: self.last_outside.map_or(0, |o| o.contact),
            outside_value: self.last_outside.map_or(0.0, |o| o.value),
            outside_min: self.last_outside.map_or(0.0, |o| o.lo),
            outside_max: self.last_outside.map_or(0.0, |o| o.hi),
            outside_unit: self
                .last_outside
                .map_or(String::new(), |o| o.unit.to_string()),
        }
    }

    /// The record of a wire message.
    pub fn from_wire(m: &LoopStatistics) -> Self {
        Self {
            stamp_ns: m.header.stamp.to_ns(),
            steps: m.steps,
            deadline_misses: m.deadline_misses,
            catch_up_steps: m.catch_up_steps,
            time_jumps: m.time_jumps,
            clock_jumps: m.clock_jumps,
            commands_received: m.commands_received,
            commands_applied: m.commands_applied,
            commands_overwritten: m.commands_overwritten,
            commands_rejected: m.commands_rejected,
            command_timeouts: m.command_timeouts,
            publish_drops: m.publish_drops,
            publish_failures: m.publish_failures,
            statistics_not_sent: m.statistics_not_sent,
            recorder_drops: m.recorder_drops,
            recording: RecordingStatus {
                files: m.recording_files,
                files_deleted: m.recording_files_deleted,
                lost: m.recording_lost,
                snapshots: m.snapshots,
                last_snapshot: Note::new(&m.last_snapshot),
                last_snapshot_span_s: m.last_snapshot_span_s,
            },
            compute_time_ns: [
                m.compute_time_p50_ns,
                m.compute_time_p99_ns,
                m.compute_time_max_ns,
            ],
            period_jitter_ns: [
                m.period_jitter_p50_ns,
                m.period_jitter_p99_ns,
                m.period_jitter_max_ns,
            ],
            steps_not_converged: m.steps_not_converged,
            parameter_updates: m.parameter_updates,
            contacts: m.contacts,
            slowest_contact: m.slowest_contact,
            slowest_contact_compute_ns: m.slowest_contact_compute_ns,
            steps_outside_calibrated_range: m.steps_outside_calibrated_range,
            last_outside: OutsideEvent::input_of_code(OutsideEvent::input_code(&m.outside_input))
                .map(|input| OutsideEvent {
                    contact: m.outside_contact,
                    input,
                    value: m.outside_value,
                    lo: m.outside_min,
                    hi: m.outside_max,
                    unit: OutsideEvent::unit_of_code(OutsideEvent::unit_code(&m.outside_unit)),
                }),
        }
    }
}

/// What a command carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandKind {
    /// Sliding velocity, m/s.
    Velocity,
    /// Normal load, N.
    Load,
    /// Lubricant temperature, °C.
    Temperature,
    /// One joint's velocity out of a `sensor_msgs/JointState` (m/s, or
    /// rad/s for a rotary joint), for the configured contact at index
    /// `contact`, which slides at its `gain` × it; `last` marks the
    /// message's last configured joint (lockstep steps every contact once
    /// per message, on it).
    JointVelocity {
        /// The contact (configured order).
        contact: u16,
        /// Whether it is the last contact's of the step (the lockstep loop steps after it).
        last: bool,
        /// The value is the joint's velocity (true), or already the
        /// contact's own sliding speed in m/s (false: a replay of recorded
        /// estimates, which hold the contact's speed).
        joint: bool,
    },
}

impl CommandKind {}

/// A command as received from a transport (Copy, no heap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// What the command sets.
    pub kind: CommandKind,
    /// Its value, SI (m/s, N, °C).
    pub value: f64,
    /// The sender's stamp (header stamp, or the sample's source time), ns.
    pub stamp_ns: u64,
}

/// A received sample exactly as it came off the wire: recorded unchanged.
#[derive(Debug, Clone, PartialEq)]
pub struct RawSample {
    /// What the sample commands.
    pub kind: CommandKind,
    /// The CDR bytes, encapsulation header included.
    pub cdr: Vec<u8>,
    /// The publisher's stamp (source timestamp, else the header's), ns.
    pub publish_ns: u64,
    /// When the node took it from the transport (wall clock), ns.
    pub received_ns: u64,
}
