//! Replay: run the model over the velocity recorded in any ROS 2 MCAP bag.
//!
//! The commanded velocity is read from a channel of type
//! `std_msgs/msg/Float64`, `geometry_msgs/msg/TwistStamped` (`linear.x`) or
//! `sensor_msgs/msg/JointState` (the `velocity` of one joint), detected from
//! its schema; a `std_msgs/msg/Float64` load channel is optional. The model
//! runs in lockstep on the messages' timestamps (the node's own loop, fed one
//! command at a time), so a replay is exactly what the node would have done.
//!
//! For a bag recorded by friction-node, replay uses the recorded
//! configuration by default and is driven by the recorded estimates' own
//! velocity and load (what each step of the node actually applied, in timer
//! and lockstep mode alike); it then reports whether the re-simulation is
//! bit-identical to the recording, and the largest deviation per field if not
//! (the determinism oracle).
//!
//! A truncated or corrupt bag replays everything before the damage and says
//! where it stopped. Nothing is written before the input is validated.

use crate::config::{Config, ConfigError, Origin, TimeoutBehaviour};
use crate::msgs::{
    self, estimate_constants as codes, Command, CommandKind, EstimateRecord, MsgType,
};
use crate::node::{LiveStatus, Loop, NodeError};
use crate::physics::Estimate;
use crate::transport::memory::MemoryLink;
use crate::transport::PeerPort;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Errors of the replay layer.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error("cannot read bag {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{} is not an MCAP file: {message}", path.display())]
    NotMcap { path: PathBuf, message: String },
    #[error("no usable velocity topic (std_msgs/msg/Float64, geometry_msgs/msg/TwistStamped or sensor_msgs/msg/JointState); the bag has:\n{}", list(.available))]
    NoVelocityTopic {
        available: Vec<(String, String, u64)>,
    },
    #[error("several topics could be the velocity; choose one with --topic:\n{}", list(.candidates))]
    AmbiguousVelocity {
        candidates: Vec<(String, String, u64)>,
    },
    #[error("topic `{topic}` is not in the bag; it has:\n{}", list(.available))]
    TopicNotFound {
        topic: String,
        available: Vec<(String, String, u64)>,
    },
    #[error(
        "topic `{topic}` has type `{type_name}`, which replay cannot read (expected {expected})"
    )]
    UnsupportedType {
        topic: String,
        type_name: String,
        expected: &'static str,
    },
    #[error(
        "topic `{topic}`: the schema does not match its declared type `{type_name}`: {message}"
    )]
    SchemaMismatch {
        topic: String,
        type_name: String,
        message: String,
    },
    #[error("topic `{topic}` is JointState: choose a joint with --joint (joints: {})", .joints.join(", "))]
    JointRequired { topic: String, joints: Vec<String> },
    #[error("topic `{topic}` has no joint `{joint}` (joints: {})", .joints.join(", "))]
    JointMissing {
        topic: String,
        joint: String,
        joints: Vec<String>,
    },
    #[error("topic `{topic}`, message {index}: cannot decode as {type_name}: {message}")]
    Decode {
        topic: String,
        type_name: String,
        index: u64,
        message: String,
    },
    #[error("topic `{topic}` has no messages before {}", damage_note(.damage))]
    Empty {
        topic: String,
        damage: Option<Damage>,
    },
    #[error("cannot write {}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    #[error("the recorded configuration in the bag: {0}")]
    RecordedConfig(ConfigError),
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Node(#[from] NodeError),
}

fn list(v: &[(String, String, u64)]) -> String {
    if v.is_empty() {
        return "  (no channels)".into();
    }
    v.iter()
        .map(|(t, ty, n)| format!("  {t}  [{ty}]  {n} messages"))
        .collect::<Vec<_>>()
        .join("\n")
}

fn damage_note(d: &Option<Damage>) -> String {
    match d {
        Some(d) => format!("the damage ({d})"),
        None => "the end of the bag".into(),
    }
}

/// Where a damaged bag stopped being readable.
#[derive(Debug, Clone, PartialEq)]
pub struct Damage {
    /// Messages read before the damage.
    pub after_messages: u64,
    /// Log time of the last good message, ns.
    pub last_log_time_ns: Option<u64>,
    pub error: String,
}

impl std::fmt::Display for Damage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "after {} messages", self.after_messages)?;
        if let Some(t) = self.last_log_time_ns {
            write!(f, " (last good log time {:.6} s)", t as f64 / 1e9)?;
        }
        write!(f, ": {}", self.error)
    }
}

/// One channel of the bag.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelInfo {
    pub topic: String,
    pub schema_name: String,
    pub schema_encoding: String,
    pub schema_text: String,
    pub message_encoding: String,
    pub messages: u64,
}

impl ChannelInfo {
    fn new(c: &mcap::Channel<'_>, messages: u64) -> Self {
        let schema = c.schema.as_ref();
        Self {
            topic: c.topic.clone(),
            schema_name: schema.map_or(String::new(), |s| s.name.clone()),
            schema_encoding: schema.map_or(String::new(), |s| s.encoding.clone()),
            schema_text: schema.map_or(String::new(), |s| {
                String::from_utf8_lossy(&s.data).into_owned()
            }),
            message_encoding: c.message_encoding.clone(),
            messages,
        }
    }
}

/// What a first pass over the bag found.
#[derive(Debug, Clone)]
pub struct BagScan {
    pub channels: BTreeMap<u16, ChannelInfo>,
    pub messages: u64,
    /// `config_yaml` of the `friction_node` metadata record, if any.
    pub recorded_config: Option<String>,
    pub damage: Option<Damage>,
}

impl BagScan {
    fn listing(&self) -> Vec<(String, String, u64)> {
        self.channels
            .values()
            .map(|c| (c.topic.clone(), c.schema_name.clone(), c.messages))
            .collect()
    }
}

/// A memory-mapped bag.
pub struct Bag {
    path: PathBuf,
    map: memmap2::Mmap,
}

impl Bag {
    pub fn open(path: &Path) -> Result<Self, ReplayError> {
        let io = |source| ReplayError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = std::fs::File::open(path).map_err(io)?;
        // SAFETY: the bag is opened read-only; a concurrent writer could
        // change it under us, which the mcap reader reports as damage.
        let map = unsafe { memmap2::Mmap::map(&file) }.map_err(io)?;
        if map.len() < 8 || &map[..8] != b"\x89MCAP0\r\n" {
            return Err(ReplayError::NotMcap {
                path: path.to_path_buf(),
                message: "it does not start with the MCAP magic".into(),
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            map,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn bytes(&self) -> &[u8] {
        &self.map
    }

    fn stream(&self) -> Result<mcap::MessageStream<'_>, ReplayError> {
        mcap::MessageStream::new_with_options(
            &self.map,
            mcap::read::Options::IgnoreEndMagic | mcap::read::Options::ValidateChunkCrcs,
        )
        .map_err(|e| ReplayError::NotMcap {
            path: self.path.clone(),
            message: e.to_string(),
        })
    }

    /// Channels, counts and the recorded config: from the summary section
    /// when the bag has a complete one (damage inside chunks then shows in
    /// the decoding pass), else by reading every message (a recording that
    /// was never finalised), noting where the bag stops being readable.
    pub fn scan(&self) -> Result<BagScan, ReplayError> {
        let mut scan = match self.scan_summary() {
            Some(s) => s,
            None => self.scan_messages()?,
        };
        scan.recorded_config = self.recorded_config();
        Ok(scan)
    }

    fn scan_summary(&self) -> Option<BagScan> {
        let summary = mcap::Summary::read(&self.map).ok()??;
        let stats = summary.stats.as_ref()?;
        let channels = summary
            .channels
            .iter()
            .map(|(id, c)| {
                let n = stats.channel_message_counts.get(id).copied().unwrap_or(0);
                (*id, ChannelInfo::new(c, n))
            })
            .collect();
        Some(BagScan {
            channels,
            messages: stats.message_count,
            recorded_config: None,
            damage: None,
        })
    }

    fn scan_messages(&self) -> Result<BagScan, ReplayError> {
        let mut scan = BagScan {
            channels: BTreeMap::new(),
            messages: 0,
            recorded_config: None,
            damage: None,
        };
        let mut last = None;
        for m in self.stream()? {
            match m {
                Ok(m) => {
                    scan.messages += 1;
                    last = Some(m.log_time);
                    let c = &m.channel;
                    scan.channels
                        .entry(c.id)
                        .or_insert_with(|| ChannelInfo::new(c, 0))
                        .messages += 1;
                }
                Err(e) => {
                    scan.damage = Some(Damage {
                        after_messages: scan.messages,
                        last_log_time_ns: last,
                        error: e.to_string(),
                    });
                    break;
                }
            }
        }
        Ok(scan)
    }

    /// `config_yaml` of the `friction_node` metadata record. Metadata
    /// records sit outside the chunks: a walk over the records (chunks are
    /// skipped, not decompressed) finds them even without a summary.
    fn recorded_config(&self) -> Option<String> {
        let reader = mcap::read::LinearReader::new_with_options(
            &self.map,
            mcap::read::Options::IgnoreEndMagic.into(),
        )
        .ok()?;
        for r in reader {
            match r {
                Ok(mcap::records::Record::Metadata(m)) if m.name == "friction_node" => {
                    return m.metadata.get("config_yaml").cloned();
                }
                Ok(_) => {}
                Err(_) => break,
            }
        }
        None
    }
}

/// How the velocity is read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum VelocityKind {
    Float64,
    TwistStamped,
    JointState {
        joint: String,
        index_hint: Option<usize>,
    },
}

/// What drives the replay.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InputMode {
    /// A velocity (and optional load) topic.
    Topics {
        velocity: String,
        kind: VelocityKind,
        load: Option<String>,
    },
    /// A friction-node bag: the recorded estimates' velocity and load.
    RecordedEstimates { topic: String },
}

/// Options of a replay.
#[derive(Debug, Clone, Default)]
pub struct ReplayOptions {
    /// The velocity topic (default: detected).
    pub topic: Option<String>,
    /// JointState: which joint.
    pub joint: Option<String>,
    /// The load topic (default: a Float64 topic ending in `normal_load`).
    pub load_topic: Option<String>,
    /// A parameter file instead of the recorded (or default) configuration.
    pub config: Option<PathBuf>,
    /// Overrides applied to whichever configuration is used.
    pub overrides: Vec<String>,
}

/// The validated input of a replay.
#[derive(Debug, Clone)]
pub struct PreparedReplay {
    pub config: Config,
    pub config_source: String,
    pub mode: InputMode,
    /// Commands in time order.
    pub commands: Vec<Command>,
    /// The recorded estimates (friction-node bags).
    pub recorded: Vec<EstimateRecord>,
    pub scan: BagScan,
    /// Silences in the velocity topic longer than the command timeout.
    pub gaps: Vec<Gap>,
    /// Velocity messages read.
    pub velocity_messages: usize,
}

const VELOCITY_TYPES: &str =
    "std_msgs/msg/Float64, geometry_msgs/msg/TwistStamped or sensor_msgs/msg/JointState";

fn norm_type(t: &str) -> String {
    // "std_msgs/msg/Header", "std_msgs/Header", "Header" → "Header".
    t.rsplit('/').next().unwrap_or(t).to_string()
}

/// The schema text's top-level fields must be those of the declared type.
fn check_schema(c: &ChannelInfo, expected: &MsgType) -> Result<(), ReplayError> {
    let mismatch = |message: String| ReplayError::SchemaMismatch {
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

fn velocity_kind(schema: &str) -> Option<&'static MsgType> {
    match schema {
        "std_msgs/msg/Float64" => Some(&msgs::FLOAT64),
        "geometry_msgs/msg/TwistStamped" => Some(&msgs::TWIST_STAMPED),
        "sensor_msgs/msg/JointState" => Some(&msgs::JOINT_STATE),
        _ => None,
    }
}

fn decode<T: serde::de::DeserializeOwned>(
    c: &ChannelInfo,
    index: u64,
    data: &[u8],
) -> Result<T, ReplayError> {
    msgs::from_cdr(data).map_err(|message| ReplayError::Decode {
        topic: c.topic.clone(),
        type_name: c.schema_name.clone(),
        index,
        message,
    })
}

/// Choose the configuration: `--config`, else the bag's recorded one, else
/// the default; overrides on top.
fn choose_config(scan: &BagScan, opts: &ReplayOptions) -> Result<(Config, String), ReplayError> {
    if let Some(p) = &opts.config {
        return Ok((
            Config::load(Some(p), &opts.overrides)?,
            p.display().to_string(),
        ));
    }
    if let Some(text) = &scan.recorded_config {
        let c = Config::from_yaml(text, &Origin::Embedded, &opts.overrides)
            .map_err(ReplayError::RecordedConfig)?;
        return Ok((c, "recorded in the bag".into()));
    }
    Ok((
        Config::load(None, &opts.overrides)?,
        "built-in default".into(),
    ))
}

/// Validate the bag against the options and decode every input.
pub fn prepare(bag: &Bag, opts: &ReplayOptions) -> Result<PreparedReplay, ReplayError> {
    let mut scan = bag.scan()?;
    let (config, config_source) = choose_config(&scan, opts)?;
    let find = |topic: &str| {
        scan.channels
            .iter()
            .find(|(_, c)| c.topic == topic)
            .map(|(id, c)| (*id, c.clone()))
    };
    // A friction-node bag without --topic: drive it by its estimates.
    let estimate_channel = scan
        .channels
        .iter()
        .find(|(_, c)| c.schema_name == "friction_msgs/msg/FrictionEstimate")
        .map(|(id, c)| (*id, c.clone()));
    let mode = match (&opts.topic, &estimate_channel, &scan.recorded_config) {
        (None, Some((_, c)), Some(_)) => {
            check_schema(c, &msgs::FRICTION_ESTIMATE)?;
            InputMode::RecordedEstimates {
                topic: c.topic.clone(),
            }
        }
        _ => {
            let (vel_topic, vel) = match &opts.topic {
                Some(t) => find(t).map(|(_, c)| (t.clone(), c)).ok_or_else(|| {
                    ReplayError::TopicNotFound {
                        topic: t.clone(),
                        available: scan.listing(),
                    }
                })?,
                None => {
                    let candidates: Vec<&ChannelInfo> = scan
                        .channels
                        .values()
                        .filter(|c| {
                            velocity_kind(&c.schema_name).is_some()
                                && !c.topic.ends_with("normal_load")
                                && !c.topic.ends_with("friction_force")
                        })
                        .collect();
                    let preferred: Vec<&&ChannelInfo> = candidates
                        .iter()
                        .filter(|c| c.topic.ends_with("cmd_velocity"))
                        .collect();
                    match (candidates.len(), preferred.len()) {
                        (_, 1) => (preferred[0].topic.clone(), (*preferred[0]).clone()),
                        (1, _) => (candidates[0].topic.clone(), candidates[0].clone()),
                        (0, _) => {
                            return Err(ReplayError::NoVelocityTopic {
                                available: scan.listing(),
                            })
                        }
                        _ => {
                            return Err(ReplayError::AmbiguousVelocity {
                                candidates: candidates
                                    .iter()
                                    .map(|c| (c.topic.clone(), c.schema_name.clone(), c.messages))
                                    .collect(),
                            })
                        }
                    }
                }
            };
            let Some(t) = velocity_kind(&vel.schema_name) else {
                return Err(ReplayError::UnsupportedType {
                    topic: vel_topic,
                    type_name: vel.schema_name,
                    expected: VELOCITY_TYPES,
                });
            };
            check_schema(&vel, t)?;
            let kind = match vel.schema_name.as_str() {
                "std_msgs/msg/Float64" => VelocityKind::Float64,
                "geometry_msgs/msg/TwistStamped" => VelocityKind::TwistStamped,
                _ => VelocityKind::JointState {
                    joint: opts.joint.clone().unwrap_or_default(),
                    index_hint: None,
                },
            };
            let load = match &opts.load_topic {
                Some(t) => {
                    let (_, c) = find(t).ok_or_else(|| ReplayError::TopicNotFound {
                        topic: t.clone(),
                        available: scan.listing(),
                    })?;
                    if c.schema_name != "std_msgs/msg/Float64" {
                        return Err(ReplayError::UnsupportedType {
                            topic: t.clone(),
                            type_name: c.schema_name,
                            expected: "std_msgs/msg/Float64",
                        });
                    }
                    check_schema(&c, &msgs::FLOAT64)?;
                    Some(t.clone())
                }
                None => scan
                    .channels
                    .values()
                    .find(|c| {
                        c.topic.ends_with("normal_load")
                            && c.schema_name == "std_msgs/msg/Float64"
                            && check_schema(c, &msgs::FLOAT64).is_ok()
                    })
                    .map(|c| c.topic.clone()),
            };
            InputMode::Topics {
                velocity: vel_topic,
                kind,
                load,
            }
        }
    };
    let Inputs {
        commands,
        recorded,
        mode,
        gaps,
        velocity_messages,
        damage,
    } = decode_inputs(bag, &scan, &config, mode)?;
    if damage.is_some() {
        scan.damage = damage;
    }
    Ok(PreparedReplay {
        config,
        config_source,
        mode,
        commands,
        recorded,
        scan,
        gaps,
        velocity_messages,
    })
}

fn stamp_or(stamp: u64, publish: u64, log: u64) -> u64 {
    if stamp != 0 {
        stamp
    } else if publish != 0 {
        publish
    } else {
        log
    }
}

/// What [`decode_inputs`] read.
struct Inputs {
    commands: Vec<Command>,
    recorded: Vec<EstimateRecord>,
    mode: InputMode,
    gaps: Vec<Gap>,
    velocity_messages: usize,
    /// A message that did not decode (everything before it is kept).
    damage: Option<Damage>,
}

fn decode_inputs(
    bag: &Bag,
    scan: &BagScan,
    config: &Config,
    mut mode: InputMode,
) -> Result<Inputs, ReplayError> {
    let mut commands = Vec::new();
    let mut velocity_samples: Vec<(u64, f64)> = Vec::new();
    let mut load_samples: Vec<(u64, f64)> = Vec::new();
    let mut recorded = Vec::new();
    let mut joints_seen: Vec<String> = Vec::new();
    let mut index: BTreeMap<String, u64> = BTreeMap::new();
    let limit = scan.messages;
    let (vel_topic, load_topic) = match &mode {
        InputMode::Topics { velocity, load, .. } => (velocity.clone(), load.clone()),
        InputMode::RecordedEstimates { topic } => (topic.clone(), None),
    };
    let info = |topic: &str| {
        scan.channels
            .values()
            .find(|c| c.topic == topic)
            .cloned()
            .expect("selected topics exist")
    };
    let vel_info = info(&vel_topic);
    let load_info = load_topic.as_deref().map(info);
    let mut last_load: Option<f64> = None;
    // A message that does not decode is damage: replay what came before.
    let mut undecodable: Option<(u64, ReplayError)> = None;
    let mut stream_damage: Option<Damage> = None;
    let mut last_log: Option<u64> = None;
    for (n, m) in bag.stream()?.enumerate() {
        if n as u64 >= limit {
            break;
        }
        let m = match m {
            Ok(m) => m,
            Err(e) => {
                stream_damage = Some(Damage {
                    after_messages: n as u64,
                    last_log_time_ns: last_log,
                    error: e.to_string(),
                });
                break;
            }
        };
        let previous_log = last_log.replace(m.log_time);
        let topic = &m.channel.topic;
        let i = index.entry(topic.clone()).or_insert(0);
        *i += 1;
        let idx = *i;
        if *topic == vel_topic {
            match &mut mode {
                InputMode::RecordedEstimates { .. } => {
                    let e: msgs::FrictionEstimate = match decode(&vel_info, idx, &m.data) {
                        Ok(x) => x,
                        Err(e) => {
                            undecodable = Some((n as u64, e));
                            last_log = previous_log;
                            break;
                        }
                    };
                    let r = EstimateRecord::from_wire(&e);
                    // The load the node applied, then the velocity.
                    if last_load != Some(r.load_n) {
                        commands.push(Command {
                            kind: CommandKind::Load,
                            value: r.load_n,
                            stamp_ns: r.stamp_ns,
                        });
                        last_load = Some(r.load_n);
                    }
                    commands.push(Command {
                        kind: CommandKind::Velocity,
                        value: r.velocity_m_s,
                        stamp_ns: r.stamp_ns,
                    });
                    recorded.push(r);
                }
                InputMode::Topics { kind, .. } => {
                    let (value, stamp) = match kind {
                        VelocityKind::Float64 => {
                            let f: msgs::Float64 = match decode(&vel_info, idx, &m.data) {
                                Ok(x) => x,
                                Err(e) => {
                                    undecodable = Some((n as u64, e));
                                    last_log = previous_log;
                                    break;
                                }
                            };
                            (f.data, stamp_or(0, m.publish_time, m.log_time))
                        }
                        VelocityKind::TwistStamped => {
                            let t: msgs::TwistStamped = match decode(&vel_info, idx, &m.data) {
                                Ok(x) => x,
                                Err(e) => {
                                    undecodable = Some((n as u64, e));
                                    last_log = previous_log;
                                    break;
                                }
                            };
                            (
                                t.twist.linear.x,
                                stamp_or(t.header.stamp.to_ns(), m.publish_time, m.log_time),
                            )
                        }
                        VelocityKind::JointState { joint, index_hint } => {
                            let j: msgs::JointState = match decode(&vel_info, idx, &m.data) {
                                Ok(x) => x,
                                Err(e) => {
                                    undecodable = Some((n as u64, e));
                                    last_log = previous_log;
                                    break;
                                }
                            };
                            if joints_seen.is_empty() {
                                joints_seen = j.name.clone();
                            }
                            if joint.is_empty() {
                                if j.name.len() == 1 {
                                    *joint = j.name[0].clone();
                                } else {
                                    return Err(ReplayError::JointRequired {
                                        topic: vel_topic.clone(),
                                        joints: j.name.clone(),
                                    });
                                }
                            }
                            let k = match index_hint.filter(|k| j.name.get(*k) == Some(joint)) {
                                Some(k) => k,
                                None => {
                                    j.name.iter().position(|n| n == joint).ok_or_else(|| {
                                        ReplayError::JointMissing {
                                            topic: vel_topic.clone(),
                                            joint: joint.clone(),
                                            joints: j.name.clone(),
                                        }
                                    })?
                                }
                            };
                            *index_hint = Some(k);
                            let v = j.velocity.get(k).copied().ok_or_else(|| ReplayError::Decode {
                                topic: vel_topic.clone(),
                                type_name: vel_info.schema_name.clone(),
                                index: idx,
                                message: format!("joint `{joint}` has no velocity entry ({} velocities for {} names)", j.velocity.len(), j.name.len()),
                            })?;
                            (
                                v,
                                stamp_or(j.header.stamp.to_ns(), m.publish_time, m.log_time),
                            )
                        }
                    };
                    velocity_samples.push((stamp, value));
                }
            }
        } else if load_topic.as_deref() == Some(topic.as_str()) {
            let li = load_info.as_ref().expect("load topic");
            let f: msgs::Float64 = match decode(li, idx, &m.data) {
                Ok(x) => x,
                Err(e) => {
                    undecodable = Some((n as u64, e));
                    last_log = previous_log;
                    break;
                }
            };
            load_samples.push((stamp_or(0, m.publish_time, m.log_time), f.data));
        }
    }
    let damage = match undecodable {
        // Nothing before it: the decode error is the answer.
        Some((_, e)) if commands.is_empty() && velocity_samples.is_empty() => return Err(e),
        Some((n, e)) => Some(Damage {
            after_messages: n,
            last_log_time_ns: last_log,
            error: e.to_string(),
        }),
        None => stream_damage,
    };
    if commands.is_empty() && velocity_samples.is_empty() {
        return Err(ReplayError::Empty {
            topic: vel_topic,
            damage: damage.or_else(|| scan.damage.clone()),
        });
    }
    let mut gaps = Vec::new();
    let messages = velocity_samples.len() + recorded.len();
    if matches!(mode, InputMode::Topics { .. }) {
        let hold = Hold {
            dt_s: config.solver.dt_s,
            timeout_s: config.node.command_timeout_s,
            behaviour: config.node.timeout_behaviour,
            deceleration_m_s2: config.node.timeout_deceleration_m_s2,
        };
        (commands, gaps) = resample(&mut velocity_samples, &mut load_samples, &hold);
    } else {
        // Time order; at equal stamps a load applies to that velocity's step.
        commands.sort_by_key(|c| (c.stamp_ns, c.kind == CommandKind::Velocity));
    }
    Ok(Inputs {
        commands,
        recorded,
        mode,
        gaps,
        velocity_messages: messages,
        damage,
    })
}

/// How a sampled velocity becomes fixed steps.
#[derive(Debug, Clone, Copy)]
pub struct Hold {
    /// The model's step, s.
    pub dt_s: f64,
    /// `node.command_timeout_s`: a longer silence is a gap.
    pub timeout_s: f64,
    pub behaviour: TimeoutBehaviour,
    pub deceleration_m_s2: f64,
}

/// A stretch without velocity messages longer than the command timeout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gap {
    /// Stamp of the last message before the gap, ns.
    pub from_ns: u64,
    /// Length of the silence, s.
    pub length_s: f64,
}

/// Put sampled inputs onto the model's fixed time grid
/// `t_k = t_first + k·Δt`, from the first velocity sample to the last (the
/// solver's step is fixed; BDF2 needs it so).
///
/// - velocity: linear interpolation between the bracketing samples; across a
///   silence longer than `timeout_s` the node's timeout rule applies (hold
///   the last velocity, or ramp it to zero at the configured deceleration)
///   once `timeout_s` has passed, and the silence is reported as a [`Gap`];
/// - load: the latest sample at or before `t_k` (a set point, held).
///
/// Samples are sorted by stamp first; of equal stamps the last one counts.
pub fn resample(
    velocity: &mut Vec<(u64, f64)>,
    load: &mut [(u64, f64)],
    hold: &Hold,
) -> (Vec<Command>, Vec<Gap>) {
    velocity.sort_by_key(|s| s.0);
    // Keep the last of equal stamps.
    velocity.reverse();
    velocity.dedup_by_key(|s| s.0);
    velocity.reverse();
    load.sort_by_key(|s| s.0);
    let mut commands = Vec::new();
    let mut gaps = Vec::new();
    let (Some(&(t_first, _)), Some(&(t_last, _))) = (velocity.first(), velocity.last()) else {
        return (commands, gaps);
    };
    let timeout_ns = (hold.timeout_s * 1e9) as u64;
    for w in velocity.windows(2) {
        if w[1].0 - w[0].0 > timeout_ns {
            gaps.push(Gap {
                from_ns: w[0].0,
                length_s: (w[1].0 - w[0].0) as f64 / 1e9,
            });
        }
    }
    let dt_ns = hold.dt_s * 1e9;
    let steps = ((t_last - t_first) as f64 / dt_ns).floor() as u64;
    commands.reserve(steps as usize + 1);
    let (mut j, mut l) = (0usize, 0usize);
    let mut applied_load: Option<f64> = None;
    // Velocity applied in the previous step (for ramp_to_zero).
    let mut applied = velocity[0].1;
    for k in 0..=steps {
        let t = t_first + (k as f64 * dt_ns).round() as u64;
        while j + 1 < velocity.len() && velocity[j + 1].0 <= t {
            j += 1;
        }
        let (ta, va) = velocity[j];
        let v = match velocity.get(j + 1) {
            _ if ta == t => va,
            Some(&(tb, vb)) if tb - ta <= timeout_ns => {
                va + (vb - va) * ((t - ta) as f64 / (tb - ta) as f64)
            }
            _ if t - ta <= timeout_ns => va,
            _ => match hold.behaviour {
                TimeoutBehaviour::Hold => va,
                TimeoutBehaviour::RampToZero => {
                    let dv = hold.deceleration_m_s2 * hold.dt_s;
                    if applied.abs() <= dv {
                        0.0
                    } else {
                        applied - dv * applied.signum()
                    }
                }
            },
        };
        applied = v;
        while l < load.len() && load[l].0 <= t {
            l += 1;
        }
        if l > 0 && applied_load != Some(load[l - 1].1) {
            let value = load[l - 1].1;
            commands.push(Command {
                kind: CommandKind::Load,
                value,
                stamp_ns: t,
            });
            applied_load = Some(value);
        }
        commands.push(Command {
            kind: CommandKind::Velocity,
            value: v,
            stamp_ns: t,
        });
    }
    (commands, gaps)
}

/// The replayed estimates.
#[derive(Debug, Clone)]
pub struct ReplayResult {
    /// One per step: the core estimate and the published record.
    pub estimates: Vec<(Estimate, EstimateRecord)>,
    /// The commands as fed (inputs for the output bag).
    pub commands_rejected: u64,
    pub oracle: Option<Oracle>,
}

/// Outcome of the determinism check.
#[derive(Debug, Clone)]
pub struct Oracle {
    pub compared: usize,
    pub identical: bool,
    /// (field, largest |replayed − recorded|, at step index), non-zero only.
    pub deviations: Vec<(&'static str, f64, usize)>,
    /// Steps recorded but not replayed or vice versa.
    pub count_mismatch: Option<(usize, usize)>,
}

/// Run the model over the prepared input; `progress(done, total)` now and
/// then, `on_step` after every step (e.g. [`OutputStream::push`]).
pub fn run(
    p: &PreparedReplay,
    progress: &mut dyn FnMut(usize, usize),
    on_step: &mut dyn FnMut(&Estimate, &EstimateRecord),
) -> Result<ReplayResult, ReplayError> {
    let mut cfg = p.config.clone();
    cfg.node.step_mode = crate::config::StepMode::Lockstep;
    let link = MemoryLink::new(16);
    let mut peer = link.peer();
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )?;
    let mut out = Vec::with_capacity(p.commands.len());
    let total = p.commands.len();
    for (k, c) in p.commands.iter().enumerate() {
        l.feed(*c);
        if let Ok(Some(rec)) = peer.try_recv() {
            let e = *l.solver().last_estimate().expect("a step happened");
            on_step(&e, &rec);
            out.push((e, rec));
        }
        if k % 4096 == 0 {
            progress(k, total);
        }
    }
    progress(total, total);
    let oracle =
        matches!(p.mode, InputMode::RecordedEstimates { .. }).then(|| compare(&out, &p.recorded));
    Ok(ReplayResult {
        estimates: out,
        commands_rejected: l.summary().commands_rejected,
        oracle,
    })
}

/// Node-level flags (timeout, rejected command) describe what the node was
/// told, not the physics; replay compares the solver's status.
fn solver_status(s: u8) -> u8 {
    match s {
        codes::STATUS_COMMAND_TIMEOUT | codes::STATUS_COMMAND_REJECTED => codes::STATUS_CONVERGED,
        other => other,
    }
}

fn compare(replayed: &[(Estimate, EstimateRecord)], recorded: &[EstimateRecord]) -> Oracle {
    type Field = (&'static str, fn(&EstimateRecord) -> f64);
    let fields: [Field; 12] = [
        ("velocity_m_s", |r| r.velocity_m_s),
        ("load_n", |r| r.load_n),
        ("friction_force_n", |r| r.friction_force_n),
        ("cof", |r| r.cof),
        ("h0_m", |r| r.h0_m),
        ("h_min_m", |r| r.h_min_m),
        ("hydrodynamic_force_n", |r| r.hydrodynamic_force_n),
        ("asperity_force_n", |r| r.asperity_force_n),
        ("asperity_load_share", |r| r.asperity_load_share),
        ("regime", |r| r.regime as f64),
        ("status", |r| solver_status(r.status) as f64),
        ("iterations", |r| r.iterations as f64),
    ];
    let n = replayed.len().min(recorded.len());
    let mut identical = replayed.len() == recorded.len();
    let mut deviations = Vec::new();
    for (name, f) in fields {
        let (mut worst, mut at) = (0.0f64, 0usize);
        for k in 0..n {
            let (a, b) = (f(&replayed[k].1), f(&recorded[k]));
            if a.to_bits() != b.to_bits() {
                identical = false;
                let d = (a - b).abs();
                if d > worst || worst == 0.0 {
                    worst = d;
                    at = k;
                }
            }
        }
        if worst != 0.0 || (0..n).any(|k| f(&replayed[k].1).to_bits() != f(&recorded[k]).to_bits())
        {
            deviations.push((name, worst, at));
        }
    }
    Oracle {
        compared: n,
        identical,
        deviations,
        count_mismatch: (replayed.len() != recorded.len())
            .then_some((recorded.len(), replayed.len())),
    }
}

/// Output format of a replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// The `simulate` columns, then `stamp_ns`; `t_s` is the stamp relative
    /// to the first step.
    Csv,
    /// ROS 2 profile, the node's topics: the inputs and the estimates.
    Mcap,
}

impl OutputFormat {
    /// From the output path's extension (`.csv` or `.mcap`).
    pub fn from_path(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "csv" => Some(Self::Csv),
            "mcap" => Some(Self::Mcap),
            _ => None,
        }
    }
}

type Step = (Estimate, EstimateRecord);

/// One output file, written to a temporary sibling and renamed over the
/// destination only when complete.
trait Sink: Send {
    fn write(&mut self, steps: &[Step]) -> Result<(), String>;
    fn finish(self: Box<Self>, oracle: Option<&Oracle>) -> Result<PathBuf, ReplayError>;
}

struct CsvSink {
    file: crate::offline::AtomicFile,
    t0: Option<u64>,
}

impl Sink for CsvSink {
    fn write(&mut self, steps: &[Step]) -> Result<(), String> {
        use std::io::Write;
        for (e, rec) in steps {
            let t0 = *self.t0.get_or_insert(rec.stamp_ns);
            let mut e = *e;
            e.time = rec.stamp_ns.saturating_sub(t0) as f64 / 1e9;
            let row = crate::offline::simulate_row_with_status(&e, msgs::status_name(rec.status));
            writeln!(self.file.writer(), "{row},{}", rec.stamp_ns).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    fn finish(self: Box<Self>, _: Option<&Oracle>) -> Result<PathBuf, ReplayError> {
        let path = self.file.path().to_path_buf();
        self.file.commit().map_err(|e| ReplayError::Output {
            path,
            message: e.to_string(),
        })
    }
}

struct McapSink {
    /// None once finished.
    w: Option<crate::record::BagWriter>,
    path: PathBuf,
    tmp: PathBuf,
    /// The inputs, written in stamp order between the estimates.
    commands: Vec<Command>,
    next: usize,
}

impl McapSink {
    fn writer(&mut self) -> Result<&mut crate::record::BagWriter, String> {
        self.w
            .as_mut()
            .ok_or_else(|| "already finished".to_string())
    }

    fn commands_up_to(&mut self, stamp: u64) -> Result<(), String> {
        while let Some(&c) = self.commands.get(self.next).filter(|c| c.stamp_ns <= stamp) {
            let item = msgs::RecordItem::Command {
                command: c,
                received_ns: c.stamp_ns,
            };
            self.writer()?.write_item(&item, c.stamp_ns)?;
            self.next += 1;
        }
        Ok(())
    }
}

impl Sink for McapSink {
    fn write(&mut self, steps: &[Step]) -> Result<(), String> {
        for (_, rec) in steps {
            self.commands_up_to(rec.stamp_ns)?;
            self.writer()?
                .write_item(&msgs::RecordItem::Estimate(*rec), rec.stamp_ns)?;
        }
        Ok(())
    }

    fn finish(mut self: Box<Self>, oracle: Option<&Oracle>) -> Result<PathBuf, ReplayError> {
        let err = |path: &Path, message: String| ReplayError::Output {
            path: path.to_path_buf(),
            message,
        };
        let result = (|| {
            self.commands_up_to(u64::MAX)?;
            if let Some(o) = oracle {
                let mut m = BTreeMap::new();
                m.insert("bit_identical".to_string(), o.identical.to_string());
                m.insert("compared_steps".to_string(), o.compared.to_string());
                self.writer()?
                    .write_metadata("friction_node_replay_oracle", m)?;
            }
            Ok::<(), String>(())
        })();
        let (path, tmp) = (self.path.clone(), self.tmp.clone());
        let w = self.w.take();
        let finished =
            result.and_then(|_| w.ok_or_else(|| "already finished".to_string())?.finish());
        if let Err(e) = finished {
            let _ = std::fs::remove_file(&tmp);
            return Err(err(&path, e));
        }
        std::fs::rename(&tmp, &path).map_err(|e| err(&path, e.to_string()))?;
        Ok(path)
    }
}

impl Drop for McapSink {
    fn drop(&mut self) {
        // An unfinished output is abandoned (a finished one was renamed).
        if self.w.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// The replay's output, written by a background thread while the model
/// runs (the formatting and compression then cost no replay time on a
/// machine with a second core). Nothing replaces the destination until
/// [`OutputStream::finish`]; dropped unfinished, the temporary file is
/// removed.
pub struct OutputStream {
    tx: Option<std::sync::mpsc::SyncSender<Vec<Step>>>,
    batch: Vec<Step>,
    thread: Option<std::thread::JoinHandle<SinkOutcome>>,
    path: PathBuf,
}

const BATCH: usize = 1024;

/// The writer thread hands its sink back with the first write error.
type SinkOutcome = (Box<dyn Sink>, Result<(), String>);

impl OutputStream {
    /// Create the temporary output next to `path` and start the writer.
    pub fn start(
        path: &Path,
        format: OutputFormat,
        p: &PreparedReplay,
        source: &Path,
    ) -> Result<Self, ReplayError> {
        let out_err = |message: String| ReplayError::Output {
            path: path.to_path_buf(),
            message,
        };
        let sink: Box<dyn Sink> = match format {
            OutputFormat::Csv => {
                let mut file =
                    crate::offline::AtomicFile::create(path).map_err(|e| out_err(e.to_string()))?;
                file.line(format_args!(
                    "{},stamp_ns",
                    crate::offline::SIMULATE_COLUMNS
                ))
                .map_err(|e| out_err(e.to_string()))?;
                Box::new(CsvSink { file, t0: None })
            }
            OutputFormat::Mcap => {
                let tmp = tmp_sibling(path);
                let mut extra = BTreeMap::new();
                extra.insert("replay_of".to_string(), source.display().to_string());
                extra.insert(
                    "replay_input".to_string(),
                    match &p.mode {
                        InputMode::Topics { velocity, .. } => format!("topic {velocity}"),
                        InputMode::RecordedEstimates { topic } => {
                            format!("recorded estimates {topic}")
                        }
                    },
                );
                let names = crate::transport::names::TopicNames::from_config(&p.config);
                let w = crate::record::BagWriter::create(&tmp, &p.config, &names, extra).map_err(
                    |e| {
                        let _ = std::fs::remove_file(&tmp);
                        out_err(e.to_string())
                    },
                )?;
                Box::new(McapSink {
                    w: Some(w),
                    path: path.to_path_buf(),
                    tmp,
                    commands: p.commands.clone(),
                    next: 0,
                })
            }
        };
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<Step>>(8);
        let thread = std::thread::Builder::new()
            .name("replay-output".into())
            .spawn(move || {
                let mut sink = sink;
                let mut result = Ok(());
                for batch in rx {
                    if result.is_ok() {
                        result = sink.write(&batch);
                    }
                }
                (sink, result)
            })
            .map_err(|e| out_err(format!("cannot start the writer thread: {e}")))?;
        Ok(Self {
            tx: Some(tx),
            batch: Vec::with_capacity(BATCH),
            thread: Some(thread),
            path: path.to_path_buf(),
        })
    }

    /// Queue one step.
    pub fn push(&mut self, e: &Estimate, rec: &EstimateRecord) {
        self.batch.push((*e, *rec));
        if self.batch.len() >= BATCH {
            self.send();
        }
    }

    fn send(&mut self) {
        let batch = std::mem::replace(&mut self.batch, Vec::with_capacity(BATCH));
        if let Some(tx) = &self.tx {
            // A failed writer has stopped receiving; finish reports why.
            let _ = tx.send(batch);
        }
    }

    /// Write what is queued, close the file and move it into place.
    pub fn finish(mut self, oracle: Option<&Oracle>) -> Result<PathBuf, ReplayError> {
        self.send();
        self.tx = None;
        let (sink, result) = self
            .thread
            .take()
            .expect("finish once")
            .join()
            .map_err(|_| ReplayError::Output {
                path: self.path.clone(),
                message: "the writer thread panicked".into(),
            })?;
        if let Err(message) = result {
            // Dropping the sink removes the temporary file.
            drop(sink);
            return Err(ReplayError::Output {
                path: self.path.clone(),
                message,
            });
        }
        sink.finish(oracle)
    }
}

impl Drop for OutputStream {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(t) = self.thread.take() {
            // The sink is dropped with the thread's result: temp removed.
            let _ = t.join();
        }
    }
}

fn tmp_sibling(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(".tmp-{}", std::process::id()));
    path.with_file_name(name)
}

/// The first step's stamp, ns.
fn t0_ns(p: &PreparedReplay) -> u64 {
    p.commands.first().map_or(0, |c| c.stamp_ns)
}

/// "1.200 s (0.5 s long), …" relative to `t0_ns`, at most five.
pub fn gap_list(gaps: &[Gap], t0_ns: u64) -> String {
    let mut s: Vec<String> = gaps
        .iter()
        .take(5)
        .map(|g| {
            format!(
                "at {:.3} s ({:.3} s long)",
                g.from_ns.saturating_sub(t0_ns) as f64 / 1e9,
                g.length_s
            )
        })
        .collect();
    if gaps.len() > 5 {
        s.push(format!("and {} more", gaps.len() - 5));
    }
    s.join(", ")
}

/// Cycles of a replay: segments between upward crossings of the mean
/// velocity (with 10 % hysteresis), and their loop metrics.
pub fn cycles(r: &ReplayResult, mass: f64) -> Vec<crate::analysis::LoopMetrics> {
    use crate::analysis::{metrics::one_cycle, LoopSample};
    let e = &r.estimates;
    if e.len() < 8 {
        return Vec::new();
    }
    let t0 = e[0].1.stamp_ns;
    let samples: Vec<LoopSample> = e
        .iter()
        .map(|(est, rec)| {
            let mut s = LoopSample::from(est);
            s.t = rec.stamp_ns.saturating_sub(t0) as f64 / 1e9;
            s
        })
        .collect();
    let (lo, hi) = samples
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
            (a.min(s.velocity), b.max(s.velocity))
        });
    let mean = samples.iter().map(|s| s.velocity).sum::<f64>() / samples.len() as f64;
    let band = 0.1 * 0.5 * (hi - lo);
    if band <= 0.0 {
        return Vec::new();
    }
    let mut crossings = Vec::new();
    let mut below = samples[0].velocity < mean;
    for (k, s) in samples.iter().enumerate() {
        if below && s.velocity >= mean {
            crossings.push(k);
            below = false;
        } else if s.velocity < mean - band {
            below = true;
        }
    }
    crossings
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[1] - w[0] >= 8)
        .map(|(k, w)| {
            one_cycle(
                k,
                samples[w[0]].t,
                samples[w[1]].t,
                &samples[w[0]..w[1]],
                mass,
                6,
            )
        })
        .collect()
}

/// Write the report: `summary.md`, `cycles.csv` and (feature `plots`) SVG
/// figures into `dir`.
pub fn write_report(
    dir: &Path,
    bag: &Path,
    p: &PreparedReplay,
    r: &ReplayResult,
    wall_s: f64,
) -> Result<Vec<PathBuf>, crate::offline::OfflineError> {
    use crate::offline::{AtomicFile, OfflineError};
    use crate::text::Num;
    let io = |source| OfflineError::Output {
        path: dir.to_path_buf(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(io)?;
    let mut files = Vec::new();
    let cyc = cycles(r, p.config.contact.mass_kg);
    let mut f = AtomicFile::create(&dir.join("cycles.csv"))?;
    f.line(format_args!(
        "cycle,t_start_s,t_end_s,{}",
        crate::analysis::metrics::LOOP_METRIC_COLUMNS
    ))?;
    for m in &cyc {
        f.line(format_args!(
            "{},{},{},{}",
            m.cycle + 1,
            Num(m.t_start),
            Num(m.t_end),
            m.csv_fields()
        ))?;
    }
    files.push(f.commit()?);
    #[cfg(feature = "plots")]
    let figures = plots::write(dir, r)?;
    #[cfg(not(feature = "plots"))]
    let figures: Vec<PathBuf> = Vec::new();
    // Markdown summary.
    let e = &r.estimates;
    let span = match (e.first(), e.last()) {
        (Some(a), Some(b)) => (b.1.stamp_ns.saturating_sub(a.1.stamp_ns)) as f64 / 1e9,
        _ => 0.0,
    };
    let mut status = BTreeMap::new();
    let mut regime = [0usize; 3];
    for (_, rec) in e {
        *status
            .entry(msgs::status_name(rec.status))
            .or_insert(0usize) += 1;
        regime[(rec.regime as usize).min(2)] += 1;
    }
    let mut md = String::new();
    md.push_str(&format!("# Replay of `{}`\n\n", bag.display()));
    md.push_str("| | |\n|---|---|\n");
    md.push_str(&format!(
        "| input | {} |\n",
        match &p.mode {
            InputMode::Topics {
                velocity,
                kind,
                load,
            } => format!(
                "velocity `{velocity}` ({}){}",
                match kind {
                    VelocityKind::Float64 => "std_msgs/msg/Float64".to_string(),
                    VelocityKind::TwistStamped =>
                        "geometry_msgs/msg/TwistStamped, linear.x".to_string(),
                    VelocityKind::JointState { joint, .. } =>
                        format!("sensor_msgs/msg/JointState, joint `{joint}`"),
                },
                load.as_ref()
                    .map_or(String::new(), |l| format!(", load `{l}`"))
            ),
            InputMode::RecordedEstimates { topic } =>
                format!("the recorded estimates `{topic}` (velocity and load each step applied)"),
        }
    ));
    md.push_str(&format!("| configuration | {} |\n", p.config_source));
    md.push_str(&format!(
        "| steps | {} over {:.3} s of bag time, replayed in {:.3} s ({:.0}× real time) |\n",
        e.len(),
        span,
        wall_s,
        if wall_s > 0.0 {
            span / wall_s
        } else {
            f64::NAN
        }
    ));
    md.push_str(&format!(
        "| commands rejected | {} |\n",
        r.commands_rejected
    ));
    if !p.gaps.is_empty() {
        md.push_str(&format!(
            "| velocity gaps | {} longer than the command timeout ({} s; the node's timeout rule applied): {} |\n",
            p.gaps.len(),
            p.config.node.command_timeout_s,
            gap_list(&p.gaps, t0_ns(p))
        ));
    }
    if let Some(d) = &p.scan.damage {
        md.push_str(&format!(
            "| **damaged bag** | replayed everything before the damage, {d} |\n"
        ));
    }
    md.push_str(&format!(
        "| statuses | {} |\n",
        status
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    let n = e.len().max(1) as f64;
    md.push_str(&format!(
        "| regime (share of steps) | boundary {:.1} %, mixed {:.1} %, hydrodynamic {:.1} % |\n",
        100.0 * regime[0] as f64 / n,
        100.0 * regime[1] as f64 / n,
        100.0 * regime[2] as f64 / n
    ));
    if let Some(o) = &r.oracle {
        md.push_str(&format!(
            "| determinism | {} |\n",
            if o.identical {
                format!(
                    "re-simulation **bit-identical** to the recording ({} steps)",
                    o.compared
                )
            } else {
                format!(
                    "**differs** from the recording: {}{}",
                    o.deviations
                        .iter()
                        .map(|(f, d, k)| format!("{f} by up to {d:.3e} (step {k})"))
                        .collect::<Vec<_>>()
                        .join("; "),
                    o.count_mismatch.map_or(String::new(), |(a, b)| format!(
                        "; {a} steps recorded, {b} replayed"
                    ))
                )
            }
        ));
    }
    if !cyc.is_empty() {
        md.push_str(&format!(
            "\n## Loop metrics ({} cycles; `cycles.csv` has all columns)\n\n",
            cyc.len()
        ));
        md.push_str("| cycle | t (s) | friction loop area (N·m/s) | COF loop area (m/s) | peak COF at v | mean COF | h0 range (µm) | asperity share | M raw / smooth |\n|---|---|---|---|---|---|---|---|---|\n");
        for m in cyc.iter().take(20) {
            md.push_str(&format!(
                "| {} | {:.3}–{:.3} | {:.2} | {:.5} | {:.4} at {:+.3} m/s | {:.4} | {:.3}–{:.3} | {:.1} % | {:.1e} / {:.1e} |\n",
                m.cycle + 1,
                m.t_start,
                m.t_end,
                m.friction_loop_area,
                m.cof_loop_area,
                m.peak_cof,
                m.peak_cof_velocity,
                m.mean_cof,
                m.h0_min * 1e6,
                m.h0_max * 1e6,
                100.0 * m.mean_asperity_share,
                m.inertia_share,
                m.inertia_share_smooth
            ));
        }
        if cyc.len() > 20 {
            md.push_str(&format!(
                "| … | {} more in `cycles.csv` | | | | | | | |\n",
                cyc.len() - 20
            ));
        }
    } else {
        md.push_str("\nNo periodic cycles were detected (the velocity does not cross its mean repeatedly).\n");
    }
    if !figures.is_empty() {
        md.push_str("\n## Figures\n\n");
        for f in &figures {
            if let Some(name) = f.file_name() {
                md.push_str(&format!("![{0}]({0})\n\n", name.to_string_lossy()));
            }
        }
    }
    files.extend(figures);
    let mut f = AtomicFile::create(&dir.join("summary.md"))?;
    f.line(format_args!("{}", md.trim_end()))?;
    files.push(f.commit()?);
    Ok(files)
}

#[cfg(feature = "plots")]
mod plots {
    use super::*;
    use crate::offline::OfflineError;
    use crate::plot::{figure, Axes, Line, Panel, COLORS};
    use plotters::prelude::SeriesLabelPosition;

    pub fn write(dir: &Path, r: &ReplayResult) -> Result<Vec<PathBuf>, OfflineError> {
        let e = &r.estimates;
        let t0 = e.first().map_or(0, |x| x.1.stamp_ns);
        let t = |rec: &EstimateRecord| rec.stamp_ns.saturating_sub(t0) as f64 / 1e9;
        let line = |label: &str, k: usize, pts: Vec<(f64, f64)>| Line {
            label: Some(label.to_string()),
            points: pts,
            color: COLORS[k % COLORS.len()],
            dashed: false,
        };
        let ax = |x, y, legend| Axes {
            x,
            y,
            log_x: false,
            log_y: false,
            legend,
            legend_everywhere: true,
        };
        let files = vec![
            figure(
                &dir.join("friction_velocity.svg"),
                "friction against velocity",
                &[
                    Panel {
                        title: "friction force".into(),
                        lines: vec![line(
                            "F_f",
                            0,
                            e.iter()
                                .map(|(_, r)| (r.velocity_m_s, r.friction_force_n))
                                .collect(),
                        )],
                    },
                    Panel {
                        title: "coefficient of friction".into(),
                        lines: vec![line(
                            "COF",
                            1,
                            e.iter().map(|(_, r)| (r.velocity_m_s, r.cof)).collect(),
                        )],
                    },
                ],
                &ax("velocity (m/s)", "", SeriesLabelPosition::UpperRight),
            )?,
            figure(
                &dir.join("time_series.svg"),
                "velocity, friction and film thickness against time",
                &[
                    Panel {
                        title: "velocity (m/s)".into(),
                        lines: vec![line(
                            "v",
                            0,
                            e.iter().map(|(_, r)| (t(r), r.velocity_m_s)).collect(),
                        )],
                    },
                    Panel {
                        title: "friction force (N)".into(),
                        lines: vec![line(
                            "F_f",
                            1,
                            e.iter().map(|(_, r)| (t(r), r.friction_force_n)).collect(),
                        )],
                    },
                    Panel {
                        title: "h0 (µm)".into(),
                        lines: vec![line(
                            "h0",
                            2,
                            e.iter().map(|(_, r)| (t(r), r.h0_m * 1e6)).collect(),
                        )],
                    },
                ],
                &ax("time (s)", "", SeriesLabelPosition::UpperRight),
            )?,
            figure(
                &dir.join("regime_share.svg"),
                "lubrication regime and load share against time",
                &[
                    Panel {
                        title: "load share".into(),
                        lines: vec![
                            line(
                                "asperities",
                                0,
                                e.iter()
                                    .map(|(_, r)| (t(r), r.asperity_load_share))
                                    .collect(),
                            ),
                            line(
                                "fluid",
                                1,
                                e.iter()
                                    .map(|(_, r)| (t(r), r.hydrodynamic_force_n / r.load_n))
                                    .collect(),
                            ),
                        ],
                    },
                    Panel {
                        title: "regime: 0 boundary, 1 mixed, 2 hydrodynamic".into(),
                        lines: vec![line(
                            "regime",
                            3,
                            e.iter().map(|(_, r)| (t(r), r.regime as f64)).collect(),
                        )],
                    },
                ],
                &ax("time (s)", "", SeriesLabelPosition::UpperRight),
            )?,
        ];
        Ok(files)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    fn hold(behaviour: TimeoutBehaviour) -> Hold {
        Hold {
            dt_s: 1e-3,
            timeout_s: 0.1,
            behaviour,
            deceleration_m_s2: 10.0,
        }
    }

    fn velocities(c: &[Command]) -> Vec<(u64, f64)> {
        c.iter()
            .filter(|c| c.kind == CommandKind::Velocity)
            .map(|c| (c.stamp_ns, c.value))
            .collect()
    }

    #[test]
    fn velocity_is_interpolated_linearly_onto_the_step_grid() {
        // 4 ms samples, out of order and with a duplicate stamp (last wins).
        let mut v = vec![(8 * MS, 0.8), (0, 0.0), (4 * MS, 0.1), (4 * MS, 0.4)];
        let (c, gaps) = resample(&mut v, &mut [], &hold(TimeoutBehaviour::Hold));
        assert!(gaps.is_empty());
        let got = velocities(&c);
        assert_eq!(got.len(), 9);
        for (k, (t, v)) in got.iter().enumerate() {
            assert_eq!(*t, k as u64 * MS);
            approx::assert_relative_eq!(*v, 0.1 * k as f64, epsilon = 1e-15);
        }
    }

    #[test]
    fn the_load_is_held_from_its_stamp_and_sent_only_when_it_changes() {
        let mut v = vec![(0, 0.0), (10 * MS, 0.0)];
        let mut l = vec![(3 * MS, 200.0), (0, 100.0), (5 * MS, 200.0)];
        let (c, _) = resample(&mut v, &mut l, &hold(TimeoutBehaviour::Hold));
        let loads: Vec<(u64, f64)> = c
            .iter()
            .filter(|c| c.kind == CommandKind::Load)
            .map(|c| (c.stamp_ns, c.value))
            .collect();
        assert_eq!(loads, vec![(0, 100.0), (3 * MS, 200.0)]);
        // A load precedes the velocity of its step.
        let k = c
            .iter()
            .position(|c| c.kind == CommandKind::Load && c.stamp_ns == 3 * MS)
            .unwrap();
        assert_eq!(c[k + 1].kind, CommandKind::Velocity);
        assert_eq!(c[k + 1].stamp_ns, 3 * MS);
    }

    #[test]
    fn a_silence_longer_than_the_timeout_is_a_gap_with_the_node_timeout_rule() {
        let mut v = vec![(0, 1.0), (300 * MS, -1.0)];
        let (c, gaps) = resample(&mut v.clone(), &mut [], &hold(TimeoutBehaviour::Hold));
        assert_eq!(
            gaps,
            vec![Gap {
                from_ns: 0,
                length_s: 0.3
            }]
        );
        let got = velocities(&c);
        // Held (not interpolated) through the gap, then the new sample.
        assert!(got[..300].iter().all(|&(_, v)| v == 1.0));
        assert_eq!(got[300], (300 * MS, -1.0));
        // ramp_to_zero: held for the timeout, then 10 m/s² · 1 ms per step.
        let (c, _) = resample(&mut v, &mut [], &hold(TimeoutBehaviour::RampToZero));
        let got = velocities(&c);
        assert_eq!(got[100].1, 1.0);
        approx::assert_relative_eq!(got[101].1, 0.99, epsilon = 1e-12);
        approx::assert_relative_eq!(got[150].1, 0.5, epsilon = 1e-12);
        assert_eq!(got[250].1, 0.0);
        assert_eq!(got[299].1, 0.0);
    }

    #[test]
    fn no_velocity_samples_give_no_steps() {
        let (c, g) = resample(&mut vec![], &mut [(0, 5.0)], &hold(TimeoutBehaviour::Hold));
        assert!(c.is_empty() && g.is_empty());
    }
}
