//! Standard ROS 2 interfaces the node serves or publishes besides its own:
//! parameters (`rcl_interfaces`), logs (`/rosout`), diagnostics
//! (`diagnostic_msgs`), simulated time (`rosgraph_msgs/Clock`) and the
//! `std_srvs/srv/Trigger` service. Wire structs in `.msg` field order (CDR
//! needs exactly that) with their definitions, as in ROS 2 Humble.

use super::types::{MsgType, HEADER, TIME};
use super::wire::{Header, Time};
use serde::{Deserialize, Serialize};

/// `rcl_interfaces/msg/ParameterType` constants.
pub mod parameter_type {
    /// No value.
    pub const NOT_SET: u8 = 0;
    /// Bool.
    pub const BOOL: u8 = 1;
    /// Int64.
    pub const INTEGER: u8 = 2;
    /// Float64.
    pub const DOUBLE: u8 = 3;
    /// String.
    pub const STRING: u8 = 4;
    /// Byte[].
    pub const BYTE_ARRAY: u8 = 5;
    /// Bool[].
    pub const BOOL_ARRAY: u8 = 6;
    /// Int64[].
    pub const INTEGER_ARRAY: u8 = 7;
    /// Float64[].
    pub const DOUBLE_ARRAY: u8 = 8;
    /// String[].
    pub const STRING_ARRAY: u8 = 9;
}

/// `rcl_interfaces/msg/ParameterValue`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ParameterValue {
    /// Which of the values is set (`parameter_type`).
    pub r#type: u8,
    /// The value when the type is BOOL.
    pub bool_value: bool,
    /// The value when the type is INTEGER.
    pub integer_value: i64,
    /// The value when the type is DOUBLE.
    pub double_value: f64,
    /// The value when the type is STRING.
    pub string_value: String,
    /// The value when the type is BYTE_ARRAY.
    pub byte_array_value: Vec<u8>,
    /// The value when the type is BOOL_ARRAY.
    pub bool_array_value: Vec<bool>,
    /// The value when the type is INTEGER_ARRAY.
    pub integer_array_value: Vec<i64>,
    /// The value when the type is DOUBLE_ARRAY.
    pub double_array_value: Vec<f64>,
    /// The value when the type is STRING_ARRAY.
    pub string_array_value: Vec<String>,
}

/// `rcl_interfaces/msg/Parameter`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Parameter {
    /// The parameter's name (a dotted configuration key).
    pub name: String,
    /// Its value.
    pub value: ParameterValue,
}

/// `rcl_interfaces/msg/ParameterEvent`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ParameterEvent {
    /// When the change took effect.
    pub stamp: Time,
    /// The fully qualified name of the node whose parameters changed.
    pub node: String,
    /// Parameters declared.
    pub new_parameters: Vec<Parameter>,
    /// Parameters whose value changed.
    pub changed_parameters: Vec<Parameter>,
    /// Parameters undeclared.
    pub deleted_parameters: Vec<Parameter>,
}

/// `rcl_interfaces/msg/FloatingPointRange`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FloatingPointRange {
    /// Lower bound.
    pub from_value: f64,
    /// Upper bound.
    pub to_value: f64,
    /// Step between allowed values (0: any).
    pub step: f64,
}

/// `rcl_interfaces/msg/IntegerRange`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct IntegerRange {
    /// Lower bound.
    pub from_value: i64,
    /// Upper bound.
    pub to_value: i64,
    /// Step between allowed values (0: any).
    pub step: u64,
}

/// `rcl_interfaces/msg/ParameterDescriptor` (Humble: with
/// `dynamic_typing`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ParameterDescriptor {
    /// The parameter's name.
    pub name: String,
    /// Its type (`parameter_type`).
    pub r#type: u8,
    /// What it is, with its unit.
    pub description: String,
    /// Constraints in words.
    pub additional_constraints: String,
    /// Whether it can only be set at start-up.
    pub read_only: bool,
    /// Whether its type may change.
    pub dynamic_typing: bool,
    /// At most one.
    pub floating_point_range: Vec<FloatingPointRange>,
    /// At most one.
    pub integer_range: Vec<IntegerRange>,
}

/// `rcl_interfaces/msg/SetParametersResult`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SetParametersResult {
    /// Whether the change was applied.
    pub successful: bool,
    /// Why not, when it was refused.
    pub reason: String,
}

/// `rcl_interfaces/msg/ListParametersResult`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ListParametersResult {
    /// Parameter names.
    pub names: Vec<String>,
    /// Their distinct prefixes.
    pub prefixes: Vec<String>,
}

/// `rcl_interfaces/srv/ListParameters` request.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ListParametersRequest {
    /// Only names under these prefixes (empty: all).
    pub prefixes: Vec<String>,
    /// How many levels below a prefix (0: unlimited).
    pub depth: u64,
}

/// `rcl_interfaces/srv/ListParameters` response.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ListParametersResponse {
    /// The names and prefixes.
    pub result: ListParametersResult,
}

/// Requests that name parameters: `GetParameters`, `GetParameterTypes`,
/// `DescribeParameters`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct NamesRequest {
    /// The parameters asked for.
    pub names: Vec<String>,
}

/// `rcl_interfaces/srv/GetParameters` response.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GetParametersResponse {
    /// Their values, in the order asked.
    pub values: Vec<ParameterValue>,
}

/// `rcl_interfaces/srv/GetParameterTypes` response.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct GetParameterTypesResponse {
    /// Their types, in the order asked.
    pub types: Vec<u8>,
}

/// `rcl_interfaces/srv/DescribeParameters` response.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DescribeParametersResponse {
    /// Their descriptors, in the order asked.
    pub descriptors: Vec<ParameterDescriptor>,
}

/// `rcl_interfaces/srv/SetParameters` and `SetParametersAtomically`
/// request.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SetParametersRequest {
    /// The new values.
    pub parameters: Vec<Parameter>,
}

/// `rcl_interfaces/srv/SetParameters` response.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SetParametersResponse {
    /// One result per parameter.
    pub results: Vec<SetParametersResult>,
}

/// `rcl_interfaces/srv/SetParametersAtomically` response.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SetParametersAtomicallyResponse {
    /// One result for all.
    pub result: SetParametersResult,
}

/// `std_srvs/srv/Trigger` request (empty: one placeholder byte in CDR, as
/// rosidl generates for empty structures).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TriggerRequest {
    /// Padding (ROS 2 gives empty messages one byte).
    pub structure_needs_at_least_one_member: u8,
}

/// `std_srvs/srv/Trigger` response.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TriggerResponse {
    /// Whether the request was carried out.
    pub success: bool,
    /// What happened.
    pub message: String,
}

/// `rcl_interfaces/msg/Log` levels.
pub mod log_level {
    /// Debug.
    pub const DEBUG: u8 = 10;
    /// Information.
    pub const INFO: u8 = 20;
    /// Warning.
    pub const WARN: u8 = 30;
    /// Error.
    pub const ERROR: u8 = 40;
    /// Fatal.
    pub const FATAL: u8 = 50;
}

/// `rcl_interfaces/msg/Log` (what `/rosout` carries).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Log {
    /// When it was logged.
    pub stamp: Time,
    /// Severity (`log_level`).
    pub level: u8,
    /// The logger (the node).
    pub name: String,
    /// The message.
    pub msg: String,
    /// The source file that logged it.
    pub file: String,
    /// The function (module) that logged it.
    pub function: String,
    /// The source line.
    pub line: u32,
}

/// `diagnostic_msgs/msg/KeyValue`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct KeyValue {
    /// The value's name.
    pub key: String,
    /// The value, as text.
    pub value: String,
}

/// `diagnostic_msgs/msg/DiagnosticStatus` levels.
pub mod diagnostic_level {
    /// Healthy.
    pub const OK: u8 = 0;
    /// Something to look at.
    pub const WARN: u8 = 1;
    /// Something is wrong.
    pub const ERROR: u8 = 2;
    /// No recent information.
    pub const STALE: u8 = 3;
}

/// `diagnostic_msgs/msg/DiagnosticStatus`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// OK, WARN, ERROR or STALE (`diagnostic_level`).
    pub level: u8,
    /// `<node>: <concern>`.
    pub name: String,
    /// The state in a few words.
    pub message: String,
    /// What the status is about (the node).
    pub hardware_id: String,
    /// The counters behind it.
    pub values: Vec<KeyValue>,
}

/// `diagnostic_msgs/msg/DiagnosticArray`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct DiagnosticArray {
    /// Stamp and frame.
    pub header: Header,
    /// One status per concern.
    pub status: Vec<DiagnosticStatus>,
}

/// `rosgraph_msgs/msg/Clock`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Clock {
    /// The simulated time.
    pub clock: Time,
}

/// The `parameter_value` message type (definition and dependencies).
pub static PARAMETER_VALUE: MsgType = MsgType {
    package: "rcl_interfaces",
    name: "ParameterValue",
    definition: "uint8 type\nbool bool_value\nint64 integer_value\nfloat64 double_value\nstring string_value\nbyte[] byte_array_value\nbool[] bool_array_value\nint64[] integer_array_value\nfloat64[] double_array_value\nstring[] string_array_value\n",
    dependencies: &[],
};

/// The `parameter` message type (definition and dependencies).
pub static PARAMETER: MsgType = MsgType {
    package: "rcl_interfaces",
    name: "Parameter",
    definition: "string name\nParameterValue value\n",
    dependencies: &[&PARAMETER_VALUE],
};

/// The `parameter_event` message type (definition and dependencies).
pub static PARAMETER_EVENT: MsgType = MsgType {
    package: "rcl_interfaces",
    name: "ParameterEvent",
    definition: "builtin_interfaces/Time stamp\nstring node\nParameter[] new_parameters\nParameter[] changed_parameters\nParameter[] deleted_parameters\n",
    dependencies: &[&TIME, &PARAMETER],
};

/// The `log` message type (definition and dependencies).
pub static LOG: MsgType = MsgType {
    package: "rcl_interfaces",
    name: "Log",
    definition: "byte DEBUG=10\nbyte INFO=20\nbyte WARN=30\nbyte ERROR=40\nbyte FATAL=50\nbuiltin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\nstring file\nstring function\nuint32 line\n",
    dependencies: &[&TIME],
};

/// The `key_value` message type (definition and dependencies).
pub static KEY_VALUE: MsgType = MsgType {
    package: "diagnostic_msgs",
    name: "KeyValue",
    definition: "string key\nstring value\n",
    dependencies: &[],
};

/// The `diagnostic_status` message type (definition and dependencies).
pub static DIAGNOSTIC_STATUS: MsgType = MsgType {
    package: "diagnostic_msgs",
    name: "DiagnosticStatus",
    definition: "byte OK=0\nbyte WARN=1\nbyte ERROR=2\nbyte STALE=3\nbyte level\nstring name\nstring message\nstring hardware_id\nKeyValue[] values\n",
    dependencies: &[&KEY_VALUE],
};

/// The `diagnostic_array` message type (definition and dependencies).
pub static DIAGNOSTIC_ARRAY: MsgType = MsgType {
    package: "diagnostic_msgs",
    name: "DiagnosticArray",
    definition: "std_msgs/Header header\nDiagnosticStatus[] status\n",
    dependencies: &[&HEADER, &DIAGNOSTIC_STATUS],
};

/// The `clock` message type (definition and dependencies).
pub static CLOCK: MsgType = MsgType {
    package: "rosgraph_msgs",
    name: "Clock",
    definition: "builtin_interfaces/Time clock\n",
    dependencies: &[&TIME],
};

impl ParameterValue {
    /// The value as YAML text (for configuration overrides), or why it
    /// cannot be one.
    pub fn to_yaml(&self) -> Result<String, String> {
        use parameter_type as t;
        let seq = |items: Vec<String>| format!("[{}]", items.join(", "));
        Ok(match self.r#type {
            t::BOOL => self.bool_value.to_string(),
            t::INTEGER => self.integer_value.to_string(),
            t::DOUBLE => {
                if !self.double_value.is_finite() {
                    return Err(format!("{} is not finite", self.double_value));
                }
                format!("{:?}", self.double_value)
            }
            t::STRING => serde_norway::to_string(&self.string_value)
                .map_err(|e| e.to_string())?
                .trim()
                .to_string(),
            t::BOOL_ARRAY => seq(self
                .bool_array_value
                .iter()
                .map(|b| b.to_string())
                .collect()),
            t::INTEGER_ARRAY => seq(self
                .integer_array_value
                .iter()
                .map(|b| b.to_string())
                .collect()),
            t::DOUBLE_ARRAY => seq(self
                .double_array_value
                .iter()
                .map(|b| format!("{b:?}"))
                .collect()),
            t::STRING_ARRAY => seq(self
                .string_array_value
                .iter()
                .map(|s| {
                    serde_norway::to_string(s)
                        .map(|y| y.trim().to_string())
                        .unwrap_or_default()
                })
                .collect()),
            t::NOT_SET => return Err("the value is not set".into()),
            other => return Err(format!("parameter type {other} is not supported")),
        })
    }

    /// A YAML value as a parameter value.
    pub fn from_yaml(v: &serde_norway::Value) -> Self {
        use parameter_type as t;
        use serde_norway::Value as Y;
        let mut p = ParameterValue::default();
        match v {
            Y::Bool(b) => {
                p.r#type = t::BOOL;
                p.bool_value = *b;
            }
            Y::Number(n) if n.is_i64() => {
                p.r#type = t::INTEGER;
                p.integer_value = n.as_i64().unwrap_or(0);
            }
            Y::Number(n) => {
                p.r#type = t::DOUBLE;
                p.double_value = n.as_f64().unwrap_or(f64::NAN);
            }
            Y::String(s) => {
                p.r#type = t::STRING;
                p.string_value = s.clone();
            }
            Y::Sequence(items) => {
                if items.iter().all(|i| matches!(i, Y::String(_))) && !items.is_empty() {
                    p.r#type = t::STRING_ARRAY;
                    p.string_array_value = items
                        .iter()
                        .filter_map(|i| i.as_str().map(String::from))
                        .collect();
                } else if items.iter().all(|i| i.is_bool()) && !items.is_empty() {
                    p.r#type = t::BOOL_ARRAY;
                    p.bool_array_value = items.iter().filter_map(|i| i.as_bool()).collect();
                } else if items.iter().all(|i| i.is_i64()) && !items.is_empty() {
                    p.r#type = t::INTEGER_ARRAY;
                    p.integer_array_value = items.iter().filter_map(|i| i.as_i64()).collect();
                } else {
                    p.r#type = t::DOUBLE_ARRAY;
                    p.double_array_value = items.iter().filter_map(|i| i.as_f64()).collect();
                }
            }
            _ => p.r#type = t::NOT_SET,
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parameter_values_round_trip_through_yaml() {
        for text in ["5762.0", "3", "true", "hold", "[0.01, 0.02]", "[\"a:=b\"]"] {
            let y: serde_norway::Value = serde_norway::from_str(text).unwrap();
            let p = ParameterValue::from_yaml(&y);
            let back: serde_norway::Value = serde_norway::from_str(&p.to_yaml().unwrap()).unwrap();
            assert_eq!(y, back, "{text}");
        }
        let nan = ParameterValue {
            r#type: parameter_type::DOUBLE,
            double_value: f64::NAN,
            ..Default::default()
        };
        assert!(nan.to_yaml().unwrap_err().contains("not finite"));
    }

    #[test]
    fn wire_structs_follow_their_definitions() {
        use crate::msgs::msg_fields;
        let field_names =
            |def: &str| -> Vec<String> { msg_fields(def).into_iter().map(|(_, n)| n).collect() };
        assert_eq!(
            field_names(PARAMETER_VALUE.definition),
            [
                "type",
                "bool_value",
                "integer_value",
                "double_value",
                "string_value",
                "byte_array_value",
                "bool_array_value",
                "integer_array_value",
                "double_array_value",
                "string_array_value"
            ]
        );
        assert_eq!(
            field_names(LOG.definition),
            ["stamp", "level", "name", "msg", "file", "function", "line"]
        );
        assert_eq!(
            field_names(DIAGNOSTIC_STATUS.definition),
            ["level", "name", "message", "hardware_id", "values"]
        );
        // A ParameterEvent survives CDR.
        let e = ParameterEvent {
            stamp: Time::from_ns(1_700_000_000_123_456_789),
            node: "/friction_node".into(),
            changed_parameters: vec![Parameter {
                name: "contact.load_n".into(),
                value: ParameterValue {
                    r#type: parameter_type::DOUBLE,
                    double_value: 5762.0,
                    ..Default::default()
                },
            }],
            ..Default::default()
        };
        let bytes = crate::msgs::to_cdr(&e).unwrap();
        assert_eq!(crate::msgs::from_cdr::<ParameterEvent>(&bytes).unwrap(), e);
    }
}

#[cfg(feature = "ros2")]
mod ros2_messages {
    use super::*;
    impl ros2_client::Message for ParameterEvent {}
    impl ros2_client::Message for Log {}
    impl ros2_client::Message for DiagnosticArray {}
    impl ros2_client::Message for Clock {}
    impl ros2_client::Message for ListParametersRequest {}
    impl ros2_client::Message for ListParametersResponse {}
    impl ros2_client::Message for NamesRequest {}
    impl ros2_client::Message for GetParametersResponse {}
    impl ros2_client::Message for GetParameterTypesResponse {}
    impl ros2_client::Message for DescribeParametersResponse {}
    impl ros2_client::Message for SetParametersRequest {}
    impl ros2_client::Message for SetParametersResponse {}
    impl ros2_client::Message for SetParametersAtomicallyResponse {}
    impl ros2_client::Message for TriggerRequest {}
    impl ros2_client::Message for TriggerResponse {}
}
