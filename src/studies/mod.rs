//! The paper's parametric studies (MODEL.md §8) as data and computation.
//!
//! A study is a list of [`Case`]s (a resolved configuration and a sinusoidal
//! motion v = V0 + V1 sin 2πft) plus the steady Stribeck curves that are
//! overlaid on its loops. Running a case gives the loop metrics of its last
//! complete cycle ([`CaseResult`]); [`claims`] evaluates the paper's claims
//! on the results. The computation does no I/O; [`report`] writes the CSVs,
//! plots and the claims page for the `study` command.
//!
//! Where MODEL.md's study table is silent this module decides, and says so:
//! the load, viscosity and inertia studies use V1 = 1 m/s (Table A4 lists
//! 0.25 and 1); the unidirectional study runs at 5 762 N (Table A3 says 5 kN,
//! the text gives no load) with V0 extended to 1, 2, 3 m/s so that the loops
//! reach full film; the roughness study runs at V0 = 1 m/s (where MODEL.md
//! says the σ = 2.5 µm fluid-share claim holds) and also at V0 = 0.25 m/s;
//! the Hersey study is two groups of four loops with equal μ·V1/F.

pub mod claims;
pub mod report;

use crate::analysis::{cycle_metrics, LoopMetrics, LoopSample};
use crate::config::Config;
use crate::physics::{Estimate, Solver, Status};

/// The studies of MODEL.md §8.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StudyKind {
    Stribeck,
    AmplitudeFrequency,
    Load,
    Viscosity,
    Inertia,
    Unidirectional,
    Roughness,
    Hersey,
}

impl StudyKind {
    pub const ALL: [StudyKind; 8] = [
        StudyKind::Stribeck,
        StudyKind::AmplitudeFrequency,
        StudyKind::Load,
        StudyKind::Viscosity,
        StudyKind::Inertia,
        StudyKind::Unidirectional,
        StudyKind::Roughness,
        StudyKind::Hersey,
    ];

    pub fn name(self) -> &'static str {
        match self {
            StudyKind::Stribeck => "stribeck",
            StudyKind::AmplitudeFrequency => "amplitude-frequency",
            StudyKind::Load => "load",
            StudyKind::Viscosity => "viscosity",
            StudyKind::Inertia => "inertia",
            StudyKind::Unidirectional => "unidirectional",
            StudyKind::Roughness => "roughness",
            StudyKind::Hersey => "hersey",
        }
    }

    pub fn from_name(s: &str) -> Option<StudyKind> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }

    /// The paper's figure(s).
    pub fn figure(self) -> &'static str {
        match self {
            StudyKind::Stribeck => "Fig. 4",
            StudyKind::AmplitudeFrequency => "Figs. 5–6",
            StudyKind::Load => "Fig. 7",
            StudyKind::Viscosity => "Fig. 8",
            StudyKind::Inertia => "Figs. 9–10",
            StudyKind::Unidirectional => "Fig. 11",
            StudyKind::Roughness => "Figs. 12–13",
            StudyKind::Hersey => "Fig. 14",
        }
    }
}

/// v(t) = V0 + V1 sin(2π f t).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    pub v0: f64,
    pub v1: f64,
    pub f_hz: f64,
}

impl Motion {
    pub fn at(&self, t: f64) -> f64 {
        self.v0 + self.v1 * (2.0 * std::f64::consts::PI * self.f_hz * t).sin()
    }

    pub fn period(&self) -> f64 {
        1.0 / self.f_hz
    }

    pub fn v_range(&self) -> (f64, f64) {
        (self.v0 - self.v1.abs(), self.v0 + self.v1.abs())
    }
}

/// One transient case of a study.
#[derive(Debug, Clone)]
pub struct Case {
    pub study: StudyKind,
    /// File-safe identifier.
    pub id: String,
    /// Panel of the plots this case belongs to (e.g. "f = 1 Hz").
    pub panel: String,
    /// Series within the panel (e.g. "V1 = 0.5 m/s").
    pub series: String,
    pub config: Config,
    pub motion: Motion,
    pub cycles: usize,
    /// Key of the steady curve overlaid on this case.
    pub steady_key: String,
}

impl Case {
    pub fn steps(&self) -> usize {
        (self.cycles as f64 * self.motion.period() / self.config.solver.dt_s).round() as usize
    }

    pub fn load_n(&self) -> f64 {
        self.config.contact.load_n
    }

    pub fn viscosity(&self) -> f64 {
        self.config.lubricant.viscosity_pa_s
    }
}

/// Options shared by every case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StudyOptions {
    /// Cycles per case; metrics are those of the last one (≥ 3 for the paper).
    pub cycles: usize,
    /// Points of each steady overlay curve.
    pub steady_points: usize,
    /// Points of the Stribeck study's curves (the paper: 60 on [−5, 5] m/s).
    pub stribeck_points: usize,
}

impl Default for StudyOptions {
    fn default() -> Self {
        Self {
            cycles: 3,
            steady_points: 81,
            stribeck_points: 60,
        }
    }
}

const FREQUENCIES: [f64; 3] = [0.25, 1.0, 4.0];

/// The low-speed point added to the Stribeck curves, m/s.
pub const LOW_SPEED: f64 = 1e-3;

fn fmt_g(x: f64) -> String {
    let s = format!("{x}");
    s.trim_end_matches(".0").to_string()
}

fn with(base: &Config, f: impl FnOnce(&mut Config)) -> Config {
    let mut c = base.clone();
    f(&mut c);
    c
}

/// Key of the steady curve for a configuration (the parameters that change
/// the steady state).
pub fn steady_key(c: &Config) -> String {
    format!(
        "F{}_mu{}_sigma{}",
        fmt_g(c.contact.load_n),
        fmt_g(c.lubricant.viscosity_pa_s),
        fmt_g(c.roughness.sigma_m * 1e6)
    )
}

/// The transient cases of a study (empty for `stribeck`).
pub fn cases(study: StudyKind, base: &Config, opts: &StudyOptions) -> Vec<Case> {
    let mut out = Vec::new();
    let mut push = |config: Config, motion: Motion, id: String, panel: String, series: String| {
        out.push(Case {
            study,
            steady_key: steady_key(&config),
            id,
            panel,
            series,
            config,
            motion,
            cycles: opts.cycles,
        });
    };
    let fpanel = |f: f64| format!("f = {} Hz", fmt_g(f));
    match study {
        StudyKind::Stribeck => {}
        StudyKind::AmplitudeFrequency => {
            let c = with(base, |c| {
                c.contact.load_n = 20_762.0;
                c.lubricant.viscosity_pa_s = 0.0564;
            });
            for f in FREQUENCIES {
                for v1 in [0.1, 0.5, 1.0] {
                    push(
                        c.clone(),
                        Motion {
                            v0: 0.0,
                            v1,
                            f_hz: f,
                        },
                        format!("v1-{}_f-{}", fmt_g(v1), fmt_g(f)),
                        fpanel(f),
                        format!("V1 = {} m/s", fmt_g(v1)),
                    );
                }
            }
        }
        StudyKind::Load => {
            for f in FREQUENCIES {
                for load in [5762.0, 10_762.0, 20_762.0] {
                    let c = with(base, |c| {
                        c.contact.load_n = load;
                        c.lubricant.viscosity_pa_s = 0.056;
                    });
                    push(
                        c,
                        Motion {
                            v0: 0.0,
                            v1: 1.0,
                            f_hz: f,
                        },
                        format!("load-{}_f-{}", fmt_g(load), fmt_g(f)),
                        fpanel(f),
                        format!("F = {} N", fmt_g(load)),
                    );
                }
            }
        }
        StudyKind::Viscosity => {
            for f in FREQUENCIES {
                for mu in [0.056, 0.103, 0.143] {
                    let c = with(base, |c| {
                        c.contact.load_n = 20_762.0;
                        c.lubricant.viscosity_pa_s = mu;
                    });
                    push(
                        c,
                        Motion {
                            v0: 0.0,
                            v1: 1.0,
                            f_hz: f,
                        },
                        format!("mu-{}_f-{}", fmt_g(mu), fmt_g(f)),
                        fpanel(f),
                        format!("μ = {} Pa·s", fmt_g(mu)),
                    );
                }
            }
        }
        StudyKind::Inertia => {
            for f in FREQUENCIES {
                for m in [0.1, 1.0, 10.0, 100.0] {
                    let c = with(base, |c| {
                        c.contact.load_n = 5762.0;
                        c.lubricant.viscosity_pa_s = 0.0564;
                        c.contact.mass_kg = m;
                    });
                    push(
                        c,
                        Motion {
                            v0: 0.0,
                            v1: 1.0,
                            f_hz: f,
                        },
                        format!("m-{}_f-{}", fmt_g(m), fmt_g(f)),
                        fpanel(f),
                        format!("m = {} kg", fmt_g(m)),
                    );
                }
            }
        }
        StudyKind::Unidirectional => {
            // The text gives no load for Fig. 11; Table A3 says 5 kN: use the
            // nearest text load. V0 = 1, 2, 3 m/s extend the paper's 0.05,
            // 0.25, 0.5 so that the loops reach full film (claim 7).
            let c = with(base, |c| {
                c.contact.load_n = 5762.0;
                c.lubricant.viscosity_pa_s = 0.0564;
            });
            for f in FREQUENCIES {
                for v0 in [0.05, 0.25, 0.5, 1.0, 2.0, 3.0] {
                    push(
                        c.clone(),
                        Motion {
                            v0,
                            v1: 0.5 * v0,
                            f_hz: f,
                        },
                        format!("v0-{}_f-{}", fmt_g(v0), fmt_g(f)),
                        fpanel(f),
                        format!("V0 = {} m/s", fmt_g(v0)),
                    );
                }
            }
        }
        StudyKind::Roughness => {
            for v0 in [1.0, 0.25] {
                for f in FREQUENCIES {
                    for sigma in [2.5e-6, 5e-6, 7.5e-6] {
                        let c = with(base, |c| {
                            c.contact.load_n = 20_762.0;
                            c.lubricant.viscosity_pa_s = 0.0564;
                            c.roughness.sigma_m = sigma;
                        });
                        push(
                            c,
                            Motion {
                                v0,
                                v1: 0.5 * v0,
                                f_hz: f,
                            },
                            format!(
                                "v0-{}_sigma-{}_f-{}",
                                fmt_g(v0),
                                fmt_g(sigma * 1e6),
                                fmt_g(f)
                            ),
                            format!("V0 = {} m/s, f = {} Hz", fmt_g(v0), fmt_g(f)),
                            format!("σ = {} µm", fmt_g(sigma * 1e6)),
                        );
                    }
                }
            }
        }
        StudyKind::Hersey => {
            // Two groups; inside a group μ·V1/F is the same, so every loop
            // spans the same Hersey-number range.
            // (viscosity Pa·s, load N, V1 m/s, f Hz)
            type Member = (f64, f64, f64, f64);
            let groups: [(&str, [Member; 4]); 2] = [
                (
                    "H range ±9.79e-6",
                    [
                        (0.0564, 5762.0, 1.0, 1.0),
                        (0.103, 5762.0 * 0.103 / 0.0564, 1.0, 1.0),
                        (0.143, 5762.0 * 0.143 / 0.0564, 1.0, 1.0),
                        (0.0564, 5762.0, 1.0, 4.0),
                    ],
                ),
                (
                    "H range ±2.72e-6",
                    [
                        (0.0564, 20_762.0, 1.0, 1.0),
                        (0.0564, 10_381.0, 0.5, 1.0),
                        (0.143, 20_762.0, 0.0564 / 0.143, 1.0),
                        (0.0564, 20_762.0, 1.0, 4.0),
                    ],
                ),
            ];
            for (g, (panel, members)) in groups.iter().enumerate() {
                for (k, &(mu, load, v1, f)) in members.iter().enumerate() {
                    let c = with(base, |c| {
                        c.contact.load_n = load;
                        c.lubricant.viscosity_pa_s = mu;
                    });
                    push(
                        c,
                        Motion {
                            v0: 0.0,
                            v1,
                            f_hz: f,
                        },
                        format!("group-{}_{}", g + 1, k + 1),
                        panel.to_string(),
                        format!("μ {} F {:.0} V1 {:.3} f {}", fmt_g(mu), load, v1, fmt_g(f)),
                    );
                }
            }
        }
    }
    out
}

/// A steady curve to compute: its key, configuration and velocities.
#[derive(Debug, Clone)]
pub struct SteadySpec {
    pub key: String,
    pub label: String,
    pub config: Config,
    pub velocities: Vec<f64>,
}

/// The steady curves a study needs: the Stribeck study's six curves, or one
/// overlay per distinct steady configuration over the velocity range of its
/// cases.
pub fn steady_specs(
    study: StudyKind,
    base: &Config,
    cases: &[Case],
    opts: &StudyOptions,
) -> Vec<SteadySpec> {
    if study == StudyKind::Stribeck {
        let n = opts.stribeck_points.max(2);
        let mut vs: Vec<f64> = (0..n)
            .map(|k| -5.0 + 10.0 * k as f64 / (n - 1) as f64)
            .collect();
        // ±1 mm/s for the low-speed limit of claim 1.
        vs.extend([-LOW_SPEED, LOW_SPEED]);
        vs.sort_by(f64::total_cmp);
        let mut out = Vec::new();
        for load in [5720.0, 20_762.0] {
            for mu in [0.056, 0.103, 0.143] {
                let c = with(base, |c| {
                    c.contact.load_n = load;
                    c.lubricant.viscosity_pa_s = mu;
                });
                out.push(SteadySpec {
                    key: steady_key(&c),
                    label: format!("F = {} N, μ = {} Pa·s", fmt_g(load), fmt_g(mu)),
                    config: c,
                    velocities: vs.clone(),
                });
            }
        }
        return out;
    }
    let mut out: Vec<SteadySpec> = Vec::new();
    for case in cases {
        let (lo, hi) = case.motion.v_range();
        match out.iter_mut().find(|s| s.key == case.steady_key) {
            Some(s) => {
                let (a, b) = (s.velocities[0], s.velocities[s.velocities.len() - 1]);
                if lo < a || hi > b {
                    s.velocities = linspace(lo.min(a), hi.max(b), opts.steady_points);
                }
            }
            None => out.push(SteadySpec {
                key: case.steady_key.clone(),
                label: case.steady_key.clone(),
                config: case.config.clone(),
                velocities: linspace(lo, hi, opts.steady_points),
            }),
        }
    }
    out
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    let n = n.max(2);
    (0..n)
        .map(|k| a + (b - a) * k as f64 / (n - 1) as f64)
        .collect()
}

/// A computed steady curve.
#[derive(Debug, Clone)]
pub struct SteadyCurve {
    pub key: String,
    pub label: String,
    pub load_n: f64,
    pub viscosity: f64,
    pub points: Vec<Estimate>,
}

impl SteadyCurve {
    /// Linear interpolation of a quantity at velocity v (None outside).
    pub fn interpolate(&self, v: f64, q: impl Fn(&Estimate) -> f64) -> Option<f64> {
        let p = &self.points;
        let j = p.partition_point(|e| e.velocity < v);
        if j == 0 || j >= p.len() {
            return (p.first().is_some_and(|e| e.velocity == v)).then(|| q(&p[0]));
        }
        let (a, b) = (&p[j - 1], &p[j]);
        let w = (v - a.velocity) / (b.velocity - a.velocity);
        Some(q(a) + w * (q(b) - q(a)))
    }
}

/// Compute a steady curve (velocities swept outwards from zero per sign).
pub fn steady_curve(spec: &SteadySpec) -> Result<SteadyCurve, crate::offline::OfflineError> {
    let points =
        crate::offline::stribeck(&spec.config, &spec.velocities, spec.config.contact.load_n)?;
    Ok(SteadyCurve {
        key: spec.key.clone(),
        label: spec.label.clone(),
        load_n: spec.config.contact.load_n,
        viscosity: spec.config.lubricant.viscosity_pa_s,
        points,
    })
}

/// Outcome of one case.
#[derive(Debug, Clone)]
pub struct CaseResult {
    pub case: Case,
    pub steps: usize,
    pub status_counts: Vec<(Status, usize)>,
    pub substepped_steps: usize,
    pub max_iterations: u32,
    /// Metrics of the last complete cycle.
    pub metrics: Option<LoopMetrics>,
    /// Estimates of the last complete cycle.
    pub last_cycle: Vec<Estimate>,
    /// Set when the case could not run or did not converge everywhere.
    pub failure: Option<String>,
}

impl CaseResult {
    pub fn failed(&self) -> bool {
        self.failure.is_some()
    }
}

/// Run one case; `progress(n)` is called with the number of steps done since
/// the last call.
pub fn run_case(case: &Case, progress: &dyn Fn(usize)) -> CaseResult {
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
            progress(pending);
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
    pub cof_accelerating: f64,
    pub cof_decelerating: f64,
    pub h0_accelerating: f64,
    pub h0_decelerating: f64,
    /// Mean of COF − COF_steady(v(t)) over the whole cycle.
    pub cof_mean: f64,
    /// Mean of COF_steady(v(t)) over the cycle.
    pub steady_cof_mean: f64,
}

impl CaseResult {
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
    pub study: StudyKind,
    pub cases: Vec<CaseResult>,
    pub steady: Vec<SteadyCurve>,
}

impl StudyResult {
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
) -> Result<StudyResult, crate::offline::OfflineError> {
    let cs = cases(study, base, opts);
    let specs = steady_specs(study, base, &cs, opts);
    let steady = specs
        .iter()
        .map(steady_curve)
        .collect::<Result<Vec<_>, _>>()?;
    let cases = cs.iter().map(|c| run_case(c, &|_| {})).collect();
    Ok(StudyResult {
        study,
        cases,
        steady,
    })
}
