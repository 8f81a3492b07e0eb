//! From a solved state to an [`Estimate`]: forces, friction, COF, inertia,
//! diagnostics; and, when the step advances time, the new history level.

use super::assembly::assemble;
use super::lanes::{lane_max, lane_sum};
use super::{Ctx, H0Mode, Outcome, Solver};
use crate::physics::estimate::{Diagnostics, Estimate, Regime};
use crate::physics::scheme::StepCoefficients;

impl Solver {
    // ------------------------------------------------------------------
    // Post-processing
    // ------------------------------------------------------------------

    #[inline(always)]
    pub(super) fn finish(&mut self, ctx: &Ctx, out: Outcome, advance: bool) -> Estimate {
        let d = &self.d;
        let n = d.grid.n;
        let (b, dx) = (d.grid.width, d.grid.dx);
        let v = ctx.v;
        let sum_asp = d.contact.pressure_sum(self.h0).0;
        let sum_area = d.contact.area_sum(self.h0);
        // After a converged Newton update the last assembly point differs from
        // the state by the update (≤ tolerance): first-order corrections of
        // the stored properties are exact to O(tolerance²).
        let lin = self.w.linearised.take().is_some();
        let p = &self.p[..n];
        let gc = &d.grid.g_cell[..n];
        let (rho, mu) = (&mut self.w.tmp[..n], &mut self.w.shear[..n]);
        if lin {
            let c = &self.w.cells;
            let (c_rho, c_drho, c_mu, c_dmu) = (&c.rho[..n], &c.drho[..n], &c.mu[..n], &c.dmu[..n]);
            let dp = &self.w.dp[..n];
            for i in 0..n {
                rho[i] = c_rho[i] + c_drho[i] * dp[i];
                mu[i] = c_mu[i] + c_dmu[i] * dp[i];
            }
        } else {
            for i in 0..n {
                let s = d.eos.eval(p[i]);
                rho[i] = s.rho;
                mu[i] = s.mu;
            }
        }
        // Vapour fraction α > ½ ⇔ ρ < (ρl + ρg)/2 (α = (ρl − ρ)/(ρl − ρg)).
        let rho_half = 0.5 * (d.eos.rho_l + d.eos.rho_g);
        let cav = rho.iter().filter(|&&r| r < rho_half).count();
        // Shear force per cell, −½ h (p_r − p_l) + μ v Δx / h, with the face
        // pressures the mean of the neighbours (p_amb at the edges); into
        // `mu`, and ρ h into `rho` (the new level's storage).
        let vdx = v * dx;
        let edge = |i: usize, pl: f64, pr: f64, rho: &mut [f64], mu: &mut [f64]| {
            let h = self.h0 + gc[i];
            mu[i] = -0.5 * h * (pr - pl) + mu[i] * vdx / h;
            rho[i] *= h;
        };
        let (first_l, first_r) = (d.p_amb, if n > 1 { 0.5 * (p[0] + p[1]) } else { d.p_amb });
        let (last_l, last_r) = (
            if n > 1 {
                0.5 * (p[n - 2] + p[n - 1])
            } else {
                d.p_amb
            },
            d.p_amb,
        );
        for i in 1..n.saturating_sub(1) {
            let h = self.h0 + gc[i];
            let (pl, pr) = (0.5 * (p[i - 1] + p[i]), 0.5 * (p[i] + p[i + 1]));
            mu[i] = -0.5 * h * (pr - pl) + mu[i] * vdx / h;
            rho[i] *= h;
        }
        edge(0, first_l, first_r, rho, mu);
        if n > 1 {
            edge(n - 1, last_l, last_r, rho, mu);
        }
        let visc = lane_sum(mu, 0.0);
        let sum_p = lane_sum(p, d.p_amb);
        let p_max = lane_max(p);
        // The film's forces on the reference width (its load is the load
        // per reference width: f_net and the history stay in its terms).
        let f_hyd = b * dx * sum_p;
        let f_asp = b * dx * sum_asp;
        let f_visc = b * visc;
        let f_net = f_hyd + f_asp - ctx.load;
        let load = ctx.load;
        let (inertia, load_res) = match ctx.time {
            Some((c, dt)) if self.hist_len >= 1 => {
                let h1 = self.hist[0].h0;
                let h2 = if self.hist_len >= 2 {
                    self.hist[1].h0
                } else {
                    h1
                };
                let acc = (self.h0 - 2.0 * h1 + h2) / (dt * dt);
                let inertia = d.mass * acc;
                let weighted =
                    c.w[0] * f_net + c.w[1] * self.hist[0].f_net + c.w[2] * self.hist[1].f_net;
                (inertia, (inertia - weighted).abs() / load)
            }
            _ => (0.0, f_net.abs() / load),
        };
        // A soft contact's forces on its width at this load (w = 1: rigid,
        // and every force below is the film's, bit for bit).
        let w = self.width_scale;
        let (f_hyd, f_asp, f_visc, inertia) = (w * f_hyd, w * f_asp, w * f_visc, w * inertia);
        let contact_friction = if d.presliding.is_on() {
            // Gross sliding's level, through the contact's compliance.
            let level = f_visc + d.mu_bl * f_asp * crate::physics::presliding::sgn(v);
            let p = d.presliding;
            match (advance, ctx.time) {
                (true, Some((_, dt))) => {
                    let (z, f) = p.advance(self.bristle, level, v, dt);
                    self.bristle = z;
                    f
                }
                // A steady state (or a solve that does not advance time):
                // the displacement of steady sliding.
                _ => {
                    if ctx.time.is_none() {
                        self.bristle = p.steady_displacement(level);
                    }
                    level
                }
            }
        } else {
            f_visc + d.mu_bl * f_asp * (v / d.v_reg).tanh()
        };
        // Zero drivetrain terms leave the contact's force untouched (bit for bit).
        // The load itself (the film's load is per reference width).
        let load = w * load;
        let friction = if d.drivetrain.is_zero() {
            contact_friction
        } else {
            contact_friction + d.drivetrain.force(v, load, d.v_reg)
        };
        let cof = (f_visc.abs() + d.mu_bl * f_asp) / load;
        let share = f_asp / load;
        let load_residual = match ctx.gap {
            H0Mode::Balance => load_res,
            H0Mode::Prescribed(_) => f64::NAN,
        };
        if advance {
            if ctx.time.is_some() {
                self.advance_time();
            }
            // The θ scheme needs this level's flux divergence.
            let needs_div = ctx.time.is_some_and(|(c, _)| c.uses_force_history())
                || StepCoefficients::for_scheme(self.settings.scheme).uses_force_history();
            self.hist.swap(0, 1);
            self.w.hist_term_valid = None;
            let lvl = &mut self.hist[0];
            lvl.rho_h.copy_from_slice(&self.w.tmp);
            lvl.f_net = f_net;
            lvl.h0 = self.h0;
            self.hist_len = (self.hist_len + 1).min(2);
            if needs_div {
                let c_steady = Ctx {
                    time: None,
                    gap: H0Mode::Prescribed(self.h0),
                    ..*ctx
                };
                assemble(
                    &self.d,
                    &self.hist,
                    &self.p,
                    self.h0,
                    &c_steady,
                    &mut self.w,
                );
                let lvl = &mut self.hist[0];
                for i in 0..n {
                    lvl.div[i] = self.w.faces.q[i + 1] - self.w.faces.q[i];
                }
            }
        }
        Estimate {
            time: self.time,
            velocity: v,
            load,
            h0: self.h0,
            h_min: self.h0 + self.d.grid.g_min,
            hydrodynamic_force: f_hyd,
            asperity_force: f_asp,
            viscous_force: f_visc,
            friction_force: friction,
            contact_friction_force: contact_friction,
            cof,
            asperity_load_share: share,
            inertia_force: inertia,
            contact_area_ratio: sum_area / n as f64,
            max_pressure: p_max,
            cavitated_fraction: cav as f64 / n as f64,
            regime: Regime::from_asperity_share(share),
            status: out.status,
            diagnostics: Diagnostics {
                iterations: out.iterations,
                inner_iterations: out.inner_iterations,
                residual: out.residual,
                load_residual,
                backtracks: out.backtracks,
                film_floor_active: false,
                substeps: 0,
            },
        }
    }
}
