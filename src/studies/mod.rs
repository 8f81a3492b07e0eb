//! The paper's parametric studies (docs/model.md §9) as data and computation.
//!
//! A study is a list of [`Case`]s (a resolved configuration and a sinusoidal
//! motion v = V0 + V1 sin 2πft) plus the steady Stribeck curves that are
//! overlaid on its loops. Running a case gives the loop metrics of its last
//! complete cycle ([`CaseResult`]); [`claims`] evaluates the paper's claims
//! on the results. The computation does no I/O; [`report`] writes the CSVs,
//! plots and the claims page for the `study` command.
//!
//! Where docs/model.md's study table is silent this module decides, and says so:
//! the load, viscosity and inertia studies use V1 = 1 m/s (Table A4 lists
//! 0.25 and 1); the unidirectional study runs at 5 762 N (Table A3 says 5 kN,
//! the text gives no load) with V0 extended to 1, 2, 3 m/s so that the loops
//! reach full film; the roughness study runs at V0 = 1 m/s (where docs/model.md
//! says the σ = 2.5 µm fluid-share claim holds) and also at V0 = 0.25 m/s;
//! the Hersey study is two groups of four loops with equal μ·V1/F.
//!
//! | file | job |
//! |---|---|
//! | `cases.rs` | the cases of each study (docs/model.md §9), one function per study |
//! | `run.rs` | steady curves, one case's transient run and its analysed cycle |
//! | `report.rs` | per-case CSVs, steady curves, figures and the claims' report |
//! | `claims/` | the paper's claims 1–9 evaluated on the results |

mod cases;
pub mod claims;
pub mod report;

use crate::analysis::{cycle_metrics, LoopMetrics, LoopSample};
use crate::config::Config;
use crate::physics::{Estimate, Solver, Status};

/// The studies of docs/model.md §9.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StudyKind {
    /// Steady Stribeck curves (Fig. 4).
    Stribeck,
    /// Velocity amplitude and frequency (Figs. 5–6).
    AmplitudeFrequency,
    /// Normal load (Fig. 7).
    Load,
    /// Lubricant viscosity (Fig. 8).
    Viscosity,
    /// Slider mass (Figs. 9–10).
    Inertia,
    /// Motion without reversal, an offset V0 (Fig. 11).
    Unidirectional,
    /// Surface roughness (Figs. 12–13).
    Roughness,
    /// COF against the Hersey number (Fig. 14).
    Hersey,
}

impl StudyKind {
    /// Every study, in the order they run.
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

    /// The name on the command line and in the output folders.
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

    /// The study named `s`.
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
    /// V0, mean velocity, m/s.
    pub v0: f64,
    /// V1, amplitude, m/s.
    pub v1: f64,
    /// f, frequency, Hz.
    pub f_hz: f64,
}

impl Motion {
    /// v at time `t` (s), m/s.
    pub fn at(&self, t: f64) -> f64 {
        self.v0 + self.v1 * (2.0 * std::f64::consts::PI * self.f_hz * t).sin()
    }

    /// 1/f, s.
    pub fn period(&self) -> f64 {
        1.0 / self.f_hz
    }

    /// The lowest and highest velocity, m/s.
    pub fn v_range(&self) -> (f64, f64) {
        (self.v0 - self.v1.abs(), self.v0 + self.v1.abs())
    }
}

/// One transient case of a study.
#[derive(Debug, Clone)]
pub struct Case {
    /// The study it belongs to.
    pub study: StudyKind,
    /// File-safe identifier.
    pub id: String,
    /// Panel of the plots this case belongs to (e.g. "f = 1 Hz").
    pub panel: String,
    /// Series within the panel (e.g. "V1 = 0.5 m/s").
    pub series: String,
    /// Its configuration.
    pub config: Config,
    /// Its velocity.
    pub motion: Motion,
    /// Cycles to run (the last is measured).
    pub cycles: usize,
    /// Key of the steady curve overlaid on this case.
    pub steady_key: String,
}

impl Case {
    /// Steps it takes.
    pub fn steps(&self) -> usize {
        (self.cycles as f64 * self.motion.period() / self.config.solver.dt_s).round() as usize
    }

    /// Its normal load, N.
    pub fn load_n(&self) -> f64 {
        self.config.contact.load_n
    }

    /// Its liquid viscosity, Pa·s.
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

pub use cases::cases;

/// A steady curve to compute: its key, configuration and velocities.
#[derive(Debug, Clone)]
pub struct SteadySpec {
    /// The key cases refer to it by.
    pub key: String,
    /// Its legend.
    pub label: String,
    /// Its configuration.
    pub config: Config,
    /// The velocities, m/s.
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
    /// The key cases refer to it by.
    pub key: String,
    /// Its legend.
    pub label: String,
    /// Its normal load, N.
    pub load_n: f64,
    /// Its liquid viscosity, Pa·s.
    pub viscosity: f64,
    /// One steady state per velocity.
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
pub fn steady_curve(spec: &SteadySpec) -> Result<SteadyCurve, crate::offline::SimulationError> {
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

mod run;
pub use run::{run_case, run_study, CaseResult, SteadyOffsets, StudyResult};
