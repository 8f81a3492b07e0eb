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
//!
//! ## Hard steps: the vapour-fraction map and the restart
//!
//! When a vapour pocket collapses or a reformation front sweeps cells, the
//! cells cross the EOS's steep transition, where α(p) is exponential in p
//! (width 1/β ≈ 21 kPa). Newton in p then crawls: from the vapour side the
//! linearisation sees the mixture's large compressibility and moves p by
//! about 1/(2β) an iteration; from the liquid side it overshoots deep into
//! the vapour. A large update (scaled size above [`MAPPED_UPDATE`], time
//! steps only) is therefore applied in the variable
//!
//! ```text
//! U(p) = p − K α(p),   U'(p) = 1 + 2 K β α (1 − α),   K = MAP_STIFFNESS / β
//! ```
//!
//! which is p in the liquid (α → 0) and ∝ −α, i.e. the density, in the
//! mixture, where the accumulation term is linear: the new pressure is
//! U⁻¹(U(p) + λ U'(p) Δp), by one Newton step on U from p + λΔp (U is
//! monotone, U' ≥ 1). It is Newton on R(p(U)) (J_U = J_p U', so the linear
//! solve is unchanged), so quadratic convergence and the solution are the
//! same; small updates, and the last update of every step, stay linear, so
//! steps that converge at once are untouched.
//!
//! The quadratic predictor extrapolates a collapse's jump into the next
//! step (absolute pressures below zero). When the first update from the
//! prediction exceeds [`PREDICTION_RESTART`], the step also tries the
//! previous state as the start and keeps the one with the smaller update.
//! (Before Newton starts, the predictor's guard in `step.rs` already keeps a
//! falling liquid cell from being extrapolated into the vapour.)
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | p, Δp | cell pressure, its Newton update | Pa |
//! | α | vapour volume fraction | – |
//! | β | steepness of the EOS transition | 1/Pa |
//! | U, K | mapped variable, its vapour weight | Pa |
//! | λ | step length of the line search | – |
//!
//! `Solver`'s fields this file uses: `d`, `settings`, `p`, `h0`, `velocity`, `hist`, `hist_save`, `last_load`, `w`, `predictor`, `contraction`.

use super::assembly::assemble;
use super::bordered::{direction_with_old_factors, factor_solve};
use super::lanes::lane_max_abs;
use super::{Ctx, H0Mode, Outcome, Solver};
use crate::physics::estimate::Status;
use crate::physics::scheme::StepCoefficients;

/// Finest sub-division of a step that failed to converge.
pub(super) const MAX_SUBSTEPS: usize = 16;

/// Largest relative change of h0 in one Newton update.
const H0_TRUST: f64 = 0.25;

/// Updates below this (scaled) are taken without the monotonicity test
/// (with the h0 trust region and a consistent merit scale they are safe; it
/// saves a solve per iteration in the slow phase of a vapour-pocket
/// collapse), except right after a damped update: there an untested full
/// step of a cell at the cavitation edge can throw it back into a cycle of
/// update sizes (the measured case: `docs/solver-tuning.md`).
const SMALL_UPDATE: f64 = 1e-1;

/// Bounds of the Newton contraction constant K (‖e_(k+1)‖ ≈ K‖e_k‖², scaled
/// norm) used to estimate the error left after an update; K starts at the
/// upper bound and follows the observed ratios.
const CONTRACTION_MIN: f64 = 1.0;
pub(super) const CONTRACTION_MAX: f64 = 1e6;

/// Updates above this (scaled) are applied through the vapour-fraction map
/// (module doc); smaller ones are added as they are.
const MAPPED_UPDATE: f64 = 1e-2;

/// The map's vapour weight K in units of 1/β: U is mostly p below a vapour
/// fraction of 1/(2 · MAP_STIFFNESS) = 1 % (α at the saturation pressure by
/// default), mostly −Kα above. Any K from 10 to 1000 removes the crawl; the
/// value is the measured best (`docs/solver-tuning.md`).
const MAP_STIFFNESS: f64 = 50.0;

/// A first update from the predictor above this (scaled) sends the step
/// back to the previous state as the start (module doc).
const PREDICTION_RESTART: f64 = 3.0;

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
        // The previous state, when this solve starts from a prediction.
        let held_h0 = self.predictor.held_h0.take();
        // Norm of the previous update when it was taken in full.
        let mut previous: Option<f64> = None;
        let mut damped = false;
        for k in 1..=max_it {
            out.iterations += 1;
            let Some(mut dh) = factor_solve(&mut self.w) else {
                out.status = Status::NonFinite;
                return out;
            };
            let mut scale = norm_scale(&self.p, self.h0, self.d.p_amb);
            let mut norm = scaled_norm(&self.w.dp, dh, scale);
            if k == 1 && norm > PREDICTION_RESTART {
                if let Some(h_held) = held_h0 {
                    let Some(first) = self.restart_from_held(ctx, h_held, norm, &mut out) else {
                        out.status = Status::NonFinite;
                        return out;
                    };
                    (dh, scale, norm) = first;
                }
            }
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
            let Some(lambda) = self.line_search(ctx, dh, scale, norm, damped, &mut out) else {
                out.status = Status::NonFinite;
                return out;
            };
            // λ ≤ 1 always: ≥ 1 is the full step.
            previous = (lambda >= 1.0).then_some(norm);
            damped = lambda < 1.0;
            std::mem::swap(&mut self.p, &mut self.w.p_trial);
        }
        out
    }

    /// The step length λ of the update (Δp in `w.dp`, `dh`, scaled size
    /// `norm` on `scale`): the h0 trust region, then halvings until the
    /// natural monotonicity test passes (untested below [`SMALL_UPDATE`]
    /// unless the previous update was `damped`).
    /// The accepted trial state is assembled, in `w.p_trial` and `self.h0`;
    /// None when no finite trial state was found.
    #[inline(always)]
    fn line_search(
        &mut self,
        ctx: &Ctx,
        dh: f64,
        scale: (f64, f64),
        norm: f64,
        damped: bool,
        out: &mut Outcome,
    ) -> Option<f64> {
        // Trust region on the gap: |Δh0| ≤ 25 % of h0 per iteration.
        let mut lambda: f64 = 1.0;
        if dh.abs() > H0_TRUST * self.h0 {
            lambda = H0_TRUST * self.h0 / dh.abs();
        }
        // Deep in the quadratic region the full step is taken untested; not
        // right after a damped update, which says the iterate is not there.
        let test = norm > SMALL_UPDATE || damped;
        let mapped = ctx.time.is_some() && norm > MAPPED_UPDATE;
        if mapped {
            self.prepare_map();
        }
        for _ in 0..12 {
            let h_trial = self.h0 + lambda * dh;
            if mapped {
                self.mapped_trial(lambda);
            } else {
                for ((pt, p), dp) in self.w.p_trial.iter_mut().zip(&self.p).zip(&self.w.dp) {
                    *pt = p + lambda * dp;
                }
            }
            let pt = std::mem::take(&mut self.w.p_trial);
            let ok = assemble(&self.d, &self.hist, &pt, h_trial, ctx, &mut self.w);
            self.w.p_trial = pt;
            if ok && !test && lambda >= 1.0 && dh.abs() <= H0_TRUST * self.h0 {
                self.h0 = h_trial;
                return Some(lambda);
            }
            if ok {
                let dhb = direction_with_old_factors(&mut self.w);
                let nb = scaled_norm(&self.w.dbar, dhb, scale);
                // Descent, or none to be found: take the small step and go on.
                if (nb.is_finite() && nb <= (1.0 - 0.25 * lambda) * norm) || lambda < 1.0 / 256.0 {
                    self.h0 = h_trial;
                    return Some(lambda);
                }
            }
            lambda *= 0.5;
            out.backtracks += 1;
        }
        None
    }

    /// The first Newton direction from the previous state (p in
    /// `w.p_backup`, `h_held`) instead of the prediction, whose first update
    /// had scaled size `predicted`; the start with the smaller update is
    /// kept, assembled and factored. Returns its (Δh0, scale, norm), None
    /// when the system is singular or non-finite at the kept start.
    fn restart_from_held(
        &mut self,
        ctx: &Ctx,
        h_held: f64,
        predicted: f64,
        out: &mut Outcome,
    ) -> Option<(f64, (f64, f64), f64)> {
        let h_predicted = self.h0;
        self.w.p_trial.copy_from_slice(&self.p);
        self.p.copy_from_slice(&self.w.p_backup);
        // A prescribed gap stays prescribed; only the pressures start over.
        self.h0 = match ctx.gap {
            H0Mode::Prescribed(h) => h,
            H0Mode::Balance => h_held,
        };
        out.iterations += 1;
        let held = if assemble(&self.d, &self.hist, &self.p, self.h0, ctx, &mut self.w) {
            factor_solve(&mut self.w).map(|dh| {
                let scale = norm_scale(&self.p, self.h0, self.d.p_amb);
                (dh, scale, scaled_norm(&self.w.dp, dh, scale))
            })
        } else {
            None
        };
        if let Some(first) = held.filter(|h| h.2 < predicted) {
            return Some(first);
        }
        // The prediction was the better start after all: back to it.
        std::mem::swap(&mut self.p, &mut self.w.p_trial);
        self.h0 = h_predicted;
        out.iterations += 1;
        if !assemble(&self.d, &self.hist, &self.p, self.h0, ctx, &mut self.w) {
            return None;
        }
        let dh = factor_solve(&mut self.w)?;
        let scale = norm_scale(&self.p, self.h0, self.d.p_amb);
        Some((dh, scale, scaled_norm(&self.w.dp, dh, scale)))
    }

    /// U(p) − λ-independent part and U'(p)Δp per cell (module doc), from
    /// the current iterate's assembled densities: α = (ρl − ρ)/(ρl − ρg),
    /// 2βα(1 − α) = (dρ/dp)/(ρl − ρg).
    #[inline(always)]
    fn prepare_map(&mut self) {
        let eos = &self.d.eos;
        let k = MAP_STIFFNESS / eos.beta;
        let inv = 1.0 / (eos.rho_l - eos.rho_g);
        let w = &mut self.w;
        let cells = &w.cells;
        for ((((u, du), p), dp), (rho, drho)) in w
            .map_u
            .iter_mut()
            .zip(w.map_du.iter_mut())
            .zip(&self.p)
            .zip(&w.dp)
            .zip(cells.rho.iter().zip(&cells.drho))
        {
            *u = p - k * ((eos.rho_l - rho) * inv);
            *du = (1.0 + k * (drho * inv)) * dp;
        }
    }

    /// The trial pressures U⁻¹(U(p) + λ U'(p)Δp), by one Newton step on U
    /// from p + λΔp (branch-free, so it vectorises).
    #[inline(always)]
    fn mapped_trial(&mut self, lambda: f64) {
        let eos = &self.d.eos;
        let k = MAP_STIFFNESS / eos.beta;
        let k2b = 2.0 * k * eos.beta;
        let w = &mut self.w;
        for ((((pt, p), dp), u), du) in w
            .p_trial
            .iter_mut()
            .zip(&self.p)
            .zip(&w.dp)
            .zip(&w.map_u)
            .zip(&w.map_du)
        {
            let q = p + lambda * dp;
            let a = eos.alpha_branchless(q);
            let g = q - k * a - (u + lambda * du);
            *pt = q - g / (1.0 + k2b * a * (1.0 - a));
        }
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
