//! Wire types. `msg/msg/*.msg` (the ROS 2 package `friction_msgs`) is the
//! source of truth for message layout; the structs here mirror it field by
//! field (a test checks names, order and types against the `.msg` text) and
//! convert to and from the loop's heap-free records. The standard ROS types
//! the node reads or writes are mirrored too.
//!
//! Units are SI and part of each field's name; stamps are ROS time
//! (`builtin_interfaces/Time`), nanoseconds in the records (`stamp_ns`).

use crate::physics::{Estimate, Regime, Status};
use serde::{Deserialize, Serialize};

/// `builtin_interfaces/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

impl Time {
    pub fn from_ns(ns: u64) -> Self {
        Self {
            sec: (ns / 1_000_000_000) as i32,
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }

    /// Nanoseconds (negative times map to 0).
    pub fn to_ns(self) -> u64 {
        if self.sec < 0 {
            return 0;
        }
        self.sec as u64 * 1_000_000_000 + self.nanosec as u64
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

/// Constants of `friction_msgs/FrictionEstimate`.
pub mod estimate_constants {
    pub const REGIME_BOUNDARY: u8 = 0;
    pub const REGIME_MIXED: u8 = 1;
    pub const REGIME_HYDRODYNAMIC: u8 = 2;
    pub const STATUS_CONVERGED: u8 = 0;
    pub const STATUS_MAX_ITERATIONS: u8 = 1;
    pub const STATUS_NON_FINITE: u8 = 2;
    pub const STATUS_NON_FINITE_INPUT: u8 = 3;
    pub const STATUS_COMMAND_TIMEOUT: u8 = 4;
    pub const STATUS_COMMAND_REJECTED: u8 = 5;
}

/// `friction_msgs/FrictionEstimate`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrictionEstimate {
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
    pub commands_received: u64,
    pub commands_rejected: u64,
    pub command_timeouts: u64,
    pub publish_drops: u64,
    pub recorder_drops: u64,
    pub compute_time_p50_ns: u64,
    pub compute_time_p99_ns: u64,
    pub compute_time_max_ns: u64,
    pub period_jitter_p50_ns: u64,
    pub period_jitter_p99_ns: u64,
    pub period_jitter_max_ns: u64,
}

#[cfg(feature = "ros2")]
mod ros2_impls {
    use super::*;
    impl ros2_client::Message for Time {}
    impl ros2_client::Message for Header {}
    impl ros2_client::Message for Float64 {}
    impl ros2_client::Message for TwistStamped {}
    impl ros2_client::Message for JointState {}
    impl ros2_client::Message for FrictionEstimate {}
    impl ros2_client::Message for FilmProfile {}
    impl ros2_client::Message for LoopStatistics {}
}

// ---------------------------------------------------------------------------
// Message types and their `ros2msg` schemas.
// ---------------------------------------------------------------------------

/// A ROS 2 message type: package, name, `.msg` text and the types it uses.
#[derive(Debug)]
pub struct MsgType {
    pub package: &'static str,
    pub name: &'static str,
    pub definition: &'static str,
    pub dependencies: &'static [&'static MsgType],
}

impl MsgType {
    /// `pkg/msg/Name` (the MCAP schema name and ROS 2 type string).
    pub fn full_name(&self) -> String {
        format!("{}/msg/{}", self.package, self.name)
    }

    /// The `ros2msg` schema: the definition, then every (transitive)
    /// dependency after a line of 80 `=` and `MSG: pkg/Name`.
    pub fn ros2msg_schema(&self) -> String {
        let mut out = self.definition.trim_end().to_string();
        out.push('\n');
        let mut seen: Vec<&str> = Vec::new();
        fn walk(t: &MsgType, out: &mut String, seen: &mut Vec<&'static str>) {
            for d in t.dependencies {
                let key = d.name;
                if seen.contains(&key) {
                    continue;
                }
                seen.push(key);
                out.push_str(&"=".repeat(80));
                out.push_str(&format!("\nMSG: {}/{}\n", d.package, d.name));
                out.push_str(d.definition.trim_end());
                out.push('\n');
                walk(d, out, seen);
            }
        }
        walk(self, &mut out, &mut seen);
        out
    }
}

pub static TIME: MsgType = MsgType {
    package: "builtin_interfaces",
    name: "Time",
    definition: "int32 sec\nuint32 nanosec\n",
    dependencies: &[],
};

pub static HEADER: MsgType = MsgType {
    package: "std_msgs",
    name: "Header",
    definition: "builtin_interfaces/Time stamp\nstring frame_id\n",
    dependencies: &[&TIME],
};

pub static FLOAT64: MsgType = MsgType {
    package: "std_msgs",
    name: "Float64",
    definition: "float64 data\n",
    dependencies: &[],
};

pub static VECTOR3: MsgType = MsgType {
    package: "geometry_msgs",
    name: "Vector3",
    definition: "float64 x\nfloat64 y\nfloat64 z\n",
    dependencies: &[],
};

pub static TWIST: MsgType = MsgType {
    package: "geometry_msgs",
    name: "Twist",
    definition: "Vector3 linear\nVector3 angular\n",
    dependencies: &[&VECTOR3],
};

pub static TWIST_STAMPED: MsgType = MsgType {
    package: "geometry_msgs",
    name: "TwistStamped",
    definition: "std_msgs/Header header\nTwist twist\n",
    dependencies: &[&HEADER, &TWIST],
};

pub static JOINT_STATE: MsgType = MsgType {
    package: "sensor_msgs",
    name: "JointState",
    definition: "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
    dependencies: &[&HEADER],
};

pub static FRICTION_ESTIMATE: MsgType = MsgType {
    package: "friction_msgs",
    name: "FrictionEstimate",
    definition: include_str!("../msg/msg/FrictionEstimate.msg"),
    dependencies: &[&HEADER],
};

pub static FILM_PROFILE: MsgType = MsgType {
    package: "friction_msgs",
    name: "FilmProfile",
    definition: include_str!("../msg/msg/FilmProfile.msg"),
    dependencies: &[&HEADER],
};

pub static LOOP_STATISTICS: MsgType = MsgType {
    package: "friction_msgs",
    name: "LoopStatistics",
    definition: include_str!("../msg/msg/LoopStatistics.msg"),
    dependencies: &[&HEADER],
};

/// Fields of a `.msg` text, in order: (type, name). Comments, blank lines
/// and constants are skipped.
pub fn msg_fields(definition: &str) -> Vec<(String, String)> {
    definition
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .filter(|l| !l.is_empty())
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            let ty = it.next()?;
            let rest = it.next()?;
            if rest.contains('=') || l.contains('=') {
                return None; // constant
            }
            Some((ty.to_string(), rest.to_string()))
        })
        .collect()
}

// ---------------------------------------------------------------------------
// Heap-free records used by the loop, and their conversions.
// ---------------------------------------------------------------------------

/// One estimate as the loop produces it (Copy, no heap).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EstimateRecord {
    pub stamp_ns: u64,
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

pub fn regime_code(r: Regime) -> u8 {
    match r {
        Regime::Boundary => estimate_constants::REGIME_BOUNDARY,
        Regime::Mixed => estimate_constants::REGIME_MIXED,
        Regime::Hydrodynamic => estimate_constants::REGIME_HYDRODYNAMIC,
    }
}

pub fn status_code(s: Status) -> u8 {
    match s {
        Status::Converged => estimate_constants::STATUS_CONVERGED,
        Status::MaxIterations => estimate_constants::STATUS_MAX_ITERATIONS,
        Status::NonFinite => estimate_constants::STATUS_NON_FINITE,
        Status::NonFiniteInput => estimate_constants::STATUS_NON_FINITE_INPUT,
    }
}

/// Name of a status code (logs, CSV).
pub fn status_name(code: u8) -> &'static str {
    use estimate_constants::*;
    match code {
        STATUS_CONVERGED => "converged",
        STATUS_MAX_ITERATIONS => "max_iterations",
        STATUS_NON_FINITE => "non_finite",
        STATUS_NON_FINITE_INPUT => "non_finite_input",
        STATUS_COMMAND_TIMEOUT => "command_timeout",
        STATUS_COMMAND_REJECTED => "command_rejected",
        _ => "unknown",
    }
}

impl EstimateRecord {
    pub fn from_estimate(e: &Estimate, stamp_ns: u64, compute_time_ns: u64) -> Self {
        Self {
            stamp_ns,
            velocity_m_s: e.velocity,
            load_n: e.load,
            friction_force_n: e.friction_force,
            cof: e.cof,
            h0_m: e.h0,
            h_min_m: e.h_min,
            hydrodynamic_force_n: e.hydrodynamic_force,
            asperity_force_n: e.asperity_force,
            asperity_load_share: e.asperity_load_share,
            regime: regime_code(e.regime),
            status: status_code(e.status),
            iterations: e.diagnostics.iterations,
            compute_time_ns,
        }
    }

    pub fn to_wire(&self, frame_id: &str) -> FrictionEstimate {
        FrictionEstimate {
            header: Header {
                stamp: Time::from_ns(self.stamp_ns),
                frame_id: frame_id.to_string(),
            },
            velocity_m_s: self.velocity_m_s,
            load_n: self.load_n,
            friction_force_n: self.friction_force_n,
            cof: self.cof,
            h0_m: self.h0_m,
            h_min_m: self.h_min_m,
            hydrodynamic_force_n: self.hydrodynamic_force_n,
            asperity_force_n: self.asperity_force_n,
            asperity_load_share: self.asperity_load_share,
            regime: self.regime,
            status: self.status,
            iterations: self.iterations,
            compute_time_ns: self.compute_time_ns,
        }
    }

    pub fn from_wire(m: &FrictionEstimate) -> Self {
        Self {
            stamp_ns: m.header.stamp.to_ns(),
            velocity_m_s: m.velocity_m_s,
            load_n: m.load_n,
            friction_force_n: m.friction_force_n,
            cof: m.cof,
            h0_m: m.h0_m,
            h_min_m: m.h_min_m,
            hydrodynamic_force_n: m.hydrodynamic_force_n,
            asperity_force_n: m.asperity_force_n,
            asperity_load_share: m.asperity_load_share,
            regime: m.regime,
            status: m.status,
            iterations: m.iterations,
            compute_time_ns: m.compute_time_ns,
        }
    }
}

/// Loop statistics as the loop produces them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StatisticsRecord {
    pub stamp_ns: u64,
    pub steps: u64,
    pub deadline_misses: u64,
    pub commands_received: u64,
    pub commands_rejected: u64,
    pub command_timeouts: u64,
    pub publish_drops: u64,
    pub recorder_drops: u64,
    pub compute_time_ns: [u64; 3],
    pub period_jitter_ns: [u64; 3],
}

impl StatisticsRecord {
    pub fn to_wire(&self, frame_id: &str) -> LoopStatistics {
        LoopStatistics {
            header: Header {
                stamp: Time::from_ns(self.stamp_ns),
                frame_id: frame_id.to_string(),
            },
            steps: self.steps,
            deadline_misses: self.deadline_misses,
            commands_received: self.commands_received,
            commands_rejected: self.commands_rejected,
            command_timeouts: self.command_timeouts,
            publish_drops: self.publish_drops,
            recorder_drops: self.recorder_drops,
            compute_time_p50_ns: self.compute_time_ns[0],
            compute_time_p99_ns: self.compute_time_ns[1],
            compute_time_max_ns: self.compute_time_ns[2],
            period_jitter_p50_ns: self.period_jitter_ns[0],
            period_jitter_p99_ns: self.period_jitter_ns[1],
            period_jitter_max_ns: self.period_jitter_ns[2],
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
}

/// A command as received from a transport (Copy, no heap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    pub kind: CommandKind,
    pub value: f64,
    /// The sender's stamp (header stamp, or the sample's source time), ns.
    pub stamp_ns: u64,
}

/// What the loop hands to the recorder (Copy, no heap).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RecordItem {
    /// A received command and when it arrived (wall clock, ns).
    Command {
        command: Command,
        received_ns: u64,
    },
    Estimate(EstimateRecord),
    Statistics(StatisticsRecord),
}

/// Encode a message as CDR with the 4-byte encapsulation header (little endian).
pub fn to_cdr<T: Serialize>(m: &T) -> Result<Vec<u8>, String> {
    let mut out = vec![0x00, 0x01, 0x00, 0x00];
    let body =
        cdr_encoding::to_vec::<T, byteorder_le::LittleEndian>(m).map_err(|e| e.to_string())?;
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decode a CDR message (with its encapsulation header).
pub fn from_cdr<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Result<T, String> {
    if bytes.len() < 4 {
        return Err(format!(
            "{} bytes is too short for a CDR message",
            bytes.len()
        ));
    }
    let body = &bytes[4..];
    match bytes[1] {
        0x01 => cdr_encoding::from_bytes::<T, byteorder_le::LittleEndian>(body)
            .map(|(v, _)| v)
            .map_err(|e| e.to_string()),
        0x00 => cdr_encoding::from_bytes::<T, byteorder_le::BigEndian>(body)
            .map(|(v, _)| v)
            .map_err(|e| e.to_string()),
        other => Err(format!(
            "unsupported CDR encapsulation 0x{:02x}{other:02x}",
            bytes[0]
        )),
    }
}

mod byteorder_le {
    pub use byteorder::{BigEndian, LittleEndian};
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_norway::Value;

    /// Field names and kinds of a serialized struct, in order.
    fn fields<T: Serialize>(v: &T) -> Vec<(String, Value)> {
        match serde_norway::to_value(v).unwrap() {
            Value::Mapping(m) => m
                .into_iter()
                .map(|(k, v)| (k.as_str().unwrap().to_string(), v))
                .collect(),
            other => panic!("not a struct: {other:?}"),
        }
    }

    fn kind_ok(msg_type: &str, v: &Value) -> bool {
        if msg_type.ends_with("[]") {
            return matches!(v, Value::Sequence(_));
        }
        match msg_type {
            "float64" | "float32" => matches!(v, Value::Number(n) if n.is_f64()),
            "uint8" | "uint32" | "uint64" | "int32" | "int64" => {
                matches!(v, Value::Number(n) if n.is_u64() || n.is_i64())
            }
            "string" => matches!(v, Value::String(_)),
            _ => matches!(v, Value::Mapping(_)),
        }
    }

    fn check<T: Serialize + Default>(t: &MsgType) {
        let msg = msg_fields(t.definition);
        let rust = fields(&T::default());
        let names: Vec<&str> = rust.iter().map(|(n, _)| n.as_str()).collect();
        let msg_names: Vec<&str> = msg.iter().map(|(_, n)| n.as_str()).collect();
        assert_eq!(
            names, msg_names,
            "{}: field names/order differ from the .msg",
            t.name
        );
        for ((ty, name), (_, v)) in msg.iter().zip(&rust) {
            assert!(
                kind_ok(ty, v),
                "{}.{name}: .msg type {ty}, Rust value {v:?}",
                t.name
            );
        }
    }

    #[test]
    fn wire_structs_mirror_the_msg_files_field_by_field() {
        check::<FrictionEstimate>(&FRICTION_ESTIMATE);
        check::<FilmProfile>(&FILM_PROFILE);
        check::<LoopStatistics>(&LOOP_STATISTICS);
        check::<Header>(&HEADER);
        check::<Time>(&TIME);
        check::<TwistStamped>(&TWIST_STAMPED);
        check::<JointState>(&JOINT_STATE);
        check::<Float64>(&FLOAT64);
    }

    #[test]
    fn msg_constants_match_the_rust_constants() {
        use estimate_constants::*;
        let text = FRICTION_ESTIMATE.definition;
        for (name, value) in [
            ("REGIME_BOUNDARY", REGIME_BOUNDARY),
            ("REGIME_MIXED", REGIME_MIXED),
            ("REGIME_HYDRODYNAMIC", REGIME_HYDRODYNAMIC),
            ("STATUS_CONVERGED", STATUS_CONVERGED),
            ("STATUS_MAX_ITERATIONS", STATUS_MAX_ITERATIONS),
            ("STATUS_NON_FINITE", STATUS_NON_FINITE),
            ("STATUS_NON_FINITE_INPUT", STATUS_NON_FINITE_INPUT),
            ("STATUS_COMMAND_TIMEOUT", STATUS_COMMAND_TIMEOUT),
            ("STATUS_COMMAND_REJECTED", STATUS_COMMAND_REJECTED),
        ] {
            assert!(
                text.contains(&format!("uint8 {name}={value}")),
                "{name}={value} not in the .msg"
            );
        }
    }

    #[test]
    fn ros2msg_schema_appends_each_dependency_once() {
        let s = FRICTION_ESTIMATE.ros2msg_schema();
        assert!(s.starts_with("# The friction estimate"));
        assert_eq!(s.matches(&"=".repeat(80)).count(), 2);
        assert!(
            s.contains("\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n")
        );
        assert!(s.contains("\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"));
        let t = TWIST_STAMPED.ros2msg_schema();
        for dep in [
            "MSG: std_msgs/Header",
            "MSG: builtin_interfaces/Time",
            "MSG: geometry_msgs/Twist",
            "MSG: geometry_msgs/Vector3",
        ] {
            assert!(t.contains(dep), "{dep}");
        }
    }

    #[test]
    fn cdr_round_trips_with_the_encapsulation_header() {
        let r = EstimateRecord {
            stamp_ns: 1_234_567_891_011,
            velocity_m_s: -0.25,
            friction_force_n: -123.5,
            iterations: 3,
            status: estimate_constants::STATUS_COMMAND_TIMEOUT,
            ..Default::default()
        };
        let bytes = to_cdr(&r.to_wire("slider")).unwrap();
        assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
        let back: FrictionEstimate = from_cdr(&bytes).unwrap();
        assert_eq!(EstimateRecord::from_wire(&back), r);
        assert_eq!(back.header.frame_id, "slider");
        assert!(from_cdr::<FrictionEstimate>(&bytes[..10]).is_err());
    }
}
