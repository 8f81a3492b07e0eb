//! The real-time loop on simulated time (exact step counts: no test here
//! depends on how busy the machine is): deadlines, catch-up, clock jumps,
//! command validation and accounting, timeouts, statistics; then MCAP
//! recording (round trip, signals, crashes, full disks) in real processes,
//! which the tests wait on by events, never by fixed sleeps.

use friction_node::clock::{Clock, SimClock};
use friction_node::config::{Config, StepMode, TimeoutBehaviour};
use friction_node::msgs::{
    estimate_constants as codes, Command, CommandKind, EstimateRecord, StatisticsRecord,
};
use friction_node::node::{LiveStatus, Loop, RunSummary};
use friction_node::transport::memory::{MemoryLink, MemoryNode};
use friction_node::transport::{NodePort, PeerPort, PortCounters, TransportError};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

const WALL0: u64 = 1_763_900_000_000_000_000;
const MS: u64 = 1_000_000;

fn timer_config() -> Config {
    let mut c = Config::default();
    c.solver.cells = 32;
    c.node.step_mode = StepMode::Timer;
    c.node.statistics_rate_hz = 10.0;
    c.node.command_timeout_s = 0.05;
    c
}

fn drain(peer: &mut dyn PeerPort) -> Vec<EstimateRecord> {
    std::iter::from_fn(|| peer.try_recv().unwrap()).collect()
}

fn velocity(value: f64, stamp_ns: u64) -> Command {
    Command {
        kind: CommandKind::Velocity,
        value,
        stamp_ns,
    }
}

/// A memory port that does something to the clock at given polls (a stall,
/// an NTP step) or sends a command then: events at exact simulated times.
struct Scripted {
    inner: MemoryNode,
    clock: Arc<SimClock>,
    polls: u64,
    /// (poll number, advance monotonic ns, step wall ns)
    events: Vec<(u64, u64, i64)>,
}

impl NodePort for Scripted {
    fn name(&self) -> &'static str {
        "scripted"
    }
    fn poll_command(&mut self) -> Result<Option<Command>, TransportError> {
        let c = self.inner.poll_command()?;
        if c.is_none() {
            self.polls += 1;
            for &(at, advance, jump) in &self.events {
                if at == self.polls {
                    self.clock.advance(advance);
                    self.clock.jump_wall(jump);
                }
            }
        }
        Ok(c)
    }
    fn publish_estimate(&mut self, contact: usize, e: &EstimateRecord) -> bool {
        self.inner.publish_estimate(contact, e)
    }
    fn publish_efforts(&mut self, stamp_ns: u64, efforts: &[f64]) -> bool {
        self.inner.publish_efforts(stamp_ns, efforts)
    }
    fn publish_statistics(&mut self, s: &StatisticsRecord) -> bool {
        self.inner.publish_statistics(s)
    }
    fn wait_for_command(&mut self, t: Duration) -> Result<(), TransportError> {
        self.inner.wait_for_command(t)
    }
    fn counters(&self) -> PortCounters {
        self.inner.counters()
    }
}

/// Run a loop on a simulated clock for `ms` simulated milliseconds.
fn run_sim(
    cfg: &Config,
    port: Box<dyn NodePort>,
    clock: Arc<SimClock>,
    first_step: u64,
    ms: u64,
) -> RunSummary {
    let mut l = Loop::new(cfg, vec![port], None, None, Arc::new(LiveStatus::default()))
        .unwrap()
        .with_clock(clock)
        .resume_at_step(first_step);
    l.run(&AtomicBool::new(false), Some(Duration::from_millis(ms)))
}

fn sim(link: &MemoryLink, cfg: &Config, first_step: u64, ms: u64) -> (RunSummary, Arc<SimClock>) {
    let clock = Arc::new(SimClock::starting_at(first_step * MS, WALL0));
    let s = run_sim(cfg, Box::new(link.node()), clock.clone(), first_step, ms);
    (s, clock)
}

#[test]
fn timer_mode_takes_one_step_per_period_holds_the_command_and_flags_the_timeout() {
    let cfg = timer_config();
    let link = MemoryLink::new(100_000);
    let mut peer = link.peer();
    peer.send(&velocity(0.4, 1)).unwrap();
    let (s, _) = sim(&link, &cfg, 0, 400);
    let est = drain(&mut peer);
    assert_eq!(s.steps, 400, "exactly one step per simulated millisecond");
    assert_eq!(est.len(), 400);
    assert_eq!((s.deadline_misses, s.catch_up_steps), (0, 0));
    assert_eq!(s.jitter_ns, [0, 0, 0]);
    assert!(est.iter().all(|e| e.velocity_m_s == 0.4));
    // Fresh at the first step, held while younger than 50 ms, then timed out.
    assert_eq!(est[0].command_status, codes::COMMAND_FRESH);
    assert!(est[1..51]
        .iter()
        .all(|e| e.command_status == codes::COMMAND_HELD));
    assert!(est[51..]
        .iter()
        .all(|e| e.command_status == codes::COMMAND_TIMED_OUT));
    assert!(est.iter().all(|e| e.status == codes::STATUS_CONVERGED));
    assert_eq!(s.command_timeouts, 349);
    // Stamps are the deadlines in wall time: exactly 1 ms apart.
    assert!(est.windows(2).all(|w| w[1].stamp_ns - w[0].stamp_ns == MS));
    assert_eq!(est[0].stamp_ns, WALL0 + MS);
    // Statistics at 10 Hz, with the accounting of every command.
    let stats = link.take_statistics();
    assert_eq!(stats.len(), 4);
    assert_eq!(stats[0].steps, 100);
    assert_eq!(
        (stats[3].commands_received, stats[3].commands_applied),
        (1, 1)
    );
}

#[test]
fn deadlines_stay_exactly_one_period_apart_across_step_2_pow_32_and_after_a_year() {
    for first in [(1u64 << 32) - 10, 365 * 86_400 * 1000] {
        let link = MemoryLink::new(1000);
        let mut peer = link.peer();
        peer.send(&velocity(0.1, 1)).unwrap();
        let (s, clock) = sim(&link, &timer_config(), first, 20);
        let est = drain(&mut peer);
        assert_eq!(s.steps, 20, "from step {first}");
        assert!(
            est.windows(2).all(|w| w[1].stamp_ns - w[0].stamp_ns == MS),
            "stamps k·Δt apart from step {first}"
        );
        assert!(est.iter().all(|e| e.late_ns == 0));
        assert_eq!(s.jitter_ns, [0, 0, 0]);
        assert_eq!(s.deadline_misses, 0);
        assert_eq!(clock.now_ns(), (first + 20) * MS, "the last deadline");
    }
}

#[test]
fn a_late_wake_up_is_caught_up_step_by_step_and_model_time_stays_wall_time() {
    let cfg = timer_config();
    let link = MemoryLink::new(1000);
    let mut peer = link.peer();
    let clock = Arc::new(SimClock::new(WALL0));
    let port = Scripted {
        inner: link.node(),
        clock: clock.clone(),
        polls: 0,
        // During the 100th step the machine stalls for 30 ms.
        events: vec![(100, 30 * MS, 0)],
    };
    peer.send(&velocity(0.2, 1)).unwrap();
    let s = run_sim(&cfg, Box::new(port), clock, 0, 300);
    let est = drain(&mut peer);
    assert_eq!(s.steps, 300, "no period lost");
    assert_eq!(s.time_jumps, 0);
    // Steps 101..=129 were due during the stall: each starts late, and says
    // how late; step 130 is on time again.
    assert_eq!(s.catch_up_steps, 29);
    assert_eq!(est[100].late_ns, 29 * MS);
    assert!(est[100..129].iter().all(|e| e.late_ns >= MS));
    assert!(est[129..].iter().all(|e| e.late_ns == 0));
    assert!(est[..100].iter().all(|e| e.late_ns == 0));
    // Stamps still follow the deadlines exactly.
    assert!(est.windows(2).all(|w| w[1].stamp_ns - w[0].stamp_ns == MS));
}

#[test]
fn a_stall_beyond_the_catch_up_bound_is_advanced_in_one_long_step() {
    let cfg = timer_config(); // max_catch_up_s = 0.1
    let link = MemoryLink::new(1000);
    let mut peer = link.peer();
    let clock = Arc::new(SimClock::new(WALL0));
    let port = Scripted {
        inner: link.node(),
        clock: clock.clone(),
        polls: 0,
        events: vec![(50, 500 * MS, 0)],
    };
    peer.send(&velocity(0.2, 1)).unwrap();
    let s = run_sim(&cfg, Box::new(port), clock, 0, 1000);
    let est = drain(&mut peer);
    assert_eq!(s.time_jumps, 1);
    // 50 steps, the stall during the 50th; one long step over the 500 ms
    // lost (to the last deadline passed, 550 ms), then 450 steps.
    assert_eq!(s.steps, 50 + 1 + 450);
    let jump = est
        .windows(2)
        .find(|w| w[1].stamp_ns - w[0].stamp_ns > MS)
        .unwrap();
    assert_eq!(jump[0].stamp_ns, WALL0 + 50 * MS);
    assert_eq!(jump[1].stamp_ns - jump[0].stamp_ns, 500 * MS);
    assert!(est.iter().all(|e| e.status == codes::STATUS_CONVERGED));
    // Model time is wall time: the last stamp is the last deadline.
    assert_eq!(est.last().unwrap().stamp_ns, WALL0 + 1000 * MS);
}

/// A simulated clock that logs how the loop waits: ("sleep" | "spin", deadline).
struct WaitLog {
    inner: SimClock,
    waits: std::sync::Mutex<Vec<(&'static str, u64)>>,
}

impl Clock for WaitLog {
    fn now_ns(&self) -> u64 {
        self.inner.now_ns()
    }
    fn sleep_until_ns(&self, deadline_ns: u64) {
        self.waits.lock().unwrap().push(("sleep", deadline_ns));
        self.inner.sleep_until_ns(deadline_ns)
    }
    fn spin_until_ns(&self, deadline_ns: u64) {
        self.waits.lock().unwrap().push(("spin", deadline_ns));
        self.inner.sleep_until_ns(deadline_ns)
    }
    fn wall_ns(&self) -> u64 {
        self.inner.wall_ns()
    }
}

#[test]
fn timer_spin_busy_waits_the_last_microseconds_of_each_period_and_changes_no_estimate() {
    let run = |spin_us: u64| {
        let mut cfg = timer_config();
        cfg.node.timer_spin_us = spin_us;
        let link = MemoryLink::new(1000);
        let mut peer = link.peer();
        peer.send(&velocity(0.3, 1)).unwrap();
        let clock = Arc::new(WaitLog {
            inner: SimClock::new(WALL0),
            waits: Default::default(),
        });
        let mut l = Loop::new(
            &cfg,
            vec![Box::new(link.node())],
            None,
            None,
            Default::default(),
        )
        .unwrap()
        .with_clock(clock.clone());
        let s = l.run(&AtomicBool::new(false), Some(Duration::from_millis(50)));
        let waits = clock.waits.lock().unwrap().clone();
        (s, drain(&mut peer), waits)
    };
    let (slept, est_slept, waits_slept) = run(0);
    assert_eq!(slept.steps, 50);
    assert!(waits_slept.iter().all(|w| w.0 == "sleep"));
    for spin_us in [300, 5_000] {
        let (spun, est_spun, waits) = run(spin_us);
        assert_eq!(spun.steps, 50, "spin {spin_us} µs");
        assert_eq!(spun.deadline_misses, 0);
        // Each period: sleep to the deadline less the spin, then spin to it.
        let steps: Vec<_> = waits.chunks(2).collect();
        assert_eq!(steps.len(), 50);
        for (k, w) in steps.iter().enumerate() {
            let due = (k as u64 + 1) * MS;
            assert_eq!(w[0], ("sleep", due.saturating_sub(spin_us * 1000)));
            assert_eq!(w[1], ("spin", due));
        }
        assert_eq!(est_spun.len(), est_slept.len());
        for (a, b) in est_spun.iter().zip(&est_slept) {
            assert_eq!(a.stamp_ns, b.stamp_ns);
            assert_eq!(a.friction_force_n.to_bits(), b.friction_force_n.to_bits());
        }
    }
}

#[test]
fn a_wall_clock_set_back_changes_no_deadline_and_stamps_stay_monotonic() {
    let cfg = timer_config();
    let link = MemoryLink::new(1000);
    let mut peer = link.peer();
    let clock = Arc::new(SimClock::new(WALL0));
    let port = Scripted {
        inner: link.node(),
        clock: clock.clone(),
        polls: 0,
        // NTP sets the wall clock back 10 s, later forward 2 s.
        events: vec![(100, 0, -10_000_000_000), (200, 0, 2_000_000_000)],
    };
    peer.send(&velocity(0.2, 1)).unwrap();
    let s = run_sim(&cfg, Box::new(port), clock, 0, 300);
    let est = drain(&mut peer);
    assert_eq!(s.steps, 300);
    assert_eq!(s.clock_jumps, 2);
    assert_eq!(s.deadline_misses, 0);
    assert!(est.iter().all(|e| e.late_ns == 0), "no deadline moved");
    assert!(
        est.windows(2).all(|w| w[1].stamp_ns > w[0].stamp_ns),
        "stamps never go back"
    );
}

#[test]
fn timeout_ramp_brings_the_velocity_to_zero_at_the_configured_deceleration() {
    let mut cfg = timer_config();
    cfg.node.timeout_behaviour = TimeoutBehaviour::RampToZero;
    cfg.node.timeout_deceleration_m_s2 = 4.0;
    let link = MemoryLink::new(100_000);
    let mut peer = link.peer();
    peer.send(&velocity(0.3, 1)).unwrap();
    sim(&link, &cfg, 0, 600);
    let est = drain(&mut peer);
    let ramp: Vec<f64> = est
        .iter()
        .filter(|e| e.command_status == codes::COMMAND_TIMED_OUT)
        .map(|e| e.velocity_m_s)
        .collect();
    assert_eq!(ramp.len(), 600 - 51);
    // 4 m/s² × 1 ms per step: 0.3 → 0 in 75 steps, monotonically.
    for (k, v) in ramp.iter().enumerate() {
        let expect = (0.3 - 0.004 * (k + 1) as f64).max(0.0);
        assert!((v - expect).abs() < 1e-12, "step {k}: {v} vs {expect}");
    }
}

#[test]
fn absurd_and_non_finite_commands_never_reach_the_solver_and_are_all_accounted_for() {
    let cfg = timer_config();
    let link = MemoryLink::new(100_000);
    let mut peer = link.peer();
    let mut send = |kind, value| {
        peer.send(&Command {
            kind,
            value,
            stamp_ns: 1,
        })
        .unwrap()
    };
    send(CommandKind::Velocity, 0.2);
    send(CommandKind::Load, 12_000.0);
    for bad in [f64::NAN, f64::INFINITY, 11.0, -50.0] {
        send(CommandKind::Velocity, bad);
    }
    for bad in [f64::NAN, -1.0, 0.0, 1e9] {
        send(CommandKind::Load, bad);
    }
    let (s, _) = sim(&link, &cfg, 0, 30);
    let est = drain(&mut link.peer());
    assert_eq!(s.commands_received, 10);
    assert_eq!(s.commands_rejected, 8);
    assert_eq!(s.commands_applied, 2);
    assert_eq!(
        s.commands_received,
        s.commands_applied + s.commands_overwritten + s.commands_rejected
    );
    // The first step reports the rejections; the good values are held.
    assert_eq!(est[0].command_status, codes::COMMAND_REJECTED);
    assert_eq!(est[0].status, codes::STATUS_CONVERGED);
    assert!(est
        .iter()
        .all(|e| e.velocity_m_s == 0.2 && e.load_n == 12_000.0 && e.friction_force_n.is_finite()));
    assert!(est[1..]
        .iter()
        .all(|e| e.command_status != codes::COMMAND_REJECTED));
}

#[test]
fn a_rejection_is_reported_even_when_the_solver_also_hits_its_iteration_bound() {
    // One Newton iteration allowed: steps end at the bound (status 1); the
    // rejected command must still show in command_status.
    let mut cfg = timer_config();
    cfg.node.step_mode = StepMode::Lockstep;
    cfg.solver.max_iterations = 1;
    cfg.solver.tolerance = 1e-14;
    let link = MemoryLink::new(1000);
    let mut peer = link.peer();
    peer.send(&velocity(0.5, 10)).unwrap();
    peer.send(&velocity(f64::NAN, 20)).unwrap();
    peer.send(&velocity(0.6, 30)).unwrap();
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
    .with_clock(Arc::new(SimClock::new(WALL0)));
    for c in [velocity(0.5, 10), velocity(f64::NAN, 20), velocity(0.6, 30)] {
        l.feed(c);
    }
    let est = drain(&mut peer);
    assert_eq!(est.len(), 3);
    assert_eq!(est[1].status, codes::STATUS_MAX_ITERATIONS);
    assert_eq!(est[1].command_status, codes::COMMAND_REJECTED);
    assert_eq!(est[1].velocity_m_s, 0.5, "the last good velocity held");
    assert_eq!(est[2].command_status, codes::COMMAND_FRESH);
}

#[test]
fn an_output_nobody_reads_for_ten_simulated_minutes_is_counted_and_does_not_stop_the_loop() {
    let mut cfg = timer_config();
    cfg.solver.cells = 8;
    let link = MemoryLink::new(16);
    let mut peer = link.peer();
    peer.send(&velocity(0.1, 1)).unwrap();
    let (s, _) = sim(&link, &cfg, 0, 600_000);
    assert_eq!(s.steps, 600_000);
    assert_eq!(
        s.publish_drops,
        600_000 - 16,
        "every estimate the full queue refused"
    );
    assert_eq!(s.deadline_misses, 0);
    drop(drain(&mut peer));
}

#[cfg(feature = "mcap")]
mod recording {
    use super::*;
    use friction_node::config::CommandType;
    use friction_node::msgs;
    use friction_node::record::{RecordPlan, Recorder};
    use friction_node::transport::names::TopicNames;
    use friction_node::transport::ProfileSlot;
    use std::collections::BTreeMap;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("fn-node-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d.join(name)
    }

    /// Decode every message of a finished MCAP file: counts per schema.
    fn decode_all(
        path: &std::path::Path,
    ) -> (BTreeMap<String, usize>, Vec<msgs::FrictionEstimate>, String) {
        let bytes = std::fs::read(path).unwrap();
        let summary = mcap::Summary::read(&bytes)
            .unwrap()
            .expect("a summary section");
        let mut counts = BTreeMap::new();
        let mut est = Vec::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(schema.encoding, "ros2msg");
            assert_eq!(m.channel.message_encoding, "cdr");
            assert!(m.channel.metadata.contains_key("offered_qos_profiles"));
            let name = schema.name.clone();
            match name.as_str() {
                "friction_msgs/msg/FrictionEstimate" => {
                    est.push(msgs::from_cdr::<msgs::FrictionEstimate>(&m.data).unwrap())
                }
                "friction_msgs/msg/FilmProfile" => {
                    let p: msgs::FilmProfile = msgs::from_cdr(&m.data).unwrap();
                    assert_eq!(p.h_m.len(), 32);
                }
                "friction_msgs/msg/LoopStatistics" => {
                    drop(msgs::from_cdr::<msgs::LoopStatistics>(&m.data).unwrap())
                }
                "std_msgs/msg/Float64" => drop(msgs::from_cdr::<msgs::Float64>(&m.data).unwrap()),
                "geometry_msgs/msg/TwistStamped" => {
                    drop(msgs::from_cdr::<msgs::TwistStamped>(&m.data).unwrap())
                }
                other => panic!("unexpected schema {other}"),
            }
            *counts
                .entry(format!("{} {}", m.channel.topic, name))
                .or_insert(0) += 1;
        }
        let mut config = String::new();
        for idx in &summary.metadata_indexes {
            let md = mcap::read::metadata(&bytes, idx).unwrap();
            if md.name == "friction_node" {
                config = md.metadata["config_yaml"].clone();
            }
        }
        (counts, est, config)
    }

    #[test]
    fn a_recorded_lockstep_run_decodes_message_by_message_with_its_config() {
        let mut cfg = timer_config();
        cfg.node.step_mode = StepMode::Lockstep;
        cfg.ros.command_type = CommandType::TwistStamped;
        cfg.node.profile_rate_hz = 100.0;
        cfg.contact.load_n = 15_000.0;
        let path = tmp("roundtrip.mcap");
        let slot = ProfileSlot::new(cfg.solver.cells);
        let rec = Recorder::start(
            RecordPlan {
                path: Some(path.clone()),
                snapshot_dir: path.parent().unwrap().to_path_buf(),
            },
            &cfg,
            &TopicNames::from_config(&cfg),
            Some(slot.clone()),
            Arc::new(SimClock::new(WALL0)),
        )
        .unwrap();
        let link = MemoryLink::new(100_000);
        let mut peer = link.peer();
        let n = 200;
        for k in 1..=n {
            peer.send(&Command {
                kind: CommandKind::Velocity,
                value: (k as f64 * 0.01).sin(),
                stamp_ns: 1_000_000 * k,
            })
            .unwrap();
        }
        let mut l = Loop::new(
            &cfg,
            vec![Box::new(link.node_recording(Some(rec.queue())))],
            Some(rec.queue()),
            Some(slot),
            Arc::new(LiveStatus::default()),
        )
        .unwrap()
        .with_clock(Arc::new(SimClock::new(WALL0)));
        while l.poll_once() > 0 {}
        let s = l.summary();
        assert_eq!(s.steps, n);
        let live = drain(&mut peer);
        let report = rec.finish();
        assert!(report.error.is_none(), "{report:?}");
        let (counts, est, config) = decode_all(&path);
        assert_eq!(
            counts["/friction_node/cmd_velocity geometry_msgs/msg/TwistStamped"],
            n as usize
        );
        assert_eq!(
            counts["/friction_node/friction friction_msgs/msg/FrictionEstimate"],
            n as usize
        );
        assert_eq!(
            counts["/friction_node/friction_force std_msgs/msg/Float64"],
            n as usize
        );
        assert!(counts["/friction_node/film_profile friction_msgs/msg/FilmProfile"] >= 1);
        assert_eq!(report.messages as usize, counts.values().sum::<usize>());
        // The recorded estimates are the published ones, bit for bit.
        let recorded: Vec<EstimateRecord> = est.iter().map(EstimateRecord::from_wire).collect();
        assert_eq!(recorded, live);
        // The config in the file is the resolved config.
        let back =
            Config::from_yaml(&config, &friction_node::config::Origin::Embedded, &[]).unwrap();
        assert_eq!(back, cfg);
    }

    #[cfg(feature = "ros2")]
    #[test]
    fn a_received_ros2_command_is_recorded_byte_for_byte_as_it_arrived() {
        use friction_node::transport::{ros2::Ros2Peer, ros2::Ros2Spec, BackendSpec};
        let mut cfg = timer_config();
        cfg.node.step_mode = StepMode::Lockstep;
        cfg.ros.command_type = CommandType::TwistStamped;
        cfg.ros.domain_id = 100 + (std::process::id() % 100) as i64;
        cfg.ros.namespace = format!("/fn_raw_{}", std::process::id());
        cfg.ros.qos.commands.reliability = friction_node::config::Reliability::Reliable;
        cfg.ros.qos.commands.durability = friction_node::config::Durability::TransientLocal;
        cfg.ros.qos.commands.depth = 100;
        let path = tmp("raw.mcap");
        let rec = Recorder::start(
            RecordPlan {
                path: Some(path.clone()),
                snapshot_dir: path.parent().unwrap().to_path_buf(),
            },
            &cfg,
            &TopicNames::from_config(&cfg),
            None,
            Arc::new(SimClock::new(WALL0)),
        )
        .unwrap();
        let spec = Ros2Spec::from_config(&cfg).unwrap();
        let port = BackendSpec::Ros2(spec.clone())
            .open_node(friction_node::transport::PortIo {
                record: Some(rec.queue()),
                ..Default::default()
            })
            .unwrap();
        let mut l = Loop::new(
            &cfg,
            vec![port],
            Some(rec.queue()),
            None,
            Arc::new(LiveStatus::default()),
        )
        .unwrap();
        let mut peer = Ros2Peer::open(&spec).unwrap();
        let start = std::time::Instant::now();
        while !peer.is_matched() {
            assert!(start.elapsed() < Duration::from_secs(30), "discovery");
            std::thread::sleep(Duration::from_millis(5));
        }
        // Everything a sender may put in it: another frame, angular velocity.
        let mut sent = msgs::TwistStamped::default();
        sent.header.frame_id = "sender_frame_äö".into();
        sent.header.stamp = msgs::Time::from_ns(WALL0 + 123);
        sent.twist.linear.x = 0.25;
        sent.twist.linear.y = -1.5;
        sent.twist.angular.z = 0.7;
        peer.send_twist(&sent).unwrap();
        let start = std::time::Instant::now();
        while l.summary().steps == 0 {
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "the command arrives"
            );
            l.poll_once();
            std::thread::sleep(Duration::from_millis(1));
        }
        drop(l);
        let report = rec.finish();
        assert!(report.error.is_none(), "{report:?}");
        let bytes = std::fs::read(&path).unwrap();
        let raw: Vec<Vec<u8>> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .map(Result::unwrap)
            .filter(|m| m.channel.topic.ends_with("cmd_velocity"))
            .map(|m| m.data.into_owned())
            .collect();
        assert_eq!(raw.len(), 1);
        assert_eq!(raw[0], msgs::to_cdr(&sent).unwrap(), "the bytes as sent");
        let back: msgs::TwistStamped = msgs::from_cdr(&raw[0]).unwrap();
        assert_eq!(back, sent);
    }

    fn node_cmd(args: &[&str]) -> std::process::Command {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_friction-node"));
        let svc = format!("fn_node_test_{}_{}", std::process::id(), args.len());
        c.args(args)
            .arg("--set")
            .arg(format!("iceoryx2.cmd_velocity_service={svc}/v"))
            .arg("--set")
            .arg(format!("iceoryx2.normal_load_service={svc}/l"))
            .arg("--set")
            .arg(format!("iceoryx2.friction_service={svc}/f"))
            .arg("--set")
            .arg(format!("iceoryx2.cmd_event_service={svc}/e"))
            .arg("--set")
            .arg(format!("iceoryx2.loop_statistics_service={svc}/s"))
            .arg("--set")
            .arg("solver.cells=32")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        c
    }

    /// Wait (at most `limit`) until `ok()` holds; panics with `what` if not.
    fn wait_for(what: &str, limit: Duration, mut ok: impl FnMut() -> bool) {
        let start = std::time::Instant::now();
        while !ok() {
            assert!(start.elapsed() < limit, "{what} not within {limit:?}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Read the child's stderr until the loop-running line (then keep
    /// draining it in the background so the child never blocks on it).
    fn wait_running(child: &mut std::process::Child) {
        use std::io::BufRead;
        let err = child.stderr.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(err).lines().map_while(Result::ok) {
                if line.contains("loop running") {
                    let _ = tx.send(());
                }
            }
        });
        rx.recv_timeout(Duration::from_secs(60))
            .expect("the node reports its loop running");
    }

    fn messages_before_damage(path: &std::path::Path) -> (usize, bool) {
        let bytes = std::fs::read(path).unwrap();
        let mut n = 0;
        let mut damaged = false;
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            match m {
                Ok(_) => n += 1,
                Err(_) => {
                    damaged = true;
                    break;
                }
            }
        }
        (n, damaged)
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn sigterm_finalises_the_recording() {
        let path = tmp("sigterm.mcap");
        let mut child = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "600",
            "--quiet",
            "--record",
            path.to_str().unwrap(),
        ])
        .spawn()
        .unwrap();
        wait_running(&mut child);
        // The first chunk reached the disk: the node is recording.
        wait_for("a flushed chunk", Duration::from_secs(60), || {
            messages_before_damage(&path).0 > 100
        });
        unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
        let out = child.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("stopped by signal"), "{stdout}");
        let bytes = std::fs::read(&path).unwrap();
        assert!(
            mcap::Summary::read(&bytes).unwrap().is_some(),
            "finalised with a summary"
        );
        let (n, damaged) = messages_before_damage(&path);
        assert!(n > 100 && !damaged, "{n} messages");
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn a_killed_node_leaves_its_recording_readable_up_to_the_last_chunk() {
        let path = tmp("killed.mcap");
        let mut child = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "600",
            "--quiet",
            "--record",
            path.to_str().unwrap(),
        ])
        .spawn()
        .unwrap();
        wait_running(&mut child);
        let mut before = 0;
        wait_for("two flushed chunks", Duration::from_secs(60), || {
            before = messages_before_damage(&path).0;
            before > 1000
        });
        child.kill().unwrap();
        let _ = child.wait();
        // No footer, but every complete chunk (closed at least each second) reads.
        let (n, _) = messages_before_damage(&path);
        assert!(
            n >= before,
            "{n} messages readable after a crash, {before} before it"
        );
    }

    /// A child whose files cannot grow beyond `limit` bytes: writes beyond
    /// fail with EFBIG, as on a full disk (SIGXFSZ ignored).
    fn with_file_limit(mut c: std::process::Command, limit: u64) -> std::process::Command {
        use std::os::unix::process::CommandExt;
        unsafe {
            c.pre_exec(move || {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let r = libc::rlimit {
                    rlim_cur: limit,
                    rlim_max: limit,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &r) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        c
    }

    fn summary_steps(stdout: &str) -> u64 {
        stdout
            .lines()
            .find(|l| l.trim_start().starts_with("steps"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|s| s.parse().ok())
            .unwrap()
    }

    /// ROS 2 arguments on a domain and namespace of this test's own
    /// (iceoryx2 needs shared-memory files, which a file-size limit breaks).
    fn ros2_own(name: &str) -> [String; 4] {
        [
            "--set".into(),
            format!("ros.namespace=/fn_{name}_{}", std::process::id()),
            "--set".into(),
            format!("ros.domain_id={}", 150 + std::process::id() % 50),
        ]
    }

    #[cfg(feature = "ros2")]
    #[test]
    fn a_full_disk_stops_the_recording_not_the_loop() {
        let path = tmp("full.mcap");
        let mut c = node_cmd(&[
            "run",
            "--transport",
            "ros2",
            "--duration",
            "1.5",
            "--quiet",
            "--set",
            "recording.chunk_size_bytes=4096",
            "--record",
            path.to_str().unwrap(),
        ]);
        c.args(ros2_own("full"));
        let out = with_file_limit(c, 60_000).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{stdout}");
        assert!(stdout.contains("recording        FAILED"), "{stdout}");
        // Model time is wall time: 1.5 s of 1 ms steps (a stall beyond
        // node.max_catch_up_s would merge steps, never lose time).
        assert!(summary_steps(&stdout) >= 10, "{stdout}");
        // What reached the disk reads, up to the last complete chunk.
        assert!(messages_before_damage(&path).0 > 10);
    }

    #[cfg(feature = "ros2")]
    #[test]
    fn a_split_recording_resumes_in_a_new_file_when_writing_fails() {
        let dir = tmp("resume");
        let _ = std::fs::remove_dir_all(&dir);
        let mut c = node_cmd(&[
            "run",
            "--transport",
            "ros2",
            "--duration",
            "1.5",
            "--quiet",
            "--set",
            "recording.chunk_size_bytes=4096",
            "--set",
            "recording.split.max_duration_s=3600",
            "--record",
            dir.to_str().unwrap(),
        ]);
        c.args(ros2_own("resume"));
        let out = with_file_limit(c, 60_000).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{stdout}");
        let meta = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
        let files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".mcap"))
            .collect();
        assert!(
            files.len() >= 2,
            "resumed in new files: {files:?}\n{stdout}"
        );
        for f in &files {
            assert!(meta.contains(f.as_str()), "{f} listed in metadata.yaml");
            assert!(messages_before_damage(&dir.join(f)).0 > 0, "{f} readable");
        }
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn an_unwritable_recording_path_is_an_error_before_the_loop_runs() {
        let out = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "0.3",
            "--quiet",
            "--record",
            "/proc/nope/x.mcap",
        ])
        .output()
        .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("/proc/nope/x.mcap"), "{stderr}");
        assert!(!stderr.contains("loop running"), "{stderr}");
    }
}
