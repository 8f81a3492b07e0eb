//! Running the node: transports, recorder, real-time setup, signals, the
//! demo driver and the live status line around the [`Loop`].

use super::{rt, LiveStatus, Loop, NodeError, RunSummary};
use crate::config::{Config, StepMode, TransportKind};
use crate::msgs::{Command, CommandKind};
use crate::transport::{self, BackendSpec, NodePort, ProfileSlot, TransportError};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What to run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Transports (overrides `node.transport`); empty = the config's.
    pub transport: Option<TransportKind>,
    /// Record to this file (overrides `recording.*`).
    pub record: Option<PathBuf>,
    /// Drive the node with the paper's reciprocating velocity for this long, s.
    pub demo_s: Option<f64>,
    /// Stop after this long, s (None: until SIGINT/SIGTERM).
    pub duration_s: Option<f64>,
    /// Print a live status line on stderr.
    pub status_line: bool,
}

/// Errors that prevent the node from running.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Node(#[from] NodeError),
    #[error(transparent)]
    Transport(#[from] TransportError),
    #[error("invalid option: {0}")]
    Option(String),
}

/// What the demo driver did.
#[derive(Debug, Clone, Default)]
pub struct DemoReport {
    pub commands_sent: u64,
    pub estimates_received: u64,
    pub error: Option<String>,
}

/// Everything a run reports.
#[derive(Debug, Clone, Default)]
pub struct RunReport {
    pub summary: RunSummary,
    pub transports: Vec<String>,
    pub realtime_applied: Vec<String>,
    pub warnings: Vec<String>,
    pub recording: Option<RecordingOutcome>,
    pub demo: Option<DemoReport>,
    pub rss_bytes: Option<u64>,
    pub peak_rss_bytes: Option<u64>,
    pub interrupted: bool,
}

/// How the recording went.
#[derive(Debug, Clone, Default)]
pub struct RecordingOutcome {
    pub path: PathBuf,
    pub messages: u64,
    pub bytes: u64,
    pub error: Option<String>,
}

/// The file name used when none is given: `bags/friction_node_<UTC>.mcap`.
pub fn default_recording_path(dir: &Path) -> PathBuf {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (d, s) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = d as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + (month <= 2) as i64;
    dir.join(format!(
        "friction_node_{year:04}{month:02}{day:02}T{:02}{:02}{:02}Z.mcap",
        s / 3600,
        (s % 3600) / 60,
        s % 60
    ))
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
        out.push(BackendSpec::Iceoryx2((&config.iceoryx2).into()));
        #[cfg(not(feature = "iceoryx2"))]
        return Err(TransportError::NotBuiltIn("iceoryx2"));
    }
    let _ = config;
    Ok(out)
}

fn demo_driver(
    spec: BackendSpec,
    mode: StepMode,
    dt: f64,
    seconds: f64,
    ready: std::sync::mpsc::Sender<Result<(), String>>,
    stop: Arc<AtomicBool>,
) -> DemoReport {
    let mut report = DemoReport::default();
    let mut peer = match spec.open_peer() {
        Ok(p) => p,
        Err(e) => {
            let _ = ready.send(Err(e.to_string()));
            report.error = Some(e.to_string());
            return report;
        }
    };
    if let Err(e) = transport::wait_matched(peer.as_mut(), Duration::from_secs(20)) {
        let _ = ready.send(Err(e.to_string()));
        report.error = Some(e.to_string());
        return report;
    }
    let _ = ready.send(Ok(()));
    // The paper's reciprocating case: v = V1 sin(2π f t), V1 = 1 m/s, f = 1 Hz.
    let v = |t: f64| (2.0 * std::f64::consts::PI * t).sin();
    let steps = (seconds / dt).round() as u64;
    let start = Instant::now();
    let t0 = super::wall_ns();
    for k in 1..=steps {
        if stop.load(Ordering::Relaxed) {
            break;
        }
        let t = k as f64 * dt;
        if mode == StepMode::Timer {
            // A plain sleep: the driver must not compete with the loop's spin.
            let due = start + Duration::from_secs_f64(t - dt);
            let now = Instant::now();
            if due > now {
                std::thread::sleep(due - now);
            }
        }
        let c = Command {
            kind: CommandKind::Velocity,
            value: v(t),
            stamp_ns: t0 + (t * 1e9) as u64,
        };
        if let Err(e) = peer.send(&c) {
            report.error.get_or_insert(e.to_string());
            continue;
        }
        report.commands_sent += 1;
        if mode == StepMode::Lockstep {
            if let Ok(Some(_)) = transport::recv_timeout(peer.as_mut(), Duration::from_secs(2)) {
                report.estimates_received += 1;
            }
        }
        while let Ok(Some(_)) = peer.try_recv() {
            report.estimates_received += 1;
        }
    }
    // Estimates still in flight.
    let until = Instant::now() + Duration::from_millis(300);
    while Instant::now() < until {
        match peer.try_recv() {
            Ok(Some(_)) => report.estimates_received += 1,
            _ => std::thread::sleep(Duration::from_millis(5)),
        }
    }
    report
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
                LiveStatus::f(&live.velocity_bits),
                LiveStatus::f(&live.friction_bits),
                LiveStatus::f(&live.cof_bits),
                LiveStatus::f(&live.h0_bits) * 1e6,
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
        ..Default::default()
    };
    #[cfg(feature = "ros2")]
    for s in &specs {
        if let BackendSpec::Ros2(r) = s {
            if !r.localhost_only {
                report.warnings.push(format!(
                    "ROS 2 discovery range SUBNET: DDS traffic (multicast included) goes to every interface (domain {})",
                    r.domain_id
                ));
            }
        }
    }
    let profile =
        (config.node.profile_rate_hz > 0.0).then(|| ProfileSlot::new(config.solver.cells));
    // Recording: a failure to start is reported, the node runs anyway.
    let record_path = opts.record.clone().or_else(|| {
        config.recording.enabled.then(|| {
            if config.recording.path.is_empty() {
                default_recording_path(std::path::Path::new("bags"))
            } else {
                PathBuf::from(&config.recording.path)
            }
        })
    });
    #[cfg(feature = "mcap")]
    let recorder = match &record_path {
        Some(p) => match crate::record::Recorder::start(
            p,
            config,
            &transport::names::TopicNames::from_config(config),
            profile.clone(),
        ) {
            Ok(r) => Some(r),
            Err(e) => {
                tracing::error!("{e}; running without recording");
                report.recording = Some(RecordingOutcome {
                    path: p.clone(),
                    error: Some(e.to_string()),
                    ..Default::default()
                });
                None
            }
        },
        None => None,
    };
    #[cfg(not(feature = "mcap"))]
    if let Some(p) = &record_path {
        report.recording = Some(RecordingOutcome {
            path: p.clone(),
            error: Some("built without the `mcap` feature".into()),
            ..Default::default()
        });
    }
    let mut ports: Vec<Box<dyn NodePort>> = Vec::new();
    for s in &specs {
        ports.push(s.open_node(profile.clone())?);
    }
    #[cfg(feature = "mcap")]
    let queue = recorder.as_ref().map(|r| r.queue());
    #[cfg(not(feature = "mcap"))]
    let queue = None;
    let live = Arc::new(LiveStatus::default());
    let mut l = Loop::new(config, ports, queue, profile, live.clone())?;
    // The demo driver publishes on the first transport's real topics.
    let mut driver = None;
    if let Some(seconds) = opts.demo_s {
        if !(seconds > 0.0 && seconds.is_finite()) {
            return Err(RunError::Option(format!(
                "--demo {seconds}: needs a positive number of seconds"
            )));
        }
        let (tx, rx) = std::sync::mpsc::channel();
        let spec = specs[0].clone();
        let (mode, dt, s2) = (config.node.step_mode, config.solver.dt_s, stop.clone());
        driver = Some(std::thread::spawn(move || {
            demo_driver(spec, mode, dt, seconds, tx, s2)
        }));
        match rx.recv_timeout(Duration::from_secs(30)) {
            Ok(Ok(())) => {}
            Ok(Err(e)) => report.warnings.push(format!("demo driver: {e}")),
            Err(_) => report
                .warnings
                .push("demo driver: no match within 30 s".into()),
        }
    }
    let (applied, warnings) = rt::apply(&config.node.realtime);
    report.realtime_applied = applied;
    report.warnings.extend(warnings);
    for w in &report.warnings {
        tracing::warn!("{w}");
    }
    let status_stop = Arc::new(AtomicBool::new(false));
    let status = opts
        .status_line
        .then(|| status_thread(live.clone(), status_stop.clone(), config.solver.dt_s));
    let duration = opts.demo_s.or(opts.duration_s).map(Duration::from_secs_f64);
    report.summary = l.run(&stop, duration);
    report.interrupted = stop.load(Ordering::Relaxed);
    status_stop.store(true, Ordering::Relaxed);
    if let Some(s) = status {
        let _ = s.join();
    }
    drop(l);
    if let Some(d) = driver {
        report.demo = d.join().ok();
    }
    #[cfg(feature = "mcap")]
    if let Some(r) = recorder {
        let rep = r.finish();
        report.recording = Some(RecordingOutcome {
            path: rep.path,
            messages: rep.messages,
            bytes: rep.bytes,
            error: rep.error,
        });
    }
    report.rss_bytes = rt::resident_bytes();
    report.peak_rss_bytes = rt::peak_resident_bytes();
    Ok(report)
}

/// Install SIGINT/SIGTERM handlers that set the returned flag.
pub fn stop_on_signals() -> Arc<AtomicBool> {
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        if let Err(e) = signal_hook::flag::register(sig, stop.clone()) {
            tracing::warn!("cannot handle signal {sig}: {e}");
        }
    }
    stop
}
