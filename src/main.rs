//! The `friction-node` command line.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use friction_node::config::Config;
use friction_node::offline::{self, AtomicFile, Gap};
use friction_node::signal::Signal;
use std::cell::Cell;
use std::path::PathBuf;

/// Counts heap allocations (per thread) so that `bench` can report
/// allocations per step.
struct CountingAlloc;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count_allocation() {
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl std::alloc::GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        count_allocation();
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, size: usize) -> *mut u8 {
        count_allocation();
        unsafe { std::alloc::System.realloc(ptr, layout, size) }
    }
}

#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

#[derive(Parser)]
#[command(
    name = "friction-node",
    version,
    about = "Physics-based sliding-friction estimate: transient mixed lubrication (Driesen et al. 2023)",
    long_about = None
)]
struct Cli {
    #[command(flatten)]
    common: Common,
    #[command(subcommand)]
    command: Command,
}

/// Accepted before and after the subcommand; overrides accumulate in order
/// (clap's `global` would replace the earlier ones).
#[derive(clap::Args, Clone, Default)]
struct Common {
    /// ROS 2 parameter file (default: the built-in launch-config/default.yaml).
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
    /// Override a parameter, e.g. --set contact.load_n=5762 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
}

#[derive(Subcommand)]
enum Command {
    /// Run the transient model over a velocity (and load) history; write a CSV.
    Simulate {
        #[command(flatten)]
        common: Common,
        /// Velocity in m/s: const:V | sine:V0,V1,F[,PHASE] | csv:FILE[@COLUMN].
        #[arg(long, value_name = "SPEC")]
        velocity: String,
        /// Load in N (same forms; default: contact.load_n).
        #[arg(long, value_name = "SPEC")]
        load: Option<String>,
        /// Simulated time, s.
        #[arg(long, value_name = "S")]
        duration: f64,
        /// Output CSV.
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Steady Stribeck curve over a velocity range; write a CSV.
    Stribeck {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_name = "V", allow_hyphen_values = true)]
        v_min: f64,
        #[arg(long, value_name = "V", allow_hyphen_values = true)]
        v_max: f64,
        #[arg(long, value_name = "N", default_value_t = 60)]
        points: usize,
        /// Logarithmic spacing (the range must not contain 0).
        #[arg(long)]
        log: bool,
        /// Load in N (default: contact.load_n).
        #[arg(long, value_name = "N")]
        load: Option<f64>,
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Steady fields along the slider at one velocity; write a CSV.
    Profile {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_name = "V", allow_hyphen_values = true)]
        velocity: f64,
        /// Prescribed minimum separation h0, m.
        #[arg(
            long,
            value_name = "M",
            conflicts_with = "load",
            required_unless_present = "load"
        )]
        h0: Option<f64>,
        /// Load in N: h0 from the load balance.
        #[arg(long, value_name = "N")]
        load: Option<f64>,
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Run the real-time node: ROS 2 / iceoryx2 topics, fixed steps, MCAP recording.
    Run {
        #[command(flatten)]
        common: Common,
        /// Transport (default: node.transport).
        #[arg(long, value_enum)]
        transport: Option<TransportArg>,
        /// Record inputs and outputs to this MCAP file.
        #[arg(long, value_name = "FILE.mcap")]
        record: Option<PathBuf>,
        /// Drive the node with the paper's reciprocating velocity (V1 = 1 m/s,
        /// f = 1 Hz) on its own topics for this many seconds, then stop.
        #[arg(long, value_name = "SECONDS")]
        demo: Option<f64>,
        /// Stop after this many seconds (default: run until SIGINT/SIGTERM).
        #[arg(long, value_name = "SECONDS", conflicts_with = "demo")]
        duration: Option<f64>,
        /// No live status line.
        #[arg(long)]
        quiet: bool,
    },
    /// Re-run the model over the velocity recorded in a ROS 2 MCAP bag.
    Replay {
        #[command(flatten)]
        common: Common,
        /// The bag to replay.
        #[arg(value_name = "BAG.mcap")]
        bag: PathBuf,
        /// Velocity topic (std_msgs/Float64, geometry_msgs/TwistStamped or
        /// sensor_msgs/JointState); default: detected. For a friction-node bag
        /// the default is its recorded estimates (the determinism oracle).
        #[arg(long, value_name = "NAME")]
        topic: Option<String>,
        /// JointState: the joint whose velocity drives the slider.
        #[arg(long, value_name = "NAME")]
        joint: Option<String>,
        /// Load topic (std_msgs/Float64); default: one ending in normal_load.
        #[arg(long, value_name = "NAME")]
        load_topic: Option<String>,
        /// Output: OUT.mcap (ROS 2 profile) or OUT.csv (the simulate columns).
        #[arg(long, value_name = "OUT.mcap|OUT.csv")]
        out: PathBuf,
        /// Also write a report (loop metrics, plots, markdown) into DIR.
        #[arg(long, value_name = "DIR")]
        report: Option<PathBuf>,
        /// Exit with status 3 unless the re-simulation is bit-identical to
        /// the recorded estimates.
        #[arg(long)]
        expect_identical: bool,
    },
    /// Reproduce the paper's parametric studies: CSVs, loop metrics, plots, claims.
    Study {
        #[command(flatten)]
        common: Common,
        /// Which study (or `all`).
        #[arg(value_enum)]
        name: StudyName,
        /// Output directory (created if needed).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Cycles per case; metrics are those of the last one.
        #[arg(long, default_value_t = 3)]
        cycles: usize,
        /// Worker threads (default: one per core).
        #[arg(long)]
        jobs: Option<usize>,
    },
    /// Command → estimate latency through a transport (release build!).
    BenchLatency {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_enum, default_value = "iceoryx2")]
        transport: TransportArg,
        #[arg(long, default_value_t = 10_000)]
        samples: usize,
        #[arg(long, default_value_t = 500)]
        warmup: usize,
    },
    /// Benchmark one step of the paper's reciprocating case (release build!).
    Bench {
        #[command(flatten)]
        common: Common,
        /// Grid sizes.
        #[arg(long, value_delimiter = ',', default_value = "64,256,1024")]
        cells: Vec<usize>,
        /// Timed cycles per grid (after one warm-up cycle).
        #[arg(long, default_value_t = 3)]
        cycles: usize,
        /// States at which the reference solver is timed.
        #[arg(long, default_value_t = 12)]
        reference_steps: usize,
        /// Also write the results as CSV.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
}

fn main() {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                // RustDDS logs harmless chatter at participant teardown;
                // RUST_LOG=rustdds=warn shows it.
                .unwrap_or_else(|_| {
                    tracing_subscriber::EnvFilter::new("warn,rustdds=off,ros2_client=error")
                }),
        )
        .with_writer(std::io::stderr)
        .init();
    if let Err(e) = run(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(2);
    }
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum TransportArg {
    Ros2,
    Iceoryx2,
    Both,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum StudyName {
    Stribeck,
    AmplitudeFrequency,
    Load,
    Viscosity,
    Inertia,
    Unidirectional,
    Roughness,
    Hersey,
    All,
}

impl Command {
    fn common(&self) -> &Common {
        match self {
            Command::Study { common, .. }
            | Command::Run { common, .. }
            | Command::BenchLatency { common, .. }
            | Command::Replay { common, .. } => common,
            Command::Simulate { common, .. }
            | Command::Stribeck { common, .. }
            | Command::Profile { common, .. }
            | Command::Bench { common, .. } => common,
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    let sub = cli.command.common().clone();
    if cli.common.config.is_some() && sub.config.is_some() {
        anyhow::bail!("--config given twice (before and after the subcommand)");
    }
    let path = sub.config.or(cli.common.config);
    let sets: Vec<String> = cli.common.sets.iter().chain(&sub.sets).cloned().collect();
    if let Command::Replay {
        bag,
        topic,
        joint,
        load_topic,
        out,
        report,
        expect_identical,
        ..
    } = cli.command
    {
        #[cfg(feature = "mcap")]
        return replay(
            bag,
            topic,
            joint,
            load_topic,
            out,
            report,
            expect_identical,
            path,
            sets,
        );
        #[cfg(not(feature = "mcap"))]
        {
            let _ = (bag, topic, joint, load_topic, out, report, expect_identical);
            anyhow::bail!("replay needs the `mcap` feature");
        }
    }
    let config = Config::load(path.as_deref(), &sets)?;
    match cli.command {
        Command::Replay { .. } => unreachable!("handled above"),
        Command::Simulate {
            common: _,
            velocity,
            load,
            duration,
            out,
        } => {
            let velocity = Signal::parse(&velocity, "velocity")?;
            let load = match load {
                Some(s) => Signal::parse(&s, "load")?,
                None => Signal::Const(config.contact.load_n),
            };
            let mut file = AtomicFile::create(&out)?;
            file.line(format_args!("{}", offline::SIMULATE_COLUMNS))?;
            eprintln!(
                "simulate: velocity {velocity}, load {load}, {duration} s, N = {}, dt = {} s, {:?} solver",
                config.solver.cells, config.solver.dt_s, config.solver.method
            );
            let report = offline::simulate(&config, &velocity, &load, duration, |e, _| {
                file.line(format_args!("{}", offline::simulate_row(e)))
            })?;
            let path = file.commit()?;
            print!("{report}");
            println!("wrote {} ({} rows)", path.display(), report.steps);
        }
        Command::Stribeck {
            common: _,
            v_min,
            v_max,
            points,
            log,
            load,
            out,
        } => {
            let vs = offline::sweep(v_min, v_max, points, log)?;
            let load = load.unwrap_or(config.contact.load_n);
            let mut file = AtomicFile::create(&out)?;
            let rows = offline::stribeck(&config, &vs, load)?;
            file.line(format_args!("{}", offline::STRIBECK_COLUMNS))?;
            for e in &rows {
                file.line(format_args!("{}", offline::stribeck_row(e)))?;
            }
            let path = file.commit()?;
            let min = rows
                .iter()
                .min_by(|a, b| a.cof.total_cmp(&b.cof))
                .context("empty sweep")?;
            let failed = rows.iter().filter(|e| !e.status.is_converged()).count();
            println!(
                "{} points, load {load} N: COF {:.4} at v = {} m/s … minimum {:.4} at v = {} m/s",
                rows.len(),
                rows[0].cof,
                rows[0].velocity,
                min.cof,
                min.velocity
            );
            if failed > 0 {
                println!("warning: {failed} points did not converge (see the status column)");
            }
            println!("wrote {}", path.display());
        }
        Command::Profile {
            common: _,
            velocity,
            h0,
            load,
            out,
        } => {
            let gap = match (h0, load) {
                (Some(h), _) => Gap::H0(h),
                (None, Some(f)) => Gap::Load(f),
                (None, None) => unreachable!("clap requires one"),
            };
            let mut file = AtomicFile::create(&out)?;
            let (e, field) = offline::profile(&config, velocity, gap)?;
            file.line(format_args!("{}", offline::PROFILE_COLUMNS))?;
            for p in &field {
                file.line(format_args!("{}", offline::profile_row(p)))?;
            }
            let path = file.commit()?;
            println!("status           {}", e.status.as_str());
            println!(
                "h0               {:.4} µm (h_min {:.4} µm)",
                e.h0 * 1e6,
                e.h_min * 1e6
            );
            println!("p_max            {:.6e} Pa (absolute)", e.max_pressure);
            println!("hydrodynamic load {:.3} N", e.hydrodynamic_force);
            println!("asperity load    {:.3} N", e.asperity_force);
            println!(
                "friction         {:.3} N (COF {:.5})",
                e.friction_force, e.cof
            );
            println!("wrote {} ({} cells)", path.display(), field.len());
        }
        Command::BenchLatency {
            common: _,
            transport,
            samples,
            warmup,
        } => {
            if cfg!(debug_assertions) {
                eprintln!("warning: this is a debug build; benchmark with `cargo run --release -- bench-latency`");
            }
            let kind = match transport {
                TransportArg::Ros2 => friction_node::config::TransportKind::Ros2,
                TransportArg::Iceoryx2 => friction_node::config::TransportKind::Iceoryx2,
                TransportArg::Both => {
                    anyhow::bail!("bench-latency measures one transport: ros2 or iceoryx2")
                }
            };
            let spec = friction_node::node::runner::backend_specs(&config, kind)?.remove(0);
            eprintln!(
                "bench-latency: {} round trips through {} (N = {}), lockstep node",
                samples,
                spec.name(),
                config.solver.cells
            );
            let r = friction_node::bench::latency(&config, spec, samples, warmup)?;
            println!(
                "{}: command → estimate p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs over {} samples ({} lost); model step p50 {:.1} µs, p99 {:.1} µs",
                r.transport, r.latency_us[0], r.latency_us[1], r.latency_us[2], r.latency_us[3], r.samples, r.lost, r.step_us[0], r.step_us[1]
            );
        }
        Command::Run {
            common: _,
            transport,
            record,
            demo,
            duration,
            quiet,
        } => run_node(&config, transport, record, demo, duration, quiet)?,
        Command::Study {
            common: _,
            name,
            out,
            cycles,
            jobs,
        } => run_study(&config, name, &out, cycles, jobs)?,
        Command::Bench {
            common: _,
            cells,
            cycles,
            reference_steps,
            out,
        } => {
            if cfg!(debug_assertions) {
                eprintln!(
                    "warning: this is a debug build; benchmark with `cargo run --release -- bench`"
                );
            }
            let counter = || ALLOCATIONS.with(Cell::get);
            let progress = |m: &str| eprintln!("  {m}");
            let cases = friction_node::bench::run(
                &config,
                &friction_node::bench::BenchOptions {
                    cells,
                    cycles,
                    reference_steps,
                    allocation_counter: Some(&counter),
                    progress: &progress,
                },
            )?;
            print!("{}", friction_node::bench::table(&cases));
            if let Some(out) = out {
                let mut f = AtomicFile::create(&out)?;
                f.line(format_args!(
                    "{}",
                    friction_node::bench::csv(&cases).trim_end()
                ))?;
                println!("wrote {}", f.commit()?.display());
            }
        }
    }
    Ok(())
}

fn run_study(
    config: &Config,
    name: StudyName,
    out: &std::path::Path,
    cycles: usize,
    jobs: Option<usize>,
) -> Result<()> {
    use friction_node::studies::{self, claims, report, StudyKind, StudyOptions, StudyResult};
    use indicatif::{ProgressBar, ProgressStyle};
    use rayon::prelude::*;
    if cycles < 1 {
        anyhow::bail!("--cycles must be at least 1 (the paper's loops need 3)");
    }
    report::prepare_output_dir(out)?;
    let kinds: Vec<StudyKind> = match name {
        StudyName::All => StudyKind::ALL.to_vec(),
        other => {
            let n = <StudyName as clap::ValueEnum>::to_possible_value(&other).expect("named");
            vec![StudyKind::from_name(n.get_name()).expect("study names match")]
        }
    };
    if let Some(j) = jobs {
        rayon::ThreadPoolBuilder::new()
            .num_threads(j.max(1))
            .build_global()
            .ok();
    }
    let opts = StudyOptions {
        cycles,
        ..Default::default()
    };
    let started = std::time::Instant::now();
    // Every steady curve and case of every study, as one job list.
    enum Job {
        Steady(StudyKind, studies::SteadySpec),
        Case(studies::Case),
    }
    let mut jobs_list = Vec::new();
    let mut total = 0u64;
    for &k in &kinds {
        let cases = studies::cases(k, config, &opts);
        for s in studies::steady_specs(k, config, &cases, &opts) {
            total += s.velocities.len() as u64 * 20;
            jobs_list.push(Job::Steady(k, s));
        }
        for c in cases {
            total += c.steps() as u64;
            jobs_list.push(Job::Case(c));
        }
    }
    let n_cases = jobs_list
        .iter()
        .filter(|j| matches!(j, Job::Case(_)))
        .count();
    eprintln!(
        "study {}: {} cases on {} threads, N = {}, dt = {} s, {} cycles per case",
        kinds
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(", "),
        n_cases,
        rayon::current_num_threads(),
        config.solver.cells,
        config.solver.dt_s,
        cycles
    );
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent:>3}% {msg}")
            .expect("template")
            .progress_chars("=> "),
    );
    enum Done {
        Steady(
            StudyKind,
            Result<studies::SteadyCurve, friction_node::offline::OfflineError>,
        ),
        Case(Box<studies::CaseResult>),
    }
    let done: Vec<Done> = jobs_list
        .into_par_iter()
        .map(|j| match j {
            Job::Steady(k, s) => {
                let r = studies::steady_curve(&s);
                bar.inc(s.velocities.len() as u64 * 20);
                Done::Steady(k, r)
            }
            Job::Case(c) => {
                bar.set_message(format!("{} {}", c.study.name(), c.id));
                Done::Case(Box::new(studies::run_case(&c, &|n| bar.inc(n as u64))))
            }
        })
        .collect();
    bar.finish_and_clear();
    let mut results: claims::Results = kinds
        .iter()
        .map(|&k| {
            (
                k,
                StudyResult {
                    study: k,
                    cases: Vec::new(),
                    steady: Vec::new(),
                },
            )
        })
        .collect();
    for d in done {
        match d {
            Done::Steady(k, r) => results.get_mut(&k).expect("study").steady.push(r?),
            Done::Case(c) => results
                .get_mut(&c.case.study)
                .expect("study")
                .cases
                .push(*c),
        }
    }
    let compute_s = started.elapsed().as_secs_f64();
    let mut failed = Vec::new();
    for r in results.values() {
        let files = report::write_study(out, r)?;
        let bad: Vec<String> = r
            .cases
            .iter()
            .filter_map(|c| c.failure.as_ref().map(|f| format!("{} ({f})", c.case.id)))
            .collect();
        println!(
            "{:<20} {:>3} cases, {} files in {}{}",
            r.study.name(),
            r.cases.len(),
            files.len(),
            out.join(r.study.name()).display(),
            if bad.is_empty() {
                String::new()
            } else {
                format!(" — FAILED: {}", bad.join(", "))
            }
        );
        failed.extend(bad);
    }
    let evaluated = claims::evaluate(&results, config.contact.boundary_friction);
    if evaluated
        .iter()
        .any(|c| c.verdict() != claims::Verdict::NotEvaluated)
    {
        let path = out.join("claims.md");
        std::fs::write(&path, report::claims_markdown(&evaluated, &failed))
            .with_context(|| format!("cannot write {}", path.display()))?;
        println!("\nclaims (MODEL.md §8), details in {}:", path.display());
        for c in &evaluated {
            if c.verdict() != claims::Verdict::NotEvaluated {
                let passed = c.checks.iter().filter(|k| k.pass).count();
                println!(
                    "  {}. {:<18} {}/{} checks",
                    c.number,
                    c.verdict().as_str(),
                    passed,
                    c.checks.len()
                );
            }
        }
    }
    println!(
        "done in {:.1} s ({:.1} s computing on {} threads)",
        started.elapsed().as_secs_f64(),
        compute_s,
        rayon::current_num_threads()
    );
    Ok(())
}

fn run_node(
    config: &Config,
    transport: Option<TransportArg>,
    record: Option<PathBuf>,
    demo: Option<f64>,
    duration: Option<f64>,
    quiet: bool,
) -> Result<()> {
    use friction_node::config::TransportKind;
    use friction_node::msgs::status_name;
    use friction_node::node::runner::{self, RunOptions};
    let opts = RunOptions {
        transport: transport.map(|t| match t {
            TransportArg::Ros2 => TransportKind::Ros2,
            TransportArg::Iceoryx2 => TransportKind::Iceoryx2,
            TransportArg::Both => TransportKind::Both,
        }),
        record,
        demo_s: demo,
        duration_s: duration,
        status_line: !quiet,
    };
    let stop = runner::stop_on_signals();
    eprintln!(
        "friction-node run: {:?} mode, dt = {} s, N = {}, transport {:?}{}",
        config.node.step_mode,
        config.solver.dt_s,
        config.solver.cells,
        opts.transport.unwrap_or(config.node.transport),
        demo.map_or(String::new(), |s| format!(", demo {s} s"))
    );
    let r = runner::run_node(config, &opts, stop)?;
    let s = &r.summary;
    let us = |ns: u64| ns as f64 / 1e3;
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
    println!(
        "  compute time     p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        us(s.compute_ns[0]),
        us(s.compute_ns[1]),
        us(s.compute_ns[2])
    );
    if config.node.step_mode == friction_node::config::StepMode::Timer {
        println!(
            "  period jitter    p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
            us(s.jitter_ns[0]),
            us(s.jitter_ns[1]),
            us(s.jitter_ns[2])
        );
        println!("  deadline misses  {}", s.deadline_misses);
    }
    println!(
        "  commands         {} received, {} rejected; {} steps without a fresh command",
        s.commands_received, s.commands_rejected, s.command_timeouts
    );
    println!(
        "  drops            {} publish, {} recorder; {} transport errors",
        s.publish_drops, s.recorder_drops, s.transport_errors
    );
    let statuses: Vec<String> = s
        .status_counts
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(c, n)| format!("{} {n}", status_name(c as u8)))
        .collect();
    println!("  statuses         {}", statuses.join(", "));
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
        match &rec.error {
            None => println!(
                "  recording        {}: {} messages, {:.2} MB",
                rec.path.display(),
                rec.messages,
                rec.bytes as f64 / 1e6
            ),
            Some(e) => println!("  recording        FAILED ({}): {e}", rec.path.display()),
        }
    }
    if r.recording.as_ref().is_some_and(|rec| rec.error.is_some()) {
        std::process::exit(1);
    }
    Ok(())
}

#[cfg(feature = "mcap")]
#[allow(clippy::too_many_arguments)]
fn replay(
    bag_path: PathBuf,
    topic: Option<String>,
    joint: Option<String>,
    load_topic: Option<String>,
    out: PathBuf,
    report: Option<PathBuf>,
    expect_identical: bool,
    config: Option<PathBuf>,
    overrides: Vec<String>,
) -> Result<()> {
    use friction_node::replay::{self, Bag, InputMode, OutputFormat, OutputStream, ReplayOptions};
    use indicatif::{ProgressBar, ProgressStyle};
    let started = std::time::Instant::now();
    let Some(format) = OutputFormat::from_path(&out) else {
        anyhow::bail!(
            "--out {}: the output must end in .mcap or .csv",
            out.display()
        );
    };
    // Validate the input completely before touching any output.
    let bag = Bag::open(&bag_path)?;
    let opts = ReplayOptions {
        topic,
        joint,
        load_topic,
        config,
        overrides,
    };
    let prepared = replay::prepare(&bag, &opts)?;
    if let Some(r) = &report {
        friction_node::studies::report::prepare_output_dir(r)?;
    }
    let steps = prepared
        .commands
        .iter()
        .filter(|c| c.kind == friction_node::msgs::CommandKind::Velocity)
        .count();
    eprintln!(
        "replay {}: {} ({} velocity messages → {} steps of {} s), configuration {}",
        bag_path.display(),
        match &prepared.mode {
            InputMode::Topics { velocity, .. } => format!("topic {velocity}"),
            InputMode::RecordedEstimates { topic } => format!("recorded estimates {topic}"),
        },
        prepared.velocity_messages,
        steps,
        prepared.config.solver.dt_s,
        prepared.config_source,
    );
    if let Some(d) = &prepared.scan.damage {
        eprintln!("warning: the bag is damaged {d}; replaying everything before it");
    }
    if !prepared.gaps.is_empty() {
        eprintln!(
            "warning: {} velocity gaps longer than node.command_timeout_s = {} s (the node's timeout rule applied): {}",
            prepared.gaps.len(),
            prepared.config.node.command_timeout_s,
            replay::gap_list(&prepared.gaps, prepared.commands.first().map_or(0, |c| c.stamp_ns))
        );
    }
    // Written to a temporary sibling while the model runs; moved into place
    // only when complete.
    let mut stream = OutputStream::start(&out, format, &prepared, &bag_path)?;
    let bar = ProgressBar::new(prepared.commands.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} commands, {per_sec}",
        )
        .expect("template")
        .progress_chars("=> "),
    );
    let model_started = std::time::Instant::now();
    let result = replay::run(
        &prepared,
        &mut |done, _| bar.set_position(done as u64),
        &mut |e, rec| stream.push(e, rec),
    )?;
    let model_wall = model_started.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let written = stream.finish(result.oracle.as_ref())?;
    let wall = started.elapsed().as_secs_f64();
    let e = &result.estimates;
    let span = match (e.first(), e.last()) {
        (Some(a), Some(b)) => (b.1.stamp_ns.saturating_sub(a.1.stamp_ns)) as f64 / 1e9,
        _ => 0.0,
    };
    println!(
        "steps            {} over {:.3} s of bag time",
        e.len(),
        span
    );
    let rate = |w: f64| if w > 0.0 { span / w } else { f64::NAN };
    println!(
        "replay time      {:.3} s ({:.0}× real time; reading, model and writing), model {:.3} s ({:.0}×)",
        wall,
        rate(wall),
        model_wall,
        rate(model_wall)
    );
    println!("commands         {} rejected", result.commands_rejected);
    if let Some(d) = &prepared.scan.damage {
        println!("damaged bag      stopped {d}");
    }
    let mut identical = true;
    if let Some(o) = &result.oracle {
        identical = o.identical;
        if o.identical {
            println!(
                "determinism      bit-identical to the recorded estimates ({} steps)",
                o.compared
            );
        } else {
            println!(
                "determinism      DIFFERS from the recording over {} steps:",
                o.compared
            );
            for (f, d, k) in &o.deviations {
                println!("                 {f:<22} up to {d:.3e} (first largest at step {k})");
            }
            if let Some((a, b)) = o.count_mismatch {
                println!("                 {a} steps recorded, {b} replayed");
            }
        }
    }
    println!("wrote {}", written.display());
    if let Some(r) = &report {
        let files = replay::write_report(r, &bag_path, &prepared, &result, wall)?;
        println!(
            "report           {} ({} files)",
            r.join("summary.md").display(),
            files.len()
        );
    }
    if expect_identical && (result.oracle.is_none() || !identical) {
        eprintln!(
            "error: --expect-identical: {}",
            if result.oracle.is_none() {
                "the bag has no recorded estimates to compare with"
            } else {
                "the re-simulation differs"
            }
        );
        std::process::exit(3);
    }
    Ok(())
}
