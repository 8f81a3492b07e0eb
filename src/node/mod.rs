//! The real-time node: a fixed-step loop around the physics core.
//!
//! Two step modes (`node.step_mode`):
//! - **timer**: steps of `solver.dt_s` against absolute deadlines on the
//!   monotonic clock; the latest velocity and load commands are held
//!   (zero-order hold); a velocity older than `node.command_timeout_s` is
//!   held or ramped to zero and the estimate's status says so. A step that
//!   ends after the next deadline is a deadline miss; when the loop falls
//!   more than a period behind it skips ahead instead of bursting.
//! - **lockstep**: one step per received velocity command, stamped with the
//!   command's stamp. Deterministic: the estimates equal an offline
//!   `simulate` of the same velocities bit for bit. A duplicate or
//!   out-of-order stamp is rejected, counted and produces no step.
//!
//! Commands that are not finite or beyond the configured limits never reach
//! the solver: they are rejected, counted, flagged in the next estimate's
//! status, and the last good value is held. Outputs go to every transport
//! port and to the recorder queue without blocking; a full queue is a
//! counted drop. The loop allocates nothing per step.

pub mod rt;
pub mod runner;
pub mod stats;

use crate::config::{Config, StepMode, TimeoutBehaviour};
use crate::msgs::{
    estimate_constants as codes, Command, CommandKind, EstimateRecord, RecordItem, StatisticsRecord,
};
use crate::physics::{SetupError, Solver};
use crate::transport::{NodePort, ProfileSlot};
use crossbeam_queue::ArrayQueue;
use stats::{Histogram, Window};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Wall-clock (ROS) time, ns since the Unix epoch.
pub fn wall_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// Live values for a status line (written by the loop, read anywhere).
#[derive(Debug, Default)]
pub struct LiveStatus {
    pub steps: AtomicU64,
    pub deadline_misses: AtomicU64,
    pub commands_received: AtomicU64,
    pub commands_rejected: AtomicU64,
    pub drops: AtomicU64,
    pub velocity_bits: AtomicU64,
    pub friction_bits: AtomicU64,
    pub cof_bits: AtomicU64,
    pub h0_bits: AtomicU64,
    pub compute_ns: AtomicU64,
    pub status: AtomicU64,
}

impl LiveStatus {
    pub fn f(v: &AtomicU64) -> f64 {
        f64::from_bits(v.load(Ordering::Relaxed))
    }
}

/// What a run reports when it ends.
#[derive(Debug, Clone, Default)]
pub struct RunSummary {
    pub steps: u64,
    pub wall_s: f64,
    pub deadline_misses: u64,
    pub commands_received: u64,
    pub commands_rejected: u64,
    pub command_timeouts: u64,
    pub publish_drops: u64,
    pub recorder_drops: u64,
    pub transport_errors: u64,
    /// p50, p99, max, ns.
    pub compute_ns: [u64; 3],
    pub jitter_ns: [u64; 3],
    /// Steps per estimate status code (index = code).
    pub status_counts: [u64; 8],
}

/// Settings the loop reads every step (from the configuration).
#[derive(Debug, Clone, PartialEq)]
pub struct LoopSettings {
    pub mode: StepMode,
    pub dt: f64,
    pub command_timeout: Duration,
    pub timeout_behaviour: TimeoutBehaviour,
    pub deceleration: f64,
    pub max_abs_velocity: f64,
    pub min_load: f64,
    pub max_load: f64,
    /// Steps between profile and statistics publications (0 = never).
    pub profile_every: u64,
    pub statistics_every: u64,
    pub lockstep_spin: Duration,
}

impl LoopSettings {
    pub fn from_config(c: &Config) -> Self {
        let dt = c.solver.dt_s;
        let every = |hz: f64| {
            if hz > 0.0 {
                ((1.0 / hz) / dt).round().max(1.0) as u64
            } else {
                0
            }
        };
        Self {
            mode: c.node.step_mode,
            dt,
            command_timeout: Duration::from_secs_f64(c.node.command_timeout_s),
            timeout_behaviour: c.node.timeout_behaviour,
            deceleration: c.node.timeout_deceleration_m_s2,
            max_abs_velocity: c.node.max_abs_velocity_m_s,
            min_load: c.node.min_load_n,
            max_load: c.node.max_load_n,
            profile_every: every(c.node.profile_rate_hz),
            statistics_every: every(c.node.statistics_rate_hz),
            lockstep_spin: Duration::from_micros(c.node.lockstep_spin_us),
        }
    }
}

/// Errors of the node layer (setup only: a running loop never fails).
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    #[error(transparent)]
    Setup(#[from] SetupError),
    #[error("the node needs at least one transport")]
    NoTransport,
}

/// The loop: solver, ports, outputs and bookkeeping.
pub struct Loop {
    solver: Solver,
    s: LoopSettings,
    ports: Vec<Box<dyn NodePort>>,
    record: Option<Arc<ArrayQueue<RecordItem>>>,
    profile: Option<Arc<ProfileSlot>>,
    live: Arc<LiveStatus>,
    // command state
    velocity: f64,
    applied: f64,
    load: f64,
    last_velocity_at: Instant,
    last_stamp: Option<u64>,
    rejected_pending: bool,
    timed_out: bool,
    // statistics
    summary: RunSummary,
    window_compute: Window,
    window_jitter: Window,
    hist_compute: Histogram,
    hist_jitter: Histogram,
    started: Instant,
}

impl Loop {
    /// Build the solver at the steady state of `node.initial_velocity_m_s`
    /// under `contact.load_n`.
    pub fn new(
        config: &Config,
        ports: Vec<Box<dyn NodePort>>,
        record: Option<Arc<ArrayQueue<RecordItem>>>,
        profile: Option<Arc<ProfileSlot>>,
        live: Arc<LiveStatus>,
    ) -> Result<Self, NodeError> {
        if ports.is_empty() {
            return Err(NodeError::NoTransport);
        }
        let mut solver = Solver::new(&config.model(), &config.solver_settings())?;
        let v0 = config.node.initial_velocity_m_s;
        let load = config.contact.load_n;
        solver.initialize_steady(v0, load);
        let s = LoopSettings::from_config(config);
        let window = (s.statistics_every as usize).clamp(16, 1 << 16);
        Ok(Self {
            solver,
            ports,
            record,
            profile,
            live,
            velocity: v0,
            applied: v0,
            load,
            last_velocity_at: Instant::now(),
            last_stamp: None,
            rejected_pending: false,
            timed_out: false,
            summary: RunSummary::default(),
            window_compute: Window::new(window),
            window_jitter: Window::new(window),
            hist_compute: Histogram::new(),
            hist_jitter: Histogram::new(),
            started: Instant::now(),
            s,
        })
    }

    pub fn solver(&self) -> &Solver {
        &self.solver
    }

    /// Apply one command as lockstep mode does (replay drives the loop this
    /// way): a velocity command steps the model unless its stamp is not newer
    /// than the last one; a load command updates the load.
    pub fn feed(&mut self, c: Command) {
        self.lockstep_command(c);
    }

    /// Counters so far (replay).
    pub fn summary(&self) -> &RunSummary {
        &self.summary
    }

    /// Run until `stop` is set or `duration` has passed (in the loop's mode).
    pub fn run(&mut self, stop: &AtomicBool, duration: Option<Duration>) -> RunSummary {
        self.started = Instant::now();
        self.last_velocity_at = self.started;
        match self.s.mode {
            StepMode::Timer => self.run_timer(stop, duration),
            StepMode::Lockstep => self.run_lockstep(stop, duration),
        }
        let mut out = self.summary.clone();
        out.wall_s = self.started.elapsed().as_secs_f64();
        out.compute_ns = self.hist_compute.summary();
        out.jitter_ns = self.hist_jitter.summary();
        out
    }

    fn run_timer(&mut self, stop: &AtomicBool, duration: Option<Duration>) {
        let dt = Duration::from_secs_f64(self.s.dt);
        let t0 = self.started;
        let end = duration.map(|d| t0 + d);
        let mut k: u64 = 0;
        loop {
            k += 1;
            let deadline = t0 + dt * k as u32;
            if end.is_some_and(|e| deadline > e) || stop.load(Ordering::Relaxed) {
                break;
            }
            rt::sleep_until(deadline);
            let woke = Instant::now();
            let jitter = woke.saturating_duration_since(deadline).as_nanos() as u64;
            self.drain_commands(woke);
            self.apply_timeout(woke);
            self.step(self.applied, wall_ns(), jitter);
            let done = Instant::now();
            if done > deadline + dt {
                self.summary.deadline_misses += 1;
                self.live.deadline_misses.fetch_add(1, Ordering::Relaxed);
                // More than a period behind: skip the lost periods.
                let behind = (done.duration_since(t0).as_secs_f64() / self.s.dt).floor() as u64;
                if behind > k {
                    self.summary.deadline_misses += behind - k - 1;
                    k = behind;
                }
            }
        }
    }

    fn run_lockstep(&mut self, stop: &AtomicBool, duration: Option<Duration>) {
        let end = duration.map(|d| self.started + d);
        let mut last_command = Instant::now();
        while !stop.load(Ordering::Relaxed) && end.is_none_or(|e| Instant::now() < e) {
            let mut any = false;
            for i in 0..self.ports.len() {
                while let Some(c) = self.poll(i) {
                    any = true;
                    self.lockstep_command(c);
                }
            }
            if any {
                last_command = Instant::now();
            } else if last_command.elapsed() < self.s.lockstep_spin {
                std::hint::spin_loop();
            } else {
                let wait = Duration::from_millis(if self.ports.len() == 1 { 20 } else { 1 });
                if self.ports[0].wait_for_command(wait).is_err() {
                    self.summary.transport_errors += 1;
                }
            }
        }
    }

    fn poll(&mut self, i: usize) -> Option<Command> {
        match self.ports[i].poll_command() {
            Ok(c) => c,
            Err(e) => {
                self.summary.transport_errors += 1;
                if self.summary.transport_errors == 1 {
                    tracing::warn!("{}: {e}", self.ports[i].name());
                }
                None
            }
        }
    }

    fn received(&mut self, c: &Command) {
        self.summary.commands_received += 1;
        self.live.commands_received.fetch_add(1, Ordering::Relaxed);
        if let Some(q) = &self.record {
            if q.push(RecordItem::Command {
                command: *c,
                received_ns: wall_ns(),
            })
            .is_err()
            {
                self.summary.recorder_drops += 1;
            }
        }
    }

    fn reject(&mut self) {
        self.summary.commands_rejected += 1;
        self.live.commands_rejected.fetch_add(1, Ordering::Relaxed);
        self.rejected_pending = true;
    }

    fn velocity_ok(&self, v: f64) -> bool {
        v.is_finite() && v.abs() <= self.s.max_abs_velocity
    }

    fn load_ok(&self, f: f64) -> bool {
        f.is_finite() && f >= self.s.min_load && f <= self.s.max_load
    }

    fn drain_commands(&mut self, now: Instant) {
        for i in 0..self.ports.len() {
            while let Some(c) = self.poll(i) {
                self.received(&c);
                match c.kind {
                    CommandKind::Velocity if self.velocity_ok(c.value) => {
                        self.velocity = c.value;
                        self.last_velocity_at = now;
                    }
                    CommandKind::Load if self.load_ok(c.value) => self.load = c.value,
                    _ => self.reject(),
                }
            }
        }
    }

    fn apply_timeout(&mut self, now: Instant) {
        self.timed_out = now.duration_since(self.last_velocity_at) > self.s.command_timeout;
        if !self.timed_out {
            self.applied = self.velocity;
            return;
        }
        self.summary.command_timeouts += 1;
        match self.s.timeout_behaviour {
            TimeoutBehaviour::Hold => self.applied = self.velocity,
            TimeoutBehaviour::RampToZero => {
                let dv = self.s.deceleration * self.s.dt;
                self.applied = if self.applied.abs() <= dv {
                    0.0
                } else {
                    self.applied - dv * self.applied.signum()
                };
            }
        }
    }

    fn lockstep_command(&mut self, c: Command) {
        self.received(&c);
        match c.kind {
            CommandKind::Load => {
                if self.load_ok(c.value) {
                    self.load = c.value;
                } else {
                    self.reject();
                }
            }
            CommandKind::Velocity => {
                if self.last_stamp.is_some_and(|last| c.stamp_ns <= last) {
                    // Duplicate or out of order: no step.
                    self.summary.commands_rejected += 1;
                    self.live.commands_rejected.fetch_add(1, Ordering::Relaxed);
                    return;
                }
                self.last_stamp = Some(c.stamp_ns);
                if self.velocity_ok(c.value) {
                    self.velocity = c.value;
                } else {
                    self.reject();
                }
                self.timed_out = false;
                self.step(self.velocity, c.stamp_ns, 0);
            }
        }
    }

    /// One model step with its outputs.
    fn step(&mut self, v: f64, stamp_ns: u64, jitter_ns: u64) {
        let start = Instant::now();
        let e = self.solver.step(v, self.load);
        let compute = start.elapsed().as_nanos() as u64;
        let mut rec = EstimateRecord::from_estimate(&e, stamp_ns, compute);
        if rec.status == codes::STATUS_CONVERGED {
            if self.timed_out {
                rec.status = codes::STATUS_COMMAND_TIMEOUT;
            } else if self.rejected_pending {
                rec.status = codes::STATUS_COMMAND_REJECTED;
            }
        }
        self.rejected_pending = false;
        self.summary.steps += 1;
        self.summary.status_counts[(rec.status as usize).min(7)] += 1;
        for p in self.ports.iter_mut() {
            if !p.publish_estimate(&rec) {
                self.summary.publish_drops += 1;
            }
        }
        if let Some(q) = &self.record {
            if q.push(RecordItem::Estimate(rec)).is_err() {
                self.summary.recorder_drops += 1;
            }
        }
        let n = self.summary.steps;
        if self.s.profile_every > 0 && n.is_multiple_of(self.s.profile_every) {
            if let Some(slot) = &self.profile {
                let solver = &self.solver;
                slot.try_write(|d| {
                    d.stamp_ns = stamp_ns;
                    d.dx_m = solver.dx();
                    for (i, f) in solver.field().enumerate() {
                        d.h_m[i] = f.h;
                        d.p_pa[i] = f.p;
                    }
                });
            }
        }
        self.window_compute.push(compute);
        self.window_jitter.push(jitter_ns);
        self.hist_compute.record(compute);
        if self.s.mode == StepMode::Timer {
            self.hist_jitter.record(jitter_ns);
        }
        if self.s.statistics_every > 0 && n.is_multiple_of(self.s.statistics_every) {
            self.publish_statistics(stamp_ns);
        }
        let l = &self.live;
        l.steps.store(n, Ordering::Relaxed);
        l.velocity_bits.store(v.to_bits(), Ordering::Relaxed);
        l.friction_bits
            .store(rec.friction_force_n.to_bits(), Ordering::Relaxed);
        l.cof_bits.store(rec.cof.to_bits(), Ordering::Relaxed);
        l.h0_bits.store(rec.h0_m.to_bits(), Ordering::Relaxed);
        l.compute_ns.store(compute, Ordering::Relaxed);
        l.status.store(rec.status as u64, Ordering::Relaxed);
        l.drops.store(
            self.summary.publish_drops + self.summary.recorder_drops,
            Ordering::Relaxed,
        );
    }

    fn publish_statistics(&mut self, stamp_ns: u64) {
        let s = StatisticsRecord {
            stamp_ns,
            steps: self.summary.steps,
            deadline_misses: self.summary.deadline_misses,
            commands_received: self.summary.commands_received,
            commands_rejected: self.summary.commands_rejected,
            command_timeouts: self.summary.command_timeouts,
            publish_drops: self.summary.publish_drops,
            recorder_drops: self.summary.recorder_drops,
            compute_time_ns: self.window_compute.percentiles(),
            period_jitter_ns: if self.s.mode == StepMode::Timer {
                self.window_jitter.percentiles()
            } else {
                [0; 3]
            },
        };
        self.window_compute.clear();
        self.window_jitter.clear();
        for p in self.ports.iter_mut() {
            if !p.publish_statistics(&s) {
                self.summary.publish_drops += 1;
            }
        }
        if let Some(q) = &self.record {
            if q.push(RecordItem::Statistics(s)).is_err() {
                self.summary.recorder_drops += 1;
            }
        }
    }
}
