//! Residual and Jacobian of one Newton iterate (docs/model.md §2–§5, finite volumes).
//!
//! Three passes over the cells: mixture properties of each cell (in
//! `cell_pass.rs`), the mass flux through each face with its derivatives,
//! then the rows of the bordered system (tridiagonal in p, a dense column
//! ∂R/∂h0) and the load-balance row G. See the parent module for the
//! discrete equations.

use super::cell_pass::cell_pass;
use super::flux::muscl_pass;
use super::lanes::{all_finite, lane_sum};
use super::work::{CellColumns, CellProps, FaceColumns, FaceFlux, RowColumns, Work};
use super::{Ctx, Disc, H0Mode, Level};
use crate::physics::scheme::StepCoefficients;
use crate::physics::settings::CouetteFlux;

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
/// non-finite. (Always inlined: it is compiled into each instruction-set
/// version of the step, see `step.rs`.)
#[inline(always)]
pub(crate) fn assemble(
    d: &Disc,
    hist: &[Level; 2],
    p: &[f64],
    h0: f64,
    ctx: &Ctx,
    w: &mut Work,
) -> bool {
    let n = d.grid.n;
    let p = &p[..n];
    cell_pass(d, p, w);
    face_pass(d, p, h0, ctx, w);
    let rows_finite = row_pass(d, hist, h0, ctx, w);
    let g_finite = balance_row(d, hist, p, h0, ctx, w);
    rows_finite && g_finite
}

/// The load-balance row: G, ∂G/∂h0 and the uniform ∂G/∂p (`w.c_row`), with
/// the net force. Returns false when G is not finite.
#[inline(always)]
pub(super) fn balance_row(
    d: &Disc,
    hist: &[Level; 2],
    p: &[f64],
    h0: f64,
    ctx: &Ctx,
    w: &mut Work,
) -> bool {
    let sum_p = lane_sum(p, d.p_amb);
    let (sum_asp, sum_dasp) = d.contact.pressure_sum(h0);
    let bdx = d.grid.width * d.grid.dx;
    let f_net = bdx * (sum_p + sum_asp) - ctx.load;
    w.f_net = f_net;
    let (h1, h2) = (&hist[0], &hist[1]);
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
    w.g.is_finite()
}

/// Pass 2: the mass flux through every face. Without flow factors the
/// interior faces run a specialised loop (no per-face branch; vectorises).
#[inline(always)]
pub(super) fn face_pass(d: &Disc, p: &[f64], h0: f64, ctx: &Ctx, w: &mut Work) {
    let n = p.len();
    let inv_dx = 1.0 / d.grid.dx;
    let edge = CellProps {
        rho: d.rho_edge,
        drho: 0.0,
        gr: d.gr_edge,
        dgr: 0.0,
    };
    let fx = FluxCtx {
        d,
        half_v: 0.5 * ctx.v,
        upwind_left: ctx.v >= 0.0,
    };
    let gf = &d.grid.g_face[..=n];
    let cells = &w.cells;
    let first = fx.flux(
        h0 + gf[0],
        2.0 * inv_dx,
        d.p_amb,
        &edge,
        p[0],
        &cells.props(0),
    );
    let last = fx.flux(
        h0 + gf[n],
        2.0 * inv_dx,
        p[n - 1],
        &cells.props(n - 1),
        d.p_amb,
        &edge,
    );
    w.faces.set(0, first);
    w.faces.set(n, last);
    match (&d.ff, fx.upwind_left) {
        (None, true) => smooth_faces::<true>(gf, p, h0, inv_dx, fx.half_v, cells, &mut w.faces),
        (None, false) => smooth_faces::<false>(gf, p, h0, inv_dx, fx.half_v, cells, &mut w.faces),
        (Some(_), _) => {
            for i in 1..n {
                let f = fx.flux(
                    h0 + gf[i],
                    inv_dx,
                    p[i - 1],
                    &cells.props(i - 1),
                    p[i],
                    &cells.props(i),
                );
                w.faces.set(i, f);
            }
        }
    }
    w.banded = match d.flux {
        CouetteFlux::Upwind => false,
        CouetteFlux::Muscl(limiter) => {
            muscl_pass(d, h0, ctx, limiter, w);
            true
        }
    };
}

/// Interior faces without flow factors (φx = 1, φs = 0): [`FluxCtx::flux`]
/// with those constants folded, bit-identical to it for finite values.
#[inline(always)]
fn smooth_faces<const UPWIND_LEFT: bool>(
    gf: &[f64],
    p: &[f64],
    h0: f64,
    inv_dx: f64,
    half_v: f64,
    cells: &CellColumns,
    faces: &mut FaceColumns,
) {
    let n = p.len();
    let k = inv_dx * (1.0 / 12.0);
    let (rho, drho, gr, dgr) = (
        &cells.rho[..n],
        &cells.drho[..n],
        &cells.gr[..n],
        &cells.dgr[..n],
    );
    let (q, dql, dqr, dqh) = (
        &mut faces.q[..n],
        &mut faces.dql[..n],
        &mut faces.dqr[..n],
        &mut faces.dqh[..n],
    );
    for i in 1..n {
        let (l, r) = (i - 1, i);
        let hf = h0 + gf[i];
        let h2 = hf * hf;
        let cf = h2 * hf * k;
        let dcf = 3.0 * h2 * k;
        let gbar = 0.5 * (gr[l] + gr[r]);
        let dpf = p[r] - p[l];
        let cg = cf * gbar;
        let qi = -cg * dpf;
        let dl = cg - 0.5 * cf * dgr[l] * dpf;
        let dr = -cg - 0.5 * cf * dgr[r] * dpf;
        let dh = -dcf * gbar * dpf;
        if UPWIND_LEFT {
            q[i] = qi + half_v * hf * rho[l];
            dqh[i] = dh + half_v * rho[l];
            dql[i] = dl + half_v * hf * drho[l];
            dqr[i] = dr;
        } else {
            q[i] = qi + half_v * hf * rho[r];
            dqh[i] = dh + half_v * rho[r];
            dql[i] = dl;
            dqr[i] = dr + half_v * hf * drho[r];
        }
    }
}

/// Pass 3: the rows of the bordered system (mass balance of every cell).
/// Returns false when a row is not finite.
#[inline(always)]
pub(super) fn row_pass(d: &Disc, hist: &[Level; 2], h0: f64, ctx: &Ctx, w: &mut Work) -> bool {
    let n = d.grid.n;
    let dx = d.grid.dx;
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
    let gc = &d.grid.g_cell[..n];
    let hist_term = &w.hist_term[..n];
    let (rho, drho) = (&w.cells.rho[..n], &w.cells.drho[..n]);
    let f = &w.faces;
    let (q, dql, dqr, dqh) = (&f.q[..=n], &f.dql[..=n], &f.dqr[..=n], &f.dqh[..=n]);
    let rows = &mut w.rows;
    let (ra, rb, rc, rcol, rr) = (
        &mut rows.a[..n],
        &mut rows.b[..n],
        &mut rows.c[..n],
        &mut rows.col[..n],
        &mut rows.r[..n],
    );
    for i in 0..n {
        let hc = h0 + gc[i];
        rr[i] = w0 * (q[i + 1] - q[i]) + sa0 * rho[i] * hc + hist_term[i];
        rcol[i] = w0 * (dqh[i + 1] - dqh[i]) + sa0 * rho[i];
        ra[i] = -w0 * dql[i];
        rb[i] = w0 * (dql[i + 1] - dqr[i]) + sa0 * drho[i] * hc;
        rc[i] = w0 * dqr[i + 1];
    }
    if w.has_source {
        for (r, s) in rr.iter_mut().zip(&w.source) {
            *r -= s;
        }
    }
    if w.banded {
        band_rows(n, w0, ctx.v >= 0.0, &f.dqx[..=n], rows);
    }
    let (rr, rcol, ra, rc) = (
        &rows.r[..n],
        &rows.col[..n],
        &mut rows.a[..n],
        &mut rows.c[..n],
    );
    let finite = all_finite(rr, rcol);
    ra[0] = 0.0;
    rc[n - 1] = 0.0;
    finite
}

/// The far-upwind derivatives of a MUSCL flux (`flux.rs`) in the rows:
/// v ≥ 0, face i's far cell is i − 2 and face (i+1)'s is i − 1; v < 0, face
/// (i+1)'s is i + 2 and face i's is i + 1.
#[inline(always)]
fn band_rows(n: usize, w0: f64, forward: bool, dqx: &[f64], rows: &mut RowColumns) {
    rows.reversed = !forward;
    if forward {
        rows.c2[..n].fill(0.0);
        for i in 0..n {
            rows.a2[i] = -w0 * dqx[i];
            rows.a[i] += w0 * dqx[i + 1];
        }
    } else {
        rows.a2[..n].fill(0.0);
        for i in 0..n {
            rows.c2[i] = w0 * dqx[i + 1];
            rows.c[i] -= w0 * dqx[i];
        }
    }
}

#[cfg(test)]
mod jacobian_tests {
    //! The analytic Jacobian equals central finite differences of the
    //! residual, for random states (property test).
    use super::super::Solver;
    use super::*;
    use crate::physics::{Limiter, ModelParams, Pocket, Profile, SolverSettings, TimeScheme};
    use proptest::prelude::*;

    fn residual(s: &mut Solver, p: &[f64], h0: f64, ctx: &Ctx) -> (Vec<f64>, f64) {
        assemble(&s.d, &s.hist, p, h0, ctx, &mut s.w);
        (s.w.rows.r.clone(), s.w.g)
    }

    /// The solver of one property-test case, started in steady sliding.
    fn case_solver(
        profile: Profile,
        pocket: bool,
        flow_factors: bool,
        sigma: f64,
        cells: usize,
        theta: bool,
        flux: CouetteFlux,
    ) -> (Solver, SolverSettings) {
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
            cells,
            scheme: if theta {
                TimeScheme::PAPER
            } else {
                TimeScheme::Bdf2
            },
            flux,
            ..Default::default()
        };
        let mut s = Solver::new(&m, &st).unwrap();
        s.initialize_steady(0.1, 20_000.0);
        (s, st)
    }

    /// The analytic Jacobian's element (i, j) from its bands.
    fn element(rows: &RowColumns, banded: bool, i: usize, j: usize) -> f64 {
        if i == j {
            rows.b[i]
        } else if i + 1 == j {
            rows.c[i]
        } else if j + 1 == i {
            rows.a[i]
        } else if i + 2 == j && banded {
            rows.c2[i]
        } else if j + 2 == i && banded {
            rows.a2[i]
        } else {
            0.0
        }
    }

    /// The largest |element| of row i, for the tolerance of its elements.
    fn row_scale(rows: &RowColumns, i: usize) -> f64 {
        let outer = rows.a2[i].abs().max(rows.c2[i].abs());
        rows.a[i]
            .abs()
            .max(rows.b[i].abs())
            .max(rows.c[i].abs())
            .max(outer)
            + 1e-300
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
        flux: CouetteFlux,
    ) {
        let (mut s, st) = case_solver(profile, pocket, flow_factors, sigma, p.len(), theta, flux);
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
        let scale: Vec<f64> = (0..n).map(|i| row_scale(&rows, i)).collect();
        // Magnitude of the terms of each mass residual (storage levels and
        // face fluxes), for the rounding error of a difference quotient.
        let g_max = s.d.grid.g_cell.iter().cloned().fold(0.0, f64::max);
        let storage = s.d.grid.dx / st.dt * 4.0 * s.d.eos.rho_l * (h0 + g_max);
        let r_mag: Vec<f64> = (0..n)
            .map(|i| storage + s.w.faces.q[i].abs() + s.w.faces.q[i + 1].abs())
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
                let an = element(&rows, s.w.banded, i, j);
                let round = 8.0 * f64::EPSILON * r_mag[i] / h;
                close(fd, an, scale[i], round, &format!("dR{i}/dp{j}"));
            }
            let fd = (gp - gm) / (2.0 * h);
            assert!(
                (fd - c_row).abs() <= 1e-5 * c_row.abs() + 8.0 * f64::EPSILON * g_mag / h,
                "dG/dp{j}: finite difference {fd:e} vs analytic {c_row:e}"
            );
        }
        check_h0_column(&mut s, &p, h0, &ctx, &rows, dgdh, &r_mag, g_mag);
    }

    /// The h0 column of the Jacobian (dR/dh0, dG/dh0) against central
    /// differences, with the rounding allowance of each residual.
    #[allow(clippy::too_many_arguments)]
    fn check_h0_column(
        s: &mut Solver,
        p: &[f64],
        h0: f64,
        ctx: &Ctx,
        rows: &RowColumns,
        dgdh: f64,
        r_mag: &[f64],
        g_mag: f64,
    ) {
        let hh = 1e-7 * h0;
        let (rp, gp) = residual(s, p, h0 + hh, ctx);
        let (rm, gm) = residual(s, p, h0 - hh, ctx);
        let col_scale = rows.col.iter().map(|c| c.abs()).fold(0.0, f64::max);
        for i in 0..p.len() {
            let fd = (rp[i] - rm[i]) / (2.0 * hh);
            let round = 8.0 * f64::EPSILON * r_mag[i] / hh;
            assert!(
                (fd - rows.col[i]).abs() <= 1e-5 * (rows.col[i].abs() + col_scale) + round,
                "dR{i}/dh0: finite difference {fd:e} vs analytic {:e}",
                rows.col[i]
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
            check(profile, pocket, false, 5e-6, p, h0, v, theta, CouetteFlux::Upwind);
        }

        /// The MUSCL flux's Jacobian (pentadiagonal) with each limiter,
        /// states reaching into the cavitation range (p down to 2 kPa).
        #[test]
        fn muscl_jacobian_matches_finite_differences(
            profile in profile(),
            pocket in any::<bool>(),
            p in prop::collection::vec(prop_oneof![2e3..1.2e5f64, 1e5..4e6f64], 6..20),
            h0 in 8e-6..30e-6f64,
            v in -3.0..3.0f64,
            theta in any::<bool>(),
            limiter in prop_oneof![
                Just(Limiter::Minmod),
                Just(Limiter::VanLeer),
                Just(Limiter::VanAlbada),
            ],
            flow_factors in any::<bool>(),
        ) {
            let (sigma, h0) = if flow_factors { (1e-6, h0.max(6e-6)) } else { (5e-6, h0) };
            let flux = CouetteFlux::Muscl(limiter);
            check(profile, pocket, flow_factors, sigma, p, h0, v, theta, flux);
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
            check(Profile::Flat, false, true, sigma, p, h0, v, false, CouetteFlux::Upwind);
        }
    }
}
