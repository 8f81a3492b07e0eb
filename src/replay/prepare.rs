//! Preparing a replay: the configuration, the input topics chosen and
//! checked against the bag, and every input decoded, before anything is
//! written.

use super::inputs;
use super::{InputMode, ReplayError};
use crate::bag::decode::VELOCITY_TYPES;
use crate::bag::{
    check_schema, Bag, BagError, BagScan, ChannelInfo, SampleKind, Silence, TopicDecoder,
};
use crate::config::{Config, Origin};
use crate::msgs::{self, Command, EstimateRecord};
use std::path::PathBuf;

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
    /// The configuration the replay runs with.
    pub config: Config,
    /// Where it came from (a file, the bag, the built-in default).
    pub config_source: String,
    /// What drives the replay.
    pub mode: InputMode,
    /// Commands in time order.
    pub commands: Vec<Command>,
    /// The recorded estimates (friction-node bags; the first contact's when
    /// there are several).
    pub recorded: Vec<EstimateRecord>,
    /// Several contacts: each contact's name and recorded estimates
    /// (configured order); empty for one contact.
    pub recorded_contacts: Vec<(String, Vec<EstimateRecord>)>,
    /// The bag's channels, recorded configuration and damage.
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
    /// The parameters changed and their new values.
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
        let origin = Origin::Text("recorded in the bag");
        return match Config::from_recorded_yaml(text, &origin, &opts.overrides) {
            Ok(c) => Ok((c, "recorded in the bag".into())),
            // The recorded configuration holds without the overrides: the
            // error is the overrides', not the bag's.
            Err(e) if Config::from_recorded_yaml(text, &origin, &[]).is_ok() => {
                Err(ReplayError::Config(e))
            }
            Err(e) => Err(ReplayError::RecordedConfig(e)),
        };
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
    // `--joint` names a joint of a JointState topic: the bag's only one is meant.
    let joint_states: Vec<&&ChannelInfo> = candidates
        .iter()
        .filter(|c| opts.joint.is_some() && c.schema_name == "sensor_msgs/msg/JointState")
        .collect();
    if let [one] = joint_states.as_slice() {
        return Ok((**one).clone());
    }
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

/// Several contacts from a JointState topic: `--topic`, else the bag's only
/// JointState topic.
fn joint_state_channel(
    scan: &BagScan,
    opts: &ReplayOptions,
    n_contacts: usize,
) -> Result<ChannelInfo, ReplayError> {
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
    Ok(topic)
}

/// One contact: `--topic` (or the detected velocity topic) with its load
/// and temperature topics.
fn topics_mode(scan: &BagScan, opts: &ReplayOptions) -> Result<InputMode, ReplayError> {
    let vel = velocity_channel(scan, opts)?;
    let Some(kind) = SampleKind::velocity_for(&vel.schema_name, opts.joint.as_deref()) else {
        return Err(BagError::UnsupportedType {
            topic: vel.topic,
            type_name: vel.schema_name,
            expected: VELOCITY_TYPES.into(),
        }
        .into());
    };
    check_schema(&vel, kind.msg_type())?;
    Ok(InputMode::Topics {
        velocity: vel.topic,
        kind,
        load: load_channel(scan, opts)?,
        temperature: temperature_channel(scan, opts)?,
    })
}

/// What drives the replay. Several contacts: a recording of them (every
/// contact's topic, no `--topic`) replays its estimates, otherwise a
/// JointState topic drives every configured joint. One contact: a
/// friction-node bag without `--topic` is driven by its estimates, any other
/// by a velocity topic.
fn input_mode(
    scan: &BagScan,
    config: &Config,
    opts: &ReplayOptions,
) -> Result<InputMode, ReplayError> {
    let n_contacts = config.contacts.0.len();
    if !config.output_plan().by_joint() {
        let estimates = scan
            .channels
            .iter()
            .find(|c| c.schema_name == "friction_msgs/msg/FrictionEstimate");
        return match (&opts.topic, estimates, &scan.recorded_config) {
            (None, Some(c), Some(_)) => {
                check_estimates(c)?;
                Ok(InputMode::RecordedEstimates {
                    topic: c.topic.clone(),
                })
            }
            _ => topics_mode(scan, opts),
        };
    }
    if opts.velocity_map.is_some() || opts.load_map.is_some() {
        return Err(ReplayError::SeveralContacts(
            n_contacts,
            "--velocity-map and --load-map apply to one velocity topic".into(),
        ));
    }
    let contact_topics = crate::config::topics::TopicNames::from_config(config).contact_friction;
    if opts.topic.is_none() && contact_topics.iter().all(|t| scan.channel(t).is_some()) {
        for t in &contact_topics {
            check_estimates(scan.require(t)?)?;
        }
        return Ok(InputMode::RecordedContacts {
            topics: contact_topics,
        });
    }
    let topic = joint_state_channel(scan, opts, n_contacts)?;
    Ok(InputMode::JointStates {
        topic: topic.topic,
        joints: config.contacts.0.iter().map(|c| c.joint.clone()).collect(),
        load: load_channel(scan, opts)?,
        temperature: temperature_channel(scan, opts)?,
    })
}

/// Maps apply to a velocity or load topic, not to recorded estimates.
fn check_maps(mode: &InputMode, opts: &ReplayOptions) -> Result<(), ReplayError> {
    let map = match (&opts.velocity_map, &opts.load_map) {
        (Some(e), _) => Some(("--velocity-map", e)),
        (None, Some(e)) => Some(("--load-map", e)),
        (None, None) => None,
    };
    match (mode, map) {
        (InputMode::RecordedEstimates { .. }, Some((flag, expr))) => Err(ReplayError::Map {
            flag,
            expr: expr.clone(),
            message: "maps apply to a velocity or load topic; this replay follows the recorded estimates (give --topic)".into(),
        }),
        _ => Ok(()),
    }
}

/// Validate the bag against the options and decode every input.
pub fn prepare(bag: &Bag, opts: &ReplayOptions) -> Result<PreparedReplay, ReplayError> {
    let mut scan = bag.scan()?;
    let (config, config_source) = choose_config(&scan, opts)?;
    let mode = input_mode(&scan, &config, opts)?;
    check_maps(&mode, opts)?;
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
