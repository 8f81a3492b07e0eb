//! `simulate`: a transient run of the model over velocity, load and
//! temperature signals, as CSV rows, with its per-step timing and a report
//! (statuses, hysteresis-loop metrics).

use super::{arg_err, SimulationError};
use crate::analysis::{CycleCollector, LoopMetrics, LoopSample};
use crate::config::Config;
use crate::physics::{Estimate, Solver, Status};
use crate::signal::Signal;
use crate::text::Num;
use std::time::Instant;

/// Columns of `simulate` (the first eleven are a stable interface).
pub const SIMULATE_COLUMNS: &str = "t_s,velocity_m_s,load_n,h0_m,h_min_m,f_hyd_n,f_asp_n,friction_n,cof,iterations,status,viscous_n,asperity_load_share,inertia_n,regime,residual,load_residual,max_pressure_pa,cavitated_fraction,contact_area_ratio,substeps,temperature_c,contact_friction_n";

/// One `simulate` row at lubricant temperature `t_c` (re-reading the CSV
/// gives the same bits).
pub fn simulate_row(e: &Estimate, t_c: f64) -> String {
    simulate_row_with_status(e, e.status.as_str(), t_c)
}

/// A `simulate` row with the status column given (replay reports the
/// node's status codes).
pub fn simulate_row_with_status(e: &Estimate, status: &str, t_c: f64) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
        Num(e.time),
        Num(e.velocity),
        Num(e.load),
        Num(e.h0),
        Num(e.h_min),
        Num(e.hydrodynamic_force),
        Num(e.asperity_force),
        Num(e.friction_force),
        Num(e.cof),
        e.diagnostics.iterations,
        status,
        Num(e.viscous_force),
        Num(e.asperity_load_share),
        Num(e.inertia_force),
        e.regime.as_str(),
        Num(e.diagnostics.residual),
        Num(e.diagnostics.load_residual),
        Num(e.max_pressure),
        Num(e.cavitated_fraction),
        Num(e.contact_area_ratio),
        e.diagnostics.substeps,
        Num(t_c),
        Num(e.contact_friction_force),
    )
}

/// Distribution of per-step solver times.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timing {
    /// Median, µs.
    pub median_us: f64,
    /// 99th percentile, µs.
    pub p99_us: f64,
    /// 99.9th percentile, µs.
    pub p999_us: f64,
    /// Maximum, µs.
    pub max_us: f64,
}

impl Timing {
    /// From a whole-run histogram (bounded memory for any run length).
    pub fn from_histogram(h: &crate::stats::Histogram) -> Self {
        let us = |ns: u64| ns as f64 / 1e3;
        Self {
            median_us: us(h.quantile(0.5)),
            p99_us: us(h.quantile(0.99)),
            p999_us: us(h.quantile(0.999)),
            max_us: us(h.max()),
        }
    }

    /// From every step's time, ns.
    pub fn from_ns(ns: &[u64]) -> Self {
        if ns.is_empty() {
            return Self::default();
        }
        let mut v = ns.to_vec();
        v.sort_unstable();
        let q =
            |p: f64| v[((p * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)] as f64 / 1e3;
        Self {
            median_us: q(0.5),
            p99_us: q(0.99),
            p999_us: q(0.999),
            max_us: *v.last().expect("non-empty") as f64 / 1e3,
        }
    }
}

/// What a `simulate` run reports.
#[derive(Debug, Clone)]
pub struct SimulateReport {
    /// Steps taken.
    pub steps: u64,
    /// Simulated time, s.
    pub duration_s: f64,
    /// Steps per status.
    pub status_counts: Vec<(Status, u64)>,
    /// Mean Newton iterations per step.
    pub mean_iterations: f64,
    /// The most in one step.
    pub max_iterations: u32,
    /// Steps where the film floor (`contact.min_film_m`) held h0.
    pub film_floor_steps: u64,
    /// Steps that needed the sub-stepping fallback.
    pub substepped_steps: u64,
    /// Compute time per step.
    pub timing: Timing,
    /// Period of the velocity input, when periodic.
    pub period_s: Option<f64>,
    /// Metrics of every complete cycle (periodic inputs).
    pub cycles: Vec<LoopMetrics>,
}

/// Count statuses in a stable order.
fn count_statuses(counts: &mut [(Status, u64)], s: Status) {
    if let Some(c) = counts.iter_mut().find(|(k, _)| *k == s) {
        c.1 += 1;
    }
}

fn all_statuses() -> Vec<(Status, u64)> {
    [
        Status::Converged,
        Status::MaxIterations,
        Status::NonFinite,
        Status::NonFiniteInput,
    ]
    .into_iter()
    .map(|s| (s, 0))
    .collect()
}

/// Check a velocity and a load signal against the envelope the node
/// accepts (`node.max_abs_velocity_m_s`, `node.min_load_n`…`node.max_load_n`):
/// a signal outside it is a user error, named before anything runs.
pub fn check_signals(
    config: &Config,
    velocity: &Signal,
    load: &Signal,
) -> Result<(), SimulationError> {
    let limits = crate::config::InputLimits::of(config);
    let v = velocity.max_abs();
    limits.check_velocity(v).map_err(|e| {
        arg_err(
            "--velocity",
            velocity,
            format!("reaches |v| = {}: {e}", Num(v)),
        )
    })?;
    // A sine at or above the steps' Nyquist frequency is sampled as a
    // slower motion (at exactly it, as v = 0 at every step).
    let nyquist = 0.5 / config.solver.dt_s;
    for (arg, s) in [("--velocity", velocity), ("--load", load)] {
        if let Some(f) = s.period().map(|p| 1.0 / p).filter(|&f| f >= nyquist) {
            return Err(arg_err(
                arg,
                s,
                format!(
                    "oscillates at {} Hz, at or above the Nyquist frequency 1/(2 solver.dt_s) = {} Hz of the steps, which would sample it as a slower motion (aliasing): lower the frequency or shorten solver.dt_s",
                    Num(f),
                    Num(nyquist)
                ),
            ));
        }
    }
    let (fmin, fmax) = load.range();
    for f in [fmin, fmax] {
        limits.check_load(f).map_err(|e| {
            arg_err(
                "--load",
                load,
                format!("spans [{}, {}] N: {e}", Num(fmin), Num(fmax)),
            )
        })?;
    }
    Ok(())
}

/// The number of steps of a run of `duration_s`, checked: in (0, 1e7] s
/// and at least one step of `solver.dt_s`.
pub fn check_duration(config: &Config, duration_s: f64) -> Result<u64, SimulationError> {
    if !(duration_s.is_finite() && duration_s > 0.0 && duration_s <= 1e7) {
        return Err(arg_err(
            "--duration",
            duration_s,
            "must be a number of seconds in (0, 1e7]",
        ));
    }
    let dt = config.solver.dt_s;
    let steps = (duration_s / dt).round();
    if steps < 1.0 {
        return Err(arg_err(
            "--duration",
            duration_s,
            format!("is shorter than one step ({dt} s)"),
        ));
    }
    Ok(steps as u64)
}

/// The steady state at the start of a run (one solve): what a run's
/// first row looks like, e.g. to estimate the size of its output.
pub fn sample_estimate(
    config: &Config,
    velocity: &Signal,
    load: &Signal,
) -> Result<Estimate, SimulationError> {
    let mut solver = Solver::new(&config.model(), &config.solver_settings())?;
    Ok(solver.initialize_steady(velocity.at(0.0), load.at(0.0)))
}

/// The inputs of a transient run: velocity (m/s), load (N) and lubricant
/// temperature (°C; None: the reference temperature) against time.
#[derive(Debug, Clone)]
pub struct SimulationInputs<'a> {
    /// Velocity, m/s.
    pub velocity: &'a Signal,
    /// Normal load, N.
    pub load: &'a Signal,
    /// Temperature, °C.
    pub temperature: Option<&'a Signal>,
}

/// Check a temperature signal against the configuration's viscosity law
/// ([`crate::config::ViscosityLaw::check_span`], the rule every entry point uses).
pub fn check_temperature(config: &Config, t: &Signal) -> Result<(), SimulationError> {
    let (lo, hi) = t.range();
    crate::config::ViscosityLaw::of(config)
        .check_span(lo, hi)
        .map_err(|e| {
            arg_err(
                "--temperature",
                t,
                format!("spans [{}, {}] °C: {e}", Num(lo), Num(hi)),
            )
        })
}

/// Run the transient model over `duration_s` and stream every estimate to
/// `on_step` (with the solver's wall time for the step, ns, and the
/// temperature, °C). Memory stays bounded for any duration: timings go to a
/// histogram and loop metrics are computed cycle by cycle.
pub fn simulate(
    config: &Config,
    velocity: &Signal,
    load: &Signal,
    duration_s: f64,
    on_step: impl FnMut(&Estimate, u64) -> Result<(), SimulationError>,
) -> Result<SimulateReport, SimulationError> {
    let mut on_step = on_step;
    simulate_inputs(
        config,
        &SimulationInputs {
            velocity,
            load,
            temperature: None,
        },
        duration_s,
        |e, ns, _| on_step(e, ns),
    )
}

/// [`simulate`] with a temperature input: with `lubricant.viscosity_model:
/// vogel` the viscosity follows it every step (no allocation).
pub fn simulate_inputs(
    config: &Config,
    inputs: &SimulationInputs<'_>,
    duration_s: f64,
    mut on_step: impl FnMut(&Estimate, u64, f64) -> Result<(), SimulationError>,
) -> Result<SimulateReport, SimulationError> {
    let (velocity, load) = (inputs.velocity, inputs.load);
    let steps = check_duration(config, duration_s)?;
    check_signals(config, velocity, load)?;
    if let Some(t) = inputs.temperature {
        check_temperature(config, t)?;
    }
    let t_ref = config.lubricant.reference_temperature_c;
    let temperature_at = |t: f64| inputs.temperature.map_or(t_ref, |s| s.at(t));
    let law = crate::config::ViscosityLaw::of(config);
    let follows = inputs.temperature.is_some() && law.follows_temperature();
    // Checked over the signal's whole range above: every value passes.
    let viscosity_at = |t_c: f64| law.viscosity_at(t_c).unwrap_or(law.mu_ref);
    let settings = config.solver_settings();
    let mut solver = Solver::new(&config.model(), &settings)?;
    if follows {
        solver.set_liquid_viscosity(viscosity_at(temperature_at(0.0)));
    }
    solver.initialize_steady(velocity.at(0.0), load.at(0.0));
    let period = velocity.period();
    let mut cycles = period.map(|p| CycleCollector::new(0.0, p, config.contact.mass_kg, 6));
    let mut times = crate::stats::Histogram::new();
    let mut counts = all_statuses();
    let (mut it_sum, mut it_max, mut floor, mut sub) = (0u64, 0u32, 0u64, 0u64);
    for k in 1..=steps {
        let t = k as f64 * settings.dt;
        let (v, f) = (velocity.at(t), load.at(t));
        let temperature = temperature_at(t);
        if follows {
            solver.set_liquid_viscosity(viscosity_at(temperature));
        }
        let start = Instant::now();
        let e = solver.step(v, f);
        let ns = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
        times.record(ns);
        count_statuses(&mut counts, e.status);
        it_sum += e.diagnostics.iterations as u64;
        it_max = it_max.max(e.diagnostics.iterations);
        floor += e.diagnostics.film_floor_active as u64;
        sub += (e.diagnostics.substeps > 0) as u64;
        if let Some(c) = cycles.as_mut() {
            c.push(LoopSample::from(&e));
        }
        on_step(&e, ns, temperature)?;
    }
    Ok(SimulateReport {
        steps,
        duration_s: steps as f64 * settings.dt,
        status_counts: counts,
        mean_iterations: it_sum as f64 / steps as f64,
        max_iterations: it_max,
        film_floor_steps: floor,
        substepped_steps: sub,
        timing: Timing::from_histogram(&times),
        period_s: period,
        cycles: cycles.map_or_else(Vec::new, CycleCollector::finish),
    })
}

impl std::fmt::Display for SimulateReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(
            f,
            "steps            {} ({} s simulated)",
            self.steps, self.duration_s
        )?;
        let statuses: Vec<String> = self
            .status_counts
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|(s, n)| format!("{} {n}", s.as_str()))
            .collect();
        writeln!(f, "status           {}", statuses.join(", "))?;
        writeln!(
            f,
            "iterations       mean {:.2}, max {}",
            self.mean_iterations, self.max_iterations
        )?;
        writeln!(
            f,
            "solver time/step median {:.1} µs, p99 {:.1} µs, max {:.1} µs",
            self.timing.median_us, self.timing.p99_us, self.timing.max_us
        )?;
        if self.substepped_steps > 0 {
            writeln!(
                f,
                "fallback         {} steps needed sub-stepping (Newton failed on the full step)",
                self.substepped_steps
            )?;
        }
        if self.film_floor_steps > 0 {
            writeln!(
                f,
                "film floor       active in {} steps (contact.min_film_m)",
                self.film_floor_steps
            )?;
        }
        match (self.period_s, self.cycles.last()) {
            (Some(p), Some(m)) => {
                writeln!(
                    f,
                    "last cycle       #{} of {} (period {p} s){}",
                    m.cycle + 1,
                    self.cycles.len(),
                    if self.cycles.len() < 3 {
                        " — fewer than 3 cycles: the loop may not be periodic yet"
                    } else {
                        ""
                    }
                )?;
                write_cycle(f, m)?;
            }
            (Some(p), None) => writeln!(f, "no complete cycle of {p} s in the run")?,
            _ => {}
        }
        Ok(())
    }
}

/// The metrics of one cycle, one line each.
fn write_cycle(
    f: &mut std::fmt::Formatter<'_>,
    m: &crate::analysis::LoopMetrics,
) -> std::fmt::Result {
    writeln!(
        f,
        "  friction loop area   {:.4} N·m/s",
        m.friction_loop_area
    )?;
    writeln!(f, "  COF loop area        {:.5} m/s", m.cof_loop_area)?;
    writeln!(
        f,
        "  peak COF             {:.4} at v = {:+.3} m/s",
        m.peak_cof, m.peak_cof_velocity
    )?;
    writeln!(f, "  mean COF             {:.4}", m.mean_cof)?;
    if let (Some(a), Some(d)) = (m.cof_v0_accelerating, m.cof_v0_decelerating) {
        writeln!(
            f,
            "  COF at v = 0         accelerating {a:.4}, decelerating {d:.4}"
        )?;
    }
    writeln!(
        f,
        "  h0 range             {:.3} … {:.3} µm",
        m.h0_min * 1e6,
        m.h0_max * 1e6
    )?;
    writeln!(
        f,
        "  asperity load share  {:.1} % (mean)",
        100.0 * m.mean_asperity_share
    )?;
    writeln!(
        f,
        "  inertia share M      {:.2e} % (raw max), {:.2e} % (smooth)",
        100.0 * m.inertia_share,
        100.0 * m.inertia_share_smooth
    )?;
    Ok(())
}
