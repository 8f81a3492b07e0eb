//! From a solved state to an [`Estimate`]: forces, friction, COF, inertia,
//! diagnostics; and, when the step advances time, the new history level.
//!
//! `Solver`'s fields this file uses: `d`, `terms`, `settings`, `p`, `h0`, `time`, `hist`, `hist_len`, `w`, `states`.

use super::assembly::assemble;
use super::lanes::{lane_max, lane_sum};
use super::work::CellColumns;
use super::{Ctx, Disc, H0Mode, Outcome, Solver};
use crate::physics::estimate::{Diagnostics, Estimate, Regime};
use crate::physics::scheme::StepCoefficients;
use crate::physics::terms::BristleMove;

/// The film's forces on the reference width at the solved state.
struct FilmForces {
    hydrodynamic: f64,
    asperity: f64,
    viscous: f64,
    /// f_hyd + f_asp − load: what the load balance drives to zero.
    net: f64,
    max_pressure: f64,
    /// Cells whose vapour fraction exceeds ½.
    cavitated: usize,
}

/// ρ and μ per cell at the solved pressure, into `rho` and `mu`. After a
/// converged Newton update the last assembly point differs from the state
/// by the update (≤ tolerance): first-order corrections of the stored
/// properties (`lin`) are exact to O(tolerance²).
#[inline(always)]
fn cell_properties(
    d: &Disc,
    (c, dp): (&CellColumns, &[f64]),
    p: &[f64],
    lin: bool,
    rho: &mut [f64],
    mu: &mut [f64],
) {
    let n = p.len();
    if lin {
        let (c_rho, c_drho, c_mu, c_dmu) = (&c.rho[..n], &c.drho[..n], &c.mu[..n], &c.dmu[..n]);
        let dp = &dp[..n];
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
}

/// Shear force per cell, −½ h (p_r − p_l) + μ v Δx / h, with the face
/// pressures the mean of the neighbours (p_amb at the edges); into `mu`
/// (which holds μ), and ρ h into `rho` (which holds ρ; the new level's
/// storage).
#[inline(always)]
fn shear_per_cell(d: &Disc, h0: f64, v: f64, p: &[f64], rho: &mut [f64], mu: &mut [f64]) {
    let n = p.len();
    let gc = &d.grid.g_cell[..n];
    let vdx = v * d.grid.dx;
    let edge = |i: usize, pl: f64, pr: f64, rho: &mut [f64], mu: &mut [f64]| {
        let h = h0 + gc[i];
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
        let h = h0 + gc[i];
        let (pl, pr) = (0.5 * (p[i - 1] + p[i]), 0.5 * (p[i] + p[i + 1]));
        mu[i] = -0.5 * h * (pr - pl) + mu[i] * vdx / h;
        rho[i] *= h;
    }
    edge(0, first_l, first_r, rho, mu);
    if n > 1 {
        edge(n - 1, last_l, last_r, rho, mu);
    }
}

impl Solver {
    // ------------------------------------------------------------------
    // Post-processing
    // ------------------------------------------------------------------

    /// The film's forces at the solved state; ρ h per cell is left in
    /// `w.tmp` (the new history level's storage).
    #[inline(always)]
    fn film_forces(&mut self, ctx: &Ctx) -> FilmForces {
        let d = &self.d;
        let n = d.grid.n;
        let (b, dx) = (d.grid.width, d.grid.dx);
        let lin = self.w.linearised.take().is_some();
        let p = &self.p[..n];
        let (rho, mu) = (&mut self.w.tmp[..n], &mut self.w.shear[..n]);
        cell_properties(d, (&self.w.cells, &self.w.dp), p, lin, rho, mu);
        // Vapour fraction α > ½ ⇔ ρ < (ρl + ρg)/2 (α = (ρl − ρ)/(ρl − ρg)).
        let rho_half = 0.5 * (d.eos.rho_l + d.eos.rho_g);
        let cavitated = rho.iter().filter(|&&r| r < rho_half).count();
        shear_per_cell(d, self.h0, ctx.v, p, rho, mu);
        let hydrodynamic = b * dx * lane_sum(p, d.p_amb);
        let asperity = b * dx * d.contact.pressure_sum(self.h0).0;
        FilmForces {
            hydrodynamic,
            asperity,
            viscous: b * lane_sum(mu, 0.0),
            net: hydrodynamic + asperity - ctx.load,
            max_pressure: lane_max(p),
            cavitated,
        }
    }

    /// The inertia force and the load balance's residual (relative to the
    /// load): the θ scheme's weighted force history against m ḧ0.
    #[inline(always)]
    fn inertia_and_residual(&self, ctx: &Ctx, f_net: f64) -> (f64, f64) {
        match ctx.time {
            Some((c, dt)) if self.hist_len >= 1 => {
                let h1 = self.hist[0].h0;
                let h2 = if self.hist_len >= 2 {
                    self.hist[1].h0
                } else {
                    h1
                };
                let acc = (self.h0 - 2.0 * h1 + h2) / (dt * dt);
                let inertia = self.d.mass * acc;
                let weighted =
                    c.w[0] * f_net + c.w[1] * self.hist[0].f_net + c.w[2] * self.hist[1].f_net;
                (inertia, (inertia - weighted).abs() / ctx.load)
            }
            _ => (0.0, f_net.abs() / ctx.load),
        }
    }

    /// The contact's friction and the total at `load` (N) from the film's
    /// viscous and asperity forces
    /// ([`crate::physics::terms::FrictionTerms::friction`]); the pre-sliding
    /// displacement advances when the step advances time, takes its steady
    /// value in a steady state, and is held otherwise.
    #[inline(always)]
    fn friction(&mut self, ctx: &Ctx, load: f64, forces: (f64, f64), advance: bool) -> (f64, f64) {
        let how = match (advance, ctx.time) {
            (true, Some((_, dt))) => BristleMove::Step(dt),
            (_, None) => BristleMove::Steady,
            _ => BristleMove::Hold,
        };
        self.terms
            .friction((ctx.v, load), forces, &mut self.states, how)
    }

    /// Make the solved state the newest history level (ρ h from `w.tmp`),
    /// with its flux divergence when the θ scheme needs it.
    fn push_history(&mut self, ctx: &Ctx, f_net: f64) {
        let n = self.d.grid.n;
        if ctx.time.is_some() {
            self.advance_time();
        }
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

    /// The estimate of the solved state; when `advance`, the state becomes
    /// the newest history level (and time moves on when the step has one).
    #[inline(always)]
    pub(super) fn finish(&mut self, ctx: &Ctx, out: Outcome, advance: bool) -> Estimate {
        let n = self.d.grid.n;
        let v = ctx.v;
        let sum_area = self.d.contact.area_sum(self.h0);
        let film = self.film_forces(ctx);
        let (inertia, load_res) = self.inertia_and_residual(ctx, film.net);
        // A soft contact's forces on its width at this load (w = 1: rigid,
        // and every force below is the film's, bit for bit).
        let w = self.states.soft_width.0;
        let (f_hyd, f_asp, f_visc, inertia) = (
            w * film.hydrodynamic,
            w * film.asperity,
            w * film.viscous,
            w * inertia,
        );
        // The load itself (the film's load is per reference width).
        let load = w * ctx.load;
        let (contact_friction, friction) = self.friction(ctx, load, (f_visc, f_asp), advance);
        let d = &self.d;
        let (cof, boundary_rate_cof) = self.terms.cof(v, f_visc, f_asp, contact_friction, load);
        let share = f_asp / load;
        let load_residual = match ctx.gap {
            H0Mode::Balance => load_res,
            H0Mode::Prescribed(_) => f64::NAN,
        };
        let h_min = self.h0 + d.grid.g_min;
        if advance {
            self.push_history(ctx, film.net);
        }
        Estimate {
            time: self.time,
            velocity: v,
            load,
            h0: self.h0,
            h_min,
            hydrodynamic_force: f_hyd,
            asperity_force: f_asp,
            viscous_force: f_visc,
            friction_force: friction,
            contact_friction_force: contact_friction,
            cof,
            boundary_rate_cof,
            asperity_load_share: share,
            inertia_force: inertia,
            contact_area_ratio: sum_area / n as f64,
            max_pressure: film.max_pressure,
            cavitated_fraction: film.cavitated as f64 / n as f64,
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
