//! `friction-node bench-cases`: the accuracy guide over a family of
//! transient cases instead of one. Each case is a reciprocating run
//! v = V0 + V1 sin 2πft under a load F (1 + a sin 4πft) with its own
//! lubricant viscosity; the cases spread over the space below with a
//! Halton sequence (deterministic, no two alike, evenly filled for any
//! count):
//!
//! | symbol | meaning | range | unit |
//! |---|---|---|---|
//! | V1 | velocity amplitude | 0.05 … 2, log-uniform | m/s |
//! | f | frequency | 0.25 … 4, log-uniform | Hz |
//! | V0 | velocity offset | 0 … V1/2 (the slider still reverses) | m/s |
//! | F | mean load | the configured load × 0.25 … 4, log-uniform | N |
//! | μ | liquid viscosity | the configured one × 0.25 … 4, log-uniform | Pa·s |
//! | a | load swing at 2f | 0 … 0.3 | 1 |
//!
//! Every case runs `cycles` cycles from the steady state at rest; the
//! answers are those of the last cycle: the friction loop area ∮ F dv
//! (N·m/s), the mean friction |F| (N), the mean and the minimum
//! separation h0 (m). Each is compared with a reference run of the same
//! case on a fine grid and step (N = 2048, Δt = 0.125 ms by default, the
//! second-order flux), and a case passes when its errors are within the
//! tolerances (area 1.5 %, film 0.2 %, mean friction 1.5 % by default).

use crate::config::{Config, FluxKind};
use crate::offline::{simulate, SimulationError};
use crate::signal::Signal;

/// One transient case (SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TransientCase {
    /// V1, m/s.
    pub velocity_amplitude_m_s: f64,
    /// f, Hz.
    pub frequency_hz: f64,
    /// V0, m/s.
    pub velocity_offset_m_s: f64,
    /// Mean normal load, N.
    pub load_n: f64,
    /// Liquid viscosity, Pa·s.
    pub viscosity_pa_s: f64,
    /// Relative load swing at twice the frequency.
    pub load_swing: f64,
}

/// The `k`-th element (from 1) of the van der Corput sequence in `base`.
fn radical_inverse(mut k: u64, base: u64) -> f64 {
    let (mut x, mut scale) = (0.0, 1.0 / base as f64);
    while k > 0 {
        x += (k % base) as f64 * scale;
        k /= base;
        scale /= base as f64;
    }
    x
}

/// `count` cases spread over the ranges of the module doc around the
/// configured load and viscosity.
pub fn cases(config: &Config, count: usize) -> Vec<TransientCase> {
    let log = |u: f64, lo: f64, hi: f64| lo * (hi / lo).powf(u);
    (1..=count as u64)
        .map(|k| {
            let u = [2, 3, 5, 7, 11, 13].map(|b| radical_inverse(k, b));
            let v1 = log(u[0], 0.05, 2.0);
            TransientCase {
                velocity_amplitude_m_s: v1,
                frequency_hz: log(u[1], 0.25, 4.0),
                velocity_offset_m_s: 0.5 * v1 * u[2],
                load_n: config.contact.load_n * log(u[3], 0.25, 4.0),
                viscosity_pa_s: config.lubricant.viscosity_pa_s * log(u[4], 0.25, 4.0),
                load_swing: 0.3 * u[5],
            }
        })
        .collect()
}

/// A case's answers on one setting (the last cycle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CaseAnswers {
    /// ∮ F dv, N·m/s.
    pub loop_area: f64,
    /// Mean |F|, N.
    pub mean_friction_n: f64,
    /// Mean h0, m.
    pub h0_mean_m: f64,
    /// Smallest h0, m.
    pub h0_min_m: f64,
}

impl CaseAnswers {
    /// Relative errors against `reference`: loop area, mean friction,
    /// film (the larger of the mean and the minimum h0's).
    pub fn errors(&self, reference: &CaseAnswers) -> [f64; 3] {
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        [
            rel(self.loop_area, reference.loop_area),
            rel(self.mean_friction_n, reference.mean_friction_n),
            rel(self.h0_mean_m, reference.h0_mean_m).max(rel(self.h0_min_m, reference.h0_min_m)),
        ]
    }
}

/// Tolerances of a pass (relative).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// On the loop area.
    pub loop_area: f64,
    /// On the mean friction.
    pub mean_friction: f64,
    /// On the film (mean and minimum h0).
    pub film: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            loop_area: 0.015,
            mean_friction: 0.015,
            film: 0.002,
        }
    }
}

impl Tolerances {
    fn pass(&self, e: &[f64; 3]) -> bool {
        e[0] <= self.loop_area && e[1] <= self.mean_friction && e[2] <= self.film
    }
}

/// Run `case` on `cells` cells, step `dt_s` and `flux`.
pub fn run_case(
    config: &Config,
    case: &TransientCase,
    (cells, dt_s, flux): (usize, f64, FluxKind),
    cycles: u32,
) -> Result<CaseAnswers, SimulationError> {
    let mut cfg = config.clone();
    cfg.solver.cells = cells;
    cfg.solver.dt_s = dt_s;
    cfg.solver.flux = flux;
    cfg.contact.load_n = case.load_n;
    cfg.lubricant.viscosity_pa_s = case.viscosity_pa_s;
    cfg.validate()?;
    let f = case.frequency_hz;
    let velocity = Signal::Sine {
        offset: case.velocity_offset_m_s,
        amplitude: case.velocity_amplitude_m_s,
        frequency_hz: f,
        phase_rad: 0.0,
    };
    let load = Signal::Sine {
        offset: case.load_n,
        amplitude: case.load_n * case.load_swing,
        frequency_hz: 2.0 * f,
        phase_rad: 0.0,
    };
    let last_start = f64::from(cycles - 1) / f;
    let (mut n, mut friction, mut h0_sum) = (0u64, 0.0, 0.0);
    let r = simulate(&cfg, &velocity, &load, f64::from(cycles) / f, |e, _| {
        if e.time > last_start + 0.5 * dt_s {
            n += 1;
            friction += e.friction_force.abs();
            h0_sum += e.h0;
        }
        Ok(())
    })?;
    let last = r.cycles.last().ok_or_else(|| SimulationError::Argument {
        name: "--cycles",
        value: cycles.to_string(),
        message: format!("gave no complete cycle at N = {cells}, dt = {dt_s} s"),
    })?;
    let n = n.max(1) as f64;
    Ok(CaseAnswers {
        loop_area: last.friction_loop_area,
        mean_friction_n: friction / n,
        h0_mean_m: h0_sum / n,
        h0_min_m: last.h0_min,
    })
}

/// One setting (grid, step, flux) over all cases.
#[derive(Debug, Clone)]
pub struct SettingResult {
    /// Grid cells.
    pub cells: usize,
    /// Time step, s.
    pub dt_s: f64,
    /// Couette flux.
    pub flux: FluxKind,
    /// Every case's answers, in case order.
    pub answers: Vec<CaseAnswers>,
}

/// The sweep: the cases, their references, every setting's answers.
#[derive(Debug, Clone)]
pub struct CasesReport {
    /// The cases.
    pub cases: Vec<TransientCase>,
    /// The reference: cells, step (s), flux.
    pub reference_setting: (usize, f64, FluxKind),
    /// The reference answers, in case order.
    pub references: Vec<CaseAnswers>,
    /// Every setting tested.
    pub settings: Vec<SettingResult>,
    /// What passes.
    pub tolerances: Tolerances,
}

/// Run every case on every setting and on the reference, `workers` cases
/// at a time; `progress` is told what runs.
pub fn run(
    config: &Config,
    count: usize,
    settings: &[(usize, f64, FluxKind)],
    reference: (usize, f64, FluxKind),
    cycles: u32,
    workers: usize,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<CasesReport, SimulationError> {
    let cases = cases(config, count);
    let all: Vec<(usize, f64, FluxKind)> = std::iter::once(reference)
        .chain(settings.iter().copied())
        .collect();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Result<Vec<CaseAnswers>, SimulationError>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..workers.clamp(1, count.max(1)))
            .map(|_| {
                s.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(case) = cases.get(i) else { break };
                        progress(&format!("case {}/{}: {}", i + 1, cases.len(), case));
                        let answers: Result<Vec<CaseAnswers>, SimulationError> = all
                            .iter()
                            .map(|&setting| run_case(config, case, setting, cycles))
                            .collect();
                        mine.push((i, answers));
                    }
                    mine
                })
            })
            .collect();
        let mut by_case: Vec<(usize, Result<Vec<CaseAnswers>, SimulationError>)> = handles
            .into_iter()
            .flat_map(|h| h.join().expect("a case worker panicked"))
            .collect();
        by_case.sort_by_key(|(i, _)| *i);
        by_case.into_iter().map(|(_, r)| r).collect()
    });
    let mut references = Vec::with_capacity(count);
    let mut settings_out: Vec<SettingResult> = settings
        .iter()
        .map(|&(cells, dt_s, flux)| SettingResult {
            cells,
            dt_s,
            flux,
            answers: Vec::with_capacity(count),
        })
        .collect();
    for answers in results {
        let answers = answers?;
        references.push(answers[0]);
        for (s, a) in settings_out.iter_mut().zip(&answers[1..]) {
            s.answers.push(*a);
        }
    }
    Ok(CasesReport {
        cases,
        reference_setting: reference,
        references,
        settings: settings_out,
        tolerances: Tolerances::default(),
    })
}

impl std::fmt::Display for TransientCase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "v = {:.3} + {:.3} sin 2π {:.3} t m/s, F = {:.0} N (± {:.0} %), μ = {:.4} Pa·s",
            self.velocity_offset_m_s,
            self.velocity_amplitude_m_s,
            self.frequency_hz,
            self.load_n,
            100.0 * self.load_swing,
            self.viscosity_pa_s
        )
    }
}

/// The median of `x` (NaN when empty).
fn median(mut x: Vec<f64>) -> f64 {
    x.sort_by(f64::total_cmp);
    match x.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => x[n / 2],
        n => 0.5 * (x[n / 2 - 1] + x[n / 2]),
    }
}

impl SettingResult {
    /// Per case: its errors against the references.
    pub fn errors(&self, references: &[CaseAnswers]) -> Vec<[f64; 3]> {
        self.answers
            .iter()
            .zip(references)
            .map(|(a, r)| a.errors(r))
            .collect()
    }

    /// Cases within `tolerances`.
    pub fn passes(&self, references: &[CaseAnswers], tolerances: &Tolerances) -> usize {
        self.errors(references)
            .iter()
            .filter(|e| tolerances.pass(e))
            .count()
    }
}

impl std::fmt::Display for CasesReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (rn, rdt, rflux) = self.reference_setting;
        let t = &self.tolerances;
        writeln!(
            f,
            "{} transient cases; reference N = {rn}, dt = {} ms, {}; a case passes with loop area within {:.1} %, mean friction within {:.1} %, film (mean and minimum h0) within {:.1} %\n",
            self.cases.len(),
            rdt * 1e3,
            rflux.name(),
            100.0 * t.loop_area,
            100.0 * t.mean_friction,
            100.0 * t.film
        )?;
        writeln!(
            f,
            "| solver.flux | solver.cells | solver.dt_s (ms) | passed | loop area median / max | mean friction median / max | film median / max |"
        )?;
        writeln!(f, "|---|---|---|---|---|---|---|")?;
        let pct = |x: f64| format!("{:.2} %", 100.0 * x);
        for s in &self.settings {
            let e = s.errors(&self.references);
            let col = |j: usize| {
                let v: Vec<f64> = e.iter().map(|x| x[j]).collect();
                let max = v.iter().copied().fold(0.0, f64::max);
                format!("{} / {}", pct(median(v)), pct(max))
            };
            writeln!(
                f,
                "| {} | {} | {} | {} of {} | {} | {} | {} |",
                s.flux.name(),
                s.cells,
                s.dt_s * 1e3,
                s.passes(&self.references, t),
                self.cases.len(),
                col(0),
                col(1),
                col(2)
            )?;
        }
        for s in &self.settings {
            let failed: Vec<String> = s
                .errors(&self.references)
                .iter()
                .enumerate()
                .filter(|(_, e)| !t.pass(e))
                .map(|(i, e)| {
                    format!(
                        "  case {}: area {}, friction {}, film {} ({})",
                        i + 1,
                        pct(e[0]),
                        pct(e[1]),
                        pct(e[2]),
                        self.cases[i]
                    )
                })
                .collect();
            if !failed.is_empty() {
                writeln!(
                    f,
                    "\n{} N = {}, dt = {} ms: failed\n{}",
                    s.flux.name(),
                    s.cells,
                    s.dt_s * 1e3,
                    failed.join("\n")
                )?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod cases_tests {
    use super::*;

    #[test]
    fn the_cases_fill_their_ranges_without_repeating() {
        let config = Config::default();
        let c = cases(&config, 64);
        assert_eq!(c.len(), 64);
        for (i, a) in c.iter().enumerate() {
            assert!((0.05..=2.0).contains(&a.velocity_amplitude_m_s));
            assert!((0.25..=4.0).contains(&a.frequency_hz));
            assert!(a.velocity_offset_m_s <= 0.5 * a.velocity_amplitude_m_s);
            assert!((0.0..0.3).contains(&a.load_swing));
            assert!(c[..i].iter().all(|b| b != a));
        }
        // Evenly filled: each half of every range holds a fair share.
        let low = c.iter().filter(|a| a.frequency_hz < 1.0).count();
        assert!((28..=36).contains(&low), "{low} of 64 below 1 Hz");
    }

    #[test]
    fn the_second_order_flux_is_nearer_a_fine_grid_than_the_upwind_one_on_a_case() {
        // Case 7 (v = 0.28 + 1.26 sin 2π 1.17 t m/s, 5.5 kN, 0.082 Pa·s):
        // fast and lightly loaded, so the grid matters (in the 64-case sweep
        // upwind N = 64 is 1.5 % off in loop area and 2.0 % in friction).
        let config = Config::default();
        let case = cases(&config, 7)[6];
        let fine = run_case(&config, &case, (512, 1e-3, FluxKind::MusclVanLeer), 2).unwrap();
        let upwind = run_case(&config, &case, (64, 1e-3, FluxKind::Upwind), 2).unwrap();
        let muscl = run_case(&config, &case, (64, 1e-3, FluxKind::MusclVanLeer), 2).unwrap();
        assert!(fine.h0_min_m > 0.0 && fine.h0_min_m <= fine.h0_mean_m);
        assert!(fine.mean_friction_n > 0.0 && fine.loop_area.is_finite());
        assert_eq!(fine.errors(&fine), [0.0; 3]);
        let (eu, em) = (upwind.errors(&fine), muscl.errors(&fine));
        assert!(
            em[0] < 0.5 * eu[0],
            "loop area: muscl {em:?}, upwind {eu:?}"
        );
        assert!(Tolerances::default().pass(&em), "{em:?}");
    }
}
