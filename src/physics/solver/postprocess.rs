//! From a solved state to an [`Estimate`]: forces, friction, COF, inertia,
//! diagnostics; and, when the step advances time, the new history level.

use super::assembly::assemble;
use super::{Ctx, H0Mode, Outcome, Solver};
use crate::physics::estimate::{Diagnostics, Estimate, Regime};
use crate::physics::scheme::StepCoefficients;

impl Solver {
    // ------------------------------------------------------------------
    // Post-processing
    // ------------------------------------------------------------------

    pub(super) fn finish(&mut self, ctx: &Ctx, out: Outcome, advance: bool) -> Estimate {
        let d = &self.d;
        let n = d.grid.n;
        let (b, dx) = (d.grid.width, d.grid.dx);
        let v = ctx.v;
        let mut sum_p = 0.0;
        let sum_asp = d.contact.pressure_sum(self.h0).0;
        let sum_area = d.contact.area_sum(self.h0);
        let mut visc = 0.0;
        let mut p_max = f64::NEG_INFINITY;
        let mut cav = 0usize;
        // After a converged Newton update the last assembly point differs from
        // the state by the update (≤ tolerance): first-order corrections of
        // the stored properties are exact to O(tolerance²).
        let lin = self.w.linearised.take().is_some();
        // Vapour fraction α > ½ ⇔ ρ < (ρl + ρg)/2 (α = (ρl − ρ)/(ρl − ρg)).
        let rho_half = 0.5 * (d.eos.rho_l + d.eos.rho_g);
        let p = &self.p[..n];
        let gc = &d.grid.g_cell[..n];
        let tmp = &mut self.w.tmp[..n];
        let vdx = v * dx;
        for i in 0..n {
            let h = self.h0 + gc[i];
            let pi = p[i];
            let (rho, mu) = if lin {
                let c = &self.w.cells[i];
                let dp = self.w.dp[i];
                (c.rho + c.drho * dp, c.mu + c.dmu * dp)
            } else {
                let s = d.eos.eval(pi);
                (s.rho, s.mu)
            };
            sum_p += pi - d.p_amb;
            // Face pressures: the mean of the neighbours, p_amb at the edges;
            // p_r − p_l = ½ (p_(i+1) − p_(i−1)).
            let pl = if i == 0 {
                d.p_amb
            } else {
                0.5 * (p[i - 1] + pi)
            };
            let pr = if i + 1 == n {
                d.p_amb
            } else {
                0.5 * (pi + p[i + 1])
            };
            visc += -0.5 * h * (pr - pl) + mu * vdx / h;
            p_max = p_max.max(pi);
            cav += (rho < rho_half) as usize;
            tmp[i] = rho * h;
        }
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
        let contact_friction = f_visc + d.mu_bl * f_asp * (v / d.v_reg).tanh();
        // Zero drivetrain terms leave the contact's force untouched (bit for bit).
        let friction = if d.drivetrain.is_zero() {
            contact_friction
        } else {
            contact_friction + d.drivetrain.force(v, ctx.load, d.v_reg)
        };
        let cof = (f_visc.abs() + d.mu_bl * f_asp) / load;
        let share = f_asp / load;
        let load_residual = match ctx.gap {
            H0Mode::Balance => load_res,
            H0Mode::Prescribed(_) => f64::NAN,
        };
        if advance {
            self.time += ctx.time.map_or(0.0, |(_, dt)| dt);
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
                    lvl.div[i] = self.w.faces[i + 1].q - self.w.faces[i].q;
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
