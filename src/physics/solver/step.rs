//! One time step: input checks, the quadratic predictor, Newton and its
//! fallbacks (retry from the last state, then backward-Euler sub-steps), the
//! optional film floor.
//!
//! ## The predictor's guard
//!
//! Extrapolation in time is exact to O(Δt³) while the film evolves smoothly,
//! but not where a cell's pressure falls fast and then levels off, as in the
//! vapour-pocket collapse after a reversal: at 10 kN a liquid cell at
//! 1.58 bar falling 0.75 bar a step was predicted at 0.09 bar, deep in the
//! vapour (α ≈ 0.9), and settled at 1.3 bar. Newton then has to cross the
//! EOS's steep transition twice (the crawl that the vapour-fraction map of
//! `newton.rs` eases). So a cell on the liquid side whose extrapolation
//! crosses into the mixture starts in the liquid instead:
//!
//! ```text
//! p_start = p_s + ¾ (p_n − p_s)   if p_n > p_s and p_extrapolated < p_s − 0.3/β
//!         = p_extrapolated        otherwise
//! ```
//!
//! The start changes, not the equations: the converged state is the same
//! within the tolerance, and a smooth dip just below p_s (a step that
//! converges at once) is left alone. ¾ and 0.3/β were chosen by measurement
//! on the reciprocating case; the sweep and its iteration counts are in
//! `docs/solver-tuning.md`.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | p_n | the cell's pressure at the last step | Pa |
//! | p_s | saturation pressure (α = α_s) | Pa |
//! | β | steepness of the EOS transition (`eos.rs`) | 1/Pa |
//!
//! `Solver`'s fields this file uses: `d`, `settings`, `p`, `h0`, `time`, `velocity`, `hist`, `last_load`, `hist_len`, `w`, `predictor`, `last`, `states`, `isa`.

use super::newton::MAX_SUBSTEPS;
use super::{Ctx, H0Mode, Isa, Outcome, Solver};
use crate::physics::eos::MixtureEos;
use crate::physics::estimate::{Diagnostics, Estimate, Regime, Status};
use crate::physics::params::{MAX_ABS_VELOCITY, MAX_LOAD, MAX_VARIABLE_STEP_S};
use crate::physics::scheme::StepCoefficients;
use crate::physics::settings::Method;

impl Solver {
    // ------------------------------------------------------------------
    // Public solves
    // ------------------------------------------------------------------

    /// Advance one step of `dt` with velocity `v` (m/s) and load `load` (N).
    ///
    /// Inputs outside the physical envelope (non-finite, |v| above
    /// [`MAX_ABS_VELOCITY`], a load not in (0, [`MAX_LOAD`]]) are rejected:
    /// nothing is computed, the state is kept (the film is held for the step),
    /// time still advances, and the estimate is the last good one (or a
    /// defined zero before any) with the status saying why.
    pub fn step(&mut self, v: f64, load: f64) -> Estimate {
        self.step_with_gap(v, load, H0Mode::Balance)
    }

    /// A step of `dt` s, as every entry point that takes a step length
    /// does it (the C API, Python): the configured step when `dt` is within
    /// 1e-9 relative of `solver.dt_s` (the second-order history goes on,
    /// whatever rounding the caller's clock or time column added), else one
    /// [`Solver::step_lasting`].
    pub fn step_by(&mut self, v: f64, load: f64, dt: f64) -> Estimate {
        let configured = self.settings.dt;
        if (dt - configured).abs() <= 1e-9 * configured {
            self.step(v, load)
        } else {
            self.step_lasting(v, load, dt)
        }
    }

    /// One backward-Euler step of arbitrary length `dt` (s, in (0,
    /// [`MAX_VARIABLE_STEP_S`]]), for a loop that lost more time than it can catch
    /// up in fixed steps. The history restarts around it: the step and the
    /// one after it are backward Euler (first order), then BDF2 resumes.
    pub fn step_lasting(&mut self, v: f64, load: f64, dt: f64) -> Estimate {
        if !(dt.is_finite() && dt > 0.0 && dt <= MAX_VARIABLE_STEP_S) {
            return self.rejected_input(v, load, Status::InputOutOfRange, true);
        }
        self.restart_history();
        let fixed = self.settings.dt;
        self.settings.dt = dt;
        self.set_time(self.time);
        let e = self.step(v, load);
        self.settings.dt = fixed;
        self.set_time(self.time);
        self.restart_history();
        e
    }

    /// A step whose inputs the caller refused by a rule of its own (a
    /// configured envelope narrower than the physical one): nothing is
    /// computed, the state is kept, time advances, and the estimate is the
    /// last good one under [`Status::InputOutOfRange`], as for inputs
    /// outside the physical envelope.
    pub fn refuse_step(&mut self) -> Estimate {
        self.rejected_input(f64::NAN, f64::NAN, Status::InputOutOfRange, true)
    }

    /// Advance one step with a prescribed gap h0 (no load balance). `load`
    /// is only used to normalise the COF.
    pub fn step_prescribed_gap(&mut self, v: f64, h0: f64, load: f64) -> Estimate {
        self.step_with_gap(v, load, H0Mode::Prescribed(h0))
    }
    /// The status of inputs outside the envelope, None when inside.
    pub(super) fn input_status(v: f64, load: f64) -> Option<Status> {
        if !(v.is_finite() && load.is_finite()) {
            Some(Status::NonFiniteInput)
        } else if v.abs() > MAX_ABS_VELOCITY || load <= 0.0 || load > MAX_LOAD {
            Some(Status::InputOutOfRange)
        } else {
            None
        }
    }

    /// The last good estimate (or a defined zero) under `status`; the
    /// rejected inputs themselves are never reported. A rejected time step
    /// still advances time (`advance`).
    pub(super) fn rejected_input(
        &mut self,
        _v: f64,
        _load: f64,
        status: Status,
        advance: bool,
    ) -> Estimate {
        if advance {
            self.advance_time();
        }
        let mut e = self.last.unwrap_or_else(|| self.blank_estimate());
        e.time = self.time;
        e.status = status;
        e.diagnostics = Diagnostics::default();
        e.inertia_force = 0.0;
        e
    }

    pub(super) fn blank_estimate(&self) -> Estimate {
        Estimate {
            time: self.time,
            velocity: self.velocity,
            load: 0.0,
            h0: self.h0,
            h_min: self.h0 + self.d.grid.g_min,
            hydrodynamic_force: 0.0,
            asperity_force: 0.0,
            viscous_force: 0.0,
            friction_force: 0.0,
            contact_friction_force: 0.0,
            cof: 0.0,
            boundary_rate_cof: 0.0,
            asperity_load_share: 0.0,
            inertia_force: 0.0,
            contact_area_ratio: 0.0,
            max_pressure: self.d.p_amb,
            cavitated_fraction: 0.0,
            regime: Regime::Boundary,
            status: Status::NonFiniteInput,
            diagnostics: Diagnostics::default(),
        }
    }

    /// One step, in the best instruction-set version of the solver this
    /// CPU runs (see [`Isa`]); every version gives the same numbers.
    fn step_with_gap(&mut self, v: f64, load: f64, gap: H0Mode) -> Estimate {
        // A soft contact: the film per reference width (1 when rigid).
        let load = self.per_reference_width(load);
        #[cfg(target_arch = "x86_64")]
        match self.isa {
            // SAFETY: `Isa::detect` found these features on this CPU.
            Isa::Avx512 => return unsafe { self.step_avx512(v, load, gap) },
            Isa::Avx2 => return unsafe { self.step_avx2(v, load, gap) },
            Isa::Baseline => {}
        }
        self.step_body(v, load, gap)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    fn step_avx512(&mut self, v: f64, load: f64, gap: H0Mode) -> Estimate {
        self.step_body(v, load, gap)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    fn step_avx2(&mut self, v: f64, load: f64, gap: H0Mode) -> Estimate {
        self.step_body(v, load, gap)
    }

    #[inline(always)]
    fn step_body(&mut self, v: f64, load: f64, gap: H0Mode) -> Estimate {
        let gap_ok = match gap {
            H0Mode::Balance => true,
            H0Mode::Prescribed(h) => h.is_finite() && h > 0.0,
        };
        let rejected = Self::input_status(v, load).or((!gap_ok).then_some(Status::InputOutOfRange));
        if let Some(status) = rejected {
            return self.rejected_input(v, load, status, true);
        }
        if self.hist_len == 0 {
            // Never initialised: start from the steady state at this input.
            // (`load` is per reference width; the steady solve takes the
            // load itself.)
            self.initialize_steady(v, load * self.states.soft_width.0);
        }
        let coeffs = if self.hist_len >= 2 {
            StepCoefficients::for_scheme(self.settings.scheme)
        } else {
            StepCoefficients::BDF1
        };
        let ctx = Ctx {
            v,
            load,
            time: Some((coeffs, self.settings.dt)),
            gap,
        };
        self.w.p_backup.copy_from_slice(&self.p);
        let h_backup = self.h0;
        self.predict(gap);
        let predicted = self.predictor.levels >= 1 && self.hist_len >= 2;
        self.predictor.held_h0 = predicted.then_some(h_backup);
        let out = match self.settings.method {
            Method::Newton => self.solve(&ctx),
            Method::Reference => self.reference_solve(&ctx),
        };
        let (out, substeps) = self.recover(&ctx, out, h_backup);
        let (out, floor) = self.hold_floor(&ctx, out);
        if out.status == Status::NonFinite {
            self.p.copy_from_slice(&self.w.p_backup);
            self.h0 = h_backup;
        }
        // The step's start becomes level n−2, and n−2 becomes n−3.
        self.predictor.push(&mut self.w.p_backup, self.hist[1].h0);
        self.velocity = v;
        self.last_load = Some(load);
        let mut e = self.finish(&ctx, out, true);
        e.diagnostics.film_floor_active = floor;
        e.diagnostics.substeps = substeps as u32;
        self.last = Some(e);
        e
    }

    /// Warm start: pressure and h0 extrapolated in time, quadratically
    /// once three levels exist (error O(Δt³): within the tolerance for
    /// smooth motion, so such steps take one Newton iteration), with a
    /// liquid cell kept out of the vapour ([`PredictionGuard`]).
    #[inline(always)]
    fn predict(&mut self, gap: H0Mode) {
        let quadratic = self.predictor.levels == 2 && self.hist_len >= 2;
        let guard = self.d.guard;
        if quadratic {
            let old = &self.predictor;
            for ((p, o), o2) in self.p.iter_mut().zip(&old.p_old).zip(&old.p_old2) {
                *p = guard.apply(*p, 3.0 * (*p - o) + o2);
            }
        } else if self.predictor.levels >= 1 && self.hist_len >= 2 {
            for (p, o) in self.p.iter_mut().zip(&self.predictor.p_old) {
                *p = guard.apply(*p, 2.0 * *p - o);
            }
        }
        match gap {
            H0Mode::Prescribed(h) => self.h0 = h,
            H0Mode::Balance => {
                if self.hist_len >= 2 {
                    let (h1, h2) = (self.hist[0].h0, self.hist[1].h0);
                    let ext = if quadratic {
                        3.0 * (h1 - h2) + self.predictor.h0_n3
                    } else {
                        2.0 * h1 - h2
                    };
                    if ext > 0.5 * self.h0 && ext.is_finite() {
                        self.h0 = ext;
                    }
                }
            }
        }
    }

    /// Fallbacks for the rare hard step (a fast vapour-pocket collapse):
    /// Newton from the last state instead of the extrapolated one, then
    /// the step split into backward-Euler sub-steps. The outcome and the
    /// number of sub-steps (0: none).
    #[inline(always)]
    fn recover(&mut self, ctx: &Ctx, out: Outcome, h_backup: f64) -> (Outcome, usize) {
        if out.status == Status::Converged || self.settings.method != Method::Newton {
            return (out, 0);
        }
        let spent = out.iterations;
        self.p.copy_from_slice(&self.w.p_backup);
        self.h0 = match ctx.gap {
            H0Mode::Prescribed(h) => h,
            H0Mode::Balance => h_backup,
        };
        let mut out = self.solve(ctx);
        out.iterations += spent;
        let (mut m, mut substeps) = (2, 0);
        while out.status != Status::Converged && m <= MAX_SUBSTEPS {
            let spent = out.iterations;
            out = self.solve_substepped(ctx, m, h_backup);
            out.iterations += spent;
            substeps = m;
            m *= 2;
        }
        (out, substeps)
    }

    /// When the film would fall below its floor, hold h0 there and give up
    /// the load balance. The outcome and whether the floor binds.
    #[inline(always)]
    fn hold_floor(&mut self, ctx: &Ctx, out: Outcome) -> (Outcome, bool) {
        let binds = out.status != Status::NonFinite
            && ctx.gap == H0Mode::Balance
            && self.h0 < self.d.min_film;
        if !binds {
            return (out, false);
        }
        let inner = out.iterations;
        let c2 = Ctx {
            gap: H0Mode::Prescribed(self.d.min_film),
            ..*ctx
        };
        self.h0 = self.d.min_film;
        let mut out = self.solve(&c2);
        out.iterations += inner;
        (out, true)
    }
}

/// The predictor's guard (module doc): the thresholds for one lubricant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PredictionGuard {
    /// p_s: a cell above it is on the liquid side (Pa).
    pub liquid_above: f64,
    /// p_s − [`GUARD_MARGIN`]/β: an extrapolation below it has crossed
    /// into the mixture (Pa).
    pub vapour_below: f64,
}

/// How far below p_s, in units of 1/β, an extrapolation must land for the
/// guard to act: 0.3/β ≈ 6.5 kPa by default (α ≈ 1.8 % there against
/// α_s = 1 %), so that a smooth dip just below p_s is left alone.
const GUARD_MARGIN: f64 = 0.3;

/// The share of its height above p_s that a guarded cell keeps.
const GUARD_KEEP: f64 = 0.75;

impl PredictionGuard {
    pub(crate) fn new(eos: &MixtureEos, saturation_pressure: f64) -> Self {
        Self {
            liquid_above: saturation_pressure,
            vapour_below: saturation_pressure - GUARD_MARGIN / eos.beta,
        }
    }

    /// The start of a cell at `p` (Pa) whose extrapolation is `predicted`
    /// (branch-free: the predictor's loop vectorises).
    #[inline(always)]
    pub(crate) fn apply(&self, p: f64, predicted: f64) -> f64 {
        if p > self.liquid_above && predicted < self.vapour_below {
            self.liquid_above + GUARD_KEEP * (p - self.liquid_above)
        } else {
            predicted
        }
    }
}

#[cfg(test)]
mod step_by_tests {
    use crate::physics::{ModelParams, Solver, SolverSettings};

    fn solver() -> Solver {
        let settings = SolverSettings {
            cells: 32,
            ..Default::default()
        };
        let mut s = Solver::new(&ModelParams::default(), &settings).unwrap();
        s.initialize_steady(0.0, 20_762.0);
        s
    }

    #[test]
    fn a_step_of_the_configured_length_up_to_rounding_continues_the_history_any_other_lasts() {
        let (mut a, mut b, mut c) = (solver(), solver(), solver());
        let dt = a.settings().dt;
        for k in 1..=20 {
            let v = 0.01 * k as f64;
            // A clock's rounding (1e-13 relative) is the configured step.
            let ea = a.step_by(v, 20_762.0, dt * (1.0 + 1e-13));
            let eb = b.step(v, 20_762.0);
            assert_eq!(ea, eb, "step {k}");
        }
        let lasting = c.step_by(0.01, 20_762.0, 2.0 * dt);
        assert_eq!(lasting, solver().step_lasting(0.01, 20_762.0, 2.0 * dt));
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the guard returns one of its inputs, bit for bit
mod guard_tests {
    use super::PredictionGuard;
    use crate::physics::eos::MixtureEos;
    use crate::physics::params::Lubricant;

    fn guard() -> (PredictionGuard, MixtureEos) {
        let l = Lubricant::default();
        let eos = MixtureEos::new(&l);
        (PredictionGuard::new(&eos, l.saturation_pressure), eos)
    }

    #[test]
    fn a_liquid_cell_extrapolated_into_the_vapour_starts_in_the_liquid_above_the_saturation_pressure(
    ) {
        let (g, eos) = guard();
        // The case from the reciprocating run at 10 kN: 1.58 bar, predicted
        // at 0.09 bar (α ≈ 0.9); it starts at 1 + 0.75 · 0.58 bar.
        assert!(eos.alpha(9.0e3) > 0.8);
        approx::assert_relative_eq!(g.apply(1.58e5, 9.0e3), 1.435e5, max_relative = 1e-12);
        approx::assert_relative_eq!(g.apply(1.58e5, -2.0e4), 1.435e5, max_relative = 1e-12);
        // The threshold sits 0.3/β below p_s, at α ≈ 1.8 %.
        approx::assert_relative_eq!(eos.alpha(g.vapour_below), 0.0182, epsilon = 2e-4);
    }

    #[test]
    fn smooth_extrapolations_and_cells_already_in_the_mixture_are_left_alone() {
        let (g, _) = guard();
        // Liquid staying liquid, or dipping just below p_s.
        assert_eq!(g.apply(3.0e5, 2.5e5), 2.5e5);
        assert_eq!(g.apply(1.02e5, 9.6e4), 9.6e4);
        // A cell already in the mixture follows its extrapolation, down or up.
        assert_eq!(g.apply(8.0e4, 2.0e4), 2.0e4);
        assert_eq!(g.apply(8.0e4, 3.0e5), 3.0e5);
        // NaN is not hidden.
        assert!(g.apply(1.5e5, f64::NAN).is_nan());
    }
}

#[cfg(test)]
mod isa_tests {
    use super::super::Isa;
    use crate::physics::Solver;
    use crate::physics::{ModelParams, SolverSettings};

    /// Every instruction-set version of the step this CPU runs gives the
    /// baseline's estimates bit for bit (reciprocating motion through
    /// reversals, where the film and the cavitation change fastest).
    #[test]
    fn every_instruction_set_version_gives_the_baseline_numbers_bit_for_bit() {
        let settings = SolverSettings {
            cells: 96,
            ..Default::default()
        };
        let run = |isa: Isa| {
            let mut s = Solver::new(&ModelParams::default(), &settings).unwrap();
            assert_eq!(s.set_isa(isa), isa);
            s.initialize_steady(0.0, 20_000.0);
            (0..1500)
                .map(|k| {
                    let t = k as f64 * settings.dt;
                    s.step((2.0 * std::f64::consts::PI * t).sin(), 20_000.0)
                })
                .collect::<Vec<_>>()
        };
        let base = run(Isa::Baseline);
        let mut versions = vec![Isa::Baseline];
        match Isa::detect() {
            Isa::Avx512 => versions.extend([Isa::Avx2, Isa::Avx512]),
            Isa::Avx2 => versions.push(Isa::Avx2),
            Isa::Baseline => {}
        }
        for isa in versions {
            let other = run(isa);
            for (k, (a, b)) in base.iter().zip(&other).enumerate() {
                assert_eq!(
                    (
                        a.friction_force.to_bits(),
                        a.h0.to_bits(),
                        a.diagnostics.iterations
                    ),
                    (
                        b.friction_force.to_bits(),
                        b.h0.to_bits(),
                        b.diagnostics.iterations
                    ),
                    "{isa:?}, step {k}"
                );
            }
        }
    }

    /// A version the CPU lacks is refused and the baseline runs instead.
    #[test]
    fn an_instruction_set_the_cpu_lacks_falls_back_to_the_baseline() {
        let mut s = Solver::new(&ModelParams::default(), &SolverSettings::default()).unwrap();
        let best = Isa::detect();
        assert_eq!(s.isa(), best);
        let got = s.set_isa(Isa::Avx512);
        assert_eq!(
            got,
            if best == Isa::Avx512 {
                Isa::Avx512
            } else {
                Isa::Baseline
            }
        );
    }
}
