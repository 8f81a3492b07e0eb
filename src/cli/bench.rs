//! `bench` (one model step, Newton against the reference) and
//! `bench-latency` (command → estimate through a transport).

use super::args::TransportArg;
use anyhow::Result;
use friction_node::config::Config;
use friction_node::output::AtomicFile;
use std::path::PathBuf;

fn warn_debug(command: &str) {
    if cfg!(debug_assertions) {
        eprintln!(
            "warning: this is a debug build; benchmark with `cargo run --release -- {command}`"
        );
    }
}

pub fn step(
    config: &Config,
    cells: Vec<usize>,
    cycles: usize,
    reference_steps: usize,
    out: Option<PathBuf>,
    breakdown: bool,
    allocations: &dyn Fn() -> u64,
) -> Result<()> {
    warn_debug("bench");
    // The output is checked before the benchmark runs.
    let file = out.as_deref().map(AtomicFile::create).transpose()?;
    let progress = |m: &str| eprintln!("  {m}");
    let cases = friction_node::bench::run(
        config,
        &friction_node::bench::BenchOptions {
            cells,
            cycles,
            reference_steps,
            allocation_counter: Some(allocations),
            breakdown,
            progress: &progress,
        },
    )?;
    print!("{}", friction_node::bench::table(&cases));
    print!("{}", friction_node::bench::breakdown_table(&cases));
    if let Some(mut f) = file {
        f.line(format_args!(
            "{}",
            friction_node::bench::csv(&cases).trim_end()
        ))?;
        println!("wrote {}", f.commit()?.display());
    }
    Ok(())
}

pub fn latency(
    config: &Config,
    transport: TransportArg,
    samples: usize,
    warmup: usize,
) -> Result<()> {
    warn_debug("bench-latency");
    if transport == TransportArg::Both {
        anyhow::bail!("--transport both: bench-latency measures one transport, ros2 or iceoryx2");
    }
    let spec = friction_node::node::runner::backend_specs(config, transport.kind())?.remove(0);
    eprintln!(
        "bench-latency: {} round trips through {} (N = {}), lockstep node",
        samples,
        spec.name(),
        config.solver.cells
    );
    let r = friction_node::bench::latency(config, spec, samples, warmup)?;
    let what = if r.contacts > 1 {
        format!("{} contacts: JointState → efforts", r.contacts)
    } else {
        "command → estimate".to_string()
    };
    println!(
        "{}: {what} p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs over {} samples ({} lost); model step p50 {:.1} µs, p99 {:.1} µs",
        r.transport, r.latency_us[0], r.latency_us[1], r.latency_us[2], r.latency_us[3], r.samples, r.lost, r.step_us[0], r.step_us[1]
    );
    Ok(())
}

/// `bench-accuracy`: the accuracy guide's table (markdown, on stdout).
pub fn accuracy(
    config: &Config,
    grids: &[usize],
    steps: &[f64],
    reference: (usize, f64),
    cycles: u32,
) -> Result<()> {
    if cfg!(debug_assertions) {
        eprintln!("warning: a debug build; the step costs are not representative (use --release)");
    }
    use friction_node::bench::reference::{check_reference, without_repeats};
    let (grids, steps) = (&without_repeats(grids), &without_repeats(steps));
    // The grids run at the configured step, the steps on the configured grid.
    let cells: Vec<usize> = grids.iter().copied().chain([config.solver.cells]).collect();
    let dts: Vec<f64> = steps.iter().copied().chain([config.solver.dt_s]).collect();
    check_reference(&cells, &dts, reference)?;
    let r = friction_node::bench::accuracy::run(config, grids, steps, reference, cycles, &|m| {
        eprintln!("  {m}")
    })?;
    print!("{r}");
    Ok(())
}

/// `bench-cases`: the transient cases' pass table (markdown, on stdout).
pub fn cases(
    config: &Config,
    count: usize,
    grids: &[usize],
    fluxes: &[friction_node::config::FluxKind],
    reference: (usize, f64),
    cycles: u32,
    jobs: usize,
) -> Result<()> {
    if cfg!(debug_assertions) {
        eprintln!("warning: a debug build; the cases take much longer (use --release)");
    }
    use friction_node::bench::reference::{check_reference, without_repeats};
    let (grids, fluxes) = (&without_repeats(grids), &without_repeats(fluxes));
    check_reference(grids, &[config.solver.dt_s], reference)?;
    let settings: Vec<_> = fluxes
        .iter()
        .flat_map(|&flux| grids.iter().map(move |&n| (n, config.solver.dt_s, flux)))
        .collect();
    let jobs = if jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        jobs
    };
    let reference = (
        reference.0,
        reference.1,
        friction_node::config::FluxKind::MusclVanLeer,
    );
    let r = friction_node::bench::cases::run(
        config,
        count,
        &settings,
        reference,
        cycles,
        jobs,
        &|m| eprintln!("  {m}"),
    )?;
    print!("{r}");
    Ok(())
}

/// `bench-recorder`: simulated hours through the recorder.
pub fn recorder(config: &Config, hours: u64, out: PathBuf) -> Result<()> {
    #[cfg(feature = "mcap")]
    {
        warn_debug("bench-recorder");
        let c = &config.recording;
        eprintln!(
            "bench-recorder: {hours} simulated hours at {} steps/s into {}, split every {} s / {} bytes, budget {} bytes",
            (1.0 / config.solver.dt_s).round(),
            out.display(),
            c.split.max_duration_s,
            c.split.max_bytes,
            c.budget_bytes
        );
        if !c.splits() {
            anyhow::bail!(
                "bench-recorder needs split files: set recording.split.max_duration_s or max_bytes"
            );
        }
        let progress = |h: u64, n: u64| eprintln!("  hour {h}/{n}");
        let r = friction_node::bench::recorder::run(config, out, hours, &progress)?;
        let mb = |b: u64| b as f64 / 1e6;
        println!("hour,rss_mb");
        for (h, rss) in r.rss_by_hour.iter().enumerate() {
            println!("{},{:.2}", h + 1, mb(*rss));
        }
        let first = r.rss_by_hour.first().copied().unwrap_or(0);
        let last = r.rss_by_hour.last().copied().unwrap_or(0);
        println!(
            "{} steps ({} simulated hours) in {:.1} s wall ({:.0}× real time); {} messages in {} files, {} deleted for the budget, {:.1} MB kept",
            r.steps,
            hours,
            r.wall_s,
            hours as f64 * 3600.0 / r.wall_s,
            r.report.messages,
            r.report.files,
            r.report.files_deleted,
            mb(r.report.bytes)
        );
        println!(
            "resident memory: {:.2} MB after hour 1, {:.2} MB after hour {hours} ({:+.2} MB)",
            mb(first),
            mb(last),
            (last as f64 - first as f64) / 1e6
        );
        if let Some(e) = &r.report.error {
            anyhow::bail!("the recording failed: {e}");
        }
        Ok(())
    }
    #[cfg(not(feature = "mcap"))]
    {
        let _ = (config, hours, out);
        anyhow::bail!("bench-recorder needs the `mcap` feature")
    }
}

/// `bench-fit`: the calibration targets on synthetic data
/// ([`friction_node::bench::fit`]), printed as markdown.
pub fn fit_targets(
    config: &Config,
    cells: usize,
    duration_s: f64,
    seeds: u64,
    out: Option<PathBuf>,
) -> Result<()> {
    warn_debug("bench-fit");
    if let Some(d) = &out {
        friction_node::output::prepare_dir(d)?;
    }
    let progress = std::sync::Arc::new(|l: &str| eprintln!("bench-fit [{l}]"));
    let md = friction_node::bench::fit::run(
        config,
        &friction_node::bench::fit::FitBenchOptions {
            cells,
            duration_s,
            seeds,
            out: out.as_deref(),
            progress,
        },
    )?;
    print!("{md}");
    Ok(())
}
