//! Replay: run the model over the velocity recorded in any ROS 2 bag (an
//! MCAP file or a rosbag2 directory, read through [`crate::bag`]).
//!
//! The commanded velocity is read from a channel of type
//! `std_msgs/msg/Float64`, `geometry_msgs/msg/TwistStamped` (`linear.x`) or
//! `sensor_msgs/msg/JointState` (the `velocity` of one joint), detected from
//! its schema; a `std_msgs/msg/Float64` load channel is optional. The model
//! runs in lockstep on the step grid (the node's own loop, fed one command at
//! a time), so a replay is exactly what the node would have done.
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
//!
//! | file | content |
//! |---|---|
//! | `mod.rs` | options, choosing topics and configuration, running the loop |
//! | `inputs.rs` | decoding the inputs: topics or recorded estimates → commands; maps |
//! | `oracle.rs` | the determinism check |
//! | `sink.rs` | CSV and MCAP outputs, written off the model's thread |
//! | `report.rs` | `summary.md`, `cycles.csv`, figures |

mod inputs;
mod oracle;
mod report;
mod sink;

pub use oracle::Oracle;
pub use report::{cycles, gap_list, write_report};
pub use sink::{OutputFormat, OutputStream};

use crate::bag::decode::VELOCITY_TYPES;
use crate::bag::{
    self, check_schema, Bag, BagError, BagScan, ChannelInfo, Damage, Hold, SampleKind, Silence,
    TopicDecoder,
};
use crate::config::{Config, ConfigError, Origin};
use crate::link::LiveStatus;
use crate::msgs::{self, Command, CommandKind, EstimateRecord};
use crate::node::{Loop, NodeError};
use crate::physics::Estimate;
use crate::transport::memory::MemoryLink;
use crate::transport::PeerPort;
use std::path::PathBuf;
use std::sync::Arc;

/// Errors of the replay layer.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error(transparent)]
    Bag(#[from] BagError),
    #[error(transparent)]
    Interrupted(#[from] crate::interrupt::Interrupted),
    #[error("no usable velocity topic ({VELOCITY_TYPES}); the bag has:\n{}", bag::listing(.available))]
    NoVelocityTopic {
        available: Vec<(String, String, u64)>,
    },
    #[error("several topics could be the velocity; choose one with --topic:\n{}", bag::listing(.candidates))]
    AmbiguousVelocity {
        candidates: Vec<(String, String, u64)>,
    },
    #[error("topic `{topic}` has no messages before {}", damage_note(.damage))]
    Empty {
        topic: String,
        damage: Option<Damage>,
    },
    #[error("cannot write {}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    #[error("topic `{topic}`: its stamps span {span_s:.3e} s, more than {MAX_REPLAY_STEPS} steps of {dt_s} s (a stamp is probably wrong; or replay a shorter part)")]
    TooLong {
        topic: String,
        span_s: f64,
        dt_s: f64,
    },
    #[error("{flag} `{expr}`: {message}")]
    Map {
        flag: &'static str,
        expr: String,
        message: String,
    },
    #[error("the recorded configuration in the bag: {0}")]
    RecordedConfig(ConfigError),
    #[error("the parameter change recorded at {stamp_ns} ns cannot be applied: {message}")]
    Parameters { stamp_ns: u64, message: String },
    #[error(transparent)]
    Setup(#[from] crate::physics::SetupError),
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Node(#[from] NodeError),
    #[error(
        "the configuration lists {0} contacts (`contacts`): a bag is replayed for several \
         contacts from a friction-node recording of them (its `~/contacts/NAME/friction` \
         topics); {1}. Replay a foreign bag with a configuration without `contacts`, once \
         per joint (--joint)"
    )]
    SeveralContacts(usize, String),
}

fn damage_note(d: &Option<Damage>) -> String {
    match d {
        Some(d) => format!("the damage ({d})"),
        None => "the end of the bag".into(),
    }
}

/// The most steps one replay runs (its inputs are held in memory: about
/// 24 bytes per step; 14 h at 1 kHz).
pub const MAX_REPLAY_STEPS: u64 = 50_000_000;

/// What drives the replay.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InputMode {
    /// A velocity (and optional load) topic.
    Topics {
        velocity: String,
        kind: SampleKind,
        load: Option<String>,
        temperature: Option<String>,
    },
    /// A friction-node bag: the recorded estimates' velocity and load.
    RecordedEstimates { topic: String },
    /// A friction-node bag of several contacts: each contact's recorded
    /// estimates (configured order), stepped together.
    RecordedContacts { topics: Vec<String> },
    /// Several contacts from a `sensor_msgs/JointState` topic: every
    /// configured joint's velocity, resampled onto the step grid like one
    /// joint's, and the load and temperature topics (applied to every
    /// contact).
    JointStates {
        topic: String,
        joints: Vec<String>,
        load: Option<String>,
        temperature: Option<String>,
    },
}

impl InputMode {
    /// Whether the replay has recorded estimates to compare with (the
    /// determinism oracle).
    pub fn has_recorded_estimates(&self) -> bool {
        matches!(
            self,
            InputMode::RecordedEstimates { .. } | InputMode::RecordedContacts { .. }
        )
    }

    /// One line for logs and reports.
    pub fn describe(&self) -> String {
        match self {
            InputMode::Topics {
                velocity,
                kind,
                load,
                temperature,
            } => format!(
                "velocity `{velocity}` ({}){}{}",
                match kind {
                    SampleKind::TwistLinearX =>
                        "geometry_msgs/msg/TwistStamped, linear.x".to_string(),
                    SampleKind::JointVelocity(joint) =>
                        format!("sensor_msgs/msg/JointState, joint `{joint}`"),
                    other => other.msg_type().full_name(),
                },
                load.as_ref()
                    .map_or(String::new(), |l| format!(", load `{l}`")),
                temperature
                    .as_ref()
                    .map_or(String::new(), |t| format!(", temperature `{t}`"))
            ),
            InputMode::RecordedEstimates { topic } => {
                format!("the recorded estimates `{topic}` (velocity and load each step applied)")
            }
            InputMode::RecordedContacts { topics } => format!(
                "the recorded estimates of {} contacts (`{}` …; velocity and load each step applied)",
                topics.len(),
                topics.first().map_or("", String::as_str)
            ),
            InputMode::JointStates {
                topic,
                joints,
                load,
                temperature,
            } => format!(
                "velocity of joints {} from `{topic}` (sensor_msgs/msg/JointState){}{}",
                joints.join(", "),
                load.as_ref()
                    .map_or(String::new(), |l| format!(", load `{l}`")),
                temperature
                    .as_ref()
                    .map_or(String::new(), |t| format!(", temperature `{t}`"))
            ),
        }
    }
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
    /// The temperature topic (default: a sensor_msgs/Temperature topic
    /// ending in `temperature`).
    pub temperature_topic: Option<String>,
    /// A parameter file instead of the recorded (or default) configuration.
    pub config: Option<PathBuf>,
    /// Overrides applied to whichever configuration is used.
    pub overrides: Vec<String>,
    /// The velocity, m/s, as an expression of the velocity topic's value
    /// `x` (e.g. `0.005 * x`: a joint's rad/s through a 5 mm lever).
    pub velocity_map: Option<String>,
    /// The load, N, as an expression of the load topic's value `x` (e.g.
    /// `5.2e-4 * x + 20`: a pressure in Pa through an area plus a preload).
    pub load_map: Option<String>,
}

/// The validated input of a replay.
#[derive(Debug, Clone)]
pub struct PreparedReplay {
    pub config: Config,
    pub config_source: String,
    pub mode: InputMode,
    /// Commands in time order.
    pub commands: Vec<Command>,
    /// The recorded estimates (friction-node bags; the first contact's when
    /// there are several).
    pub recorded: Vec<EstimateRecord>,
    /// Several contacts: each contact's name and recorded estimates
    /// (configured order); empty for one contact.
    pub recorded_contacts: Vec<(String, Vec<EstimateRecord>)>,
    pub scan: BagScan,
    /// Silences in the velocity topic longer than the command timeout.
    pub gaps: Vec<Silence>,
    /// Velocity messages read.
    pub velocity_messages: usize,
    /// Parameters the node changed while it ran (its `/parameter_events`),
    /// each stamped with the first step that used it, in time order.
    pub parameter_changes: Vec<ParameterChange>,
}

/// One recorded parameter change.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterChange {
    /// The stamp of the first step that used it.
    pub stamp_ns: u64,
    pub changed: Vec<(String, crate::msgs::ros_interfaces::ParameterValue)>,
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
        let c =
            Config::from_recorded_yaml(text, &Origin::Text("recorded in the bag"), &opts.overrides)
                .map_err(ReplayError::RecordedConfig)?;
        return Ok((c, "recorded in the bag".into()));
    }
    Ok((
        Config::load(None, &opts.overrides)?,
        "built-in default".into(),
    ))
}

/// The velocity channel: `--topic`, else the only candidate (one ending in
/// `cmd_velocity` preferred).
fn velocity_channel(scan: &BagScan, opts: &ReplayOptions) -> Result<ChannelInfo, ReplayError> {
    if let Some(t) = &opts.topic {
        return Ok(scan.require(t)?.clone());
    }
    let candidates: Vec<&ChannelInfo> = scan
        .channels
        .iter()
        .filter(|c| {
            SampleKind::velocity_for(&c.schema_name, None).is_some()
                && !c.topic.ends_with("normal_load")
                && !c.topic.ends_with("friction_force")
        })
        .collect();
    let preferred: Vec<&&ChannelInfo> = candidates
        .iter()
        .filter(|c| c.topic.ends_with("cmd_velocity"))
        .collect();
    match (candidates.len(), preferred.len()) {
        (_, 1) => Ok((*preferred[0]).clone()),
        (1, _) => Ok(candidates[0].clone()),
        (0, _) if scan.damage.is_some() => Err(ReplayError::Empty {
            topic: "(any velocity topic)".into(),
            damage: scan.damage.clone(),
        }),
        (0, _) => Err(ReplayError::NoVelocityTopic {
            available: scan.listing(),
        }),
        _ => Err(ReplayError::AmbiguousVelocity {
            candidates: candidates
                .iter()
                .map(|c| (c.topic.clone(), c.schema_name.clone(), c.messages))
                .collect(),
        }),
    }
}

/// The load channel: `--load-topic`, else the bag's default (see
/// [`crate::bag::decode::default_load_topic`]).
fn load_channel(scan: &BagScan, opts: &ReplayOptions) -> Result<Option<String>, ReplayError> {
    match &opts.load_topic {
        Some(t) => {
            let c = scan.require(t)?;
            TopicDecoder::new(c, SampleKind::Float64)?;
            Ok(Some(t.clone()))
        }
        None => Ok(crate::bag::decode::default_load_topic(scan)),
    }
}

/// The temperature channel: `--temperature-topic`, else the bag's default
/// (see [`crate::bag::decode::default_temperature_topic`]).
fn temperature_channel(
    scan: &BagScan,
    opts: &ReplayOptions,
) -> Result<Option<String>, ReplayError> {
    match &opts.temperature_topic {
        Some(t) => {
            TopicDecoder::new(scan.require(t)?, SampleKind::Temperature)?;
            Ok(Some(t.clone()))
        }
        None => Ok(crate::bag::decode::default_temperature_topic(scan)),
    }
}

/// A FrictionEstimate channel whose schema this build decodes.
fn check_estimates(c: &ChannelInfo) -> Result<(), BagError> {
    msgs::check_estimate_schema(&c.schema_text).map_err(|message| BagError::SchemaMismatch {
        topic: c.topic.clone(),
        type_name: c.schema_name.clone(),
        message,
    })
}

/// Validate the bag against the options and decode every input.
pub fn prepare(bag: &Bag, opts: &ReplayOptions) -> Result<PreparedReplay, ReplayError> {
    let mut scan = bag.scan()?;
    let (config, config_source) = choose_config(&scan, opts)?;
    let several = config.contacts.0.len() > 1;
    let n_contacts = config.contacts.0.len();
    let contact_topics = crate::config::topics::TopicNames::from_config(&config).contact_friction;
    // Several contacts: a recording of them (every contact's topic, no
    // --topic) replays its estimates; otherwise a JointState topic drives
    // every configured joint.
    let recorded_contacts =
        several && opts.topic.is_none() && contact_topics.iter().all(|t| scan.channel(t).is_some());
    if several && (opts.velocity_map.is_some() || opts.load_map.is_some()) {
        return Err(ReplayError::SeveralContacts(
            n_contacts,
            "--velocity-map and --load-map apply to one velocity topic".into(),
        ));
    }
    if recorded_contacts {
        for t in &contact_topics {
            check_estimates(scan.require(t)?)?;
        }
    }
    let joint_states = if several && !recorded_contacts {
        let topic = match &opts.topic {
            Some(t) => scan.require(t)?.clone(),
            None => {
                let js: Vec<&ChannelInfo> = scan
                    .channels
                    .iter()
                    .filter(|c| c.schema_name == "sensor_msgs/msg/JointState")
                    .collect();
                match js.as_slice() {
                    [one] => (*one).clone(),
                    [] => {
                        return Err(ReplayError::SeveralContacts(
                            n_contacts,
                            "this bag has neither their recorded estimates nor a sensor_msgs/msg/JointState topic"
                                .into(),
                        ))
                    }
                    _ => {
                        return Err(ReplayError::AmbiguousVelocity {
                            candidates: js
                                .iter()
                                .map(|c| (c.topic.clone(), c.schema_name.clone(), c.messages))
                                .collect(),
                        })
                    }
                }
            }
        };
        if topic.schema_name != "sensor_msgs/msg/JointState" {
            return Err(ReplayError::SeveralContacts(
                n_contacts,
                format!(
                    "`{}` is {}, and several contacts take a sensor_msgs/msg/JointState topic",
                    topic.topic, topic.schema_name
                ),
            ));
        }
        check_schema(&topic, SampleKind::JointVelocity(String::new()).msg_type())?;
        Some(InputMode::JointStates {
            topic: topic.topic,
            joints: config.contacts.0.iter().map(|c| c.joint.clone()).collect(),
            load: load_channel(&scan, opts)?,
            temperature: temperature_channel(&scan, opts)?,
        })
    } else {
        None
    };
    // A friction-node bag without --topic: drive it by its estimates.
    let estimates = scan
        .channels
        .iter()
        .find(|c| c.schema_name == "friction_msgs/msg/FrictionEstimate");
    let mode = match (&opts.topic, estimates, &scan.recorded_config) {
        _ if recorded_contacts => InputMode::RecordedContacts {
            topics: contact_topics,
        },
        _ if joint_states.is_some() => joint_states.expect("several contacts from JointState"),
        (None, Some(c), Some(_)) => {
            check_estimates(c)?;
            InputMode::RecordedEstimates {
                topic: c.topic.clone(),
            }
        }
        _ => {
            let vel = velocity_channel(&scan, opts)?;
            let Some(kind) = SampleKind::velocity_for(&vel.schema_name, opts.joint.as_deref())
            else {
                return Err(BagError::UnsupportedType {
                    topic: vel.topic,
                    type_name: vel.schema_name,
                    expected: VELOCITY_TYPES.into(),
                }
                .into());
            };
            check_schema(&vel, kind.msg_type())?;
            InputMode::Topics {
                velocity: vel.topic,
                kind,
                load: load_channel(&scan, opts)?,
                temperature: temperature_channel(&scan, opts)?,
            }
        }
    };
    if matches!(mode, InputMode::RecordedEstimates { .. })
        && (opts.velocity_map.is_some() || opts.load_map.is_some())
    {
        return Err(ReplayError::Map {
            flag: if opts.velocity_map.is_some() {
                "--velocity-map"
            } else {
                "--load-map"
            },
            expr: opts
                .velocity_map
                .clone()
                .or_else(|| opts.load_map.clone())
                .unwrap_or_default(),
            message: "maps apply to a velocity or load topic; this replay follows the recorded estimates (give --topic)".into(),
        });
    }
    let inputs = inputs::decode_inputs(bag, &scan, &config, mode, opts)?;
    if inputs.damage.is_some() {
        scan.damage = inputs.damage;
    }
    Ok(PreparedReplay {
        config,
        config_source,
        mode: inputs.mode,
        commands: inputs.commands,
        recorded: inputs.recorded,
        recorded_contacts: inputs.recorded_contacts,
        scan,
        gaps: inputs.gaps,
        velocity_messages: inputs.velocity_messages,
        parameter_changes: inputs.parameter_changes,
    })
}

/// The replayed estimates.
#[derive(Debug, Clone)]
pub struct ReplayResult {
    /// One per step: the core estimate and the published record (the first
    /// contact's when there are several).
    pub estimates: Vec<(Estimate, EstimateRecord)>,
    pub commands_rejected: u64,
    /// Every contact's verdict together (all identical, deviations of all).
    pub oracle: Option<Oracle>,
    /// Several contacts: each contact's name, estimates and oracle.
    pub contacts: Vec<ContactReplay>,
}

/// One contact of a replay of several.
#[derive(Debug, Clone)]
pub struct ContactReplay {
    pub name: String,
    pub estimates: Vec<(Estimate, EstimateRecord)>,
    pub oracle: Option<Oracle>,
}

/// Run the model over the prepared input; `progress(done, total)` now and
/// then, `on_step` after every step of every contact (with the contact's
/// index; e.g. [`OutputStream::push`]).
pub fn run(
    p: &PreparedReplay,
    progress: &mut dyn FnMut(usize, usize) -> Result<(), crate::interrupt::Interrupted>,
    on_step: &mut dyn FnMut(&Estimate, &EstimateRecord, u16),
) -> Result<ReplayResult, ReplayError> {
    let mut cfg = p.config.clone();
    cfg.node.step_mode = crate::config::StepMode::Lockstep;
    let joints: Vec<String> = cfg.contacts.0.iter().map(|c| c.joint.clone()).collect();
    let several = joints.len() > 1;
    let link = if several {
        MemoryLink::new(16).with_joints(&joints)
    } else {
        MemoryLink::new(16)
    };
    let mut peer = link.peer();
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )?;
    let mut out = Vec::with_capacity(p.commands.len());
    let mut per_contact: Vec<Vec<(Estimate, EstimateRecord)>> = if several {
        vec![Vec::new(); joints.len()]
    } else {
        Vec::new()
    };
    let total = p.commands.len();
    // Recorded parameter changes, re-applied before the step that used them.
    let mut current = p.config.clone();
    let declared = crate::config::parameters::declare(&current);
    let mut changes = p.parameter_changes.iter().peekable();
    for (k, c) in p.commands.iter().enumerate() {
        if c.kind == CommandKind::Velocity {
            while let Some(ch) = changes.next_if(|ch| ch.stamp_ns <= c.stamp_ns) {
                let next = crate::config::parameters::apply_set(&current, &declared, &ch.changed)
                    .map_err(|e| ReplayError::Parameters {
                    stamp_ns: ch.stamp_ns,
                    message: e.to_string(),
                })?;
                let mut u = crate::link::ParameterUpdate::prepare(
                    &current,
                    next.clone(),
                    ch.changed.clone(),
                )?;
                l.apply_update(&mut u);
                current = next;
            }
        }
        l.feed(*c);
        if several {
            while let Ok(Some((i, rec))) = peer.try_recv_contact() {
                let e = l.contacts().estimates()[i];
                let contact = u16::try_from(i).expect("at most MAX_CONTACTS contacts");
                on_step(&e, &rec, contact);
                if i == 0 {
                    out.push((e, rec));
                }
                per_contact[i].push((e, rec));
            }
            while let Ok(Some(_)) = peer.try_recv_efforts() {}
        } else if let Ok(Some(rec)) = peer.try_recv() {
            let e = l.contacts().estimates()[0];
            on_step(&e, &rec, 0);
            out.push((e, rec));
        }
        if k % 4096 == 0 {
            progress(k, total)?;
        }
    }
    progress(total, total)?;
    let contacts: Vec<ContactReplay> = cfg
        .contacts
        .0
        .iter()
        .zip(per_contact)
        .enumerate()
        .map(|(k, (c, estimates))| ContactReplay {
            name: c.name.clone(),
            oracle: p
                .recorded_contacts
                .get(k)
                .map(|(_, recorded)| oracle::compare(&estimates, recorded)),
            estimates,
        })
        .collect();
    let oracle = match &p.mode {
        InputMode::RecordedEstimates { .. } => Some(oracle::compare(&out, &p.recorded)),
        InputMode::RecordedContacts { .. } => Some(oracle::combine(
            contacts.iter().filter_map(|c| c.oracle.as_ref()),
        )),
        InputMode::Topics { .. } | InputMode::JointStates { .. } => None,
    };
    Ok(ReplayResult {
        estimates: out,
        commands_rejected: l.summary().commands_rejected,
        oracle,
        contacts,
    })
}
