//! The real-time loop on simulated time (exact step counts: no test here
//! depends on how busy the machine is): deadlines, catch-up, clock jumps,
//! command validation and accounting, timeouts, statistics. Recording is
//! tested in `tests/recording/`.

mod common;
use common::{drain, timer_config};

use friction_node::clock::{Clock, SimClock};
use friction_node::config::{Config, StepMode, TimeoutBehaviour};
use friction_node::link::LiveStatus;
use friction_node::msgs::{
    estimate_constants as codes, Command, CommandKind, EstimateRecord, StatisticsRecord,
};
use friction_node::node::{Loop, RunSummary};
use friction_node::transport::memory::{MemoryNode, MemoryQueues};
use friction_node::transport::{NodePort, PeerPort, PortCounters, TransportError};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

const WALL0: u64 = 1_763_900_000_000_000_000;
const MS: u64 = 1_000_000;

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

fn sim(link: &MemoryQueues, cfg: &Config, first_step: u64, ms: u64) -> (RunSummary, Arc<SimClock>) {
    let clock = Arc::new(SimClock::starting_at(first_step * MS, WALL0));
    let s = run_sim(cfg, Box::new(link.node()), clock.clone(), first_step, ms);
    (s, clock)
}

#[test]
fn timer_mode_takes_one_step_per_period_holds_the_command_and_flags_the_timeout() {
    let cfg = timer_config();
    let link = MemoryQueues::new(100_000);
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
        let link = MemoryQueues::new(1000);
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
    let link = MemoryQueues::new(1000);
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
fn a_stall_beyond_the_catch_up_bound_is_advanced_in_one_time_jump() {
    let cfg = timer_config(); // max_catch_up_s = 0.1
    let link = MemoryQueues::new(1000);
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
    // 50 steps, the stall during the 50th; one time jump over the 500 ms
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
        let link = MemoryQueues::new(1000);
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
    let link = MemoryQueues::new(1000);
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
    let link = MemoryQueues::new(100_000);
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
    let link = MemoryQueues::new(100_000);
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
    let link = MemoryQueues::new(1000);
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
    let link = MemoryQueues::new(16);
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
