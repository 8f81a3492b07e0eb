//! Running the node: transports, recorder, real-time setup, signals, the
//! demo driver and the live status line around the [`Loop`].

use super::driver::DemoReport;
use super::{rt, Loop, NodeError, RunSummary};
use crate::config::{Config, TransportKind};
use crate::link::FilmProfileSlot;
use crate::link::LiveStatus;
use crate::transport::{self, BackendSpec, NodePort, TransportError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// What to run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Transports (overrides `node.transport`); empty = the config's.
    pub transport: Option<TransportKind>,
    /// Record to this file (overrides `recording.*`).
    pub record: Option<PathBuf>,
    /// Drive the node with a velocity profile on its own topics for this long, s.
    pub demo_s: Option<f64>,
    /// The profile the demo driver commands.
    pub motion: super::driver::DemoMotion,
    /// Stop after this long, s (None: until SIGINT/SIGTERM).
    pub duration_s: Option<f64>,
    /// Print a live status line on stderr.
    pub status_line: bool,
}

/// Errors that prevent the node from running.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The loop could not be built.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// A transport could not be opened.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// An option (`--demo`, `use_sim_time`, recording without `mcap`) that cannot be honoured.
    #[error("invalid option: {0}")]
    Option(String),
    /// A thread of the run panicked (a defect, not a usage error).
    #[error("the {0} thread panicked")]
    ThreadPanicked(&'static str),
    #[cfg(feature = "mcap")]
    /// The recording could not be started.
    #[error(transparent)]
    Recorder(#[from] crate::record::RecorderError),
}

/// Everything a run reports.
#[derive(Debug, Clone, Default)]
pub struct RunReport {
    /// The loop's counters and timings.
    pub summary: RunSummary,
    /// The transports it ran on.
    pub transports: Vec<String>,
    /// The real-time settings that took effect.
    pub realtime_applied: Vec<String>,
    /// Everything that did not take effect or looks wrong.
    pub warnings: Vec<String>,
    /// The recording, if there was one.
    pub recording: Option<RecordingOutcome>,
    /// Snapshot files written.
    pub snapshots: Vec<PathBuf>,
    /// The demo driver's report (`--demo`).
    pub demo: Option<DemoReport>,
    /// Resident memory at the end, bytes.
    pub rss_bytes: Option<u64>,
    /// Peak resident memory, bytes.
    pub peak_rss_bytes: Option<u64>,
    /// Whether a signal (or the stop flag) ended the run.
    pub interrupted: bool,
    /// The signal that ended it (SIGINT 2, SIGTERM 15): the command exits
    /// with 128 + its number once the recording is finalised.
    pub signal: Option<i32>,
}

/// How the recording went.
#[derive(Debug, Clone, Default)]
pub struct RecordingOutcome {
    /// The file or directory.
    pub path: PathBuf,
    /// Messages written.
    pub messages: u64,
    /// Bytes on disk.
    pub bytes: u64,
    /// Files written (split recordings), and deleted to keep to the budget.
    pub files: u64,
    /// Files deleted to keep to `recording.budget_bytes`.
    pub files_deleted: u64,
    /// Messages not recorded after a write error.
    pub lost: u64,
    /// The write error that stopped the recording, if one did.
    pub error: Option<String>,
}

/// The recording used when none is given: `bags/friction_node_<UTC>.mcap`,
/// or that name without `.mcap` (a directory) for a split recording.
pub fn default_recording_path(dir: &Path, split: bool) -> PathBuf {
    let name = format!(
        "friction_node_{}",
        crate::clock::utc_stamp(crate::clock::system_wall_ns())
    );
    dir.join(if split { name } else { name + ".mcap" })
}

/// The backends a transport choice stands for.
pub fn backend_specs(
    config: &Config,
    kind: TransportKind,
) -> Result<Vec<BackendSpec>, TransportError> {
    #[cfg_attr(not(all(feature = "ros2", feature = "iceoryx2")), allow(unused_mut))]
    let mut out = Vec::new();
    if matches!(kind, TransportKind::Ros2 | TransportKind::Both) {
        #[cfg(feature = "ros2")]
        out.push(BackendSpec::Ros2(transport::ros2::Ros2Spec::from_config(
            config,
        )?));
        #[cfg(not(feature = "ros2"))]
        return Err(TransportError::NotBuiltIn("ros2"));
    }
    if matches!(kind, TransportKind::Iceoryx2 | TransportKind::Both) {
        #[cfg(feature = "iceoryx2")]
        {
            let spec = transport::iceoryx::IceoryxSpec::from(&config.iceoryx2);
            out.push(BackendSpec::Iceoryx2(spec.for_plan(config.output_plan())));
        }
        #[cfg(not(feature = "iceoryx2"))]
        return Err(TransportError::NotBuiltIn("iceoryx2"));
    }
    let _ = config;
    Ok(out)
}

fn status_thread(
    live: Arc<LiveStatus>,
    stop: Arc<AtomicBool>,
    dt: f64,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        use std::io::{IsTerminal, Write};
        let tty = std::io::stderr().is_terminal();
        let period = Duration::from_millis(if tty { 250 } else { 1000 });
        while !stop.load(Ordering::Relaxed) {
            std::thread::sleep(period);
            let n = live.steps.load(Ordering::Relaxed);
            let line = format!(
                "t {:7.2} s | v {:+6.3} m/s | F {:+9.1} N | COF {:.4} | h0 {:6.3} µm | step {:5.1} µs | {} {} | miss {} | rejected {} | drops {}",
                n as f64 * dt,
                LiveStatus::load_f64(&live.velocity_bits),
                LiveStatus::load_f64(&live.friction_bits),
                LiveStatus::load_f64(&live.cof_bits),
                LiveStatus::load_f64(&live.h0_bits) * 1e6,
                live.compute_ns.load(Ordering::Relaxed) as f64 / 1e3,
                n,
                crate::msgs::status_name(live.status.load(Ordering::Relaxed) as u8),
                live.deadline_misses.load(Ordering::Relaxed),
                live.commands_rejected.load(Ordering::Relaxed),
                live.drops.load(Ordering::Relaxed),
            );
            let mut e = std::io::stderr().lock();
            if tty {
                let _ = write!(e, "\r\x1b[2K{line}");
            } else {
                let _ = writeln!(e, "{line}");
            }
            let _ = e.flush();
        }
        if tty {
            eprintln!();
        }
    })
}

/// A timer loop that spins (nearly) the whole period under SCHED_FIFO
/// exceeds the kernel's real-time budget (`sched_rt_runtime_us`, 95 % by
/// default): the kernel then stalls it for the rest of each second.
fn spin_under_fifo(config: &Config) -> Option<String> {
    let n = &config.node;
    let period_us = config.solver.dt_s * 1e6;
    (n.realtime.fifo
        && n.step_mode == crate::config::StepMode::Timer
        && n.timer_spin_us as f64 >= 0.9 * period_us)
        .then(|| {
            format!(
                "node.timer_spin_us = {} with node.realtime.fifo: a loop that spins {:.0} % of its {period_us:.0} µs period under SCHED_FIFO runs into the kernel's real-time throttling (sched_rt_runtime_us) and stalls; spin without fifo on a core of its own, or spin less",
                n.timer_spin_us,
                (100.0 * n.timer_spin_us as f64 / period_us).min(100.0)
            )
        })
}

/// A ROS 2 transport whose discovery leaves the host says so.
fn discovery_warnings(specs: &[BackendSpec]) -> Vec<String> {
    #[cfg(feature = "ros2")]
    return specs
        .iter()
        .filter_map(|s| match s {
            BackendSpec::Ros2(r) if !r.localhost_only => Some(format!(
                "ROS 2 discovery range SUBNET: DDS traffic (multicast included) goes to every interface (domain {})",
                r.domain_id
            )),
            _ => None,
        })
        .collect();
    #[cfg(not(feature = "ros2"))]
    {
        let _ = specs;
        Vec::new()
    }
}

/// The recording's file: `--record`, else `recording.path` (or a stamped
/// name under `bags/`) when recording is enabled.
fn record_path(config: &Config, opts: &RunOptions) -> Option<PathBuf> {
    opts.record.clone().or_else(|| {
        config.recording.enabled.then(|| {
            if config.recording.path.is_empty() {
                default_recording_path(Path::new("bags"), config.recording.splits())
            } else {
                PathBuf::from(&config.recording.path)
            }
        })
    })
}

/// The recorder (and the snapshot ring), checked and created before
/// anything runs: a path that cannot be recorded into is an error now, not a
/// surprise later.
#[cfg(feature = "mcap")]
fn start_recorder(
    config: &Config,
    record_path: Option<PathBuf>,
    film_profile: Option<Arc<FilmProfileSlot>>,
    warnings: &mut Vec<String>,
) -> Result<Option<crate::record::Recorder>, RunError> {
    if record_path.is_none() && config.recording.snapshot_s == 0 {
        return Ok(None);
    }
    let snapshot_dir = record_path
        .as_deref()
        .and_then(|p| p.parent())
        .filter(|p| !p.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("bags"), Path::to_path_buf);
    let plan = crate::record::RecordPlan {
        path: record_path,
        snapshot_dir,
    };
    let r = crate::record::Recorder::start(
        plan,
        config,
        &crate::config::topics::TopicNames::from_config(config),
        film_profile,
        Arc::new(crate::clock::SystemClock::new()),
    )?;
    if config.recording.snapshot_s > 0 {
        let flag = r.snapshot_request();
        if let Err(e) = signal_hook::flag::register(signal_hook::consts::SIGUSR1, flag) {
            warnings.push(format!("snapshots on SIGUSR1 are not available: {e}"));
        }
        tracing::info!(
            "snapshot ring: the last {} s of every topic, up to about {} MB (recording.snapshot_s)",
            config.recording.snapshot_s,
            crate::config::snapshot_bytes(config) / 1_000_000
        );
    }
    Ok(Some(r))
}

/// The loop's transports; the first that serves parameters gets the
/// parameter hand-over. Returns whether one does.
fn open_ports(
    config: &Config,
    specs: &[BackendSpec],
    io: transport::PortIo,
    channel: &Arc<crate::link::ParameterChannel>,
) -> Result<(Vec<Box<dyn NodePort>>, bool), RunError> {
    let mut ports: Vec<Box<dyn NodePort>> = Vec::new();
    let mut served = false;
    for s in specs {
        let parameters = (!served && s.serves_parameters()).then(|| {
            served = true;
            crate::link::ParameterIo {
                config: config.clone(),
                channel: channel.clone(),
            }
        });
        ports.push(s.open_node(transport::PortIo {
            film_profile: io.film_profile.clone(),
            record: io.record.clone(),
            snapshot: io.snapshot.clone(),
            parameters,
            sim_time: io.sim_time.clone().filter(|_| s.serves_parameters()),
        })?);
    }
    Ok((ports, served))
}

/// `use_sim_time`: timer mode follows ROS 2 `/clock` (only a ROS 2
/// transport carries it).
fn sim_clock(
    config: &Config,
    specs: &[BackendSpec],
    stop: &Arc<AtomicBool>,
) -> Result<Option<Arc<crate::clock::ExternalClock>>, RunError> {
    if !config.use_sim_time {
        return Ok(None);
    }
    if !specs.iter().any(|s| s.serves_parameters()) {
        return Err(RunError::Option(
            "use_sim_time: true needs the ros2 transport (it follows /clock)".into(),
        ));
    }
    Ok(Some(Arc::new(crate::clock::ExternalClock::new(
        stop.clone(),
    ))))
}

/// The demo driver, publishing on the first transport's real topics for
/// `seconds`; it stops with `driver_stop` (in lockstep it waits for each
/// estimate, and a loop that has ended sends none).
fn start_demo(
    config: &Config,
    opts: &RunOptions,
    seconds: f64,
    spec: BackendSpec,
    driver_stop: Arc<AtomicBool>,
    warnings: &mut Vec<String>,
) -> Result<std::thread::JoinHandle<DemoReport>, RunError> {
    if !(seconds > 0.0 && seconds.is_finite()) {
        return Err(RunError::Option(format!(
            "--demo {seconds}: needs a positive number of seconds"
        )));
    }
    let (tx, rx) = std::sync::mpsc::channel();
    let plan = super::driver::DemoPlan {
        mode: config.node.step_mode,
        dt_s: config.solver.dt_s,
        seconds,
        motion: opts.motion,
        output: config.output_plan(),
    };
    let driver = std::thread::spawn(move || super::driver::drive(spec, plan, tx, driver_stop));
    match rx.recv_timeout(Duration::from_secs(30)) {
        Ok(Ok(())) => {}
        Ok(Err(e)) => warnings.push(format!("demo driver: {e}")),
        Err(_) => warnings.push("demo driver: no match within 30 s".into()),
    }
    Ok(driver)
}

/// What the recorder wrote.
#[cfg(feature = "mcap")]
fn finish_recording(r: crate::record::Recorder, report: &mut RunReport) {
    let rep = r.finish();
    report.snapshots = rep.snapshots.clone();
    if let Some(path) = rep.path.clone() {
        report.recording = Some(RecordingOutcome {
            path,
            messages: rep.messages,
            bytes: rep.bytes,
            files: rep.files,
            files_deleted: rep.files_deleted,
            lost: rep.lost,
            error: rep.error,
        });
    }
}

/// The loop over its transports: the parameter hand-over to the first
/// transport that serves parameters, and `/clock` when `use_sim_time`.
fn build_loop(
    config: &Config,
    specs: &[BackendSpec],
    io: transport::PortIo,
    live: Arc<LiveStatus>,
) -> Result<Loop, RunError> {
    let channel = Arc::new(crate::link::ParameterChannel::default());
    let (queue, film_profile, sim_time) = (
        io.record.clone(),
        io.film_profile.clone(),
        io.sim_time.clone(),
    );
    let (ports, served) = open_ports(config, specs, io, &channel)?;
    let mut l = Loop::new(config, ports, queue, film_profile, live)?;
    if served {
        l = l.with_parameters(channel);
    }
    if let Some(c) = sim_time {
        l = l.with_clock(c);
        tracing::info!("use_sim_time: the loop follows /clock");
    }
    Ok(l)
}

/// The real-time settings (`node.realtime`), and every warning of the run
/// so far logged.
fn apply_realtime(config: &Config, report: &mut RunReport) {
    let (applied, warnings) = rt::apply(&config.node.realtime);
    report.realtime_applied = applied;
    report.warnings.extend(warnings);
    for w in &report.warnings {
        tracing::warn!("{w}");
    }
}

/// One line when the loop starts (what scripts and tests wait for), and the
/// settings in the log.
fn announce_start(config: &Config, transports: &[String]) {
    eprintln!(
        "friction-node: loop running ({:?} mode)",
        config.node.step_mode
    );
    tracing::info!(
        "loop running: {:?} mode, dt = {} s, N = {}, transports {}",
        config.node.step_mode,
        config.solver.dt_s,
        config.solver.cells,
        transports.join(", ")
    );
}

/// The threads beside the loop: the demo driver and the status line.
struct Helpers {
    driver: Option<std::thread::JoinHandle<DemoReport>>,
    driver_stop: Arc<AtomicBool>,
    status: Option<std::thread::JoinHandle<()>>,
    status_stop: Arc<AtomicBool>,
}

impl Helpers {
    /// Start what `opts` asks for (the demo drives `spec`).
    fn start(
        config: &Config,
        opts: &RunOptions,
        spec: &BackendSpec,
        live: &Arc<LiveStatus>,
        warnings: &mut Vec<String>,
    ) -> Result<Self, RunError> {
        let driver_stop = Arc::new(AtomicBool::new(false));
        let driver = match opts.demo_s {
            Some(seconds) => Some(start_demo(
                config,
                opts,
                seconds,
                spec.clone(),
                driver_stop.clone(),
                warnings,
            )?),
            None => None,
        };
        let status_stop = Arc::new(AtomicBool::new(false));
        let status = opts
            .status_line
            .then(|| status_thread(live.clone(), status_stop.clone(), config.solver.dt_s));
        Ok(Self {
            driver,
            driver_stop,
            status,
            status_stop,
        })
    }

    /// Stop both and wait for them: the demo's report, if it ran.
    fn stop(self) -> Option<DemoReport> {
        self.driver_stop.store(true, Ordering::Relaxed);
        self.status_stop.store(true, Ordering::Relaxed);
        if let Some(s) = self.status {
            let _ = s.join();
        }
        self.driver.and_then(|d| d.join().ok())
    }
}

/// Run the node until `stop`, the duration or the demo ends.
pub fn run_node(
    config: &Config,
    opts: &RunOptions,
    stop: Arc<AtomicBool>,
) -> Result<RunReport, RunError> {
    let kind = opts.transport.unwrap_or(config.node.transport);
    let specs = backend_specs(config, kind)?;
    let mut report = RunReport {
        transports: specs.iter().map(|s| s.name().to_string()).collect(),
        warnings: discovery_warnings(&specs),
        ..Default::default()
    };
    report.warnings.extend(spin_under_fifo(config));
    let film_profile =
        (config.node.profile_rate_hz > 0.0).then(|| FilmProfileSlot::new(config.solver.cells));
    let record_path = record_path(config, opts);
    #[cfg(feature = "mcap")]
    let recorder = start_recorder(
        config,
        record_path,
        film_profile.clone(),
        &mut report.warnings,
    )?;
    #[cfg(not(feature = "mcap"))]
    if record_path.is_some() || config.recording.snapshot_s > 0 {
        return Err(RunError::Option(
            "recording needs the `mcap` feature".into(),
        ));
    }
    #[cfg(feature = "mcap")]
    let (queue, snapshot) = (
        recorder.as_ref().map(|r| r.queue()),
        recorder.as_ref().map(|r| r.snapshot_request()),
    );
    #[cfg(not(feature = "mcap"))]
    let (queue, snapshot) = (None, None);
    let io = transport::PortIo {
        film_profile,
        record: queue,
        snapshot,
        parameters: None,
        sim_time: sim_clock(config, &specs, &stop)?,
    };
    let live = Arc::new(LiveStatus::default());
    let mut l = build_loop(config, &specs, io, live.clone())?;
    #[cfg(feature = "mcap")]
    if let Some(r) = &recorder {
        l = l.with_recorder(r.counters());
    }
    let helpers = Helpers::start(config, opts, &specs[0], &live, &mut report.warnings)?;
    apply_realtime(config, &mut report);
    let duration = opts.demo_s.or(opts.duration_s).map(Duration::from_secs_f64);
    announce_start(config, &report.transports);
    report.summary = l.run(&stop, duration);
    report.interrupted = stop.load(Ordering::Relaxed);
    report.signal = match last_signal().load(Ordering::Relaxed) {
        0 => None,
        n => i32::try_from(n).ok(),
    }
    .filter(|_| report.interrupted);
    report.demo = helpers.stop();
    drop(l);
    #[cfg(feature = "mcap")]
    if let Some(r) = recorder {
        finish_recording(r, &mut report);
    }
    report.rss_bytes = rt::resident_bytes();
    report.peak_rss_bytes = rt::peak_resident_bytes();
    Ok(report)
}

/// The number of the last SIGINT/SIGTERM the handlers of
/// [`stop_on_signals`] saw (0: none).
fn last_signal() -> &'static Arc<AtomicUsize> {
    static LAST: std::sync::OnceLock<Arc<AtomicUsize>> = std::sync::OnceLock::new();
    LAST.get_or_init(|| Arc::new(AtomicUsize::new(0)))
}

/// Install SIGINT/SIGTERM handlers that set the returned flag (and note
/// which signal it was, for [`RunReport::signal`]).
pub fn stop_on_signals() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        // The signal's number first: the loop ends on the flag.
        let which = signal_hook::flag::register_usize(
            sig,
            last_signal().clone(),
            usize::try_from(sig).unwrap_or(0),
        );
        if let Err(e) = which.and_then(|_| signal_hook::flag::register(sig, stop.clone())) {
            tracing::warn!("cannot handle signal {sig}: {e}");
        }
    }
    stop
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_whole_period_spin_under_fifo_is_warned_about_and_a_short_one_is_not() {
        let mut c = Config::default();
        c.node.timer_spin_us = 1000;
        assert_eq!(spin_under_fifo(&c), None, "no fifo: no throttling");
        c.node.realtime.fifo = true;
        let w = spin_under_fifo(&c).expect("warned");
        assert!(w.contains("node.timer_spin_us = 1000"), "{w}");
        c.node.timer_spin_us = 200;
        assert_eq!(spin_under_fifo(&c), None, "20 % of the period");
        c.node.timer_spin_us = 1000;
        c.node.step_mode = crate::config::StepMode::Lockstep;
        assert_eq!(spin_under_fifo(&c), None, "lockstep ignores timer_spin_us");
    }
}
