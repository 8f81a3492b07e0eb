//! `/diagnostics`: the loop's health as `diagnostic_msgs/msg/DiagnosticArray`
//! (what `diagnostic_aggregator` and `rqt_robot_monitor` read), built from
//! two consecutive `LoopStatistics`, one `DiagnosticStatus` per concern.
//!
//! | status | OK | WARN | ERROR |
//! |---|---|---|---|
//! | `<node>: loop timing` | deadline misses < 0.1 % of the period's steps | < 5 %, or lost time advanced in one step | ≥ 5 % |
//! | `<node>: solver` | every step converged | < 1 % of the steps not converged | ≥ 1 % |
//! | `<node>: commands` | nothing rejected, overwritten or timed out | any of them | (never) |
//! | `<node>: outputs` | nothing dropped or failed | any output dropped or not sent | (never) |
//! | `<node>: recorder` | recording everything (or not recording) | messages dropped by a full queue | messages lost (a write failed) |
//! | `<node>: calibrated range` | every input inside its contact's calibrated range (or none given) | an input outside it in the period: which contact, input, value and range | (never) |
//!
//! "The period" is the time since the previous statistics (1 s by
//! default). Values carry the cumulative counters and the period's.

use crate::msgs::ros_interfaces::{
    diagnostic_level as level, DiagnosticArray, DiagnosticStatus, KeyValue,
};
use crate::msgs::{Header, StatisticsRecord, Time};

/// Misses above this fraction of a period's steps: WARN.
pub const MISS_WARN: f64 = 0.001;
/// Misses at or above this fraction: ERROR.
pub const MISS_ERROR: f64 = 0.05;
/// Non-converged steps at or above this fraction: ERROR.
pub const SOLVER_ERROR: f64 = 0.01;

/// Builds `/diagnostics` (the loop's health) from consecutive statistics;
/// not the solver's per-step [`crate::physics::Diagnostics`].
#[derive(Debug, Default)]
pub struct HealthReporter {
    previous: Option<StatisticsRecord>,
}

fn kv(key: &str, value: impl std::fmt::Display) -> KeyValue {
    KeyValue {
        key: key.into(),
        value: value.to_string(),
    }
}

/// One period: the statistics now and at the previous update.
struct Period<'a> {
    now: &'a StatisticsRecord,
    before: StatisticsRecord,
    /// Steps in the period (at least 1).
    steps: u64,
    node: &'a str,
}

impl Period<'_> {
    /// A counter's increase over the period.
    fn delta(&self, counter: impl Fn(&StatisticsRecord) -> u64) -> u64 {
        counter(self.now).saturating_sub(counter(&self.before))
    }

    /// `n` as a fraction of the period's steps.
    fn frac(&self, n: u64) -> f64 {
        n as f64 / self.steps as f64
    }

    fn status(
        &self,
        name: &str,
        level: u8,
        message: String,
        values: Vec<KeyValue>,
    ) -> DiagnosticStatus {
        DiagnosticStatus {
            level,
            name: format!("{}: {name}", self.node),
            message,
            hardware_id: self.node.to_string(),
            values,
        }
    }
}

/// Microseconds with one decimal.
fn us(ns: u64) -> String {
    format!("{:.1}", ns as f64 / 1e3)
}

fn timing(p: &Period) -> DiagnosticStatus {
    let (s, steps) = (p.now, p.steps);
    let misses = p.delta(|r| r.deadline_misses);
    let jumps = p.delta(|r| r.time_jumps);
    let (lvl, msg) = if p.frac(misses) >= MISS_ERROR {
        (
            level::ERROR,
            format!("{misses} deadline misses in {steps} steps"),
        )
    } else if p.frac(misses) >= MISS_WARN || jumps > 0 {
        (
            level::WARN,
            format!("{misses} deadline misses, {jumps} time jumps (lost time advanced in one step) in {steps} steps"),
        )
    } else {
        (level::OK, "on time".into())
    };
    p.status(
        "loop timing",
        lvl,
        msg,
        vec![
            kv("steps", s.steps),
            kv("deadline misses", s.deadline_misses),
            kv("deadline misses in the period", misses),
            kv("catch-up steps", s.catch_up_steps),
            kv("time jumps (lost time advanced in one step)", s.time_jumps),
            kv("wall clock jumps", s.clock_jumps),
            kv("compute p50 (us)", us(s.compute_time_ns[0])),
            kv("compute p99 (us)", us(s.compute_time_ns[1])),
            kv("compute max (us)", us(s.compute_time_ns[2])),
            kv("jitter p50 (us)", us(s.period_jitter_ns[0])),
            kv("jitter p99 (us)", us(s.period_jitter_ns[1])),
            kv("jitter max (us)", us(s.period_jitter_ns[2])),
        ],
    )
}

fn solver(p: &Period) -> DiagnosticStatus {
    let (s, steps) = (p.now, p.steps);
    let bad = p.delta(|r| r.steps_not_converged);
    let (lvl, msg) = if p.frac(bad) >= SOLVER_ERROR {
        (
            level::ERROR,
            format!("{bad} of {steps} steps not converged"),
        )
    } else if bad > 0 {
        (level::WARN, format!("{bad} of {steps} steps not converged"))
    } else {
        (level::OK, "every step converged".into())
    };
    p.status(
        "solver",
        lvl,
        msg,
        vec![
            kv("steps not converged", s.steps_not_converged),
            kv("steps not converged in the period", bad),
            kv("parameter updates", s.parameter_updates),
        ],
    )
}

fn commands(p: &Period) -> DiagnosticStatus {
    let s = p.now;
    let rejected = p.delta(|r| r.commands_rejected);
    let overwritten = p.delta(|r| r.commands_overwritten);
    let timeouts = p.delta(|r| r.command_timeouts);
    let (lvl, msg) = if rejected + overwritten + timeouts > 0 {
        (
            level::WARN,
            format!(
                "{rejected} rejected, {overwritten} overwritten, {timeouts} steps on a timed-out command"
            ),
        )
    } else {
        (level::OK, "every command applied".into())
    };
    p.status(
        "commands",
        lvl,
        msg,
        vec![
            kv("received", s.commands_received),
            kv("applied", s.commands_applied),
            kv("overwritten", s.commands_overwritten),
            kv("rejected", s.commands_rejected),
            kv("steps on a timed-out command", s.command_timeouts),
        ],
    )
}

fn outputs(p: &Period) -> DiagnosticStatus {
    let s = p.now;
    let lost = p.delta(|r| r.publish_drops)
        + p.delta(|r| r.publish_failures)
        + p.delta(|r| r.statistics_not_sent);
    p.status(
        "outputs",
        if lost > 0 { level::WARN } else { level::OK },
        if lost > 0 {
            format!("{lost} outputs dropped or not sent")
        } else {
            "every output sent".into()
        },
        vec![
            kv("publish drops", s.publish_drops),
            kv("publish failures", s.publish_failures),
            kv("statistics not sent", s.statistics_not_sent),
        ],
    )
}

fn recorder(p: &Period) -> DiagnosticStatus {
    let s = p.now;
    let drops = p.delta(|r| r.recorder_drops);
    let lost = p.delta(|r| r.recording.lost);
    let (lvl, msg) = if lost > 0 {
        (
            level::ERROR,
            format!("{lost} messages lost: writing failed"),
        )
    } else if drops > 0 {
        (
            level::WARN,
            format!("{drops} messages dropped by a full recorder queue"),
        )
    } else if s.recording.files == 0 {
        (level::OK, "not recording".into())
    } else {
        (level::OK, "recording".into())
    };
    p.status(
        "recorder",
        lvl,
        msg,
        vec![
            kv("files", s.recording.files),
            kv("files deleted for the budget", s.recording.files_deleted),
            kv("messages lost", s.recording.lost),
            kv("queue drops", s.recorder_drops),
            kv("snapshots", s.recording.snapshots),
            kv("last snapshot", s.recording.last_snapshot.as_str()),
        ],
    )
}

fn calibrated_range(p: &Period) -> DiagnosticStatus {
    let s = p.now;
    let outside = p.delta(|r| r.steps_outside_calibrated_range);
    let (lvl, msg) = match s.last_outside.filter(|_| outside > 0) {
        Some(o) => {
            let u = o.unit;
            let contact = if s.contacts > 1 {
                format!("contact {}: ", o.contact)
            } else {
                String::new()
            };
            (
                level::WARN,
                format!(
                    "{contact}{} {} {u} outside the calibrated {} to {} {u} ({outside} of {} contact steps outside)",
                    o.input,
                    crate::text::Num(o.value),
                    crate::text::Num(o.lo),
                    crate::text::Num(o.hi),
                    p.steps * u64::from(s.contacts.max(1)),
                ),
            )
        }
        None => (
            level::OK,
            "every input inside its contact's calibrated range (or none given)".into(),
        ),
    };
    p.status(
        "calibrated range",
        lvl,
        msg,
        vec![
            kv("steps outside", s.steps_outside_calibrated_range),
            kv("steps outside in the period", outside),
        ],
    )
}

impl HealthReporter {
    /// The array for `s` (compared with the previous statistics).
    pub fn update(&mut self, s: &StatisticsRecord, node: &str, frame_id: &str) -> DiagnosticArray {
        let before = self.previous.unwrap_or_default();
        self.previous = Some(*s);
        let period = Period {
            now: s,
            before,
            steps: s.steps.saturating_sub(before.steps).max(1),
            node,
        };
        DiagnosticArray {
            header: Header {
                stamp: Time::from_ns(s.stamp_ns),
                frame_id: frame_id.to_string(),
            },
            status: vec![
                timing(&period),
                solver(&period),
                commands(&period),
                outputs(&period),
                recorder(&period),
                calibrated_range(&period),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_outside_the_calibrated_range_warns_naming_it_and_clears_when_it_returns() {
        let mut d = HealthReporter::default();
        let mut s = StatisticsRecord {
            steps: 1000,
            contacts: 1,
            ..Default::default()
        };
        let find = |a: &DiagnosticArray| {
            a.status
                .iter()
                .find(|x| x.name == "/n: calibrated range")
                .unwrap()
                .clone()
        };
        assert_eq!(find(&d.update(&s, "/n", "f")).level, level::OK);
        s.steps = 2000;
        s.steps_outside_calibrated_range = 250;
        s.last_outside = Some(crate::msgs::OutsideEvent {
            contact: 0,
            input: "speed forward",
            value: 1.57,
            lo: 0.0,
            hi: 0.35,
            unit: "m/s",
        });
        let w = find(&d.update(&s, "/n", "f"));
        assert_eq!(w.level, level::WARN);
        assert!(
            w.message
                .contains("speed forward 1.57 m/s outside the calibrated 0 to 0.35 m/s"),
            "{}",
            w.message
        );
        assert!(w.message.contains("250 of 1000"), "{}", w.message);
        // Back inside: no new step outside in the period.
        s.steps = 3000;
        s.last_outside = None;
        let ok = find(&d.update(&s, "/n", "f"));
        assert_eq!(ok.level, level::OK, "{}", ok.message);
    }

    #[test]
    fn levels_follow_the_documented_thresholds_per_period() {
        let mut d = HealthReporter::default();
        let mut s = StatisticsRecord {
            steps: 1000,
            ..Default::default()
        };
        let a = d.update(&s, "/friction_node", "slider");
        assert!(a.status.iter().all(|x| x.level == level::OK), "{a:?}");
        assert_eq!(a.status[0].name, "/friction_node: loop timing");
        // 2 misses in 1000 steps: WARN; then 60 in 1000: ERROR.
        s.steps = 2000;
        s.deadline_misses = 2;
        s.steps_not_converged = 3;
        s.commands_rejected = 1;
        let b = d.update(&s, "/friction_node", "slider");
        assert_eq!(b.status[0].level, level::WARN);
        assert_eq!(b.status[1].level, level::WARN);
        assert_eq!(b.status[2].level, level::WARN);
        s.steps = 3000;
        s.deadline_misses = 62;
        s.steps_not_converged = 13;
        let c = d.update(&s, "/friction_node", "slider");
        assert_eq!(c.status[0].level, level::ERROR);
        assert_eq!(c.status[1].level, level::ERROR);
        assert_eq!(c.status[2].level, level::OK, "nothing new rejected");
        s.steps = 4000;
        s.recording.lost = 5;
        let e = d.update(&s, "/friction_node", "slider");
        assert_eq!(e.status[0].level, level::OK, "no new misses");
        assert_eq!(e.status[4].level, level::ERROR);
        let kv = |a: &DiagnosticArray, i: usize, k: &str| {
            a.status[i]
                .values
                .iter()
                .find(|v| v.key == k)
                .unwrap()
                .value
                .clone()
        };
        assert_eq!(kv(&c, 0, "deadline misses in the period"), "60");
    }
}
