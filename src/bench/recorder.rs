//! `friction-node bench-recorder`: the recorder over simulated days, as
//! fast as it can write. A feeder produces what the node hands the recorder
//! at its full rate (one estimate per step, the command, the statistics),
//! stamped on a simulated clock that never waits for wall time; the recorder
//! splits, deletes to its budget and writes as in production. The resident
//! memory is sampled every simulated hour.

use crate::clock::SimClock;
use crate::config::topics::TopicNames;
use crate::config::Config;
use crate::link::RecordItem;
use crate::msgs::{Command, CommandKind, EstimateRecord, StatisticsRecord};
use crate::record::{RecordPlan, Recorder, RecorderError, RecorderReport};
use std::path::PathBuf;
use std::sync::Arc;

/// What the benchmark reports.
#[derive(Debug, Clone)]
pub struct RecorderBench {
    /// Resident memory at the end of each simulated hour, bytes.
    pub rss_by_hour: Vec<u64>,
    /// What the recorder reported.
    pub report: RecorderReport,
    /// Wall time, s.
    pub wall_s: f64,
    /// Steps recorded.
    pub steps: u64,
}

/// Queue `item`, waiting for room: full rate, never lossy (the recorder is
/// waited for, not time).
fn push(q: &crossbeam_queue::ArrayQueue<RecordItem>, item: RecordItem) {
    let mut item = item;
    while let Err(back) = q.push(item) {
        item = back;
        std::thread::yield_now();
    }
}

/// One simulated step of the recording bench.
struct Step {
    /// Its number, from 1.
    k: u64,
    stamp_ns: u64,
    /// Whether loop statistics are due.
    statistics: bool,
}

impl Step {
    /// What the loop would hand the recorder at this step: the command,
    /// the estimate and, when due, the statistics.
    fn items(&self, config: &Config) -> impl Iterator<Item = RecordItem> {
        let (k, t) = (self.k, self.stamp_ns);
        let v = (2.0 * std::f64::consts::PI * k as f64 * config.solver.dt_s).sin();
        let command = RecordItem::Command {
            command: Command {
                kind: CommandKind::Velocity,
                value: v,
                stamp_ns: t,
            },
            received_ns: t,
        };
        let estimate = RecordItem::Estimate {
            record: EstimateRecord {
                stamp_ns: t,
                velocity_m_s: v,
                load_n: config.contact.load_n,
                friction_force_n: 3000.0 * v,
                cof: 0.1 + 0.01 * v,
                h0_m: 1e-5,
                iterations: 1,
                ..Default::default()
            },
            logged_ns: t,
            contact: 0,
        };
        let statistics = self.statistics.then_some(RecordItem::Statistics {
            record: StatisticsRecord {
                stamp_ns: t,
                steps: k,
                ..Default::default()
            },
            logged_ns: t,
        });
        [command, estimate].into_iter().chain(statistics)
    }
}

/// Feed `hours` of simulated recording into `dir` (a split directory).
pub fn run(
    config: &Config,
    dir: PathBuf,
    hours: u64,
    progress: &dyn Fn(u64, u64),
) -> Result<RecorderBench, RecorderError> {
    let clock = Arc::new(SimClock::new(1_763_900_000_000_000_000));
    let rec = Recorder::start(
        RecordPlan {
            path: Some(dir.clone()),
            snapshot_dir: dir,
        },
        config,
        &TopicNames::from_config(config),
        None,
        clock.clone(),
    )?;
    let q = rec.queue();
    let dt_ns = crate::link::secs_to_ns(config.solver.dt_s).max(1);
    let per_hour = 3_600_000_000_000 / dt_ns;
    let stats_every = (1.0 / config.node.statistics_rate_hz / config.solver.dt_s).round() as u64;
    let started = std::time::Instant::now();
    let mut rss_by_hour = Vec::new();
    let wall0 = 1_763_900_000_000_000_000u64;
    let mut k = 0u64;
    for h in 0..hours {
        for _ in 0..per_hour {
            k += 1;
            clock.advance(dt_ns);
            let step = Step {
                k,
                stamp_ns: wall0 + k * dt_ns,
                statistics: stats_every > 0 && k.is_multiple_of(stats_every),
            };
            for item in step.items(config) {
                push(&q, item);
            }
        }
        // Let the recorder catch up before sampling.
        while !q.is_empty() {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        rss_by_hour.push(crate::node::rt::resident_bytes().unwrap_or(0));
        progress(h + 1, hours);
    }
    let report = rec.finish();
    Ok(RecorderBench {
        rss_by_hour,
        report,
        wall_s: started.elapsed().as_secs_f64(),
        steps: k,
    })
}
