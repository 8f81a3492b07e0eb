//! Sampled inputs onto the model's fixed step grid.

use crate::config::TimeoutBehaviour;
use crate::msgs::{Command, CommandKind};

/// How a sampled velocity becomes fixed steps.
#[derive(Debug, Clone, Copy)]
pub struct Hold {
    /// The model's step, s.
    pub dt_s: f64,
    /// `node.command_timeout_s`: a longer silence is a gap.
    pub timeout_s: f64,
    /// `node.timeout_behaviour`.
    pub behaviour: TimeoutBehaviour,
    /// `node.timeout_deceleration_m_s2`.
    pub deceleration_m_s2: f64,
}

/// A stretch without velocity messages longer than the command timeout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Silence {
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
///   once `timeout_s` has passed, and the silence is reported as a [`Silence`];
/// - load: the latest sample at or before `t_k` (a set point, held).
///
/// Samples are sorted by stamp first; of equal stamps the last one counts.
pub fn resample(
    velocity: &mut Vec<(u64, f64)>,
    load: &mut [(u64, f64)],
    hold: &Hold,
) -> (Vec<Command>, Vec<Silence>) {
    resample_held(velocity, &mut [(CommandKind::Load, load)], hold)
}

/// The gaps longer than the timeout between velocity samples.
fn silences_of(velocity: &[(u64, f64)], timeout_ns: u64) -> impl Iterator<Item = Silence> + '_ {
    velocity
        .windows(2)
        .filter(move |w| w[1].0 - w[0].0 > timeout_ns)
        .map(|w| Silence {
            from_ns: w[0].0,
            length_s: (w[1].0 - w[0].0) as f64 / 1e9,
        })
}

/// The velocity at step time `t` from sample `(ta, va)` at or before it
/// and the next sample: interpolated between samples no further apart than
/// the timeout, held within the timeout, else as `hold.behaviour` says
/// (`applied`: the previous step's velocity, for ramp-to-zero).
fn velocity_at(
    t: u64,
    (ta, va): (u64, f64),
    next: Option<&(u64, f64)>,
    timeout_ns: u64,
    applied: f64,
    hold: &Hold,
) -> f64 {
    match next {
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
    }
}

/// [`resample`] with any number of held set points (load, temperature):
/// each is sent when its value changes, before the velocity of its step.
pub fn resample_held(
    velocity: &mut Vec<(u64, f64)>,
    held: &mut [(CommandKind, &mut [(u64, f64)])],
    hold: &Hold,
) -> (Vec<Command>, Vec<Silence>) {
    velocity.sort_by_key(|s| s.0);
    // Keep the last of equal stamps.
    velocity.reverse();
    velocity.dedup_by_key(|s| s.0);
    velocity.reverse();
    for (_, h) in held.iter_mut() {
        h.sort_by_key(|s| s.0);
    }
    let mut commands = Vec::new();
    let mut silences = Vec::new();
    let (Some(&(t_first, _)), Some(&(t_last, _))) = (velocity.first(), velocity.last()) else {
        return (commands, silences);
    };
    let timeout_ns = (hold.timeout_s * 1e9) as u64;
    silences.extend(silences_of(velocity, timeout_ns));
    let dt_ns = hold.dt_s * 1e9;
    let steps = ((t_last - t_first) as f64 / dt_ns).floor() as u64;
    commands.reserve(steps as usize + 1);
    let mut j = 0usize;
    let mut next = vec![0usize; held.len()];
    let mut applied_held: Vec<Option<f64>> = vec![None; held.len()];
    // Velocity applied in the previous step (for ramp_to_zero).
    let mut applied = velocity[0].1;
    for k in 0..=steps {
        let t = t_first + (k as f64 * dt_ns).round() as u64;
        while j + 1 < velocity.len() && velocity[j + 1].0 <= t {
            j += 1;
        }
        let v = velocity_at(
            t,
            velocity[j],
            velocity.get(j + 1),
            timeout_ns,
            applied,
            hold,
        );
        applied = v;
        for (k, (kind, samples)) in held.iter().enumerate() {
            let l = &mut next[k];
            while *l < samples.len() && samples[*l].0 <= t {
                *l += 1;
            }
            if *l > 0 && applied_held[k] != Some(samples[*l - 1].1) {
                let value = samples[*l - 1].1;
                commands.push(Command {
                    kind: *kind,
                    value,
                    stamp_ns: t,
                });
                applied_held[k] = Some(value);
            }
        }
        commands.push(Command {
            kind: CommandKind::Velocity,
            value: v,
            stamp_ns: t,
        });
    }
    (commands, silences)
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
        let (c, silences) = resample(&mut v, &mut [], &hold(TimeoutBehaviour::Hold));
        assert!(silences.is_empty());
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
        let (c, silences) = resample(&mut v.clone(), &mut [], &hold(TimeoutBehaviour::Hold));
        assert_eq!(
            silences,
            vec![Silence {
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
