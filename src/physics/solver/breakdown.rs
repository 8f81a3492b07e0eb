//! Where a step's time goes: each part of a Newton iteration timed alone,
//! from one state, in the instruction-set version the solver runs.
//!
//! A benchmark aid (`friction-node bench --breakdown`), not part of a
//! step. The clock is handed in (the core reads none): `now` returns
//! nanoseconds from any monotonic source. Each part runs `reps` times back
//! to back on the same inputs, so the figures are warm-cache costs; their
//! sum is close to a one-iteration step.
//!
//! `Solver`'s fields this file uses: `d`, `settings`, `hist_len`.

use super::assembly::{balance_row, face_pass, row_pass};
use super::bordered::{direction_with_old_factors, factor_solve};
use super::cell_pass::cell_pass;
use super::{Ctx, H0Mode, Isa, Outcome, Solver};
use crate::physics::estimate::Status;
use crate::physics::scheme::StepCoefficients;

/// Cost of each part of one Newton iteration, ns per call.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepBreakdown {
    /// The mixture EOS of every cell (exponential, ρ, ρ/μ, μ and their
    /// derivatives).
    pub eos_ns: f64,
    /// The mass flux through every face and its derivatives.
    pub faces_ns: f64,
    /// The rows of the bordered system, the asperity sums and G.
    pub rows_ns: f64,
    /// Factoring the bordered system and solving for the Newton update.
    pub solve_ns: f64,
    /// The line search's simplified direction with the stored factors.
    pub old_factor_solve_ns: f64,
    /// Post-processing a converged state into an estimate.
    pub finish_ns: f64,
}

impl StepBreakdown {
    /// The parts of a step that converges in one iteration.
    pub fn one_iteration_ns(&self) -> f64 {
        self.eos_ns + self.faces_ns + self.rows_ns + self.solve_ns + self.finish_ns
    }
}

impl Solver {
    /// Time each part of a Newton iteration at this state for the next step
    /// with velocity `v` (m/s) and load `load` (N), `reps` calls each (at
    /// least 1). The solver is left unchanged. `now`: a monotonic clock, ns.
    pub fn breakdown(
        &self,
        v: f64,
        load: f64,
        reps: usize,
        now: &mut dyn FnMut() -> u64,
    ) -> StepBreakdown {
        let mut s = self.clone();
        let reps = reps.max(1);
        #[cfg(target_arch = "x86_64")]
        match s.isa {
            // SAFETY: `Isa::detect` found these features on this CPU.
            Isa::Avx512 => return unsafe { s.breakdown_avx512(v, load, reps, now) },
            Isa::Avx2 => return unsafe { s.breakdown_avx2(v, load, reps, now) },
            Isa::Baseline => {}
        }
        s.breakdown_body(v, load, reps, now)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512dq,avx512vl,avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    fn breakdown_avx512(
        &mut self,
        v: f64,
        load: f64,
        reps: usize,
        now: &mut dyn FnMut() -> u64,
    ) -> StepBreakdown {
        self.breakdown_body(v, load, reps, now)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,bmi2,lzcnt,popcnt")]
    fn breakdown_avx2(
        &mut self,
        v: f64,
        load: f64,
        reps: usize,
        now: &mut dyn FnMut() -> u64,
    ) -> StepBreakdown {
        self.breakdown_body(v, load, reps, now)
    }

    #[inline(always)]
    fn breakdown_body(
        &mut self,
        v: f64,
        load: f64,
        reps: usize,
        now: &mut dyn FnMut() -> u64,
    ) -> StepBreakdown {
        let coeffs = if self.hist_len >= 2 {
            StepCoefficients::for_scheme(self.settings.scheme)
        } else {
            StepCoefficients::BDF1
        };
        let ctx = Ctx {
            v,
            load,
            time: Some((coeffs, self.settings.dt)),
            gap: H0Mode::Balance,
        };
        let n = self.d.grid.n;
        // A macro, not a closure: closures are not compiled with the
        // enclosing function's target features.
        macro_rules! time {
            ($s:ident => $body:expr) => {{
                let t0 = now();
                for _ in 0..reps {
                    let $s = &mut *self;
                    $body;
                }
                (now() - t0) as f64 / reps as f64
            }};
        }
        let eos_ns = time!(s => cell_pass(&s.d, &s.p[..n], &mut s.w));
        let faces_ns = time!(s => face_pass(&s.d, &s.p[..n], s.h0, &ctx, &mut s.w));
        let rows_ns = time!(s => {
            row_pass(&s.d, &s.hist, s.h0, &ctx, &mut s.w);
            balance_row(&s.d, &s.hist, &s.p[..n], s.h0, &ctx, &mut s.w)
        });
        let solve_ns = time!(s => factor_solve(&mut s.w));
        let old_factor_solve_ns = time!(s => direction_with_old_factors(&mut s.w));
        let out = Outcome {
            status: Status::Converged,
            iterations: 1,
            inner_iterations: 0,
            residual: 0.0,
            backtracks: 0,
        };
        let finish_ns = time!(s => {
            s.w.linearised = Some(0.0);
            s.finish(&ctx, out, false)
        });
        StepBreakdown {
            eos_ns,
            faces_ns,
            rows_ns,
            solve_ns,
            old_factor_solve_ns,
            finish_ns,
        }
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims (0, 1, representable sums)
mod tests {
    use crate::physics::{ModelParams, Solver, SolverSettings};

    /// The breakdown times every part with the clock it is handed (here a
    /// simulated one: 600 ns pass between two readings) and leaves the
    /// solver's next step bit for bit unchanged.
    #[test]
    fn breakdown_times_every_part_with_the_clock_handed_in_and_leaves_the_solver_unchanged() {
        let settings = SolverSettings {
            cells: 64,
            ..Default::default()
        };
        let mut s = Solver::new(&ModelParams::default(), &settings).unwrap();
        s.initialize_steady(0.2, 20_000.0);
        for k in 1..=5 {
            s.step(0.2 + 0.01 * k as f64, 20_000.0);
        }
        let mut twin = s.clone();
        let mut t = 0u64;
        let mut now = || {
            t += 600;
            t
        };
        let b = s.breakdown(0.3, 20_000.0, 4, &mut now);
        for part in [
            b.eos_ns,
            b.faces_ns,
            b.rows_ns,
            b.solve_ns,
            b.old_factor_solve_ns,
            b.finish_ns,
        ] {
            assert_eq!(part, 150.0);
        }
        assert_eq!(b.one_iteration_ns(), 750.0);
        let (x, y) = (s.step(0.3, 20_000.0), twin.step(0.3, 20_000.0));
        assert_eq!(x.friction_force.to_bits(), y.friction_force.to_bits());
        assert_eq!(x.h0.to_bits(), y.h0.to_bits());
    }
}
