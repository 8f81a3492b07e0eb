//! One command on the wire and back: the message a command (velocity,
//! load, temperature, one joint's velocity) travels in, and the value and
//! stamp read out of it, with one stamp rule. ROS 2 I/O and its test peer,
//! recording and bag reading all go through here.
//!
//! | command | message | value | stamp |
//! |---|---|---|---|
//! | velocity, `command_type: float64` | `std_msgs/msg/Float64` | `data`, m/s | none: the fallback |
//! | velocity, `command_type: twist_stamped` | `geometry_msgs/msg/TwistStamped` | `twist.linear.x`, m/s | `header.stamp` |
//! | load | `std_msgs/msg/Float64` | `data`, N | none: the fallback |
//! | temperature | `sensor_msgs/msg/Temperature` | `temperature`, °C | `header.stamp` |
//! | one joint's velocity | `sensor_msgs/msg/JointState` | `velocity[k]` of the joint named `name[k]` | `header.stamp` |
//!
//! **The stamp rule** ([`stamp_or`]): a header's stamp when it is set (not
//! zero), else the fallback: the sender's publish time, then the time the
//! sample was logged or received.

use super::{
    CdrError, Command, CommandKind, Float64, Header, JointState, Temperature, Time, TwistStamped,
};
use serde::{Deserialize, Serialize};

/// The message a velocity command travels in (`ros.command_type`): the
/// wire's choice, decided here and read by the configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CommandType {
    /// std_msgs/msg/Float64, m/s.
    Float64,
    /// geometry_msgs/msg/TwistStamped, linear.x in m/s.
    TwistStamped,
}

/// A command as the message it travels in.
#[derive(Debug, Clone, PartialEq)]
pub enum CommandMessage {
    /// A velocity (Float64 commands) or a load.
    Float64(Float64),
    /// A velocity (TwistStamped commands).
    Twist(TwistStamped),
    /// A temperature.
    Temperature(Temperature),
    /// One joint's velocity.
    JointState(JointState),
}

impl CommandMessage {
    /// The message carrying `c` when velocities are sent as `velocity`,
    /// stamped with `c.stamp_ns` in frame `frame_id` where it has a header;
    /// `joint` names a joint velocity's joint. None: a joint velocity
    /// without a joint's name.
    pub fn of(
        c: &Command,
        velocity: CommandType,
        frame_id: &str,
        joint: Option<&str>,
    ) -> Option<Self> {
        let header = || Header {
            stamp: Time::from_ns(c.stamp_ns),
            frame_id: frame_id.to_string(),
        };
        Some(match (c.kind, velocity) {
            (CommandKind::Load, _) | (CommandKind::Velocity, CommandType::Float64) => {
                Self::Float64(Float64 { data: c.value })
            }
            (CommandKind::Velocity, CommandType::TwistStamped) => {
                let mut m = TwistStamped {
                    header: header(),
                    ..Default::default()
                };
                m.twist.linear.x = c.value;
                Self::Twist(m)
            }
            (CommandKind::Temperature, _) => Self::Temperature(Temperature {
                header: header(),
                temperature: c.value,
                variance: 0.0,
            }),
            (CommandKind::JointVelocity { .. }, _) => Self::JointState(JointState {
                header: header(),
                name: vec![joint?.to_string()],
                position: Vec::new(),
                velocity: vec![c.value],
                effort: Vec::new(),
            }),
        })
    }

    /// The message in CDR.
    pub fn to_cdr(&self) -> Result<Vec<u8>, CdrError> {
        match self {
            Self::Float64(m) => super::to_cdr(m),
            Self::Twist(m) => super::to_cdr(m),
            Self::Temperature(m) => super::to_cdr(m),
            Self::JointState(m) => super::to_cdr(m),
        }
    }
}

/// The stamp rule: `header_ns` when it is set (not zero), else `fallback`.
pub fn stamp_or(header_ns: u64, fallback: impl FnOnce() -> u64) -> u64 {
    if header_ns != 0 {
        header_ns
    } else {
        fallback()
    }
}

/// The value of a `std_msgs/msg/Float64` (no header: stamp 0).
pub fn float64(cdr: &[u8]) -> Result<(f64, u64), CdrError> {
    super::from_cdr::<Float64>(cdr).map(|m| (m.data, 0))
}

/// `twist.linear.x` of a `geometry_msgs/msg/TwistStamped` and its header's
/// stamp.
pub fn twist_linear_x(cdr: &[u8]) -> Result<(f64, u64), CdrError> {
    super::from_cdr::<TwistStamped>(cdr).map(|m| (m.twist.linear.x, m.header.stamp.to_ns()))
}

/// The temperature of a `sensor_msgs/msg/Temperature` and its header's
/// stamp.
pub fn temperature(cdr: &[u8]) -> Result<(f64, u64), CdrError> {
    super::from_cdr::<Temperature>(cdr).map(|m| (m.temperature, m.header.stamp.to_ns()))
}

/// The value and header stamp (0: none) of a command of `kind` sent with
/// velocities as `velocity`. A joint's velocity comes in a JointState of
/// several joints, read by name where the joints are known (not here).
pub fn decode(
    kind: CommandKind,
    velocity: CommandType,
    cdr: &[u8],
) -> Result<(f64, u64), CdrError> {
    match (kind, velocity) {
        (CommandKind::Temperature, _) => temperature(cdr),
        (CommandKind::Velocity, CommandType::TwistStamped) => twist_linear_x(cdr),
        (CommandKind::Velocity, CommandType::Float64) | (CommandKind::Load, _) => float64(cdr),
        (CommandKind::JointVelocity { .. }, _) => Err(CdrError::JointByName),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn command(kind: CommandKind, value: f64) -> Command {
        Command {
            kind,
            value,
            stamp_ns: 1_500_000_007,
        }
    }

    #[test]
    fn every_command_decodes_to_its_value_and_stamp_after_encoding() {
        let joint = CommandKind::JointVelocity {
            contact: 0,
            last: true,
            joint: true,
        };
        for (kind, ty, stamped) in [
            (CommandKind::Velocity, CommandType::Float64, false),
            (CommandKind::Velocity, CommandType::TwistStamped, true),
            (CommandKind::Load, CommandType::TwistStamped, false),
            (CommandKind::Temperature, CommandType::Float64, true),
        ] {
            let c = command(kind, 0.25);
            let cdr = CommandMessage::of(&c, ty, "slider", None)
                .unwrap()
                .to_cdr()
                .unwrap();
            let (value, stamp) = decode(kind, ty, &cdr).unwrap();
            assert_eq!(value, 0.25, "{kind:?} {ty:?}");
            assert_eq!(stamp, if stamped { c.stamp_ns } else { 0 }, "{kind:?}");
        }
        let c = command(joint, -1.5);
        let Some(CommandMessage::JointState(m)) =
            CommandMessage::of(&c, CommandType::Float64, "slider", Some("elbow"))
        else {
            panic!("a joint velocity travels in a JointState");
        };
        assert_eq!(
            (m.name, m.velocity),
            (vec!["elbow".to_string()], vec![-1.5])
        );
        assert_eq!(
            CommandMessage::of(&c, CommandType::Float64, "slider", None),
            None
        );
        assert!(decode(joint, CommandType::Float64, &[]).is_err());
    }

    #[test]
    fn a_header_stamp_wins_over_the_fallback_unless_it_is_zero() {
        assert_eq!(stamp_or(7, || 9), 7);
        assert_eq!(stamp_or(0, || 9), 9);
    }

    #[test]
    fn a_truncated_message_is_an_error_not_a_value() {
        assert!(float64(&[0, 1, 0, 0, 1]).is_err());
        assert!(twist_linear_x(&[]).is_err());
    }
}
