//! Newton on the coupled unknowns (p, h0).
//!
//! The Jacobian of (R, G) in (p, h0) is tridiagonal in p, bordered by the
//! dense column ∂R/∂h0 and the uniform row ∂G/∂p = −w0 B Δx. One Thomas
//! factorisation serves two right-hand sides and a scalar Schur complement
//! gives Δh0: O(N) per iteration. Globalisation is Deuflhard's natural
//! monotonicity test: a trial step λΔ is accepted when the simplified Newton
//! correction at the trial point, computed with the *old* factors, shrinks
//! (‖Δ̄‖ ≤ (1 − λ/4)‖Δ‖); the trial point's assembly is then reused by the
//! next iteration, so a full step costs nothing extra. h0 may not change by
//! more than 25 % in one update. All buffers are allocated in
//! [`Solver::new`]; a step allocates nothing.
//!
//! The iteration stops when the error left after the last update is below
//! the tolerance. Newton converges quadratically, ‖e_(k+1)‖ ≈ K‖Δ_k‖², so
//! that error is estimated as K‖Δ_k‖² with K observed from the last two
//! full updates, ‖Δ_k‖/‖Δ_(k−1)‖² (bounded to [1, 1e6]); the first update of
//! a time step, from the predictor, uses the K last observed. After a damped
//! update K is unknown and only an update at or below the tolerance ends the
//! iteration, which is also the rule of steady solves (off the real-time
//! path, they converge to the update tolerance). Norms are the scaled
//! max-norm of (Δp / max(p_amb, max|p|), Δh0 / h0).

use super::assembly::{assemble, lane_max_abs};
use super::bordered::{direction_with_old_factors, factor_solve};
use super::{Ctx, H0Mode, Outcome, Solver};
use crate::physics::estimate::Status;
use crate::physics::scheme::StepCoefficients;

/// Finest sub-division of a step that failed to converge.
pub(super) const MAX_SUBSTEPS: usize = 16;

/// Largest relative change of h0 in one Newton update.
const H0_TRUST: f64 = 0.25;

/// Updates below this (scaled) are taken without the monotonicity test
/// (with the h0 trust region and a consistent merit scale, measured safe on
/// every study case; it saves a solve per iteration in the slow phase of a
/// vapour-pocket collapse).
const SMALL_UPDATE: f64 = 1e-1;

/// Bounds of the Newton contraction constant K (‖e_(k+1)‖ ≈ K‖e_k‖², scaled
/// norm) used to estimate the error left after an update; K starts at the
/// upper bound and follows the observed ratios.
const CONTRACTION_MIN: f64 = 1.0;
pub(super) const CONTRACTION_MAX: f64 = 1e6;

impl Solver {
    /// Newton on the current state as initial guess.
    #[inline(always)]
    pub(crate) fn solve(&mut self, ctx: &Ctx) -> Outcome {
        let max_it = self.settings.max_iterations;
        let tol = self.settings.tolerance;
        let mut out = Outcome {
            status: Status::MaxIterations,
            iterations: 0,
            inner_iterations: 0,
            residual: f64::NAN,
            backtracks: 0,
        };
        self.w.linearised = None;
        if let H0Mode::Prescribed(h) = ctx.gap {
            self.h0 = h;
        }
        if !assemble(&self.d, &self.hist, &self.p, self.h0, ctx, &mut self.w) {
            out.status = Status::NonFinite;
            return out;
        }
        // Norm of the previous update when it was taken in full.
        let mut previous: Option<f64> = None;
        for k in 1..=max_it {
            out.iterations = k;
            let Some(dh) = factor_solve(&mut self.w) else {
                out.status = Status::NonFinite;
                return out;
            };
            let scale = norm_scale(&self.p, self.h0, self.d.p_amb);
            let norm = scaled_norm(&self.w.dp, dh, scale);
            out.residual = norm;
            if !norm.is_finite() {
                out.status = Status::NonFinite;
                return out;
            }
            // Error left after this update (time steps only; steady solves
            // iterate until the update itself is within the tolerance).
            let left = match previous {
                Some(prev) if prev > 0.0 => {
                    self.contraction =
                        (norm / (prev * prev)).clamp(CONTRACTION_MIN, CONTRACTION_MAX);
                    self.contraction * norm * norm
                }
                // From the predictor: K carried from earlier steps.
                None if k == 1 => self.contraction * norm * norm,
                // After a damped update (or a zero one) K is unknown.
                _ => f64::INFINITY,
            };
            if norm <= tol || (ctx.time.is_some() && left <= tol) {
                for (p, dp) in self.p.iter_mut().zip(&self.w.dp) {
                    *p += dp;
                }
                self.h0 += dh;
                self.w.linearised = Some(dh);
                out.status = Status::Converged;
                return out;
            }
            // Trust region on the gap: |Δh0| ≤ 25 % of h0 per iteration.
            let mut lambda: f64 = 1.0;
            if dh.abs() > H0_TRUST * self.h0 {
                lambda = H0_TRUST * self.h0 / dh.abs();
            }
            let mut accepted = false;
            // Deep in the quadratic region the full step is taken untested.
            let test = norm > SMALL_UPDATE;
            for _ in 0..12 {
                let h_trial = self.h0 + lambda * dh;
                for ((pt, p), dp) in self.w.p_trial.iter_mut().zip(&self.p).zip(&self.w.dp) {
                    *pt = p + lambda * dp;
                }
                let pt = std::mem::take(&mut self.w.p_trial);
                let ok = assemble(&self.d, &self.hist, &pt, h_trial, ctx, &mut self.w);
                self.w.p_trial = pt;
                if ok && !test && lambda == 1.0 && dh.abs() <= H0_TRUST * self.h0 {
                    accepted = true;
                    self.h0 = h_trial;
                    break;
                }
                if ok {
                    let dhb = direction_with_old_factors(&mut self.w);
                    let nb = scaled_norm(&self.w.dbar, dhb, scale);
                    if nb.is_finite() && nb <= (1.0 - 0.25 * lambda) * norm {
                        accepted = true;
                        self.h0 = h_trial;
                        break;
                    }
                    if lambda < 1.0 / 256.0 {
                        // Cannot find descent: take the small step and go on.
                        accepted = true;
                        self.h0 = h_trial;
                        break;
                    }
                }
                lambda *= 0.5;
                out.backtracks += 1;
            }
            if !accepted {
                out.status = Status::NonFinite;
                return out;
            }
            previous = (lambda == 1.0).then_some(norm);
            std::mem::swap(&mut self.p, &mut self.w.p_trial);
        }
        out
    }

    /// March the step in `m` backward-Euler sub-steps of Δt/m from the
    /// previous state (in `w.p_backup`, `h_start`), with velocity and load
    /// interpolated. The stored history is saved and restored around it.
    pub(super) fn solve_substepped(&mut self, ctx: &Ctx, m: usize, h_start: f64) -> Outcome {
        let Some((_, dt)) = ctx.time else {
            return self.solve(ctx);
        };
        self.p.copy_from_slice(&self.w.p_backup);
        self.h0 = h_start;
        for (save, lvl) in self.hist_save.iter_mut().zip(&self.hist) {
            save.copy_from(lvl);
        }
        // The inertia term's previous slope, rescaled to the sub-step.
        self.hist[1].h0 = self.hist[0].h0 - (self.hist[0].h0 - self.hist[1].h0) / m as f64;
        let (v0, f0) = (self.velocity, self.last_load.unwrap_or(ctx.load));
        let mut total = Outcome {
            status: Status::Converged,
            iterations: 0,
            inner_iterations: 0,
            residual: 0.0,
            backtracks: 0,
        };
        for j in 1..=m {
            let w = j as f64 / m as f64;
            let sub = Ctx {
                v: v0 + w * (ctx.v - v0),
                load: f0 + w * (ctx.load - f0),
                time: Some((StepCoefficients::BDF1, dt / m as f64)),
                gap: ctx.gap,
            };
            let o = self.solve(&sub);
            total.iterations += o.iterations;
            total.backtracks += o.backtracks;
            total.residual = o.residual;
            if o.status != Status::Converged {
                total.status = o.status;
                break;
            }
            if j < m {
                let f_net = self.w.f_net;
                self.push_history_current(f_net);
                self.w.linearised = None;
            }
        }
        for (lvl, save) in self.hist.iter_mut().zip(&self.hist_save) {
            lvl.copy_from(save);
        }
        self.w.hist_term_valid = None;
        total
    }
}

/// Scaled max-norm of an update: pressure relative to max(p_amb, max|p|),
/// h0 relative to itself.
#[inline(always)]
pub(crate) fn scaled_norm(dp: &[f64], dh: f64, scale: (f64, f64)) -> f64 {
    // (NaN entries cannot reach here: the solve checks the sums of the
    // direction and returns None.)
    let dmax = lane_max_abs(dp, 0.0);
    (dmax / scale.0).max(dh.abs() / scale.1)
}

/// Scales of an iterate for [`scaled_norm`]: max(p_amb, max|p|) and h0. A
/// line search measures the update and the trial correction on the scales
/// of the *current* iterate, so that the merit is consistent.
#[inline(always)]
pub(crate) fn norm_scale(p: &[f64], h0: f64, p_amb: f64) -> (f64, f64) {
    let pmax = lane_max_abs(p, p_amb);
    (pmax, h0.abs().max(f64::MIN_POSITIVE))
}
