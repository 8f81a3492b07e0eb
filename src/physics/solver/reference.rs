//! The paper's reference algorithm (Algorithm 1, docs/model.md §7).
//!
//! For each step, an under-relaxed secant iteration on h0 drives the load
//! residual `ΔF = Σ w_k (F_hyd + F_asp − F_ext)^(n−k) − m h0''` to zero. For
//! every trial h0 the Reynolds equation is solved by under-relaxed Picard
//! iterations on its linearised form: ρ and μ are frozen at the current
//! iterate Pᵏ, the linear tridiagonal system is solved for P̂, and
//!
//! ```text
//! δp = max(P̂, 0) − Pᵏ ,   Pᵏ⁺¹ = Pᵏ + ω_fluid δp
//! ```
//!
//! ω_fluid adapts inside the paper's range: it starts at
//! `fluid_relaxation`, is halved (down to `fluid_relaxation_min`) whenever
//! the update grows and regrows by 25 % after 20 shrinking updates. A fixed ω is not viable: with 1 % vapour at ambient
//! pressure (the default EOS) the storage term's pressure sensitivity makes
//! the gain of the frozen-density map ≈ 2·10³ for the lowest pressure mode at
//! 1 ms steps, so the relaxed iteration is stable only for ω ≲ 1e-3, while
//! ω = 5e-4 needs ~2·10⁴ iterations for the weakly coupled modes.
//!
//! The Couette term is central-differenced (face density = mean of the two
//! cells), as in the paper; the storage term uses the same θ/BDF2
//! coefficients as the Newton solver. It is kept as a cross-check and as the
//! benchmark baseline; it is slow by construction.
//!
//! `Solver`'s fields this file uses: `d`, `settings`, `p`, `h0`, `hist`, `w`.

use super::work::Work;
use super::{Ctx, Disc, H0Mode, Level, Outcome, Solver};
use crate::physics::estimate::Status;

impl Solver {
    pub(crate) fn reference_solve(&mut self, ctx: &Ctx) -> Outcome {
        let rs = self.settings.reference;
        let mut out = Outcome {
            status: Status::MaxIterations,
            iterations: 0,
            inner_iterations: 0,
            residual: f64::NAN,
            backtracks: 0,
        };
        if let H0Mode::Prescribed(h) = ctx.gap {
            let (_, it, conv) = self.picard(h, ctx);
            self.h0 = h;
            out.inner_iterations = it;
            out.iterations = 1;
            out.status = if !self.p.iter().all(|x| x.is_finite()) {
                Status::NonFinite
            } else if conv {
                Status::Converged
            } else {
                Status::MaxIterations
            };
            return out;
        }
        let mut h_a = self.h0;
        let (mut r_a, it, _) = self.picard(h_a, ctx);
        out.inner_iterations += it;
        let mut h_b = h_a * (1.0 + 1e-3);
        let (mut r_b, it, mut fluid_ok) = self.picard(h_b, ctx);
        out.inner_iterations += it;
        for k in 1..=rs.max_motion_iterations {
            out.iterations = k;
            if !(r_a.is_finite() && r_b.is_finite()) {
                out.status = Status::NonFinite;
                return out;
            }
            let denom = r_b - r_a;
            let h_new = if denom != 0.0 {
                h_b - r_b * (h_b - h_a) / denom
            } else {
                h_b
            };
            let mut h_next = h_b + rs.motion_relaxation * (h_new - h_b);
            h_next = h_next.clamp(0.5 * h_b, 2.0 * h_b);
            let eps = (h_next - h_b).abs() / h_b;
            out.residual = eps;
            h_a = h_b;
            r_a = r_b;
            h_b = h_next;
            let (r, it, ok) = self.picard(h_b, ctx);
            out.inner_iterations += it;
            r_b = r;
            fluid_ok = ok;
            if eps < rs.motion_tolerance {
                break;
            }
        }
        self.h0 = h_b;
        out.status = if !(r_b.is_finite() && self.p.iter().all(|x| x.is_finite())) {
            Status::NonFinite
        } else if out.residual < rs.motion_tolerance && fluid_ok {
            Status::Converged
        } else {
            Status::MaxIterations
        };
        out
    }

    /// Picard solve of the Reynolds equation at fixed h0. Returns the load
    /// residual ΔF (N), the iterations used and whether it converged.
    fn picard(&mut self, h0: f64, ctx: &Ctx) -> (f64, u32, bool) {
        let rs = self.settings.reference;
        let n = self.d.grid.n;
        let half_v = 0.5 * ctx.v;
        let mut converged = false;
        let mut iters = 0;
        let mut omega = Relaxation::new(rs.fluid_relaxation, rs.fluid_relaxation_min);
        for it in 1..=rs.max_fluid_iterations {
            iters = it;
            let (d, w) = (&self.d, &mut self.w);
            for i in 0..n {
                let s = d.eos.eval(self.p[i]);
                w.cells.rho[i] = s.rho;
                w.cells.gr[i] = s.rho / s.mu;
            }
            faces(d, w, h0, half_v);
            linear_rows(d, &self.hist, w, h0, ctx);
            thomas(w, n);
            let mut pmax = d.p_amb;
            let mut change: f64 = 0.0;
            for i in 0..n {
                let dp = w.tmp[i].max(0.0) - self.p[i];
                change = change.max(dp.abs());
                pmax = pmax.max(self.p[i].abs());
            }
            let om = omega.after(change);
            for i in 0..n {
                self.p[i] += om * (w.tmp[i].max(0.0) - self.p[i]);
            }
            if !change.is_finite() {
                return (f64::NAN, iters, false);
            }
            if change / pmax < rs.fluid_tolerance {
                converged = true;
                break;
            }
        }
        let df = self.load_residual(h0, ctx);
        (df, iters, converged)
    }

    /// The load residual ΔF (N) at h0 with the current pressures: the
    /// weighted net force − inertia.
    fn load_residual(&self, h0: f64, ctx: &Ctx) -> f64 {
        let d = &self.d;
        let dx = d.grid.dx;
        let n = d.grid.n;
        let bdx = d.grid.width * dx;
        let mut sum = 0.0;
        for i in 0..n {
            sum += self.p[i] - d.p_amb + d.gw.pressure(h0 + d.grid.g_cell[i]).0;
        }
        let f_net = bdx * sum - ctx.load;
        match ctx.time {
            Some((c, dt)) => {
                let acc = (h0 - 2.0 * self.hist[0].h0 + self.hist[1].h0) / (dt * dt);
                c.w[0] * f_net + c.w[1] * self.hist[0].f_net + c.w[2] * self.hist[1].f_net
                    - d.mass * acc
            }
            None => f_net,
        }
    }
}

/// The adaptive ω_fluid of the module doc: halved (down to its minimum)
/// whenever the update grows, regrown by 25 % (up to its start) after 20
/// shrinking updates.
struct Relaxation {
    omega: f64,
    start: f64,
    min: f64,
    last_change: f64,
    shrinking: u32,
}

impl Relaxation {
    fn new(start: f64, min: f64) -> Self {
        Self {
            omega: start,
            start,
            min,
            last_change: f64::INFINITY,
            shrinking: 0,
        }
    }

    /// ω for the update whose largest change is `change`.
    fn after(&mut self, change: f64) -> f64 {
        if change > self.last_change {
            self.omega = (0.5 * self.omega).max(self.min);
            self.shrinking = 0;
        } else {
            self.shrinking += 1;
            if self.shrinking >= 20 {
                self.omega = (1.25 * self.omega).min(self.start);
                self.shrinking = 0;
            }
        }
        self.last_change = change;
        self.omega
    }
}

/// The tridiagonal rows (`w.rows`) of the Reynolds equation linearised at
/// the frozen density: flux divergence, storage against the history levels
/// and the source, with ambient pressure at both edges.
fn linear_rows(d: &Disc, hist: &[Level; 2], w: &mut Work, h0: f64, ctx: &Ctx) {
    let n = d.grid.n;
    let dx = d.grid.dx;
    let w0 = ctx.w0();
    for i in 0..n {
        let (kl, kr) = (w.faces.dql[i], w.faces.dql[i + 1]);
        let mut rhs = -w0 * (w.faces.q[i + 1] - w.faces.q[i]);
        if let Some((c, dt)) = ctx.time {
            let hc = h0 + d.grid.g_cell[i];
            let inv_dt = 1.0 / dt;
            rhs -= dx
                * inv_dt
                * (c.a[0] * w.cells.rho[i] * hc
                    + c.a[1] * hist[0].rho_h[i]
                    + c.a[2] * hist[1].rho_h[i]);
            rhs -= c.w[1] * hist[0].div[i] + c.w[2] * hist[1].div[i];
        }
        if w.has_source {
            rhs += w.source[i];
        }
        if i == 0 {
            rhs += w0 * kl * d.p_amb;
        }
        if i + 1 == n {
            rhs += w0 * kr * d.p_amb;
        }
        w.rows.a[i] = if i == 0 { 0.0 } else { -w0 * kl };
        w.rows.b[i] = w0 * (kl + kr);
        w.rows.c[i] = if i + 1 == n { 0.0 } else { -w0 * kr };
        w.rows.r[i] = rhs;
    }
}

/// Face conductances K_f (stored in `w.faces.dql`) and Couette fluxes
/// (`w.faces.q`) at h0 from the cells' density and ρ/μ.
fn faces(d: &Disc, w: &mut Work, h0: f64, half_v: f64) {
    let n = d.grid.n;
    let dx = d.grid.dx;
    for f in 0..=n {
        let hf = h0 + d.grid.g_face[f];
        let inv_df = if f == 0 || f == n { 2.0 / dx } else { 1.0 / dx };
        let (phi, phis) = match &d.ff {
            Some(ff) => (ff.pressure(hf).0, ff.shear(hf).0),
            None => (1.0, 0.0),
        };
        let (rl, gl) = if f == 0 {
            (d.rho_edge, d.gr_edge)
        } else {
            (w.cells.rho[f - 1], w.cells.gr[f - 1])
        };
        let (rr, gr) = if f == n {
            (d.rho_edge, d.gr_edge)
        } else {
            (w.cells.rho[f], w.cells.gr[f])
        };
        w.faces.dql[f] = phi * hf * hf * hf * inv_df / 12.0 * 0.5 * (gl + gr);
        w.faces.q[f] = half_v * (hf + d.sigma * phis) * 0.5 * (rl + rr);
    }
}

/// Thomas's algorithm on the tridiagonal rows of `w` (n of them): P̂ into
/// `w.tmp`.
fn thomas(w: &mut Work, n: usize) {
    let mut prev_cp = 0.0;
    let mut prev = 0.0;
    for i in 0..n {
        let (ra, rb, rc, rr) = (w.rows.a[i], w.rows.b[i], w.rows.c[i], w.rows.r[i]);
        let m = rb - ra * prev_cp;
        prev_cp = rc / m;
        prev = (rr - ra * prev) / m;
        w.factors[i].cp = prev_cp;
        w.tmp[i] = prev;
    }
    for i in (0..n - 1).rev() {
        w.tmp[i] -= w.factors[i].cp * w.tmp[i + 1];
    }
}
