//! The message types the project reads from bags, as timed samples.
//!
//! A channel is accepted only when its encoding is `cdr`, its schema
//! encoding `ros2msg` and its schema's top-level fields are those of the
//! declared type ([`check_schema`]): a lying schema is named, not decoded
//! into nonsense. Decoding is bounded by the message's bytes (a sequence
//! that declares more elements than the bytes hold is a decode error).

use super::{BagError, BagMessage, ChannelInfo};
use crate::msgs::{self, command_codec, MsgType};

/// What to read from a topic.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SampleKind {
    /// `std_msgs/msg/Float64` `data`.
    Float64,
    /// `geometry_msgs/msg/TwistStamped` `twist.linear.x`.
    TwistLinearX,
    /// `sensor_msgs/msg/JointState`: the velocity of one joint (an empty
    /// name means the only joint).
    JointVelocity(String),
    /// `sensor_msgs/msg/JointState`: the effort of one joint.
    JointEffort(String),
    /// `sensor_msgs/msg/JointState`: the position of one joint.
    JointPosition(String),
    /// `sensor_msgs/msg/Temperature` `temperature` (°C).
    Temperature,
}

impl SampleKind {
    /// The message type this kind reads.
    pub fn msg_type(&self) -> &'static MsgType {
        match self {
            SampleKind::Float64 => &msgs::FLOAT64,
            SampleKind::TwistLinearX => &msgs::TWIST_STAMPED,
            SampleKind::JointVelocity(_)
            | SampleKind::JointEffort(_)
            | SampleKind::JointPosition(_) => &msgs::JOINT_STATE,
            SampleKind::Temperature => &msgs::TEMPERATURE,
        }
    }

    /// A velocity source for a schema name (JointState needs its joint).
    pub fn velocity_for(schema_name: &str, joint: Option<&str>) -> Option<Self> {
        match schema_name {
            "std_msgs/msg/Float64" => Some(SampleKind::Float64),
            "geometry_msgs/msg/TwistStamped" => Some(SampleKind::TwistLinearX),
            "sensor_msgs/msg/JointState" => Some(SampleKind::JointVelocity(
                joint.unwrap_or_default().to_string(),
            )),
            _ => None,
        }
    }

    fn joint(&self) -> Option<&str> {
        match self {
            SampleKind::JointVelocity(j)
            | SampleKind::JointEffort(j)
            | SampleKind::JointPosition(j) => Some(j),
            _ => None,
        }
    }
}

/// The load topic used when none is named: the first valid
/// `std_msgs/msg/Float64` topic whose name ends in `normal_load` and that
/// holds a message (a node run without a load input records the topic
/// empty: the configuration's load is then the load).
pub fn default_load_topic(scan: &super::BagScan) -> Option<String> {
    scan.channels
        .iter()
        .find(|c| {
            c.topic.ends_with("normal_load")
                && c.messages > 0
                && TopicDecoder::new(c, SampleKind::Float64).is_ok()
        })
        .map(|c| c.topic.clone())
}

/// The temperature topic used when none is named: the first valid
/// `sensor_msgs/msg/Temperature` topic whose name ends in `temperature`
/// and that holds a message.
pub fn default_temperature_topic(scan: &super::BagScan) -> Option<String> {
    scan.channels
        .iter()
        .find(|c| {
            c.topic.ends_with("temperature")
                && c.messages > 0
                && TopicDecoder::new(c, SampleKind::Temperature).is_ok()
        })
        .map(|c| c.topic.clone())
}

/// Types a velocity can be read from.
pub const VELOCITY_TYPES: &str =
    "std_msgs/msg/Float64, geometry_msgs/msg/TwistStamped or sensor_msgs/msg/JointState";

fn norm_type(t: &str) -> String {
    // "std_msgs/msg/Header", "std_msgs/Header", "Header" → "Header".
    t.rsplit('/').next().unwrap_or(t).to_string()
}

/// The channel's encodings and its schema's top-level fields must be those
/// of `expected`.
pub fn check_schema(c: &ChannelInfo, expected: &MsgType) -> Result<(), BagError> {
    let mismatch = |message: String| BagError::SchemaMismatch {
        topic: c.topic.clone(),
        type_name: c.schema_name.clone(),
        message,
    };
    if c.message_encoding != "cdr" {
        return Err(mismatch(format!(
            "message encoding `{}`, expected `cdr`",
            c.message_encoding
        )));
    }
    // A Humble SQLite bag carries no message definitions: the declared type
    // name (already matched) is all there is to check.
    if c.schema_encoding.is_empty() && c.schema_text.is_empty() {
        return Ok(());
    }
    if c.schema_encoding != "ros2msg" {
        return Err(mismatch(format!(
            "schema encoding `{}`, expected `ros2msg`",
            c.schema_encoding
        )));
    }
    let main = c.schema_text.split("\n====").next().unwrap_or("");
    let got: Vec<(String, String)> = msgs::msg_fields(main)
        .into_iter()
        .map(|(t, n)| (norm_type(&t), n))
        .collect();
    let want: Vec<(String, String)> = msgs::msg_fields(expected.definition)
        .into_iter()
        .map(|(t, n)| (norm_type(&t), n))
        .collect();
    if got != want {
        let show = |v: &[(String, String)]| {
            v.iter()
                .map(|(t, n)| format!("{t} {n}"))
                .collect::<Vec<_>>()
                .join("; ")
        };
        return Err(mismatch(format!(
            "fields [{}], expected [{}]",
            show(&got),
            show(&want)
        )));
    }
    Ok(())
}

/// Decode message `index` of channel `c` as `T`.
pub fn decode_cdr<T: serde::de::DeserializeOwned>(
    c: &ChannelInfo,
    index: u64,
    data: &[u8],
) -> Result<T, BagError> {
    msgs::from_cdr(data).map_err(|e| BagError::Decode {
        topic: c.topic.clone(),
        type_name: c.schema_name.clone(),
        index,
        message: e.to_string(),
    })
}

/// The stamp of a sample by the stamp rule
/// ([`crate::msgs::command_codec::stamp_or`]): the header's when set,
/// else the publish time, else the log time.
fn stamp_or(header: u64, publish: u64, log: u64) -> u64 {
    command_codec::stamp_or(header, || if publish != 0 { publish } else { log })
}

/// Turns one topic's messages into `(stamp_ns, value)` samples.
#[derive(Debug, Clone)]
pub struct TopicDecoder {
    /// The channel decoded.
    pub channel: ChannelInfo,
    /// What is read from each message.
    pub kind: SampleKind,
    /// Messages decoded so far (1-based index of the last).
    index: u64,
    /// Where the joint was in the last message.
    joint_hint: Option<usize>,
    /// Names of the first JointState (for messages).
    pub joints: Vec<String>,
}

impl TopicDecoder {
    /// Check the channel's schema against the kind's type.
    pub fn new(channel: &ChannelInfo, kind: SampleKind) -> Result<Self, BagError> {
        let expected = kind.msg_type();
        if channel.schema_name != expected.full_name() {
            return Err(BagError::UnsupportedType {
                topic: channel.topic.clone(),
                type_name: channel.schema_name.clone(),
                expected: expected.full_name(),
            });
        }
        check_schema(channel, expected)?;
        Ok(Self {
            channel: channel.clone(),
            kind,
            index: 0,
            joint_hint: None,
            joints: Vec::new(),
        })
    }

    /// The channel's topic.
    pub fn topic(&self) -> &str {
        &self.channel.topic
    }

    /// The joint actually read (after a message named the only one).
    pub fn joint(&self) -> Option<&str> {
        self.kind.joint()
    }

    /// Decode one message of this topic.
    pub fn sample(&mut self, m: &BagMessage<'_>) -> Result<(u64, f64), BagError> {
        self.index += 1;
        let idx = self.index;
        let c = &self.channel;
        match &mut self.kind {
            SampleKind::Float64 | SampleKind::TwistLinearX | SampleKind::Temperature => {
                let read = match self.kind {
                    SampleKind::Float64 => command_codec::float64,
                    SampleKind::TwistLinearX => command_codec::twist_linear_x,
                    _ => command_codec::temperature,
                };
                let (value, header) = read(m.data).map_err(|e| BagError::Decode {
                    topic: c.topic.clone(),
                    type_name: c.schema_name.clone(),
                    index: idx,
                    message: e.to_string(),
                })?;
                Ok((stamp_or(header, m.publish_time, m.log_time), value))
            }
            SampleKind::JointVelocity(joint)
            | SampleKind::JointEffort(joint)
            | SampleKind::JointPosition(joint) => {
                let j: msgs::JointState = decode_cdr(c, idx, m.data)?;
                if self.joints.is_empty() {
                    self.joints = j.name.clone();
                }
                if joint.is_empty() {
                    if j.name.len() == 1 {
                        *joint = j.name[0].clone();
                    } else {
                        return Err(BagError::JointRequired {
                            topic: c.topic.clone(),
                            joints: j.name.clone(),
                        });
                    }
                }
                let k = match self.joint_hint.filter(|k| j.name.get(*k) == Some(joint)) {
                    Some(k) => k,
                    None => j.name.iter().position(|n| n == joint).ok_or_else(|| {
                        BagError::JointMissing {
                            topic: c.topic.clone(),
                            joint: joint.clone(),
                            joints: j.name.clone(),
                        }
                    })?,
                };
                self.joint_hint = Some(k);
                let (values, what) = match &self.kind {
                    SampleKind::JointVelocity(_) => (&j.velocity, "velocity"),
                    SampleKind::JointEffort(_) => (&j.effort, "effort"),
                    _ => (&j.position, "position"),
                };
                let v = values.get(k).copied().ok_or_else(|| BagError::Decode {
                    topic: c.topic.clone(),
                    type_name: c.schema_name.clone(),
                    index: idx,
                    message: format!(
                        "joint `{}` has no {what} entry ({} {what} values for {} names)",
                        j.name[k],
                        values.len(),
                        j.name.len()
                    ),
                })?;
                Ok((
                    stamp_or(j.header.stamp.to_ns(), m.publish_time, m.log_time),
                    v,
                ))
            }
        }
    }
}

/// Samples of several topics, read in one pass over the bag.
#[derive(Debug, Clone, Default)]
pub struct TopicSamples {
    /// `(stamp_ns, value)` per decoder, in bag order.
    pub samples: Vec<Vec<(u64, f64)>>,
    /// Where reading stopped early (a damaged file or a message that does
    /// not decode); what came before is in `samples`.
    pub damage: Option<super::Damage>,
}

/// Decode every message of the decoders' topics. A joint that is not in
/// the messages is a usage error; any other decode failure is damage.
pub fn read_topics(
    bag: &super::Bag,
    decoders: &mut [TopicDecoder],
) -> Result<TopicSamples, BagError> {
    let mut out = TopicSamples {
        samples: vec![Vec::new(); decoders.len()],
        damage: None,
    };
    let (mut read, mut last_log) = (0u64, None);
    for m in bag.messages()? {
        let m = match m {
            Ok(m) => m,
            Err(d) => {
                out.damage = Some(d);
                break;
            }
        };
        let view = m.view();
        // Every decoder of the message's topic gets it: one topic may carry
        // two of the inputs (a JointState's velocity and its effort).
        let mut failed = None;
        for (k, d) in decoders.iter_mut().enumerate() {
            if d.topic() != view.topic {
                continue;
            }
            match d.sample(&view) {
                Ok(s) => out.samples[k].push(s),
                Err(e @ (BagError::JointRequired { .. } | BagError::JointMissing { .. })) => {
                    return Err(e)
                }
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        if let Some(e) = failed {
            out.damage = Some(super::Damage {
                after_messages: read,
                last_log_time_ns: last_log,
                file: bag.path().to_path_buf(),
                error: e.to_string(),
            });
            break;
        }
        read += 1;
        last_log = Some(view.log_time);
    }
    Ok(out)
}
