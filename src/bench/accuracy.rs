//! `friction-node bench-accuracy`: how the answers of the paper's
//! reciprocating case (v = V1 sin 2πft, V1 = 1 m/s, f = 1 Hz, the shipped
//! load and lubricant) converge with the grid (`solver.cells`) and the step
//! (`solver.dt_s`), beside the cost of a step, so that a user can pick the
//! cheapest setting for the accuracy they need.
//!
//! Each setting runs `cycles` cycles from the steady state at rest; the
//! metrics are those of the last cycle ([`crate::analysis`]): the friction
//! loop area ∮ F dv (N·m/s), the mean COF, the COF where the velocity
//! crosses zero while accelerating, and the minimum separation h0 (m). The
//! error of each is relative to a reference run at the finest grid and step
//! of the sweep (N = 2048, Δt = 0.125 ms by default).

use crate::config::Config;
use crate::offline::{simulate, SimulationError};
use crate::signal::Signal;

/// One setting's answers and cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccuracyRow {
    /// Grid cells.
    pub cells: usize,
    /// Time step, s.
    pub dt_s: f64,
    /// Area of the F_f–v loop of the last cycle, N·m/s.
    pub loop_area: f64,
    /// Mean COF of the last cycle.
    pub mean_cof: f64,
    /// COF at v = 0 (accelerating).
    pub cof_v0: f64,
    /// Smallest h0 of the last cycle, m.
    pub h0_min_m: f64,
    /// Median cost of a step, µs.
    pub step_us: f64,
}

impl AccuracyRow {
    /// Relative errors against `reference`: loop area, mean COF, COF at
    /// v = 0, minimum h0.
    pub fn errors(&self, reference: &AccuracyRow) -> [f64; 4] {
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        [
            rel(self.loop_area, reference.loop_area),
            rel(self.mean_cof, reference.mean_cof),
            rel(self.cof_v0, reference.cof_v0),
            rel(self.h0_min_m, reference.h0_min_m),
        ]
    }

    /// The largest of [`AccuracyRow::errors`].
    pub fn worst_error(&self, reference: &AccuracyRow) -> f64 {
        self.errors(reference).into_iter().fold(0.0, f64::max)
    }
}

/// The sweep: grids at the configured step, steps at the configured grid,
/// and the reference.
#[derive(Debug, Clone)]
pub struct AccuracyReport {
    /// The Couette flux of every run, the reference's included.
    pub flux: crate::config::FluxKind,
    /// Grids at the configured step.
    pub grids: Vec<AccuracyRow>,
    /// Steps at the configured grid.
    pub steps: Vec<AccuracyRow>,
    /// The reference run.
    pub reference: AccuracyRow,
}

/// Run one setting.
pub fn run_setting(
    config: &Config,
    cells: usize,
    dt_s: f64,
    cycles: u32,
) -> Result<AccuracyRow, SimulationError> {
    let mut cfg = config.clone();
    cfg.solver.cells = cells;
    cfg.solver.dt_s = dt_s;
    cfg.validate()?;
    let velocity = Signal::parse("sine:0,1,1", "velocity").expect("a valid spec");
    let load =
        Signal::parse(&format!("const:{}", cfg.contact.load_n), "load").expect("a valid spec");
    let r = simulate(&cfg, &velocity, &load, f64::from(cycles), |_, _| Ok(()))?;
    let last = r.cycles.last().ok_or_else(|| SimulationError::Argument {
        name: "--cycles",
        value: cycles.to_string(),
        message: format!("gave no complete cycle at N = {cells}, dt = {dt_s} s"),
    })?;
    Ok(AccuracyRow {
        cells,
        dt_s,
        loop_area: last.friction_loop_area,
        mean_cof: last.mean_cof,
        cof_v0: last.cof_v0_accelerating.unwrap_or(f64::NAN),
        h0_min_m: last.h0_min,
        step_us: r.timing.median_us,
    })
}

/// The whole sweep; `progress` is told what runs.
pub fn run(
    config: &Config,
    grids: &[usize],
    steps: &[f64],
    reference: (usize, f64),
    cycles: u32,
    progress: &dyn Fn(&str),
) -> Result<AccuracyReport, SimulationError> {
    let dt0 = config.solver.dt_s;
    let n0 = config.solver.cells;
    progress(&format!(
        "reference: N = {}, dt = {} s",
        reference.0, reference.1
    ));
    let reference = run_setting(config, reference.0, reference.1, cycles)?;
    let mut out = AccuracyReport {
        flux: config.solver.flux,
        grids: Vec::new(),
        steps: Vec::new(),
        reference,
    };
    for &n in grids {
        progress(&format!("N = {n}, dt = {dt0} s"));
        out.grids.push(run_setting(config, n, dt0, cycles)?);
    }
    for &dt in steps {
        progress(&format!("N = {n0}, dt = {dt} s"));
        out.steps.push(run_setting(config, n0, dt, cycles)?);
    }
    Ok(out)
}

impl std::fmt::Display for AccuracyReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let r = &self.reference;
        writeln!(
            f,
            "solver.flux: {}. Reference N = {}, dt = {} ms: loop area {:.4} N·m/s, mean COF {:.5}, COF at v = 0 {:.5}, min h0 {:.3} µm\n",
            self.flux.name(),
            r.cells,
            r.dt_s * 1e3,
            r.loop_area,
            r.mean_cof,
            r.cof_v0,
            r.h0_min_m * 1e6
        )?;
        writeln!(
            f,
            "| solver.cells | solver.dt_s (ms) | loop area | mean COF | COF at v = 0 | min h0 | worst | step median (µs) |"
        )?;
        writeln!(f, "|---|---|---|---|---|---|---|---|")?;
        let pct = |x: f64| {
            if x < 0.0005 {
                "< 0.05 %".to_string()
            } else {
                format!("{:.1} %", x * 100.0)
            }
        };
        for row in self.grids.iter().chain(&self.steps) {
            let e = row.errors(r);
            writeln!(
                f,
                "| {} | {} | {} | {} | {} | {} | {} | {:.1} |",
                row.cells,
                row.dt_s * 1e3,
                pct(e[0]),
                pct(e[1]),
                pct(e[2]),
                pct(e[3]),
                pct(row.worst_error(r)),
                row.step_us
            )?;
        }
        Ok(())
    }
}
