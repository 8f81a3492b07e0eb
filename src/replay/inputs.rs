//! The inputs of a replay: the bag's velocity, load, temperature and
//! parameter-change topics (or a friction-node bag's recorded estimates)
//! decoded into the node's commands, with the `--velocity-map` and
//! `--load-map` expressions applied.

use super::*;

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

/// A temperature command when the recorded temperature changed.
fn push_temperature(commands: &mut Vec<Command>, last: &mut f64, r: &EstimateRecord) {
    if r.temperature_c.is_finite() && r.temperature_c != *last {
        commands.push(Command {
            kind: CommandKind::Temperature,
            value: r.temperature_c,
            stamp_ns: r.stamp_ns,
        });
        *last = r.temperature_c;
    }
}

/// The node's command-hold rules, for resampling a topic onto the step grid.
fn hold_of(config: &Config) -> Hold {
    Hold {
        dt_s: config.solver.dt_s,
        timeout_s: config.node.command_timeout_s,
        behaviour: config.node.timeout_behaviour,
        deceleration_m_s2: config.node.timeout_deceleration_m_s2,
    }
}

/// The recorded estimates as the commands each step applied: the load and
/// the temperature when they change, then the velocity.
fn estimates_as_commands(recorded: &[EstimateRecord], reference_c: f64) -> Vec<Command> {
    let mut commands = Vec::with_capacity(recorded.len() + 1);
    let mut last_load = None;
    let mut last_temperature = reference_c;
    for r in recorded {
        push_temperature(&mut commands, &mut last_temperature, r);
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

pub(super) fn decode_inputs(
    bag: &Bag,
    scan: &BagScan,
    config: &Config,
    mode: InputMode,
    opts: &ReplayOptions,
) -> Result<DecodedBag, ReplayError> {
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
    // Several contacts from a JointState topic: one decoder per joint.
    let mut joint_decs: Vec<TopicDecoder> = match &mode {
        InputMode::JointStates { topic, joints, .. } => joints
            .iter()
            .map(|j| TopicDecoder::new(scan.require(topic)?, SampleKind::JointVelocity(j.clone())))
            .collect::<Result<_, _>>()?,
        _ => Vec::new(),
    };
    let mut joint_samples: Vec<Vec<(u64, f64)>> = vec![Vec::new(); joint_decs.len()];
    // Several contacts: each contact's estimate topic, and what it recorded.
    let contact_topics: Vec<String> = match &mode {
        InputMode::RecordedContacts { topics } => topics.clone(),
        _ => Vec::new(),
    };
    let mut per_contact: Vec<Vec<EstimateRecord>> = vec![Vec::new(); contact_topics.len()];
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
        } else if let Some(k) = contact_topics.iter().position(|t| *t == view.topic) {
            est_index += 1;
            msgs::decode_estimate(view.data, false)
                .map_err(|message| BagError::Decode {
                    topic: view.topic.to_string(),
                    type_name: "friction_msgs/msg/FrictionEstimate".into(),
                    index: est_index,
                    message,
                })
                .map(|r| per_contact[k].push(r))
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
        } else if joint_decs.first().is_some_and(|d| d.topic() == view.topic) {
            // A message without one of the joints leaves it held (as the
            // node does); a joint that never appears is an error below.
            joint_decs
                .iter_mut()
                .zip(joint_samples.iter_mut())
                .try_for_each(|(d, out)| match d.sample(&view) {
                    Ok(s) => {
                        out.push(s);
                        Ok(())
                    }
                    Err(BagError::JointMissing { .. }) => Ok(()),
                    Err(e) => Err(e),
                })
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
    if !per_contact.is_empty() {
        // Steps every contact recorded (damage may cut them unevenly).
        let steps = per_contact.iter().map(Vec::len).min().unwrap_or(0);
        per_contact.iter_mut().for_each(|r| r.truncate(steps));
        recorded = per_contact[0].clone();
    }
    if let (InputMode::JointStates { topic, joints, .. }, false) = (&mode, joint_samples.is_empty())
    {
        if let Some(k) = joint_samples.iter().position(Vec::is_empty) {
            if damage.is_none() {
                return Err(BagError::JointMissing {
                    topic: topic.clone(),
                    joint: joints[k].clone(),
                    joints: scan_joints(bag, topic),
                }
                .into());
            }
        }
        velocity = joint_samples[0].clone();
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
                InputMode::RecordedContacts { topics } => topics[0].clone(),
                InputMode::JointStates { topic, .. } => topic.clone(),
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
    }
    | InputMode::JointStates { topic, .. } = &mode
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
            let hold = hold_of(config);
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
        InputMode::JointStates { .. } => {
            let hold = hold_of(config);
            joints_as_commands(&mut joint_samples, &mut load, &mut temperature, &hold)
        }
        InputMode::RecordedContacts { .. } => (
            contacts_as_commands(
                &per_contact,
                &config
                    .contacts
                    .0
                    .iter()
                    .map(|c| c.contact.load_n)
                    .collect::<Vec<_>>(),
                config.lubricant.reference_temperature_c,
            ),
            Vec::new(),
        ),
    };
    let recorded_contacts = config
        .contacts
        .0
        .iter()
        .map(|c| c.name.clone())
        .zip(per_contact)
        .collect();
    parameter_changes.sort_by_key(|c| c.stamp_ns);
    Ok(DecodedBag {
        commands,
        recorded,
        recorded_contacts,
        mode,
        gaps,
        velocity_messages,
        damage,
        parameter_changes,
    })
}

/// Several joints' velocities (and the load and temperature) as the
/// commands of each step: every joint resampled onto the step grid exactly
/// as one joint's topic is (interpolation, hold and timeout rules), on the
/// first joint's grid; at each step the set points that changed, then one
/// joint velocity per contact, the last marked so that the lockstep loop
/// steps once for all. Silences are the first joint's.
fn joints_as_commands(
    joints: &mut [Vec<(u64, f64)>],
    load: &mut [(u64, f64)],
    temperature: &mut [(u64, f64)],
    hold: &Hold,
) -> (Vec<Command>, Vec<Silence>) {
    let Some((first, others)) = joints.split_first_mut() else {
        return (Vec::new(), Vec::new());
    };
    let (reference, gaps) = bag::resample::resample_held(
        first,
        &mut [
            (CommandKind::Load, load),
            (CommandKind::Temperature, temperature),
        ],
        hold,
    );
    let resampled: Vec<Vec<Command>> = others
        .iter_mut()
        .map(|s| bag::resample::resample_held(s, &mut [], hold).0)
        .collect();
    let n = resampled.len() + 1;
    let mut cursors = vec![0usize; resampled.len()];
    let mut out = Vec::with_capacity(reference.len() * n);
    for c in reference {
        if c.kind != CommandKind::Velocity {
            out.push(c);
            continue;
        }
        out.push(Command {
            kind: CommandKind::JointVelocity {
                contact: 0,
                last: false,
            },
            ..c
        });
        for (k, r) in resampled.iter().enumerate() {
            let i = &mut cursors[k];
            while *i < r.len() && r[*i].stamp_ns < c.stamp_ns {
                *i += 1;
            }
            if let Some(v) = r.get(*i).filter(|v| v.stamp_ns == c.stamp_ns) {
                out.push(Command {
                    kind: CommandKind::JointVelocity {
                        contact: u16::try_from(k + 1).expect("at most MAX_CONTACTS contacts"),
                        last: false,
                    },
                    value: v.value,
                    stamp_ns: c.stamp_ns,
                });
            }
        }
        if let Some(Command {
            kind: CommandKind::JointVelocity { last, .. },
            ..
        }) = out.last_mut()
        {
            *last = true;
        }
    }
    (out, gaps)
}

/// Several contacts' recorded estimates as the commands each step applied:
/// the temperature changes and the load commands (a load command applies to
/// every contact: until one came, each contact ran on its configured load
/// `configured[k]`), then one joint velocity per contact, the last marked so
/// that the lockstep loop steps once for all.
fn contacts_as_commands(
    recorded: &[Vec<EstimateRecord>],
    configured: &[f64],
    reference_c: f64,
) -> Vec<Command> {
    let n = recorded.len();
    let steps = recorded.first().map_or(0, Vec::len);
    let mut commands = Vec::with_capacity(steps * (n + 1));
    let mut applied: Option<f64> = None;
    let mut last_temperature = reference_c;
    for i in 0..steps {
        let r0 = &recorded[0][i];
        push_temperature(&mut commands, &mut last_temperature, r0);
        let own = recorded
            .iter()
            .zip(configured)
            .all(|(r, &c)| r[i].load_n == c);
        let common = recorded.iter().all(|r| r[i].load_n == r0.load_n);
        if !(applied.is_none() && own) && common && applied != Some(r0.load_n) {
            commands.push(Command {
                kind: CommandKind::Load,
                value: r0.load_n,
                stamp_ns: r0.stamp_ns,
            });
            applied = Some(r0.load_n);
        }
        for (k, r) in recorded.iter().enumerate() {
            commands.push(Command {
                kind: CommandKind::JointVelocity {
                    contact: u16::try_from(k).expect("at most MAX_CONTACTS contacts"),
                    last: k + 1 == n,
                },
                value: r[i].velocity_m_s,
                stamp_ns: r0.stamp_ns,
            });
        }
    }
    commands
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
