//! The decoded samples as the node's commands on the step grid: a
//! velocity topic resampled with the node's hold and timeout rules, several
//! joints on one grid, or recorded estimates as the commands each step
//! applied.

use crate::bag::{self, Hold, Silence};
use crate::config::Config;
use crate::msgs::{Command, CommandKind, EstimateRecord};

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
pub(super) fn hold_of(config: &Config) -> Hold {
    Hold {
        dt_s: config.solver.dt_s,
        timeout_s: config.node.command_timeout_s,
        behaviour: config.node.timeout_behaviour,
        deceleration_m_s2: config.node.timeout_deceleration_m_s2,
    }
}

/// The recorded estimates as the commands each step applied: the load and
/// the temperature when they change, then the velocity.
pub(super) fn estimates_as_commands(recorded: &[EstimateRecord], reference_c: f64) -> Vec<Command> {
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

/// Several joints' velocities (and the load and temperature) as the
/// commands of each step: every joint resampled onto the step grid exactly
/// as one joint's topic is (interpolation, hold and timeout rules), on the
/// first joint's grid; at each step the set points that changed, then one
/// joint velocity per contact, the last marked so that the lockstep loop
/// steps once for all. Silences are the first joint's.
pub(super) fn joints_as_commands(
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
                joint: true,
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
                        joint: true,
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
pub(super) fn contacts_as_commands(
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
                // The recorded estimates hold each contact's own speed.
                kind: CommandKind::JointVelocity {
                    contact: u16::try_from(k).expect("at most MAX_CONTACTS contacts"),
                    last: k + 1 == n,
                    joint: false,
                },
                value: r[i].velocity_m_s,
                stamp_ns: r0.stamp_ns,
            });
        }
    }
    commands
}
