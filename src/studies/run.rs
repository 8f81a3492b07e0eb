//! Running the studies: steady curves, one case's transient run and its
//! loop metrics, a whole study.

use super::*;

/// Outcome of one case.
#[derive(Debug, Clone)]
pub struct CaseResult {
    /// The case.
    pub case: Case,
    /// Steps run.
    pub steps: usize,
    /// Steps per solver status.
    pub status_counts: Vec<(Status, usize)>,
    /// Steps that needed sub-steps.
    pub substepped_steps: usize,
    /// The most Newton iterations of a step.
    pub max_iterations: u32,
    /// Metrics of the last complete cycle.
    pub metrics: Option<LoopMetrics>,
    /// Estimates of the last complete cycle.
    pub last_cycle: Vec<Estimate>,
    /// Set when the case could not run or did not converge everywhere.
    pub failure: Option<String>,
}

impl CaseResult {
    /// Whether the case failed.
    pub fn failed(&self) -> bool {
        self.failure.is_some()
    }
}

/// Run one case; `progress(n)` is called with the number of steps done since
/// the last call, and returns whether to go on (false: the case ends with
/// the failure "interrupted").
pub fn run_case(case: &Case, progress: &dyn Fn(usize) -> bool) -> CaseResult {
    let mut result = CaseResult {
        case: case.clone(),
        steps: 0,
        status_counts: Vec::new(),
        substepped_steps: 0,
        max_iterations: 0,
        metrics: None,
        last_cycle: Vec::new(),
        failure: None,
    };
    let settings = case.config.solver_settings();
    let mut solver = match Solver::new(&case.config.model(), &settings) {
        Ok(s) => s,
        Err(e) => {
            result.failure = Some(format!("setup: {e}"));
            return result;
        }
    };
    let load = case.load_n();
    let steps = case.steps();
    let per_cycle = (case.motion.period() / settings.dt).round() as usize;
    solver.initialize_steady(case.motion.at(0.0), load);
    let mut samples = Vec::with_capacity(steps);
    let mut all = Vec::with_capacity(per_cycle + 1);
    let mut counts = vec![
        (Status::Converged, 0),
        (Status::MaxIterations, 0),
        (Status::NonFinite, 0),
        (Status::NonFiniteInput, 0),
    ];
    let mut pending = 0;
    for k in 1..=steps {
        let t = k as f64 * settings.dt;
        let e = solver.step(case.motion.at(t), load);
        if let Some(c) = counts.iter_mut().find(|(s, _)| *s == e.status) {
            c.1 += 1;
        }
        result.substepped_steps += (e.diagnostics.substeps > 0) as usize;
        result.max_iterations = result.max_iterations.max(e.diagnostics.iterations);
        samples.push(LoopSample::from(&e));
        if k + per_cycle > steps {
            all.push(e);
        }
        pending += 1;
        if pending == 500 {
            if !progress(pending) {
                result.failure = Some("interrupted".into());
                return result;
            }
            pending = 0;
        }
    }
    progress(pending);
    result.steps = steps;
    let metrics = cycle_metrics(
        &samples,
        0.0,
        case.motion.period(),
        case.config.contact.mass_kg,
        6,
    );
    result.metrics = metrics.last().copied();
    result.last_cycle = all;
    let bad: Vec<String> = counts
        .iter()
        .filter(|(s, n)| *s != Status::Converged && *n > 0)
        .map(|(s, n)| format!("{} {n}", s.as_str()))
        .collect();
    if !bad.is_empty() {
        result.failure = Some(bad.join(", "));
    }
    if result.metrics.is_none() && result.failure.is_none() {
        result.failure = Some("no complete cycle".into());
    }
    result.status_counts = counts;
    result
}

/// Mean deviation of a loop's branches from the steady curve at the same
/// velocity (accelerating: |v| rising; decelerating: |v| falling).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SteadyOffsets {
    /// Mean COF − COF_steady while |v| rises.
    pub cof_accelerating: f64,
    /// Mean COF − COF_steady while |v| falls.
    pub cof_decelerating: f64,
    /// Mean h0 − h0_steady while |v| rises, m.
    pub h0_accelerating: f64,
    /// Mean h0 − h0_steady while |v| falls, m.
    pub h0_decelerating: f64,
    /// Mean of COF − COF_steady(v(t)) over the whole cycle.
    pub cof_mean: f64,
    /// Mean of COF_steady(v(t)) over the cycle.
    pub steady_cof_mean: f64,
}

impl CaseResult {
    /// The last cycle's offsets from `steady` (None without a cycle or a curve).
    pub fn steady_offsets(&self, steady: &SteadyCurve) -> Option<SteadyOffsets> {
        let lc = &self.last_cycle;
        if lc.len() < 3 {
            return None;
        }
        let (mut o, mut na, mut nd, mut n) = (SteadyOffsets::default(), 0, 0, 0);
        for j in 0..lc.len() {
            let e = &lc[j];
            let (Some(c), Some(h)) = (
                steady.interpolate(e.velocity, |s| s.cof),
                steady.interpolate(e.velocity, |s| s.h0),
            ) else {
                continue;
            };
            o.cof_mean += e.cof - c;
            o.steady_cof_mean += c;
            n += 1;
            if j == 0 || j + 1 == lc.len() {
                continue;
            }
            let (before, after) = (lc[j - 1].velocity.abs(), lc[j + 1].velocity.abs());
            if after > before {
                o.cof_accelerating += e.cof - c;
                o.h0_accelerating += e.h0 - h;
                na += 1;
            } else if after < before {
                o.cof_decelerating += e.cof - c;
                o.h0_decelerating += e.h0 - h;
                nd += 1;
            }
        }
        if na == 0 || nd == 0 || n == 0 {
            return None;
        }
        o.cof_accelerating /= na as f64;
        o.h0_accelerating /= na as f64;
        o.cof_decelerating /= nd as f64;
        o.h0_decelerating /= nd as f64;
        o.cof_mean /= n as f64;
        o.steady_cof_mean /= n as f64;
        Some(o)
    }

    /// Largest |COF − other COF| over the last cycle, sample by sample.
    pub fn max_cof_difference(&self, other: &CaseResult) -> f64 {
        self.last_cycle
            .iter()
            .zip(&other.last_cycle)
            .map(|(a, b)| (a.cof - b.cof).abs())
            .fold(0.0, f64::max)
    }
}

/// All results of one study.
#[derive(Debug, Clone)]
pub struct StudyResult {
    /// The study.
    pub study: StudyKind,
    /// Its transient cases.
    pub cases: Vec<CaseResult>,
    /// Its steady curves.
    pub steady: Vec<SteadyCurve>,
}

impl StudyResult {
    /// The steady curve `key`.
    pub fn steady(&self, key: &str) -> Option<&SteadyCurve> {
        self.steady.iter().find(|s| s.key == key)
    }

    /// The case whose id is `id`.
    pub fn case(&self, id: &str) -> Option<&CaseResult> {
        self.cases.iter().find(|c| c.case.id == id)
    }

    /// Metrics of the case `id` (None if missing or failed).
    pub fn metrics(&self, id: &str) -> Option<&LoopMetrics> {
        self.case(id).and_then(|c| c.metrics.as_ref())
    }
}

/// Run a study serially (the `study` command runs cases in parallel).
pub fn run_study(
    study: StudyKind,
    base: &Config,
    opts: &StudyOptions,
) -> Result<StudyResult, crate::offline::SimulationError> {
    let cs = cases(study, base, opts);
    let specs = steady_specs(study, base, &cs, opts);
    let steady = specs
        .iter()
        .map(steady_curve)
        .collect::<Result<Vec<_>, _>>()?;
    let cases = cs.iter().map(|c| run_case(c, &|_| true)).collect();
    Ok(StudyResult {
        study,
        cases,
        steady,
    })
}
