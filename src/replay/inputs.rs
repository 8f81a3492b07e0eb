//! The inputs of a replay: the bag's velocity, load, temperature and
//! parameter-change topics (or a friction-node bag's recorded estimates)
//! decoded into the node's commands, with the `--velocity-map` and
//! `--load-map` expressions applied.

use super::commands::{contacts_as_commands, estimates_as_commands, hold_of, joints_as_commands};
use super::{InputMode, ParameterChange, ReplayError, ReplayOptions, MAX_REPLAY_STEPS};
use crate::bag::{
    self, Bag, BagError, BagMessage, BagScan, ChannelInfo, Damage, SampleKind, Silence,
    TopicDecoder,
};
use crate::config::Config;
use crate::msgs::{self, Command, CommandKind, EstimateRecord};

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
    crate::expression::check_size(expr).map_err(err)?;
    let node = evalexpr::build_operator_tree::<DefaultNumericTypes>(
        &crate::expression::with_functions(expr),
    )
    .map_err(|e| err(e.to_string()))?;
    crate::expression::check_functions(&node).map_err(err)?;
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

/// What [`decode_inputs`] read.
pub(super) struct DecodedBag {
    pub(super) commands: Vec<Command>,
    pub(super) recorded: Vec<EstimateRecord>,
    pub(super) recorded_contacts: Vec<(String, Vec<EstimateRecord>)>,
    pub(super) mode: InputMode,
    pub(super) gaps: Vec<Silence>,
    pub(super) velocity_messages: usize,
    /// Where reading stopped early (everything before it is kept).
    pub(super) damage: Option<Damage>,
    pub(super) parameter_changes: Vec<ParameterChange>,
}

/// The decoders of one replay's topics.
struct Readers<'s> {
    velocity: Option<TopicDecoder>,
    load: Option<TopicDecoder>,
    temperature: Option<TopicDecoder>,
    /// The recorded estimates driving the replay (the first contact's
    /// channel with several).
    estimates: Option<&'s ChannelInfo>,
    /// The layout the estimates were recorded in.
    layout: msgs::EstimateLayout,
    /// Several contacts from a JointState topic: one decoder per joint.
    joints: Vec<TopicDecoder>,
    /// Several contacts: each contact's estimate topic.
    contact_topics: Vec<String>,
    /// The node's `/parameter_events` (recorded estimates only).
    events: Option<&'s ChannelInfo>,
    /// The node's fully qualified name, as its parameter events carry it.
    node_fqn: String,
}

/// What the readers took from the messages.
#[derive(Default)]
struct Samples {
    recorded: Vec<EstimateRecord>,
    velocity: Vec<(u64, f64)>,
    load: Vec<(u64, f64)>,
    temperature: Vec<(u64, f64)>,
    joints: Vec<Vec<(u64, f64)>>,
    per_contact: Vec<Vec<EstimateRecord>>,
    parameter_changes: Vec<ParameterChange>,
    /// Estimate messages decoded (1-based index for errors).
    estimate_index: u64,
}

/// Where reading stopped early, and why.
#[derive(Default)]
struct Stopped {
    damage: Option<Damage>,
    decode_error: Option<BagError>,
}

impl<'s> Readers<'s> {
    fn new(scan: &'s BagScan, config: &Config, mode: &InputMode) -> Result<Self, ReplayError> {
        let optional = |t: &Option<String>, kind| -> Result<Option<TopicDecoder>, ReplayError> {
            match t {
                Some(t) => Ok(Some(TopicDecoder::new(scan.require(t)?, kind)?)),
                None => Ok(None),
            }
        };
        let (velocity, load, temperature, estimates) = match mode {
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
            InputMode::RecordedEstimates { topic } => {
                (None, None, None, Some(scan.require(topic)?))
            }
            InputMode::RecordedContacts { topics } => {
                (None, None, None, Some(scan.require(&topics[0])?))
            }
            InputMode::JointStates {
                load: l,
                temperature: t,
                ..
            } => (
                None,
                optional(l, SampleKind::Float64)?,
                optional(t, SampleKind::Temperature)?,
                None,
            ),
        };
        let joints = match mode {
            InputMode::JointStates { topic, joints, .. } => joints
                .iter()
                .map(|j| {
                    TopicDecoder::new(scan.require(topic)?, SampleKind::JointVelocity(j.clone()))
                })
                .collect::<Result<_, _>>()?,
            _ => Vec::new(),
        };
        let contact_topics = match mode {
            InputMode::RecordedContacts { topics } => topics.clone(),
            _ => Vec::new(),
        };
        let events = estimates.and_then(|_| {
            scan.channels
                .iter()
                .find(|c| c.schema_name == "rcl_interfaces/msg/ParameterEvent")
        });
        let ns = config.ros.namespace.trim_end_matches('/');
        Ok(Self {
            velocity,
            load,
            temperature,
            layout: estimates
                .and_then(|c| msgs::EstimateLayout::of_schema(&c.schema_text).ok())
                .unwrap_or_default(),
            estimates,
            joints,
            contact_topics,
            events,
            node_fqn: format!("{ns}/{}", config.ros.node_name),
        })
    }

    /// Empty sample lists, one per joint and per contact.
    fn samples(&self) -> Samples {
        Samples {
            joints: vec![Vec::new(); self.joints.len()],
            per_contact: vec![Vec::new(); self.contact_topics.len()],
            ..Samples::default()
        }
    }

    /// Decode one message into `s` if it is on one of the topics.
    fn take(&mut self, view: &BagMessage<'_>, s: &mut Samples) -> Result<(), BagError> {
        let estimate_error =
            |topic: &str, type_name: &str, index, e: msgs::CdrError| BagError::Decode {
                topic: topic.to_string(),
                type_name: type_name.to_string(),
                index,
                message: e.to_string(),
            };
        if let Some(c) = self.events.filter(|c| c.topic == view.topic) {
            self.take_event(c, view.data, s)
        } else if let Some(k) = self.contact_topics.iter().position(|t| *t == view.topic) {
            s.estimate_index += 1;
            let r = msgs::decode_estimate(view.data, self.layout).map_err(|m| {
                estimate_error(
                    view.topic,
                    "friction_msgs/msg/FrictionEstimate",
                    s.estimate_index,
                    m,
                )
            })?;
            s.per_contact[k].push(r);
            Ok(())
        } else if let Some(c) = self.estimates.filter(|c| c.topic == view.topic) {
            s.estimate_index += 1;
            let r = msgs::decode_estimate(view.data, self.layout)
                .map_err(|m| estimate_error(&c.topic, &c.schema_name, s.estimate_index, m))?;
            s.recorded.push(r);
            Ok(())
        } else if self.joints.first().is_some_and(|d| d.topic() == view.topic) {
            // A message without one of the joints leaves it held (as the
            // node does); a joint that never appears is an error later.
            self.joints
                .iter_mut()
                .zip(s.joints.iter_mut())
                .try_for_each(|(d, out)| match d.sample(view) {
                    Ok(x) => {
                        out.push(x);
                        Ok(())
                    }
                    Err(BagError::JointMissing { .. }) => Ok(()),
                    Err(e) => Err(e),
                })
        } else {
            let streams = [
                (self.velocity.as_mut(), &mut s.velocity),
                (self.load.as_mut(), &mut s.load),
                (self.temperature.as_mut(), &mut s.temperature),
            ];
            for (decoder, out) in streams {
                if let Some(d) = decoder.filter(|d| d.topic() == view.topic) {
                    out.push(d.sample(view)?);
                    break;
                }
            }
            Ok(())
        }
    }

    /// A parameter event: kept when it is this node's and changed something.
    fn take_event(&self, c: &ChannelInfo, data: &[u8], s: &mut Samples) -> Result<(), BagError> {
        let ev = msgs::from_cdr::<msgs::ros_interfaces::ParameterEvent>(data).map_err(|e| {
            BagError::Decode {
                topic: c.topic.clone(),
                type_name: c.schema_name.clone(),
                index: s.parameter_changes.len() as u64 + 1,
                message: e.to_string(),
            }
        })?;
        if ev.node == self.node_fqn && !ev.changed_parameters.is_empty() {
            s.parameter_changes.push(ParameterChange {
                stamp_ns: ev.stamp.to_ns(),
                changed: ev
                    .changed_parameters
                    .into_iter()
                    .map(|p| (p.name, p.value))
                    .collect(),
            });
        }
        Ok(())
    }
}

/// Read every message; a message that does not decode is damage (what came
/// before it is kept), except a missing joint, which is a usage error.
fn read_all(bag: &Bag, readers: &mut Readers, s: &mut Samples) -> Result<Stopped, ReplayError> {
    let (mut read, mut last_log) = (0u64, None);
    for m in bag.messages()? {
        let m = match m {
            Ok(m) => m,
            Err(d) => {
                return Ok(Stopped {
                    damage: Some(d),
                    decode_error: None,
                })
            }
        };
        let view = m.view();
        if let Err(e) = readers.take(&view, s) {
            if matches!(
                e,
                BagError::JointRequired { .. } | BagError::JointMissing { .. }
            ) {
                return Err(e.into());
            }
            return Ok(Stopped {
                damage: Some(Damage {
                    after_messages: read,
                    last_log_time_ns: last_log,
                    file: bag.path().to_path_buf(),
                    error: e.to_string(),
                }),
                decode_error: Some(e),
            });
        }
        read += 1;
        last_log = Some(view.log_time);
    }
    Ok(Stopped::default())
}

/// Several contacts: the steps every contact recorded (damage may cut them
/// unevenly); JointStates: every joint seen (unless the bag is damaged) and
/// the first joint's velocity as the velocity; and something to replay.
fn settle(
    bag: &Bag,
    scan: &BagScan,
    mode: &InputMode,
    s: &mut Samples,
    stopped: &mut Stopped,
) -> Result<(), ReplayError> {
    if !s.per_contact.is_empty() {
        let steps = s.per_contact.iter().map(Vec::len).min().unwrap_or(0);
        s.per_contact.iter_mut().for_each(|r| r.truncate(steps));
        s.recorded = s.per_contact[0].clone();
    }
    if let (InputMode::JointStates { topic, joints, .. }, false) = (mode, s.joints.is_empty()) {
        if let Some(k) = s.joints.iter().position(Vec::is_empty) {
            if stopped.damage.is_none() {
                return Err(BagError::JointMissing {
                    topic: topic.clone(),
                    joint: joints[k].clone(),
                    joints: scan_joints(bag, topic),
                }
                .into());
            }
        }
        s.velocity = s.joints[0].clone();
    }
    if s.recorded.is_empty() && s.velocity.is_empty() {
        if let Some(e) = stopped.decode_error.take() {
            // Nothing before it: the decode error is the answer.
            return Err(e.into());
        }
        return Err(ReplayError::Empty {
            topic: match mode {
                InputMode::Topics { velocity, .. } => velocity.clone(),
                InputMode::RecordedEstimates { topic } => topic.clone(),
                InputMode::RecordedContacts { topics } => topics[0].clone(),
                InputMode::JointStates { topic, .. } => topic.clone(),
            },
            damage: stopped.damage.clone().or_else(|| scan.damage.clone()),
        });
    }
    Ok(())
}

/// A velocity topic's stamps must span at most [`MAX_REPLAY_STEPS`] steps.
fn check_span(mode: &InputMode, velocity: &[(u64, f64)], dt_s: f64) -> Result<(), ReplayError> {
    if let InputMode::Topics {
        velocity: topic, ..
    }
    | InputMode::JointStates { topic, .. } = mode
    {
        let (lo, hi) = velocity
            .iter()
            .fold((u64::MAX, 0), |(a, b), s| (a.min(s.0), b.max(s.0)));
        let span_s = hi.saturating_sub(lo) as f64 / 1e9;
        if span_s / dt_s > MAX_REPLAY_STEPS as f64 {
            return Err(ReplayError::TooLong {
                topic: topic.clone(),
                span_s,
                dt_s,
            });
        }
    }
    Ok(())
}

/// The samples as the node's commands on the step grid, with the velocity
/// topic's silences.
fn as_commands(mode: &InputMode, config: &Config, s: &mut Samples) -> (Vec<Command>, Vec<Silence>) {
    let reference_c = config.lubricant.reference_temperature_c;
    match mode {
        InputMode::Topics { .. } => bag::resample::resample_held(
            &mut s.velocity,
            &mut [
                (CommandKind::Load, &mut s.load[..]),
                (CommandKind::Temperature, &mut s.temperature[..]),
            ],
            &hold_of(config),
        ),
        InputMode::RecordedEstimates { .. } => {
            (estimates_as_commands(&s.recorded, reference_c), Vec::new())
        }
        InputMode::JointStates { .. } => joints_as_commands(
            &mut s.joints,
            &mut s.load,
            &mut s.temperature,
            &hold_of(config),
        ),
        InputMode::RecordedContacts { .. } => {
            let configured: Vec<f64> = config.contacts.0.iter().map(|c| c.contact.load_n).collect();
            (
                contacts_as_commands(&s.per_contact, &configured, reference_c),
                Vec::new(),
            )
        }
    }
}

/// Decode the bag's inputs for `mode` into the node's commands.
pub(super) fn decode_inputs(
    bag: &Bag,
    scan: &BagScan,
    config: &Config,
    mode: InputMode,
    opts: &ReplayOptions,
) -> Result<DecodedBag, ReplayError> {
    let mut readers = Readers::new(scan, config, &mode)?;
    let mut s = readers.samples();
    let mut stopped = read_all(bag, &mut readers, &mut s)?;
    settle(bag, scan, &mode, &mut s, &mut stopped)?;
    // A topic's sample kind as the decoder settled it.
    let mode = match (mode, &readers.velocity) {
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
        map_samples("--velocity-map", e, &mut s.velocity)?;
    }
    if let Some(e) = &opts.load_map {
        map_samples("--load-map", e, &mut s.load)?;
    }
    let velocity_messages = s.velocity.len() + s.recorded.len();
    check_span(&mode, &s.velocity, config.solver.dt_s)?;
    let (commands, gaps) = as_commands(&mode, config, &mut s);
    let names = config.contacts.0.iter().map(|c| c.name.clone());
    s.parameter_changes.sort_by_key(|c| c.stamp_ns);
    Ok(DecodedBag {
        commands,
        recorded_contacts: names.zip(s.per_contact).collect(),
        recorded: s.recorded,
        mode,
        gaps,
        velocity_messages,
        damage: stopped.damage,
        parameter_changes: s.parameter_changes,
    })
}

/// The joint names a JointState topic carries (for an error message).
fn scan_joints(bag: &Bag, topic: &str) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    if let Ok(messages) = bag.messages() {
        for m in messages.flatten().take(10_000) {
            let view = m.view();
            if view.topic != topic {
                continue;
            }
            if let Ok(js) = msgs::from_cdr::<msgs::JointState>(view.data) {
                for n in js.name {
                    if !names.contains(&n) {
                        names.push(n);
                    }
                }
            }
        }
    }
    names
}
