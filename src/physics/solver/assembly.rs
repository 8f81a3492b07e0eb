//! Residual and Jacobian of one Newton iterate (MODEL.md §2–§5, finite volumes).
//!
//! Three passes over the cells: mixture properties of each cell, the mass
//! flux through each face with its derivatives, then the rows of the bordered
//! system (tridiagonal in p, a dense column ∂R/∂h0) and the load-balance row
//! G. See the parent module for the discrete equations.

use super::bordered::Factor;
use super::{Ctx, Disc, H0Mode, Level};
use crate::physics::scheme::StepCoefficients;

/// Mixture properties of one cell at the current iterate.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CellProps {
    pub rho: f64,
    pub drho: f64,
    /// ρ/μ and its pressure derivative.
    pub gr: f64,
    pub dgr: f64,
    pub mu: f64,
    pub dmu: f64,
}

/// Mass flux through one face and its derivatives.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FaceFlux {
    pub q: f64,
    pub dql: f64,
    pub dqr: f64,
    pub dqh: f64,
}

/// One row of the bordered system: tridiagonal (a, b, c), border column, residual.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Row {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub col: f64,
    pub r: f64,
}

/// Work arrays (allocated once).
#[derive(Debug, Clone)]
pub(crate) struct Work {
    pub cells: Vec<CellProps>,
    pub faces: Vec<FaceFlux>,
    pub rows: Vec<Row>,
    pub g: f64,
    pub dgdh: f64,
    pub f_net: f64,
    pub factors: Vec<Factor>,
    pub schur: f64,
    pub c_row: f64,
    pub balance: bool,
    /// Scratch of length N (post-processing, Picard).
    pub tmp: Vec<f64>,
    pub dp: Vec<f64>,
    pub dbar: Vec<f64>,
    pub p_trial: Vec<f64>,
    pub p_backup: Vec<f64>,
    pub p_anchor: Vec<f64>,
    pub source: Vec<f64>,
    pub has_source: bool,
    /// Σ_k≥1 (history storage and flux terms) per cell, valid for the
    /// coefficients it was computed with (reset when the history changes).
    pub hist_term: Vec<f64>,
    #[allow(clippy::type_complexity)]
    pub hist_term_valid: Option<Option<([f64; 3], [f64; 3], f64)>>,
    /// Set when the state is the last assembly point plus the update
    /// (`dp`, Δh0): post-processing then linearises instead of re-evaluating.
    pub linearised: Option<f64>,
}

impl Work {
    pub(super) fn new(n: usize) -> Self {
        Self {
            cells: vec![CellProps::default(); n],
            faces: vec![FaceFlux::default(); n + 1],
            rows: vec![Row::default(); n],
            g: 0.0,
            dgdh: 0.0,
            f_net: 0.0,
            factors: vec![Factor::default(); n],
            schur: 0.0,
            c_row: 0.0,
            balance: true,
            tmp: vec![0.0; n],
            dp: vec![0.0; n],
            dbar: vec![0.0; n],
            p_trial: vec![0.0; n],
            p_backup: vec![0.0; n],
            p_anchor: vec![0.0; n],
            source: vec![0.0; n],
            has_source: false,
            hist_term: vec![0.0; n],
            hist_term_valid: None,
            linearised: None,
        }
    }
}

/// What a face flux needs besides the two neighbouring states.
struct FluxCtx<'a> {
    d: &'a Disc,
    half_v: f64,
    upwind_left: bool,
}

impl FluxCtx<'_> {
    /// Mass flux through a face of thickness `hf` between (pl, l) and (pr, r).
    #[inline(always)]
    fn flux(
        &self,
        hf: f64,
        inv_df: f64,
        pl: f64,
        l: &CellProps,
        pr: f64,
        r: &CellProps,
    ) -> FaceFlux {
        let d = self.d;
        let (phi, dphi, phis, dphis) = match &d.ff {
            Some(ff) => {
                let (a, b) = ff.pressure(hf);
                let (c, e) = ff.shear(hf);
                (a, b, c, e)
            }
            None => (1.0, 0.0, 0.0, 0.0),
        };
        let h2 = hf * hf;
        let k = inv_df * (1.0 / 12.0);
        let cf = phi * h2 * hf * k;
        let dcf = (dphi * hf + 3.0 * phi) * h2 * k;
        let ch = hf + d.sigma * phis;
        let dch = 1.0 + d.sigma * dphis;
        let gbar = 0.5 * (l.gr + r.gr);
        let dpf = pr - pl;
        let cg = cf * gbar;
        let mut out = FaceFlux {
            q: -cg * dpf,
            dql: cg - 0.5 * cf * l.dgr * dpf,
            dqr: -cg - 0.5 * cf * r.dgr * dpf,
            dqh: -dcf * gbar * dpf,
        };
        let hv = self.half_v;
        if self.upwind_left {
            out.q += hv * ch * l.rho;
            out.dqh += hv * dch * l.rho;
            out.dql += hv * ch * l.drho;
        } else {
            out.q += hv * ch * r.rho;
            out.dqh += hv * dch * r.rho;
            out.dqr += hv * ch * r.drho;
        }
        out
    }
}

/// Assemble residual and Jacobian at (p, h0). Returns false when anything is
/// non-finite.
pub(crate) fn assemble(
    d: &Disc,
    hist: &[Level; 2],
    p: &[f64],
    h0: f64,
    ctx: &Ctx,
    w: &mut Work,
) -> bool {
    let n = d.grid.n;
    let dx = d.grid.dx;
    let inv_dx = 1.0 / dx;
    let p = &p[..n];
    // Pass 1: cell properties (independent per cell, so the exp latencies
    // overlap; fusing the passes was measured slower).
    let cells = &mut w.cells[..n];
    for (c, &pi) in cells.iter_mut().zip(p) {
        let s = d.eos.cell(pi);
        *c = CellProps {
            rho: s.rho,
            drho: s.drho,
            gr: s.gr,
            dgr: s.dgr,
            mu: s.mu,
            dmu: s.dmu,
        };
    }
    // Pass 2: face fluxes.
    let boundary = CellProps {
        rho: d.rho_b,
        drho: 0.0,
        gr: d.gr_b,
        dgr: 0.0,
        ..CellProps::default()
    };
    let fx = FluxCtx {
        d,
        half_v: 0.5 * ctx.v,
        upwind_left: ctx.v >= 0.0,
    };
    let faces = &mut w.faces[..=n];
    let gf = &d.grid.g_face[..=n];
    faces[0] = fx.flux(
        h0 + gf[0],
        2.0 * inv_dx,
        d.p_amb,
        &boundary,
        p[0],
        &cells[0],
    );
    faces[n] = fx.flux(
        h0 + gf[n],
        2.0 * inv_dx,
        p[n - 1],
        &cells[n - 1],
        d.p_amb,
        &boundary,
    );
    for (((fc, g), cw), pw) in faces[1..n]
        .iter_mut()
        .zip(&gf[1..n])
        .zip(cells.windows(2))
        .zip(p.windows(2))
    {
        *fc = fx.flux(h0 + g, inv_dx, pw[0], &cw[0], pw[1], &cw[1]);
    }
    // Pass 3: rows.
    let w0 = ctx.w0();
    let (coef, inv_dt) = match ctx.time {
        Some((c, dt)) => (c, 1.0 / dt),
        None => (
            StepCoefficients {
                a: [0.0; 3],
                w: [1.0, 0.0, 0.0],
            },
            0.0,
        ),
    };
    let st = dx * inv_dt;
    let sa0 = st * coef.a[0];
    let (h1, h2) = (&hist[0], &hist[1]);
    let key = Some(ctx.time.map(|(c, dt)| (c.a, c.w, dt)));
    if w.hist_term_valid != key {
        // The history part of the storage and flux terms is fixed in a step.
        for (i, t) in w.hist_term.iter_mut().enumerate() {
            *t = st * (coef.a[1] * h1.rho_h[i] + coef.a[2] * h2.rho_h[i])
                + coef.w[1] * h1.div[i]
                + coef.w[2] * h2.div[i];
        }
        w.hist_term_valid = key;
    }
    let rows = &mut w.rows[..n];
    let gc = &d.grid.g_cell[..n];
    let hist_term = &w.hist_term[..n];
    let source = &w.source[..n];
    let has_source = w.has_source;
    let mut sum_p = 0.0;
    let mut finite = true;
    for (i, (((row, fw), c), (&g, &pi))) in rows
        .iter_mut()
        .zip(faces.windows(2))
        .zip(cells.iter())
        .zip(gc.iter().zip(p))
        .enumerate()
    {
        let hc = h0 + g;
        let (fl, fr) = (&fw[0], &fw[1]);
        let mut r = w0 * (fr.q - fl.q) + sa0 * c.rho * hc + hist_term[i];
        if has_source {
            r -= source[i];
        }
        let col = w0 * (fr.dqh - fl.dqh) + sa0 * c.rho;
        *row = Row {
            a: -w0 * fl.dql,
            b: w0 * (fr.dql - fl.dqr) + sa0 * c.drho * hc,
            c: w0 * fr.dqr,
            col,
            r,
        };
        sum_p += pi - d.p_amb;
        finite &= (r + col).is_finite();
    }
    rows[0].a = 0.0;
    rows[n - 1].c = 0.0;
    let (sum_asp, sum_dasp) = d.contact.pressure_sum(h0);
    let bdx = d.grid.width * dx;
    let f_net = bdx * (sum_p + sum_asp) - ctx.load;
    w.f_net = f_net;
    match ctx.time {
        Some((c, dt)) => {
            let inv_dt2 = 1.0 / (dt * dt);
            w.g = d.mass * (h0 - 2.0 * h1.h0 + h2.h0) * inv_dt2
                - (c.w[0] * f_net + c.w[1] * h1.f_net + c.w[2] * h2.f_net);
            w.dgdh = d.mass * inv_dt2 - c.w[0] * bdx * sum_dasp;
            w.c_row = -c.w[0] * bdx;
        }
        None => {
            w.g = -f_net;
            w.dgdh = -bdx * sum_dasp;
            w.c_row = -bdx;
        }
    }
    w.balance = ctx.gap == H0Mode::Balance;
    finite && w.g.is_finite()
}

#[cfg(test)]
mod jacobian_tests {
    //! The analytic Jacobian equals central finite differences of the
    //! residual, for random states (property test).
    use super::super::Solver;
    use super::*;
    use crate::physics::params::{ModelParams, Pocket, Profile, SolverSettings, TimeScheme};
    use proptest::prelude::*;

    fn residual(s: &mut Solver, p: &[f64], h0: f64, ctx: &Ctx) -> (Vec<f64>, f64) {
        assemble(&s.d, &s.hist, p, h0, ctx, &mut s.w);
        (s.w.rows.iter().map(|r| r.r).collect(), s.w.g)
    }

    #[allow(clippy::too_many_arguments)]
    fn check(
        profile: Profile,
        pocket: bool,
        flow_factors: bool,
        sigma: f64,
        p: Vec<f64>,
        h0: f64,
        v: f64,
        theta: bool,
    ) {
        let mut m = ModelParams::default();
        m.geometry.profile = profile;
        if pocket {
            m.geometry.pockets.push(Pocket {
                start: 0.02,
                width: 0.011,
                depth: 4e-6,
            });
        }
        m.roughness.flow_factors = flow_factors;
        m.roughness.sigma = sigma;
        let st = SolverSettings {
            cells: p.len(),
            scheme: if theta {
                TimeScheme::PAPER
            } else {
                TimeScheme::Bdf2
            },
            ..Default::default()
        };
        let mut s = Solver::new(&m, &st).unwrap();
        s.initialize_steady(0.1, 20_000.0);
        let coef = StepCoefficients::for_scheme(st.scheme);
        let ctx = Ctx {
            v,
            load: 20_000.0,
            time: Some((coef, st.dt)),
            gap: H0Mode::Balance,
        };
        assemble(&s.d, &s.hist, &p, h0, &ctx, &mut s.w);
        let rows = s.w.rows.clone();
        let (c_row, dgdh) = (s.w.c_row, s.w.dgdh);
        // Magnitude of the terms of G, for its rounding error.
        let bdx = s.d.grid.width * s.d.grid.dx;
        let g_mag = bdx * p.iter().map(|x| x.abs()).sum::<f64>()
            + bdx * s.d.contact.pressure_sum(h0).0
            + ctx.load
            + s.d.mass * h0 / (st.dt * st.dt);
        let n = p.len();
        let scale: Vec<f64> = rows
            .iter()
            .map(|r| r.a.abs().max(r.b.abs()).max(r.c.abs()) + 1e-300)
            .collect();
        // Magnitude of the terms of each mass residual (storage levels and
        // face fluxes), for the rounding error of a difference quotient.
        let g_max = s.d.grid.g_cell.iter().cloned().fold(0.0, f64::max);
        let storage = s.d.grid.dx / st.dt * 4.0 * s.d.eos.rho_l * (h0 + g_max);
        let r_mag: Vec<f64> = (0..n)
            .map(|i| storage + s.w.faces[i].q.abs() + s.w.faces[i + 1].q.abs())
            .collect();
        let close = |fd: f64, an: f64, sc: f64, round: f64, what: &str| {
            assert!(
                (fd - an).abs() <= 1e-5 * (an.abs() + sc) + round,
                "{what}: finite difference {fd:e} vs analytic {an:e}"
            );
        };
        for j in 0..n {
            let h = 1e-6 * p[j].abs().max(1e5);
            let (mut pp, mut pm) = (p.clone(), p.clone());
            pp[j] += h;
            pm[j] -= h;
            let (rp, gp) = residual(&mut s, &pp, h0, &ctx);
            let (rm, gm) = residual(&mut s, &pm, h0, &ctx);
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                let an = if i == j {
                    rows[i].b
                } else if i + 1 == j {
                    rows[i].c
                } else if j + 1 == i {
                    rows[i].a
                } else {
                    0.0
                };
                let round = 8.0 * f64::EPSILON * r_mag[i] / h;
                close(fd, an, scale[i], round, &format!("dR{i}/dp{j}"));
            }
            let fd = (gp - gm) / (2.0 * h);
            assert!(
                (fd - c_row).abs() <= 1e-5 * c_row.abs() + 8.0 * f64::EPSILON * g_mag / h,
                "dG/dp{j}: finite difference {fd:e} vs analytic {c_row:e}"
            );
        }
        let hh = 1e-7 * h0;
        let (rp, gp) = residual(&mut s, &p, h0 + hh, &ctx);
        let (rm, gm) = residual(&mut s, &p, h0 - hh, &ctx);
        for i in 0..n {
            let col_scale = rows.iter().map(|r| r.col.abs()).fold(0.0, f64::max);
            let round = 8.0 * f64::EPSILON * r_mag[i] / hh;
            close(
                (rp[i] - rm[i]) / (2.0 * hh),
                rows[i].col,
                col_scale,
                round,
                &format!("dR{i}/dh0"),
            );
        }
        let fd = (gp - gm) / (2.0 * hh);
        assert!(
            (fd - dgdh).abs() <= 1e-5 * dgdh.abs() + 8.0 * f64::EPSILON * g_mag / hh,
            "dG/dh0: finite difference {fd:e} vs analytic {dgdh:e}"
        );
    }

    fn profile() -> impl Strategy<Value = Profile> {
        prop_oneof![
            (5e-6..40e-6f64).prop_map(|depth| Profile::Parabolic { depth }),
            (1e-6..20e-6f64).prop_map(|depth| Profile::Linear { depth }),
            Just(Profile::Flat),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn jacobian_matches_finite_differences(
            profile in profile(),
            pocket in any::<bool>(),
            p in prop::collection::vec(prop_oneof![2e3..1.2e5f64, 1e5..4e6f64], 6..20),
            h0 in 8e-6..30e-6f64,
            v in -3.0..3.0f64,
            theta in any::<bool>(),
        ) {
            check(profile, pocket, false, 5e-6, p, h0, v, theta);
        }

        #[test]
        fn jacobian_with_flow_factors_matches_finite_differences(
            thick in any::<bool>(),
            p in prop::collection::vec(prop_oneof![2e3..1.2e5f64, 1e5..4e6f64], 6..20),
            h0f in 0.0..1.0f64,
            v in -3.0..3.0f64,
        ) {
            // Stay inside one branch of Table A1's φs (it jumps at H = 5).
            let (sigma, h0) = if thick { (1e-6, 6e-6 + 20e-6 * h0f) } else { (5e-6, 3e-6 + 20e-6 * h0f * 0.05) };
            check(Profile::Flat, false, true, sigma, p, h0, v, false);
        }
    }
}
