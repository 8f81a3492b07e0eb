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
//! | `mod.rs` | options, choosing topics and configuration, decoding inputs, running the loop |
//! | `oracle.rs` | the determinism check |
//! | `sink.rs` | CSV and MCAP outputs, written off the model's thread |
//! | `report.rs` | `summary.md`, `cycles.csv`, figures |

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
use crate::msgs::{self, Command, CommandKind, EstimateRecord};
use crate::node::{LiveStatus, Loop, NodeError};
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
        "the configuration lists {0} contacts (`contacts`): replay re-simulates one contact \
         today (replay of a multi-joint bag is not built yet); replay with a configuration \
         without `contacts`, once per contact"
    )]
    SeveralContacts(usize),
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
}

impl InputMode {
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

/// `expr` of `x` applied to every sample's value; a parse error, an
/// unknown name or a non-finite result names the flag and the sample.
fn map_samples(
    flag: &'static str,
    expr: &str,
    samples: &mut [(u64, f64)],
) -> Result<(), ReplayError> {
    use evalexpr::{ContextWithMutableVariables, DefaultNumericTypes, HashMapContext, Value};
    let err = |message: String| ReplayError::Map {
        flag,
        expr: expr.to_string(),
        message,
    };
    let node = evalexpr::build_operator_tree::<DefaultNumericTypes>(expr)
        .map_err(|e| err(e.to_string()))?;
    if let Some(id) = node.iter_variable_identifiers().find(|id| *id != "x") {
        return Err(err(format!(
            "`{id}` is unknown: the expression reads the topic's value as `x`"
        )));
    }
    let mut ctx = HashMapContext::<DefaultNumericTypes>::new();
    for (k, s) in samples.iter_mut().enumerate() {
        ctx.set_value("x".into(), Value::Float(s.1))
            .map_err(|e| err(e.to_string()))?;
        let v = node
            .eval_number_with_context(&ctx)
            .map_err(|e| err(format!("message {}: {e}", k + 1)))?;
        if !v.is_finite() {
            return Err(err(format!("message {}: x = {} gives {v}", k + 1, s.1)));
        }
        s.1 = v;
    }
    Ok(())
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
        let c = Config::from_yaml(text, &Origin::Embedded, &opts.overrides)
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

/// Validate the bag against the options and decode every input.
pub fn prepare(bag: &Bag, opts: &ReplayOptions) -> Result<PreparedReplay, ReplayError> {
    let mut scan = bag.scan()?;
    let (config, config_source) = choose_config(&scan, opts)?;
    if config.contacts.0.len() > 1 {
        return Err(ReplayError::SeveralContacts(config.contacts.0.len()));
    }
    // A friction-node bag without --topic: drive it by its estimates.
    let estimates = scan
        .channels
        .iter()
        .find(|c| c.schema_name == "friction_msgs/msg/FrictionEstimate");
    let mode = match (&opts.topic, estimates, &scan.recorded_config) {
        (None, Some(c), Some(_)) => {
            msgs::check_estimate_schema(&c.schema_text).map_err(|message| {
                BagError::SchemaMismatch {
                    topic: c.topic.clone(),
                    type_name: c.schema_name.clone(),
                    message,
                }
            })?;
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
    let inputs = decode_inputs(bag, &scan, &config, mode, opts)?;
    if inputs.damage.is_some() {
        scan.damage = inputs.damage;
    }
    Ok(PreparedReplay {
        config,
        config_source,
        mode: inputs.mode,
        commands: inputs.commands,
        recorded: inputs.recorded,
        scan,
        gaps: inputs.gaps,
        velocity_messages: inputs.velocity_messages,
        parameter_changes: inputs.parameter_changes,
    })
}

/// What [`decode_inputs`] read.
struct Inputs {
    commands: Vec<Command>,
    recorded: Vec<EstimateRecord>,
    mode: InputMode,
    gaps: Vec<Silence>,
    velocity_messages: usize,
    /// Where reading stopped early (everything before it is kept).
    damage: Option<Damage>,
    parameter_changes: Vec<ParameterChange>,
}

/// The recorded estimates as the commands each step applied: the load and
/// the temperature when they change, then the velocity.
fn estimates_as_commands(recorded: &[EstimateRecord], reference_c: f64) -> Vec<Command> {
    let mut commands = Vec::with_capacity(recorded.len() + 1);
    let mut last_load = None;
    let mut last_temperature = reference_c;
    for r in recorded {
        if r.temperature_c.is_finite() && r.temperature_c != last_temperature {
            commands.push(Command {
                kind: CommandKind::Temperature,
                value: r.temperature_c,
                stamp_ns: r.stamp_ns,
            });
            last_temperature = r.temperature_c;
        }
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
    }
    // Time order; at equal stamps a set point applies to that velocity's step.
    commands.sort_by_key(|c| (c.stamp_ns, c.kind == CommandKind::Velocity));
    commands
}

fn decode_inputs(
    bag: &Bag,
    scan: &BagScan,
    config: &Config,
    mode: InputMode,
    opts: &ReplayOptions,
) -> Result<Inputs, ReplayError> {
    let mut recorded = Vec::new();
    let mut velocity: Vec<(u64, f64)> = Vec::new();
    let mut load: Vec<(u64, f64)> = Vec::new();
    let mut temperature: Vec<(u64, f64)> = Vec::new();
    let optional =
        |t: &Option<String>, kind: SampleKind| -> Result<Option<TopicDecoder>, ReplayError> {
            match t {
                Some(t) => Ok(Some(TopicDecoder::new(scan.require(t)?, kind)?)),
                None => Ok(None),
            }
        };
    let (mut vel_dec, mut load_dec, mut temp_dec, est_channel) = match &mode {
        InputMode::Topics {
            velocity: v,
            kind,
            load: l,
            temperature: t,
        } => (
            Some(TopicDecoder::new(scan.require(v)?, kind.clone())?),
            optional(l, SampleKind::Float64)?,
            optional(t, SampleKind::Temperature)?,
            None,
        ),
        InputMode::RecordedEstimates { topic } => (None, None, None, Some(scan.require(topic)?)),
    };
    let legacy = est_channel.is_some_and(|c| msgs::is_legacy_estimate_schema(&c.schema_text));
    let mut est_index = 0u64;
    // The node's parameter changes (recorded estimates only).
    let node_fqn = {
        let ns = config.ros.namespace.trim_end_matches('/');
        format!("{ns}/{}", config.ros.node_name)
    };
    let events_channel = est_channel.and_then(|_| {
        scan.channels
            .iter()
            .find(|c| c.schema_name == "rcl_interfaces/msg/ParameterEvent")
    });
    let mut parameter_changes = Vec::new();
    // A message that does not decode is damage: replay what came before.
    let mut damage: Option<Damage> = None;
    let mut decode_error: Option<BagError> = None;
    let (mut read, mut last_log) = (0u64, None);
    for m in bag.messages()? {
        let m = match m {
            Ok(m) => m,
            Err(d) => {
                damage = Some(d);
                break;
            }
        };
        let view = m.view();
        let result = if let Some(c) = events_channel.filter(|c| c.topic == view.topic) {
            msgs::from_cdr::<msgs::ros_interfaces::ParameterEvent>(view.data)
                .map_err(|message| BagError::Decode {
                    topic: c.topic.clone(),
                    type_name: c.schema_name.clone(),
                    index: parameter_changes.len() as u64 + 1,
                    message,
                })
                .map(|ev| {
                    if ev.node == node_fqn && !ev.changed_parameters.is_empty() {
                        parameter_changes.push(ParameterChange {
                            stamp_ns: ev.stamp.to_ns(),
                            changed: ev
                                .changed_parameters
                                .into_iter()
                                .map(|p| (p.name, p.value))
                                .collect(),
                        });
                    }
                })
        } else if let Some(c) = est_channel.filter(|c| c.topic == view.topic) {
            est_index += 1;
            msgs::decode_estimate(view.data, legacy)
                .map_err(|message| BagError::Decode {
                    topic: c.topic.clone(),
                    type_name: c.schema_name.clone(),
                    index: est_index,
                    message,
                })
                .map(|r| recorded.push(r))
        } else if let Some(d) = vel_dec.as_mut().filter(|d| d.topic() == view.topic) {
            d.sample(&view).map(|s| velocity.push(s))
        } else if let Some(d) = load_dec.as_mut().filter(|d| d.topic() == view.topic) {
            d.sample(&view).map(|s| load.push(s))
        } else if let Some(d) = temp_dec.as_mut().filter(|d| d.topic() == view.topic) {
            d.sample(&view).map(|s| temperature.push(s))
        } else {
            Ok(())
        };
        if let Err(e) = result {
            // A joint that was never there is a usage error, not damage.
            if matches!(
                e,
                BagError::JointRequired { .. } | BagError::JointMissing { .. }
            ) {
                return Err(e.into());
            }
            damage = Some(Damage {
                after_messages: read,
                last_log_time_ns: last_log,
                file: bag.path().to_path_buf(),
                error: e.to_string(),
            });
            decode_error = Some(e);
            break;
        }
        read += 1;
        last_log = Some(view.log_time);
    }
    if recorded.is_empty() && velocity.is_empty() {
        if let Some(e) = decode_error {
            // Nothing before it: the decode error is the answer.
            return Err(e.into());
        }
        return Err(ReplayError::Empty {
            topic: match &mode {
                InputMode::Topics { velocity, .. } => velocity.clone(),
                InputMode::RecordedEstimates { topic } => topic.clone(),
            },
            damage: damage.or_else(|| scan.damage.clone()),
        });
    }
    let mode = match (mode, &vel_dec) {
        (
            InputMode::Topics {
                velocity,
                load,
                temperature,
                ..
            },
            Some(d),
        ) => InputMode::Topics {
            velocity,
            kind: d.kind.clone(),
            load,
            temperature,
        },
        (m, _) => m,
    };
    if let Some(e) = &opts.velocity_map {
        map_samples("--velocity-map", e, &mut velocity)?;
    }
    if let Some(e) = &opts.load_map {
        map_samples("--load-map", e, &mut load)?;
    }
    let velocity_messages = velocity.len() + recorded.len();
    if let InputMode::Topics {
        velocity: topic, ..
    } = &mode
    {
        let (lo, hi) = velocity
            .iter()
            .fold((u64::MAX, 0), |(a, b), s| (a.min(s.0), b.max(s.0)));
        let span_s = hi.saturating_sub(lo) as f64 / 1e9;
        if span_s / config.solver.dt_s > MAX_REPLAY_STEPS as f64 {
            return Err(ReplayError::TooLong {
                topic: topic.clone(),
                span_s,
                dt_s: config.solver.dt_s,
            });
        }
    }
    let (commands, gaps) = match &mode {
        InputMode::Topics { .. } => {
            let hold = Hold {
                dt_s: config.solver.dt_s,
                timeout_s: config.node.command_timeout_s,
                behaviour: config.node.timeout_behaviour,
                deceleration_m_s2: config.node.timeout_deceleration_m_s2,
            };
            bag::resample::resample_held(
                &mut velocity,
                &mut [
                    (CommandKind::Load, &mut load[..]),
                    (CommandKind::Temperature, &mut temperature[..]),
                ],
                &hold,
            )
        }
        InputMode::RecordedEstimates { .. } => (
            estimates_as_commands(&recorded, config.lubricant.reference_temperature_c),
            Vec::new(),
        ),
    };
    parameter_changes.sort_by_key(|c| c.stamp_ns);
    Ok(Inputs {
        commands,
        recorded,
        mode,
        gaps,
        velocity_messages,
        damage,
        parameter_changes,
    })
}

/// The replayed estimates.
#[derive(Debug, Clone)]
pub struct ReplayResult {
    /// One per step: the core estimate and the published record.
    pub estimates: Vec<(Estimate, EstimateRecord)>,
    pub commands_rejected: u64,
    pub oracle: Option<Oracle>,
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
    // Recorded parameter changes, re-applied before the step that used them.
    let mut current = p.config.clone();
    let declared = crate::node::parameters::declare(&current);
    let mut changes = p.parameter_changes.iter().peekable();
    for (k, c) in p.commands.iter().enumerate() {
        if c.kind == CommandKind::Velocity {
            while let Some(ch) = changes.next_if(|ch| ch.stamp_ns <= c.stamp_ns) {
                let next = crate::node::parameters::apply_set(&current, &declared, &ch.changed)
                    .map_err(|e| ReplayError::Parameters {
                        stamp_ns: ch.stamp_ns,
                        message: e.to_string(),
                    })?;
                let mut u = crate::node::parameters::ParameterUpdate::prepare(
                    &current,
                    next.clone(),
                    ch.changed.clone(),
                )?;
                l.apply_update(&mut u);
                current = next;
            }
        }
        l.feed(*c);
        if let Ok(Some(rec)) = peer.try_recv() {
            let e = l.contacts().estimates()[0];
            on_step(&e, &rec);
            out.push((e, rec));
        }
        if k % 4096 == 0 {
            progress(k, total);
        }
    }
    progress(total, total);
    let oracle = matches!(p.mode, InputMode::RecordedEstimates { .. })
        .then(|| oracle::compare(&out, &p.recorded));
    Ok(ReplayResult {
        estimates: out,
        commands_rejected: l.summary().commands_rejected,
        oracle,
    })
}
