//! `run` (the real-time node) and `soak` (the node for hours under a random
//! motion, its memory sampled).

use super::args::TransportArg;
use anyhow::Result;
use friction_node::config::Config;
use friction_node::node::driver::DemoMotion;
use friction_node::node::runner::{self, RunOptions, RunReport};
use std::path::{Path, PathBuf};

pub fn run(
    config: &Config,
    transport: Option<TransportArg>,
    record: Option<PathBuf>,
    demo: Option<f64>,
    duration: Option<f64>,
    quiet: bool,
) -> Result<()> {
    let opts = RunOptions {
        transport: transport.map(TransportArg::kind),
        record,
        demo_s: demo,
        motion: DemoMotion::Paper,
        duration_s: duration,
        status_line: !quiet,
    };
    let r = start(config, &opts)?;
    summary(config, &r);
    Ok(())
}

/// `run --check`: what the node would be, without starting it: its fully
/// qualified name, transport, resolved topics (namespace and remappings
/// applied) and every parameter that differs from the built-in default.
/// The configuration was already loaded and validated by the caller.
pub fn check(config: &Config, transport: Option<TransportArg>) {
    use friction_node::config::parameters::flatten;
    use friction_node::config::topics::TopicNames;
    let r = &config.ros;
    let fqn = if r.namespace.trim_end_matches('/').is_empty() {
        format!("/{}", r.node_name)
    } else {
        format!("{}/{}", r.namespace.trim_end_matches('/'), r.node_name)
    };
    let transport = transport
        .map(TransportArg::kind)
        .unwrap_or(config.node.transport);
    println!("node: {fqn}");
    let transport = serde_norway::to_string(&transport).unwrap_or_default();
    println!("transport: {}", transport.trim_end());
    let t = TopicNames::from_config(config);
    println!("topics:");
    for (what, name) in t.opened(config) {
        println!("  {what}: {name}");
    }
    let defaults: std::collections::HashMap<String, serde_norway::Value> =
        flatten(&Config::default()).into_iter().collect();
    let all = flatten(config);
    let changed: Vec<_> = all
        .iter()
        .filter(|(k, v)| defaults.get(k) != Some(v))
        .collect();
    println!(
        "parameters: {} declared, {} differ from the defaults",
        all.len(),
        changed.len()
    );
    for (k, v) in changed {
        let one = |v: &serde_norway::Value| {
            serde_norway::to_string(v)
                .unwrap_or_default()
                .trim_end()
                .to_string()
        };
        let v = match v {
            serde_norway::Value::Sequence(s) => {
                format!("[{}]", s.iter().map(one).collect::<Vec<_>>().join(", "))
            }
            v => one(v),
        };
        println!("  {k}: {v}");
    }
    println!("configuration valid (--check: not starting)");
}

/// `soak`: the node driven by a random motion for `seconds`, its resident
/// memory sampled every `every_s` seconds into `rss_csv`.
pub fn soak(
    config: &Config,
    transport: Option<TransportArg>,
    seconds: f64,
    seed: u64,
    rss_csv: &Path,
    every_s: f64,
) -> Result<()> {
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let opts = RunOptions {
        transport: transport.map(TransportArg::kind),
        record: None,
        demo_s: Some(seconds),
        motion: DemoMotion::Random { seed },
        duration_s: None,
        status_line: false,
    };
    let mut csv = friction_node::output::AtomicFile::create(rss_csv)?;
    csv.line(format_args!("t_s,rss_bytes"))?;
    let done = Arc::new(AtomicBool::new(false));
    let d2 = done.clone();
    let sampler = std::thread::spawn(move || {
        let start = std::time::Instant::now();
        let mut samples = Vec::new();
        let mut next = 0.0;
        while !d2.load(Ordering::Relaxed) {
            let t = start.elapsed().as_secs_f64();
            if t >= next {
                samples.push((t, friction_node::node::rt::resident_bytes().unwrap_or(0)));
                next += every_s;
            }
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        samples
    });
    let r = start(config, &opts)?;
    done.store(true, Ordering::Relaxed);
    let samples = sampler.join().unwrap_or_default();
    for (t, rss) in &samples {
        csv.line(format_args!("{t:.1},{rss}"))?;
    }
    let path = csv.commit()?;
    summary(config, &r);
    // Flat after warm-up: compare the first sample after a minute with the end.
    let warm = samples.iter().find(|(t, _)| *t >= 60.0).or(samples.first());
    if let (Some(&(t0, a)), Some(&(t1, b))) = (warm, samples.last()) {
        let hours = ((t1 - t0) / 3600.0).max(1e-9);
        println!(
            "  soak memory      RSS {:.2} MB at {t0:.0} s, {:.2} MB at {t1:.0} s ({:+.3} MB, {:+.3} MB/h); samples in {}",
            a as f64 / 1e6,
            b as f64 / 1e6,
            (b as f64 - a as f64) / 1e6,
            (b as f64 - a as f64) / 1e6 / hours,
            path.display()
        );
    }
    Ok(())
}

fn start(config: &Config, opts: &RunOptions) -> Result<RunReport> {
    let stop = runner::stop_on_signals();
    let demo = opts.demo_s;
    eprintln!(
        "friction-node run: {:?} mode, dt = {} s, N = {}, transport {:?}{}",
        config.node.step_mode,
        config.solver.dt_s,
        config.solver.cells,
        opts.transport.unwrap_or(config.node.transport),
        demo.map_or(String::new(), |s| format!(", demo {s} s"))
    );
    Ok(runner::run_node(config, opts, stop)?)
}

/// The run summary; exits with status 1 when the recording failed.
fn summary(config: &Config, r: &RunReport) {
    let s = &r.summary;
    println!(
        "run summary{}",
        if r.interrupted {
            " (stopped by signal)"
        } else {
            ""
        }
    );
    println!("  transports       {}", r.transports.join(", "));
    println!(
        "  steps            {} in {:.2} s ({:?} mode)",
        s.steps, s.wall_s, config.node.step_mode
    );
    print_timing(config, s);
    println!(
        "  commands         {} received = {} applied + {} overwritten + {} rejected; {} steps timed out",
        s.commands_received,
        s.commands_applied,
        s.commands_overwritten,
        s.commands_rejected,
        s.command_timeouts
    );
    println!(
        "  drops            {} publish, {} publish failures, {} statistics not sent, {} recorder; {} transport errors",
        s.publish_drops,
        s.publish_failures,
        s.statistics_not_sent,
        s.recorder_drops,
        s.transport_errors
    );
    print_contacts_and_statuses(s);
    if let (Some(rss), Some(peak)) = (r.rss_bytes, r.peak_rss_bytes) {
        println!(
            "  memory           RSS {:.1} MB (peak {:.1} MB)",
            rss as f64 / 1e6,
            peak as f64 / 1e6
        );
    }
    if !r.realtime_applied.is_empty() {
        println!("  real time        {}", r.realtime_applied.join(", "));
    }
    for w in &r.warnings {
        println!("  warning          {w}");
    }
    if let Some(d) = &r.demo {
        println!(
            "  demo driver      {} commands sent, {} estimates received{}",
            d.commands_sent,
            d.estimates_received,
            d.error
                .as_ref()
                .map_or(String::new(), |e| format!(" ({e})"))
        );
    }
    if let Some(rec) = &r.recording {
        print_recording(rec);
    }
    for s in &r.snapshots {
        println!("  snapshot         {}", s.display());
    }
    if r.recording.as_ref().is_some_and(|rec| rec.error.is_some()) {
        std::process::exit(1);
    }
    // Stopped by SIGINT/SIGTERM: everything is finalised; the exit code
    // says how it ended (130, 143), as for every other command.
    if let Some(sig) = r.signal {
        std::process::exit(128 + sig);
    }
}

/// Compute time, and in timer mode jitter, misses and clock jumps.
fn print_timing(config: &Config, s: &friction_node::node::RunSummary) {
    let us = |ns: u64| ns as f64 / 1e3;
    println!(
        "  compute time     p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs",
        us(s.compute_ns[0]),
        us(s.compute_ns[1]),
        us(s.compute_p999_ns),
        us(s.compute_ns[2])
    );
    if config.node.step_mode == friction_node::config::StepMode::Timer {
        println!(
            "  period jitter    p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
            us(s.jitter_ns[0]),
            us(s.jitter_ns[1]),
            us(s.jitter_ns[2])
        );
        println!(
            "  deadline misses  {} ({} steps caught up late, {} time jumps: lost time advanced in one step)",
            s.deadline_misses, s.catch_up_steps, s.time_jumps
        );
        if s.clock_jumps > 0 {
            println!(
                "  wall clock       {} jumps (stamps stayed monotonic)",
                s.clock_jumps
            );
        }
    }
}

/// Several contacts, and the steps per solver and command status.
fn print_contacts_and_statuses(s: &friction_node::node::RunSummary) {
    use friction_node::msgs::{command_status_name, status_name};
    if s.contacts > 1 {
        println!(
            "  contacts         {} per step (statuses below count contact steps); the last step's slowest: contact {} ({:.1} µs)",
            s.contacts,
            s.slowest_contact,
            s.slowest_contact_ns as f64 / 1e3
        );
    }
    let statuses: Vec<String> = s
        .status_counts
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(c, n)| format!("{} {n}", status_name(c as u8)))
        .collect();
    println!("  solver statuses  {}", statuses.join(", "));
    let commands: Vec<String> = s
        .command_status_counts
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(c, n)| format!("{} {n}", command_status_name(c as u8)))
        .collect();
    println!("  command statuses {}", commands.join(", "));
    println!(
        "  calibrated range {} contact steps outside",
        s.steps_outside_calibrated_range
    );
}

/// How the recording went.
fn print_recording(rec: &runner::RecordingOutcome) {
    let files = if rec.files > 1 || rec.files_deleted > 0 {
        format!(
            " in {} files ({} deleted for the budget)",
            rec.files, rec.files_deleted
        )
    } else {
        String::new()
    };
    match &rec.error {
        None => println!(
            "  recording        {}: {} messages{files}, {:.2} MB",
            rec.path.display(),
            rec.messages,
            rec.bytes as f64 / 1e6
        ),
        Some(e) => println!(
            "  recording        FAILED ({}): {e}; {} messages recorded{files}, {} lost",
            rec.path.display(),
            rec.messages,
            rec.lost
        ),
    }
}
