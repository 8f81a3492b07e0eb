//! `simulate`, `stribeck` and `profile`: offline runs written as CSV.

use anyhow::{Context, Result};
use friction_node::config::Config;
use friction_node::offline::{self, ProfileGap};
use friction_node::output::AtomicFile;
use friction_node::signal::Signal;
use std::path::Path;

pub fn simulate(
    config: &Config,
    velocity: &str,
    load: Option<&str>,
    temperature: Option<&str>,
    duration: f64,
    out: &Path,
) -> Result<()> {
    let velocity = Signal::parse(velocity, "velocity")?;
    let load = match load {
        Some(s) => Signal::parse(s, "load")?,
        None => Signal::Const(config.contact.load_n),
    };
    let temperature = temperature
        .map(|s| Signal::parse(s, "temperature"))
        .transpose()?;
    // Inputs checked before the output is touched.
    offline::check_signals(config, &velocity, &load)?;
    if let Some(t) = &temperature {
        offline::check_temperature(config, t)?;
    }
    let steps = offline::check_duration(config, duration)?;
    for (what, s) in [
        ("velocity", Some(&velocity)),
        ("load", Some(&load)),
        ("temperature", temperature.as_ref()),
    ] {
        if let Some(w) = s
            .map(|s| s.check_coverage(what, duration))
            .transpose()?
            .flatten()
        {
            eprintln!("warning: {w}");
        }
    }
    // The size of the whole CSV, from the header and a row of this run.
    let row = offline::simulate_row(&offline::sample_estimate(config, &velocity, &load)?, 20.0);
    let estimate =
        (offline::SIMULATE_COLUMNS.len() + 1) as f64 + (steps as f64) * (row.len() + 1) as f64;
    let what = format!("the CSV ({steps} rows)");
    if let Some(w) = friction_node::output::check_room(out, estimate, &what)? {
        eprintln!("warning: {w}");
    }
    let mut file = AtomicFile::create(out)?;
    file.line(format_args!("{}", offline::SIMULATE_COLUMNS))?;
    eprintln!(
        "simulate: velocity {velocity}, load {load}, {duration} s, N = {}, dt = {} s, {:?} solver",
        config.solver.cells, config.solver.dt_s, config.solver.method
    );
    let inputs = offline::SimulationInputs {
        velocity: &velocity,
        load: &load,
        temperature: temperature.as_ref(),
    };
    let stop = friction_node::interrupt::Stop::process();
    let bar = super::progress::bar(steps, "steps");
    let report = offline::simulate_inputs(config, &inputs, duration, |e, _, t_c| {
        stop.check()?;
        bar.inc(1);
        Ok(file.line(format_args!("{}", offline::simulate_row(e, t_c)))?)
    })?;
    bar.finish_and_clear();
    // A stop after the last step: nothing is moved into place.
    stop.check()?;
    let path = file.commit()?;
    print!("{report}");
    println!("wrote {} ({} rows)", path.display(), report.steps);
    Ok(())
}

pub fn stribeck(
    config: &Config,
    v_min: f64,
    v_max: f64,
    points: usize,
    log: bool,
    load: Option<f64>,
    out: &Path,
) -> Result<()> {
    let vs = offline::sweep(v_min, v_max, points, log)?;
    let load = load.unwrap_or(config.contact.load_n);
    let mut file = AtomicFile::create(out)?;
    let rows = offline::stribeck(config, &vs, load)?;
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
    Ok(())
}

pub fn profile(
    config: &Config,
    velocity: f64,
    h0: Option<f64>,
    load: Option<f64>,
    out: &Path,
) -> Result<()> {
    let gap = match (h0, load) {
        (Some(h), _) => ProfileGap::H0(h),
        (None, Some(f)) => ProfileGap::Load(f),
        (None, None) => anyhow::bail!("profile needs --h0 or --load"),
    };
    let mut file = AtomicFile::create(out)?;
    let (e, field) = offline::profile(config, velocity, gap)?;
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
    Ok(())
}
