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
    let r = friction_node::bench::accuracy::run(config, grids, steps, reference, cycles, &|m| {
        eprintln!("  {m}")
    })?;
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

/// `bench-fit`: the calibration targets on synthetic data made by the model
/// itself. Recovery: σ = 3.5 µm, μ_bl = 0.22, μ_l = 0.08 Pa·s on two
/// amplitudes and two loads with 2 % noise, fitted from the defaults.
/// Transfer: fitted at one load and frequency, validated at another, ours
/// and the classic models side by side.
pub fn fit_targets(
    config: &Config,
    cells: usize,
    duration_s: f64,
    seeds: u64,
    out: Option<PathBuf>,
) -> Result<()> {
    use friction_node::fit::problem::fit;
    use friction_node::fit::report::{models_table, ModelRow};
    use friction_node::fit::synthetic::{
        model_friction, motion, noisy_csv, two_amplitudes_two_loads, Segment,
    };
    use friction_node::fit::{
        Baseline, BaselineKind, Data, Delimiter, LoadForm, Mapping, ParamSpec, PhysicsModel,
        Source, Table,
    };
    warn_debug("bench-fit");
    if let Some(d) = &out {
        friction_node::output::prepare_dir(d)?;
    }
    let mut base = config.clone();
    base.solver.cells = cells;
    let dt = base.solver.dt_s;
    let source = |name: &str, csv: &str| -> Result<Source> {
        if let Some(d) = &out {
            friction_node::output::write_file(&d.join(name), csv.as_bytes())?;
        }
        let t = Table::parse(csv, std::path::Path::new(name), Delimiter::Comma, None, 0)?;
        Ok(Source::new(t, &Mapping::default())?)
    };
    let data = |train: Source, validate: Vec<Source>| Data {
        train: vec![train],
        validate,
        holdout: 0.0,
        map_names: vec![],
        map_values: vec![],
    };
    let keys = [
        "roughness.sigma_m",
        "contact.boundary_friction",
        "lubricant.viscosity_pa_s",
    ];
    let specs: Vec<ParamSpec> = keys
        .iter()
        .map(|k| ParamSpec {
            name: (*k).into(),
            ..Default::default()
        })
        .collect();
    let progress = |label: &'static str| -> friction_node::fit::Options {
        friction_node::fit::Options {
            progress: Some(Box::new(move |l| eprintln!("bench-fit [{label}]: {l}"))),
            ..Default::default()
        }
    };

    // ---- recovery ----
    let truth_x = [3.5e-6, 0.22, 0.08];
    let mut truth = base.clone();
    truth.roughness.sigma_m = truth_x[0];
    truth.contact.boundary_friction = truth_x[1];
    truth.lubricant.viscosity_pa_s = truth_x[2];
    let m = two_amplitudes_two_loads(duration_s, dt);
    let clean = model_friction(&truth, &m)?;
    eprintln!(
        "bench-fit: recovery data, {} samples ({duration_s} s at {} Hz), N = {cells}, 2 % noise, {seeds} noise seeds",
        m.len(),
        1.0 / dt
    );
    println!(
        "## Recovery (from the defaults; {duration_s} s, 1 kHz, N = {cells}, two amplitudes and two loads, 2 % noise)\n"
    );
    println!(
        "truth: σ = {:.2} µm, μ_bl = {}, μ_l = {} Pa·s; start: the defaults\n",
        truth_x[0] * 1e6,
        truth_x[1],
        truth_x[2]
    );
    let mut head = String::from("| noise seed |");
    for k in keys {
        head += &format!(" `{k}` fitted (error, SE) |");
    }
    println!("{head} simulations | ms / simulation | wall s |\n|---|---|---|---|---|---|---|");
    let mut covered = [0usize; 3];
    let mut worst = [0.0f64; 3];
    for seed in 1..=seeds {
        let name = format!("recovery-seed{seed}.csv");
        let d = data(source(&name, &noisy_csv(&m, &clean, 0.02, seed))?, vec![]);
        let (scale, _, _) =
            friction_node::fit::request::data_scale(&d.train, &[], base.contact.load_n)?;
        let model = PhysicsModel::new(&base, &specs, &scale)?;
        let o = fit(&model, &d, vec![], &progress("recovery"))?;
        let mut row = format!("| {seed} |");
        for j in 0..3 {
            let (lo, hi) = o.statistics.interval95[j];
            let inside = (lo..=hi).contains(&truth_x[j]);
            covered[j] += usize::from(inside);
            let err = (o.best[j] - truth_x[j]) / truth_x[j];
            worst[j] = worst[j].max(err.abs());
            row += &format!(
                " {:.4e} ({:+.2} %, {:.2} %){} |",
                o.best[j],
                100.0 * err,
                100.0 * o.statistics.standard_error[j] / o.best[j],
                if inside { "" } else { " ✗" }
            );
        }
        println!(
            "{row} {} | {:.1} | {:.1}{} |",
            o.simulations,
            o.simulation_mean_s * 1e3,
            o.wall_s,
            if o.converged { "" } else { " (not converged)" }
        );
    }
    println!("\n| parameter | largest error over the seeds | 95 % interval covers the truth |\n|---|---|---|");
    for (j, k) in keys.iter().enumerate() {
        println!(
            "| `{k}` | {:.2} % | {} of {seeds} |",
            100.0 * worst[j],
            covered[j]
        );
    }
    println!(
        "\n✗: the 95 % interval misses the truth (expected in about 1 seed in 20 per parameter)\n"
    );

    // ---- drivetrain terms beside the contact; the global phase's seeds ----
    let dt_keys = [
        "roughness.sigma_m",
        "contact.boundary_friction",
        "drivetrain.coulomb_n",
        "drivetrain.viscous_n_s_m",
    ];
    let dt_truth = [3.5e-6, 0.22, 300.0, 800.0];
    let mut with_dt = base.clone();
    with_dt.roughness.sigma_m = dt_truth[0];
    with_dt.contact.boundary_friction = dt_truth[1];
    with_dt.drivetrain.coulomb_n = dt_truth[2];
    with_dt.drivetrain.viscous_n_s_m = dt_truth[3];
    let dt_specs: Vec<ParamSpec> = dt_keys
        .iter()
        .map(|k| ParamSpec {
            name: (*k).into(),
            ..Default::default()
        })
        .collect();
    let d = data(
        source(
            "drivetrain.csv",
            &noisy_csv(&m, &model_friction(&with_dt, &m)?, 0.02, 11),
        )?,
        vec![],
    );
    let (scale, _, _) =
        friction_node::fit::request::data_scale(&d.train, &[], base.contact.load_n)?;
    let model = PhysicsModel::new(&base, &dt_specs, &scale)?;
    println!("## Drivetrain terms beside the contact (from the defaults; global phase with three seeds)\n");
    println!(
        "truth: σ = {:.2} µm, μ_bl = {}, drivetrain Coulomb {} N, viscous {} N·s/m; same motion, 2 % noise\n",
        dt_truth[0] * 1e6,
        dt_truth[1],
        dt_truth[2],
        dt_truth[3]
    );
    let mut head = String::from("| global-phase seed |");
    for k in dt_keys {
        head += &format!(" `{k}` (error) |");
    }
    println!("{head} cost ½Σr² (N²) | wall s |\n|---|---|---|---|---|---|---|");
    for seed in 1..=3u64 {
        let mut opts = progress("drivetrain");
        opts.seed = seed;
        let o = fit(&model, &d, vec![], &opts)?;
        let mut row = format!("| {seed} |");
        for (x, t) in o.best.iter().zip(dt_truth) {
            row += &format!(" {x:.4e} ({:+.2} %) |", 100.0 * (x - t) / t);
        }
        println!(
            "{row} {:.6e} | {:.1}{} |",
            o.optima[0].cost,
            o.wall_s,
            if o.converged { "" } else { " (not converged)" }
        );
    }
    println!();

    // ---- transfer ----
    let seg = |a, f, l| Segment {
        amplitude_m_s: a,
        frequency_hz: f,
        load_n: l,
        duration_s,
    };
    let train_m = motion(&[seg(0.5, 1.0, 10_000.0)], dt);
    let valid_m = motion(&[seg(1.0, 2.0, 20_000.0)], dt);
    let train = source(
        "transfer-train.csv",
        &noisy_csv(&train_m, &model_friction(&truth, &train_m)?, 0.02, 2),
    )?;
    let valid = source(
        "transfer-validate.csv",
        &noisy_csv(&valid_m, &model_friction(&truth, &valid_m)?, 0.02, 3),
    )?;
    let d = data(train, vec![valid]);
    let (scale, mean_abs, _) =
        friction_node::fit::request::data_scale(&d.train, &[], base.contact.load_n)?;
    let model = PhysicsModel::new(&base, &specs, &scale)?;
    let ours = fit(&model, &d, vec![], &progress("transfer: ours"))?;
    let mut rows = vec![ModelRow::from(&ours)];
    for kind in BaselineKind::ALL {
        // The training data hold one load: a load-linear level cannot be
        // identified from them; the classic models get levels proportional
        // to the load (Amontons), the one form that carries a fit at one
        // load to another.
        let b = Baseline::new(kind, LoadForm::for_data(false, true), &scale, mean_abs);
        let mut opts = progress(kind.label());
        opts.max_evaluations = 2000;
        rows.push(ModelRow::from(&fit(&b, &d, vec![], &opts)?));
    }
    let scale_n = {
        let s = d.validate[0].series(&[])?;
        (s.friction.iter().map(|f| f * f).sum::<f64>() / s.len().max(1) as f64).sqrt()
    };
    println!("## Transfer (fit: 0.5 m/s, 1 Hz, 10 kN; validate: 1 m/s, 2 Hz, 20 kN; {duration_s} s each, 2 % noise)\n");
    println!("{}", models_table(&rows, scale_n));
    if let Some(d) = &out {
        println!("data in {}", d.display());
    }
    Ok(())
}
