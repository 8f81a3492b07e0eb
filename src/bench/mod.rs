//! Benchmarks (release builds; medians and ratios measured side by side in
//! one run). `mod.rs`: `friction-node bench`, per-step cost of the paper's reciprocating case
//! (V1 = 1 m/s, f = 1 Hz, F = 20 762 N, μ = 0.0564 Pa·s), Newton against the
//! reference algorithm, and allocations per step. A benchmark, not a test:
//! release build, medians and ratios measured side by side in one run.
//!
//! | file | job |
//! |---|---|
//! | `mod.rs` | `bench`: one model step, Newton against the reference, allocations per step |
//! | `latency.rs` | `bench-latency`: command → estimate through a transport, beside an empty timer loop |
//! | `recorder.rs` | `bench-recorder`: the recorder over simulated days |
//! | `accuracy.rs` | `bench-accuracy`: the accuracy guide, answers against N and Δt |
//! | `cases.rs` | `bench-cases`: the accuracy guide over a family of transient cases, passes per grid and flux |
//! | `fit.rs` | `bench-fit`: calibration targets on synthetic data (recovery, drivetrain, pre-sliding, transfer) |
//! | `reference.rs` | the accuracy guides' reference checked finer than what it judges; settings named twice measured once |

use crate::config::Config;
use crate::offline::{SimulationError, Timing};
use crate::physics::{Isa, Method, Solver, StepBreakdown};
use std::time::Instant;

/// Results for one grid size.
#[derive(Debug, Clone)]
pub struct BenchCase {
    /// Grid cells.
    pub cells: usize,
    /// Steps timed.
    pub steps: usize,
    /// Newton's time per step.
    pub newton: Timing,
    /// Mean Newton iterations per step.
    pub newton_mean_iterations: f64,
    /// The most in one step.
    pub newton_max_iterations: u32,
    /// Newton at the reference's tolerance, on the sampled states.
    pub newton_equal_tol: Timing,
    /// The reference algorithm's time per step, on the sampled states.
    pub reference: Timing,
    /// States the reference was timed on.
    pub reference_samples: usize,
    /// Mean Picard iterations of a reference step.
    pub reference_mean_picard: f64,
    /// Allocations per Newton step (None without a counting allocator).
    pub allocations_per_step: Option<f64>,
    /// The instruction-set version of the step that ran.
    pub isa: Isa,
    /// The same steps with the baseline version, when another one ran
    /// (timed right after, same states: the vectorisation's gain).
    pub baseline: Option<Timing>,
    /// Each part of an iteration timed alone: medians over states spread
    /// through one cycle (`--breakdown`).
    pub breakdown: Option<StepBreakdown>,
}

impl BenchCase {
    /// Reference median over Newton median, same states and tolerance.
    pub fn speedup(&self) -> f64 {
        self.reference.median_us / self.newton_equal_tol.median_us
    }
}

/// Options of a benchmark run.
pub struct BenchOptions<'a> {
    /// Grid sizes.
    pub cells: Vec<usize>,
    /// Timed cycles per grid.
    pub cycles: usize,
    /// States at which the reference is timed.
    pub reference_steps: usize,
    /// Reads a global allocation counter, when the binary installs one.
    pub allocation_counter: Option<&'a dyn Fn() -> u64>,
    /// Also time each part of an iteration alone ([`StepBreakdown`]).
    pub breakdown: bool,
    /// Progress lines.
    pub progress: &'a dyn Fn(&str),
}

/// The bench's velocity, m/s: a 1 Hz sine of amplitude 1 m/s.
fn velocity(t: f64) -> f64 {
    (2.0 * std::f64::consts::PI * t).sin()
}

/// Elapsed time since `start`, ns.
fn elapsed_ns(start: Instant) -> u64 {
    u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// Time the paper's reciprocating case on every grid of `opts`.
pub fn run(config: &Config, opts: &BenchOptions<'_>) -> Result<Vec<BenchCase>, SimulationError> {
    let load = config.contact.load_n;
    let mut out = Vec::new();
    for &cells in &opts.cells {
        let mut cfg = config.clone();
        cfg.solver.cells = cells;
        cfg.validate()?;
        let st = cfg.solver_settings();
        let per_cycle = (1.0 / st.dt).round() as usize;
        let mut s = Solver::new(&cfg.model(), &st)?;
        s.initialize_steady(0.0, load);
        (opts.progress)(&format!("N = {cells}: warm-up cycle"));
        for k in 1..=per_cycle {
            s.step(velocity(k as f64 * st.dt), load);
        }
        let steps = opts.cycles * per_cycle;
        (opts.progress)(&format!("N = {cells}: {steps} timed Newton steps"));
        let timed = timed_steps(&mut s, load, per_cycle, steps, opts);
        let isa = s.isa();
        let baseline = (isa != Isa::Baseline).then(|| {
            (opts.progress)(&format!(
                "N = {cells}: the same steps, baseline instruction set"
            ));
            baseline_steps(&cfg, load, per_cycle, steps)
        });
        let side = side_by_side(&cfg, load, &timed.samples, opts);
        out.push(BenchCase {
            cells,
            steps,
            newton: Timing::from_ns(&timed.times),
            newton_mean_iterations: timed.iterations_sum as f64 / steps as f64,
            newton_max_iterations: timed.iterations_max,
            newton_equal_tol: Timing::from_ns(&side.newton),
            reference: Timing::from_ns(&side.reference),
            reference_samples: side.reference.len(),
            reference_mean_picard: side.picard as f64 / side.reference.len().max(1) as f64,
            allocations_per_step: opts
                .allocation_counter
                .map(|_| timed.allocations as f64 / steps as f64),
            isa,
            baseline,
            breakdown: opts.breakdown.then(|| {
                (opts.progress)(&format!("N = {cells}: the parts of an iteration"));
                breakdown(&cfg, load, &velocity)
            }),
        });
    }
    Ok(out)
}

/// The timed Newton steps of one grid.
struct TimedSteps {
    /// Each step's time, ns.
    times: Vec<u64>,
    iterations_sum: u64,
    iterations_max: u32,
    /// Allocations over every step (0 without a counter).
    allocations: u64,
    /// States (with the velocity of their next step) for the side-by-side
    /// comparison with the reference solver.
    samples: Vec<(Solver, f64)>,
}

/// `steps` timed steps of `s` after `per_cycle` warm-up steps, sampling
/// states for the reference comparison evenly.
fn timed_steps(
    s: &mut Solver,
    load: f64,
    per_cycle: usize,
    steps: usize,
    opts: &BenchOptions<'_>,
) -> TimedSteps {
    let dt = s.settings().dt;
    let sample_every = (steps / opts.reference_steps.max(1)).max(1);
    let mut r = TimedSteps {
        times: Vec::with_capacity(steps),
        iterations_sum: 0,
        iterations_max: 0,
        allocations: 0,
        samples: Vec::new(),
    };
    for j in 0..steps {
        let t = (per_cycle + 1 + j) as f64 * dt;
        if j % sample_every == sample_every / 2 && r.samples.len() < opts.reference_steps {
            r.samples.push((s.clone(), velocity(t)));
        }
        let a0 = opts.allocation_counter.map(|c| c());
        let start = Instant::now();
        let e = s.step(velocity(t), load);
        r.times.push(elapsed_ns(start));
        if let (Some(c), Some(a0)) = (opts.allocation_counter, a0) {
            r.allocations += c() - a0;
        }
        r.iterations_sum += u64::from(e.diagnostics.iterations);
        r.iterations_max = r.iterations_max.max(e.diagnostics.iterations);
    }
    r
}

/// The same steps on the baseline instruction set.
fn baseline_steps(cfg: &Config, load: f64, per_cycle: usize, steps: usize) -> Timing {
    let st = cfg.solver_settings();
    let mut b = Solver::new(&cfg.model(), &st).expect("validated by the caller");
    b.set_isa(Isa::Baseline);
    b.initialize_steady(0.0, load);
    let mut times = Vec::with_capacity(steps);
    for k in 1..=per_cycle + steps {
        let start = Instant::now();
        b.step(velocity(k as f64 * st.dt), load);
        if k > per_cycle {
            times.push(elapsed_ns(start));
        }
    }
    Timing::from_ns(&times)
}

/// Newton and the reference solver side by side.
struct SideBySide {
    newton: Vec<u64>,
    reference: Vec<u64>,
    /// Picard iterations of the reference steps.
    picard: u64,
}

/// Newton and the reference solver from identical states at equal
/// tolerance.
fn side_by_side(
    cfg: &Config,
    load: f64,
    samples: &[(Solver, f64)],
    opts: &BenchOptions<'_>,
) -> SideBySide {
    let tol = cfg.solver.reference.motion_tolerance;
    let mut r = SideBySide {
        newton: Vec::new(),
        reference: Vec::new(),
        picard: 0,
    };
    for (i, (state, v)) in samples.iter().enumerate() {
        (opts.progress)(&format!(
            "N = {}: reference step {}/{}",
            cfg.solver.cells,
            i + 1,
            samples.len()
        ));
        let mut a = state.clone();
        a.set_method(Method::Newton, tol);
        let start = Instant::now();
        a.step(*v, load);
        r.newton.push(elapsed_ns(start));
        let mut b = state.clone();
        b.set_method(Method::Reference, tol);
        let start = Instant::now();
        let e = b.step(*v, load);
        r.reference.push(elapsed_ns(start));
        r.picard += u64::from(e.diagnostics.inner_iterations);
    }
    r
}

/// States every 25 steps of a cycle after a warm-up cycle, each part timed
/// 200 times alone; the median per part over the states.
fn breakdown(cfg: &Config, load: f64, velocity: &dyn Fn(f64) -> f64) -> StepBreakdown {
    let st = cfg.solver_settings();
    let per_cycle = (1.0 / st.dt).round() as usize;
    let mut s = Solver::new(&cfg.model(), &st).expect("validated by the caller");
    s.initialize_steady(0.0, load);
    let origin = Instant::now();
    let mut now = || origin.elapsed().as_nanos() as u64;
    let mut parts = Vec::new();
    for k in 1..=2 * per_cycle {
        let v = velocity(k as f64 * st.dt);
        if k > per_cycle && k % 25 == 0 {
            parts.push(s.breakdown(v, load, 200, &mut now));
        }
        s.step(v, load);
    }
    let median = |f: fn(&StepBreakdown) -> f64| {
        let mut x: Vec<f64> = parts.iter().map(f).collect();
        x.sort_by(f64::total_cmp);
        x.get(x.len() / 2).copied().unwrap_or(f64::NAN)
    };
    StepBreakdown {
        eos_ns: median(|b| b.eos_ns),
        faces_ns: median(|b| b.faces_ns),
        rows_ns: median(|b| b.rows_ns),
        solve_ns: median(|b| b.solve_ns),
        old_factor_solve_ns: median(|b| b.old_factor_solve_ns),
        finish_ns: median(|b| b.finish_ns),
    }
}

/// The breakdown of each grid as a table (ns per call; empty without one).
pub fn breakdown_table(cases: &[BenchCase]) -> String {
    let mut s = String::new();
    for c in cases {
        let Some(b) = c.breakdown else { continue };
        if s.is_empty() {
            s.push_str("     N | ns per call (median over a cycle's states): EOS  faces  rows+G  factor+solve  finish | sum | old-factor solve (line search)\n");
        }
        let sum = b.one_iteration_ns();
        let pct = |x: f64| 100.0 * x / sum;
        s.push_str(&format!(
            "{:>6} | {:>6.0} ({:>2.0} %) {:>5.0} ({:>2.0} %) {:>5.0} ({:>2.0} %) {:>6.0} ({:>2.0} %) {:>5.0} ({:>2.0} %) | {:>5.0} | {:>5.0}\n",
            c.cells,
            b.eos_ns,
            pct(b.eos_ns),
            b.faces_ns,
            pct(b.faces_ns),
            b.rows_ns,
            pct(b.rows_ns),
            b.solve_ns,
            pct(b.solve_ns),
            b.finish_ns,
            pct(b.finish_ns),
            sum,
            b.old_factor_solve_ns,
        ));
    }
    s
}

/// Human-readable table.
pub fn table(cases: &[BenchCase]) -> String {
    let mut s = String::new();
    s.push_str("     N | Newton µs/step: median    p99  p99.9    max | iter mean/max | allocs/step | µs/step/cell | ref. µs/step (median) | Newton @tol µs | speed-up | ISA (baseline median µs)\n");
    for c in cases {
        s.push_str(&format!(
            "{:>6} | {:>22.1} {:>6.1} {:>6.1} {:>6.1} | {:>8.2}/{:<4} | {:>11} | {:>12.4} | {:>21.0} | {:>14.1} | {:>7.0}× | {:?}{}\n",
            c.cells,
            c.newton.median_us,
            c.newton.p99_us,
            c.newton.p999_us,
            c.newton.max_us,
            c.newton_mean_iterations,
            c.newton_max_iterations,
            c.allocations_per_step.map_or("n/a".to_string(), |a| format!("{a}")),
            c.newton.median_us / c.cells as f64,
            c.reference.median_us,
            c.newton_equal_tol.median_us,
            c.speedup(),
            c.isa,
            c.baseline
                .as_ref()
                .map_or(String::new(), |b| format!(" ({:.1})", b.median_us)),
        ));
    }
    s
}

/// CSV of the results.
pub fn csv(cases: &[BenchCase]) -> String {
    let mut s = String::from("cells,steps,newton_median_us,newton_p99_us,newton_p999_us,newton_max_us,newton_mean_iterations,newton_max_iterations,allocations_per_step,reference_median_us,reference_samples,reference_mean_picard_iterations,newton_equal_tol_median_us,speedup,isa,baseline_isa_median_us\n");
    for c in cases {
        s.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:?},{}\n",
            c.cells,
            c.steps,
            c.newton.median_us,
            c.newton.p99_us,
            c.newton.p999_us,
            c.newton.max_us,
            c.newton_mean_iterations,
            c.newton_max_iterations,
            c.allocations_per_step
                .map_or(String::new(), |a| a.to_string()),
            c.reference.median_us,
            c.reference_samples,
            c.reference_mean_picard,
            c.newton_equal_tol.median_us,
            c.speedup(),
            c.isa,
            c.baseline
                .as_ref()
                .map_or(String::new(), |b| b.median_us.to_string()),
        ));
    }
    s
}

pub mod accuracy;
pub mod cases;
pub mod fit;
mod latency;
#[cfg(feature = "mcap")]
pub mod recorder;
pub mod reference;

pub use latency::{latency, LatencyReport};
