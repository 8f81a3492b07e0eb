//! The real-time node: a fixed-step loop around the physics core.
//!
//! Two step modes (`node.step_mode`):
//! - **timer**: steps of `solver.dt_s` against absolute deadlines
//!   `t0 + k·Δt` on the monotonic clock (u64 nanoseconds: no wrap-around for
//!   584 years); the latest velocity and load commands are held (zero-order
//!   hold); a velocity older than `node.command_timeout_s` is held or ramped
//!   to zero and the estimate says so. Model time is wall time: a loop that
//!   wakes up late catches up the lost steps at once (each marked late), and
//!   when it is more than `node.max_catch_up_s` behind it advances the lost
//!   time in one backward-Euler step ([`crate::physics::Solver::step_lasting`]).
//!   A step that ends after the next deadline is a deadline miss. Stamps are
//!   the deadlines in wall time; a step of the wall clock (NTP) is counted
//!   and never makes a stamp go backwards ([`crate::clock::WallStamps`]).
//! - **lockstep**: one step per received velocity command, stamped with the
//!   command's stamp. Deterministic: the estimates equal an offline
//!   `simulate` of the same velocities bit for bit. A duplicate or
//!   out-of-order stamp is rejected, counted and produces no step.
//!
//! Commands that are not finite or beyond the configured limits never reach
//! the solver: they are rejected, counted, reported in the next estimate's
//! `command_status` whatever the solver did, and the last good value is held.
//! Every command is accounted for: received = applied + overwritten +
//! rejected. Outputs go to every transport port and to the recorder queue
//! without blocking; a full queue is a counted drop. The loop allocates
//! nothing per step. Time comes from a [`Clock`] handed in: tests run the
//! loop on simulated time.
//!
//! | file | content |
//! |---|---|
//! | `mod.rs` | [`Loop`], its settings, counters and summary |
//! | `timer.rs` | timer mode: deadlines, catch-up, time jumps |
//! | `lockstep.rs` | lockstep mode and [`Loop::feed`] (replay) |
//! | `commands.rs` | command validation, timeouts, command status |
//! | `publish.rs` | one step and what it publishes: estimates, film profiles, statistics |
//! | `parameters.rs` | the loop's side of live parameters: changes applied between steps |
//! | `runner.rs` | the `run` command around the loop |
//! | `rt.rs` | real-time settings |
//! | `driver.rs` | the demo and soak driver: a peer commanding the node on its own topics |

mod commands;
pub mod driver;
mod lockstep;
pub mod parameters;
mod publish;
pub mod rt;
pub mod runner;
mod timer;

use crate::clock::{Clock, SystemClock, WallStamps};
use crate::config::{Config, StepMode};
use crate::contacts::ContactSet;
use crate::link::FilmProfileSlot;
use crate::link::LoopSettings;
use crate::link::{LiveStatus, RecordItem};
use crate::physics::SetupError;
use crate::stats::{Histogram, Window};
use crate::transport::{NodePort, PortCounters};
use crossbeam_queue::ArrayQueue;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

/// What a run reports when it ends (and what LoopStatistics carries).
#[derive(Debug, Clone, Default)]
pub struct RunSummary {
    /// Steps taken.
    pub steps: u64,
    /// Monotonic time the run took, ns.
    pub elapsed_ns: u64,
    /// Wall-clock time the run took, s.
    pub wall_s: f64,
    /// Steps that ended after their deadline.
    pub deadline_misses: u64,
    /// Steps taken after their deadline had passed (catch-up).
    pub catch_up_steps: u64,
    /// Time jumps: lost time advanced in one step.
    pub time_jumps: u64,
    /// Steps of the wall clock seen.
    pub clock_jumps: u64,
    /// Commands the transports delivered.
    pub commands_received: u64,
    /// Commands applied.
    pub commands_applied: u64,
    /// Commands replaced by a newer one before a step took them.
    pub commands_overwritten: u64,
    /// Commands rejected (out of the envelope, non-finite, wrong layout).
    pub commands_rejected: u64,
    /// Steps taken on a timed-out command.
    pub command_timeouts: u64,
    /// Publications dropped by a full queue.
    pub publish_drops: u64,
    /// Publications the transports failed to send.
    pub publish_failures: u64,
    /// LoopStatistics not sent.
    pub statistics_not_sent: u64,
    /// Items the recorder queue had no room for.
    pub recorder_drops: u64,
    /// Errors the transports reported.
    pub transport_errors: u64,
    /// p50, p99, max, ns.
    pub compute_ns: [u64; 3],
    /// p99.9 of the step's compute time, ns.
    pub compute_p999_ns: u64,
    /// Period jitter (lateness of the wake-up): p50, p99, max, ns.
    pub jitter_ns: [u64; 3],
    /// Steps per solver status code (index = code).
    pub status_counts: [u64; 8],
    /// Steps per command status code (index = code).
    pub command_status_counts: [u64; 4],
    /// Parameter changes applied while running.
    pub parameter_updates: u64,
    /// Contacts stepped per step.
    pub contacts: u32,
    /// The contact whose step took longest in the latest step, and its
    /// compute time, ns.
    pub slowest_contact: usize,
    /// The slowest contact's compute time, ns.
    pub slowest_contact_ns: u64,
    /// The longest contact step since the previous statistics: (contact, ns).
    pub window_slowest: (usize, u64),
    /// Contact steps whose input lay outside the contact's calibrated range.
    pub steps_outside_calibrated_range: u64,
    /// The latest such step since the previous statistics.
    pub window_outside: Option<crate::msgs::OutsideEvent>,
}

/// Errors of the node layer (setup only: a running loop never fails).
#[derive(Debug, thiserror::Error)]
pub enum NodeError {
    /// A solver could not be built.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// The contact set could not be built.
    #[error(transparent)]
    Contacts(#[from] crate::contacts::ContactSetError),
    /// No transport to take commands from.
    #[error("the node needs at least one transport")]
    NoTransport,
}

/// The loop: the contacts' solvers, ports, outputs and bookkeeping.
pub struct Loop {
    contacts: ContactSet,
    /// Command state per contact (index = contact).
    cmd: Vec<commands::ContactCommand>,
    /// Each contact's calibrated-range watch (index = contact).
    watches: Vec<crate::range_watch::RangeWatch>,
    /// Where each contact's input lay in the step being taken.
    flags: Vec<crate::range_watch::RangeFlag>,
    /// Per-step scratch (no allocation per step): inputs and efforts.
    velocities: Vec<f64>,
    loads: Vec<f64>,
    efforts: Vec<f64>,
    /// The contacts are driven by joints (the output plan): efforts go out
    /// every step.
    by_joint: bool,
    /// What the loop takes from the configuration (replaced by a live
    /// parameter update).
    settings: LoopSettings,
    ports: Vec<Box<dyn NodePort>>,
    record: Option<Arc<ArrayQueue<RecordItem>>>,
    film_profile: Option<Arc<FilmProfileSlot>>,
    live: Arc<LiveStatus>,
    clock: Arc<dyn Clock>,
    stamps: WallStamps,
    temperature_c: f64,
    /// How each contact's viscosity follows the temperature: μ_ref at T_ref.
    viscosity: Vec<crate::config::ViscosityLaw>,
    last_stamp: Option<u64>,
    // statistics
    summary: RunSummary,
    window_compute: Window,
    window_jitter: Window,
    hist_compute: Histogram,
    hist_jitter: Histogram,
    started_ns: u64,
    /// Timer mode: steps counted as already taken when the run starts.
    first_step: u64,
    recorder: Option<Arc<crate::link::RecorderCounters>>,
    /// Parameter changes while running (see [`parameters`]).
    parameters: Option<Arc<crate::link::ParameterChannel>>,
}

impl Loop {
    /// Build every contact's solver at the steady state of
    /// `node.initial_velocity_m_s` under its load, on the system clock,
    /// with `node.contact_workers` worker threads (pinned to
    /// `node.realtime.worker_cpus`) beside the loop's.
    pub fn new(
        config: &Config,
        ports: Vec<Box<dyn NodePort>>,
        record: Option<Arc<ArrayQueue<RecordItem>>>,
        film_profile: Option<Arc<FilmProfileSlot>>,
        live: Arc<LiveStatus>,
    ) -> Result<Self, NodeError> {
        if ports.is_empty() {
            return Err(NodeError::NoTransport);
        }
        let settings = LoopSettings::from_config(config);
        let realtime = config.node.realtime.clone();
        let cpus = config.node.realtime.worker_cpus.clone();
        let setup = Arc::new(move |k: usize| {
            let mut rt = realtime.clone();
            rt.cpu = cpus.get(k - 1).copied().unwrap_or(-1);
            let (_, warnings) = rt::apply(&rt);
            for w in warnings {
                tracing::warn!("contact worker {k}: {w}");
            }
        });
        let contacts = ContactSet::new(
            config,
            config.node.contact_workers,
            settings.lockstep_spin_ns.max(50_000),
            Arc::new(SystemClock::new()),
            setup,
        )?;
        let v0 = config.node.initial_velocity_m_s;
        let resolved = config.resolved_contacts();
        let cmd = resolved
            .iter()
            .map(|c| commands::ContactCommand::new(v0, c.config.contact.load_n))
            .collect();
        let viscosity = resolved
            .iter()
            .map(|c| crate::config::ViscosityLaw::of(&c.config))
            .collect();
        let watches = resolved
            .iter()
            .map(|c| crate::range_watch::RangeWatch::of_contact(c, config.node.outside_envelope))
            .collect();
        let n = contacts.len();
        let window = (settings.statistics_every_steps as usize).clamp(16, 1 << 16);
        let clock: Arc<dyn Clock> = Arc::new(SystemClock::new());
        Ok(Self {
            contacts,
            cmd,
            watches,
            flags: vec![Default::default(); n],
            velocities: vec![v0; n],
            loads: resolved.iter().map(|c| c.config.contact.load_n).collect(),
            efforts: vec![0.0; n],
            by_joint: config.output_plan().by_joint(),
            ports,
            record,
            film_profile,
            live,
            stamps: WallStamps::new(clock.as_ref()),
            clock,
            temperature_c: config.lubricant.reference_temperature_c,
            viscosity,
            last_stamp: None,
            summary: RunSummary::default(),
            window_compute: Window::new(window),
            window_jitter: Window::new(window),
            hist_compute: Histogram::new(),
            hist_jitter: Histogram::new(),
            started_ns: 0,
            first_step: 0,
            recorder: None,
            parameters: None,
            settings,
        })
    }

    /// Run on this clock instead of the system's (tests: [`crate::clock::SimClock`]).
    pub fn with_clock(mut self, clock: Arc<dyn Clock>) -> Self {
        self.stamps = WallStamps::new(clock.as_ref());
        self.clock = clock;
        self
    }

    /// Timer mode: start as if `steps` steps had already been taken since
    /// the loop's origin (deadlines continue at `t0 + k·Δt` for k > steps).
    /// How tests check a loop after months of uptime without running them.
    pub fn resume_at_step(mut self, steps: u64) -> Self {
        self.first_step = steps;
        self
    }

    /// Report the recorder's counters (files, deletions, snapshots) in the
    /// loop statistics.
    pub fn with_recorder(mut self, counters: Arc<crate::link::RecorderCounters>) -> Self {
        self.recorder = Some(counters);
        self
    }

    /// The contacts and their solvers.
    pub fn contacts(&self) -> &ContactSet {
        &self.contacts
    }

    /// Counters so far, the ports' included.
    pub fn summary(&self) -> RunSummary {
        let mut s = self.summary.clone();
        self.add_port_counters(&mut s);
        s
    }

    fn port_counters(&self) -> PortCounters {
        let mut total = PortCounters::default();
        for p in &self.ports {
            total.add(&p.counters());
        }
        total
    }

    fn add_port_counters(&self, s: &mut RunSummary) {
        let c = self.port_counters();
        s.commands_received = c.received;
        s.commands_overwritten = c.overwritten;
        s.publish_failures += c.publish_failures;
        s.statistics_not_sent += c.statistics_failures;
        s.recorder_drops += c.recorder_drops;
    }

    /// Run until `stop` is set or `duration` has passed (in the loop's mode).
    pub fn run(&mut self, stop: &AtomicBool, duration: Option<Duration>) -> RunSummary {
        self.started_ns = self.clock.now_ns();
        for c in &mut self.cmd {
            c.last_velocity_at_ns = self.started_ns;
        }
        self.summary.contacts = u32::try_from(self.cmd.len()).unwrap_or(u32::MAX);
        self.stamps = WallStamps::new(self.clock.as_ref());
        let duration_ns = duration.map(|d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX));
        match self.settings.mode {
            StepMode::Timer => self.run_timer(stop, duration_ns),
            StepMode::Lockstep => self.run_lockstep(stop, duration_ns),
        }
        let mut out = self.summary();
        out.elapsed_ns = self.clock.now_ns().saturating_sub(self.started_ns);
        out.wall_s = out.elapsed_ns as f64 / 1e9;
        out.compute_ns = self.hist_compute.summary();
        out.compute_p999_ns = self.hist_compute.quantile(0.999);
        out.jitter_ns = self.hist_jitter.summary();
        out.clock_jumps = self.stamps.jumps;
        out
    }
}
