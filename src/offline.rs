//! Offline runs: `simulate`, `stribeck` and `profile`, writing CSV.
//!
//! Output files are written to a temporary sibling and renamed into place
//! when complete: an existing file is never half-overwritten, and an
//! unwritable destination is reported before any computation.

use crate::analysis::{cycle_metrics, LoopMetrics, LoopSample};
use crate::config::{Config, ConfigError};
use crate::physics::{Estimate, SetupError, Solver, Status};
use crate::signal::{Signal, SignalError};
use crate::text::Num;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Errors of the offline layer.
#[derive(Debug, thiserror::Error)]
pub enum OfflineError {
    #[error(transparent)]
    Config(#[from] ConfigError),
    #[error(transparent)]
    Setup(#[from] SetupError),
    #[error(transparent)]
    Signal(#[from] SignalError),
    #[error("cannot write {}", path.display())]
    Output {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("invalid argument `{name}` = {value}: {message}")]
    Argument {
        name: &'static str,
        value: String,
        message: String,
    },
}

fn arg_err(name: &'static str, value: impl ToString, message: impl Into<String>) -> OfflineError {
    OfflineError::Argument {
        name,
        value: value.to_string(),
        message: message.into(),
    }
}

/// A file written atomically: rows go to `<name>.tmp-<pid>` in the same
/// directory, renamed over `path` by [`AtomicFile::commit`]; dropped
/// uncommitted, the temporary file is removed.
pub struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    out: Option<BufWriter<std::fs::File>>,
}

impl AtomicFile {
    pub fn create(path: &Path) -> Result<Self, OfflineError> {
        let io = |source| OfflineError::Output {
            path: path.to_path_buf(),
            source,
        };
        if path.is_dir() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "the output path is a directory",
            )));
        }
        let name = path.file_name().ok_or_else(|| {
            io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "no file name",
            ))
        })?;
        let mut tmp_name = name.to_os_string();
        tmp_name.push(format!(".tmp-{}", std::process::id()));
        let tmp = path.with_file_name(tmp_name);
        let file = std::fs::File::create(&tmp).map_err(io)?;
        Ok(Self {
            path: path.to_path_buf(),
            tmp,
            out: Some(BufWriter::new(file)),
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    pub fn writer(&mut self) -> &mut BufWriter<std::fs::File> {
        self.out.as_mut().expect("not committed")
    }

    /// Write a line, mapping the error to the destination path.
    pub fn line(&mut self, args: std::fmt::Arguments<'_>) -> Result<(), OfflineError> {
        let path = self.path.clone();
        writeln!(self.writer(), "{args}").map_err(|source| OfflineError::Output { path, source })
    }

    pub fn commit(mut self) -> Result<PathBuf, OfflineError> {
        let io = |source| OfflineError::Output {
            path: self.path.clone(),
            source,
        };
        let out = self.out.take().expect("commit once");
        let file = out.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        std::fs::rename(&self.tmp, &self.path).map_err(io)?;
        Ok(self.path.clone())
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Columns of `simulate` (the first eleven are a stable interface).
pub const SIMULATE_COLUMNS: &str = "t_s,velocity_m_s,load_n,h0_m,h_min_m,f_hyd_n,f_asp_n,friction_n,cof,iterations,status,viscous_n,asperity_load_share,inertia_n,regime,residual,load_residual,max_pressure_pa,cavitated_fraction,contact_area_ratio,substeps";

/// One `simulate` row (re-reading the CSV gives the same bits).
pub fn simulate_row(e: &Estimate) -> String {
    simulate_row_with_status(e, e.status.as_str())
}

/// A `simulate` row with the status column given (replay reports the
/// node's status codes, which include command flags).
pub fn simulate_row_with_status(e: &Estimate, status: &str) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
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
    )
}

/// Distribution of per-step solver times.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timing {
    pub median_us: f64,
    pub p99_us: f64,
    pub p999_us: f64,
    pub max_us: f64,
}

impl Timing {
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
    pub steps: usize,
    pub duration_s: f64,
    pub status_counts: Vec<(Status, usize)>,
    pub mean_iterations: f64,
    pub max_iterations: u32,
    pub film_floor_steps: usize,
    /// Steps that needed the sub-stepping fallback.
    pub substepped_steps: usize,
    pub timing: Timing,
    /// Period of the velocity input, when periodic.
    pub period_s: Option<f64>,
    /// Metrics of every complete cycle (periodic inputs).
    pub cycles: Vec<LoopMetrics>,
}

/// Count statuses in a stable order.
fn count_statuses(counts: &mut [(Status, usize)], s: Status) {
    if let Some(c) = counts.iter_mut().find(|(k, _)| *k == s) {
        c.1 += 1;
    }
}

fn all_statuses() -> Vec<(Status, usize)> {
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

/// Run the transient model over `duration_s` and stream every estimate to
/// `on_step` (with the solver's wall time for the step, ns).
pub fn simulate(
    config: &Config,
    velocity: &Signal,
    load: &Signal,
    duration_s: f64,
    mut on_step: impl FnMut(&Estimate, u64) -> Result<(), OfflineError>,
) -> Result<SimulateReport, OfflineError> {
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(arg_err(
            "--duration",
            duration_s,
            "must be a positive number of seconds",
        ));
    }
    let settings = config.solver_settings();
    let steps = (duration_s / settings.dt).round() as usize;
    if steps == 0 {
        return Err(arg_err(
            "--duration",
            duration_s,
            format!("is shorter than one step ({} s)", settings.dt),
        ));
    }
    let mut solver = Solver::new(&config.model(), &settings)?;
    solver.initialize_steady(velocity.at(0.0), load.at(0.0));
    let period = velocity.period();
    let mut samples = Vec::new();
    let mut times = Vec::with_capacity(steps);
    let mut counts = all_statuses();
    let (mut it_sum, mut it_max, mut floor, mut sub) = (0u64, 0u32, 0usize, 0usize);
    for k in 1..=steps {
        let t = k as f64 * settings.dt;
        let (v, f) = (velocity.at(t), load.at(t));
        let start = Instant::now();
        let e = solver.step(v, f);
        let ns = start.elapsed().as_nanos() as u64;
        times.push(ns);
        count_statuses(&mut counts, e.status);
        it_sum += e.diagnostics.iterations as u64;
        it_max = it_max.max(e.diagnostics.iterations);
        floor += e.diagnostics.film_floor_active as usize;
        sub += (e.diagnostics.substeps > 0) as usize;
        if period.is_some() {
            samples.push(LoopSample::from(&e));
        }
        on_step(&e, ns)?;
    }
    let cycles = match period {
        Some(p) => cycle_metrics(&samples, 0.0, p, config.contact.mass_kg, 6),
        None => Vec::new(),
    };
    Ok(SimulateReport {
        steps,
        duration_s: steps as f64 * settings.dt,
        status_counts: counts,
        mean_iterations: it_sum as f64 / steps as f64,
        max_iterations: it_max,
        film_floor_steps: floor,
        substepped_steps: sub,
        timing: Timing::from_ns(&times),
        period_s: period,
        cycles,
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
            }
            (Some(p), None) => writeln!(f, "no complete cycle of {p} s in the run")?,
            _ => {}
        }
        Ok(())
    }
}

/// Velocities of a Stribeck sweep.
pub fn sweep(v_min: f64, v_max: f64, points: usize, log: bool) -> Result<Vec<f64>, OfflineError> {
    if !(v_min.is_finite() && v_max.is_finite()) || v_min >= v_max {
        return Err(arg_err(
            "--v-min/--v-max",
            format!("{v_min}/{v_max}"),
            "need finite v-min < v-max",
        ));
    }
    if points < 2 {
        return Err(arg_err("--points", points, "need at least 2 points"));
    }
    if log {
        if !(v_min > 0.0 || v_max < 0.0) {
            return Err(arg_err(
                "--log",
                format!("[{v_min}, {v_max}]"),
                "a logarithmic sweep needs a range that does not contain 0",
            ));
        }
        let (a, b) = (v_min.abs().ln(), v_max.abs().ln());
        let s = v_min.signum();
        Ok((0..points)
            .map(|k| s * (a + (b - a) * k as f64 / (points - 1) as f64).exp())
            .collect())
    } else {
        Ok((0..points)
            .map(|k| v_min + (v_max - v_min) * k as f64 / (points - 1) as f64)
            .collect())
    }
}

/// Steady states at the given velocities (any order), returned in the
/// input order. Each sign is swept outwards from zero so that every solve
/// is warm-started from its neighbour.
pub fn stribeck(
    config: &Config,
    velocities: &[f64],
    load: f64,
) -> Result<Vec<Estimate>, OfflineError> {
    let mut out: Vec<Option<Estimate>> = vec![None; velocities.len()];
    let mut order: Vec<usize> = (0..velocities.len()).collect();
    order.sort_by(|&a, &b| velocities[a].abs().total_cmp(&velocities[b].abs()));
    for positive in [true, false] {
        let mut solver = Solver::new(&config.model(), &config.solver_settings())?;
        for &i in &order {
            let v = velocities[i];
            if (v >= 0.0) == positive {
                out[i] = Some(solver.steady(v, load));
            }
        }
    }
    Ok(out
        .into_iter()
        .map(|e| e.expect("every point solved"))
        .collect())
}

/// Columns of `stribeck`.
pub const STRIBECK_COLUMNS: &str = "velocity_m_s,h0_m,h_min_m,f_hyd_n,f_asp_n,friction_n,cof,viscous_n,asperity_load_share,regime,status,iterations";

pub fn stribeck_row(e: &Estimate) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{}",
        Num(e.velocity),
        Num(e.h0),
        Num(e.h_min),
        Num(e.hydrodynamic_force),
        Num(e.asperity_force),
        Num(e.friction_force),
        Num(e.cof),
        Num(e.viscous_force),
        Num(e.asperity_load_share),
        e.regime.as_str(),
        e.status.as_str(),
        e.diagnostics.iterations
    )
}

/// How h0 is fixed in a `profile` run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gap {
    H0(f64),
    Load(f64),
}

/// Columns of `profile`.
pub const PROFILE_COLUMNS: &str = "x_m,h_m,p_pa,vapour_fraction,p_asp_pa,shear_pa";

/// Steady field at one velocity; returns the estimate and the field rows.
pub fn profile(
    config: &Config,
    velocity: f64,
    gap: Gap,
) -> Result<(Estimate, Vec<crate::physics::FieldPoint>), OfflineError> {
    if !velocity.is_finite() {
        return Err(arg_err("--velocity", velocity, "must be finite"));
    }
    let mut solver = Solver::new(&config.model(), &config.solver_settings())?;
    let e = match gap {
        Gap::H0(h) => {
            if !(h.is_finite() && h > 0.0 && h < 1e-3) {
                return Err(arg_err("--h0", h, "must be a gap in metres, in (0, 1e-3)"));
            }
            solver.steady_prescribed_gap(velocity, h, config.contact.load_n)
        }
        Gap::Load(f) => {
            if !(f.is_finite() && f > 0.0) {
                return Err(arg_err("--load", f, "must be a positive force in newtons"));
            }
            solver.steady(velocity, f)
        }
    };
    Ok((e, solver.field().collect()))
}

pub fn profile_row(p: &crate::physics::FieldPoint) -> String {
    format!(
        "{},{},{},{},{},{}",
        Num(p.x),
        Num(p.h),
        Num(p.p),
        Num(p.vapour_fraction),
        Num(p.asperity_pressure),
        Num(p.shear)
    )
}
