//! The second-order (MUSCL) Couette flux: the face density is the upwind
//! cell's plus half its limited slope (docs/model.md §2 upwinds the density; this
//! is the `solver.flux: muscl_…` option: `muscl_minmod`, `muscl_van_leer`, `muscl_van_albada`).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | ρ_u, ρ_x, ρ_d | density of the upwind cell, of the cell beyond it (far upwind), of the downwind cell | kg/m³ |
//! | Δ−, Δ+ | ρ_u − ρ_x, ρ_d − ρ_u | kg/m³ |
//! | s(Δ−, Δ+) | the limiter's slope of the upwind cell ([`Limiter`]) | kg/m³ |
//! | h_f, σ φs | film at the face, shear-flow factor term | m |
//! | v | sliding velocity | m/s |
//!
//! ```text
//! ρ_f = ρ_u + ½ s(Δ−, Δ+) ,   q_f = q_f^Poiseuille + (v/2)(h_f + σ φs) ρ_f
//! ```
//!
//! Still a flux difference per cell, so mass is conserved exactly; every
//! limiter is 0 when Δ− and Δ+ differ in sign, so the face density stays
//! between its neighbours' (no new extrema where the film cavitates or
//! reforms). Beyond the domain the edge state (ρ at p_amb) stands in
//! for the missing cell; an edge face whose upwind side is the domain's
//! edge keeps the edge density (exact there).
//!
//! This pass adds ½(v/2)(h_f + σ φs) s to the first-order flux of
//! `assembly.rs`, with its derivatives in the three cells' pressures
//! (through dρ/dp) and in h0: the far upwind cell's goes to `dqx`, which
//! makes the Jacobian pentadiagonal (`banded.rs`).

use super::work::Work;
use super::{Ctx, Disc};
use crate::physics::settings::Limiter;

/// The limited slope s(dm = Δ−, dp = Δ+) and its derivatives ∂s/∂Δ−,
/// ∂s/∂Δ+ (branch-free, so that the loop over faces vectorises).
#[inline(always)]
pub(crate) fn slope(limiter: Limiter, dm: f64, dp: f64) -> (f64, f64, f64) {
    let same_sign = dm * dp > 0.0;
    let (s, s_m, s_p) = match limiter {
        Limiter::Minmod => {
            let left = dm.abs() <= dp.abs();
            let (a, b) = if left { (1.0, 0.0) } else { (0.0, 1.0) };
            (if left { dm } else { dp }, a, b)
        }
        Limiter::VanLeer => {
            let inv = 1.0 / if same_sign { dm + dp } else { 1.0 };
            let inv2 = inv * inv;
            (
                2.0 * dm * dp * inv,
                2.0 * dp * dp * inv2,
                2.0 * dm * dm * inv2,
            )
        }
        Limiter::VanAlbada => {
            let inv = 1.0 / if same_sign { dm * dm + dp * dp } else { 1.0 };
            let inv2 = inv * inv;
            (
                dm * dp * (dm + dp) * inv,
                dp * dp * (dp * dp + 2.0 * dm * dp - dm * dm) * inv2,
                dm * dm * (dm * dm + 2.0 * dm * dp - dp * dp) * inv2,
            )
        }
    };
    if same_sign {
        (s, s_m, s_p)
    } else {
        (0.0, 0.0, 0.0)
    }
}

/// Add the limited slope's part of the Couette flux to every face (after
/// `assembly.rs`'s face pass).
#[inline(always)]
pub(super) fn muscl_pass(d: &Disc, h0: f64, ctx: &Ctx, limiter: Limiter, w: &mut Work) {
    let n = d.grid.n;
    let forward = ctx.v >= 0.0;
    // The face whose upwind side is the domain's edge keeps the edge density.
    w.faces.dqx[if forward { 0 } else { n }] = 0.0;
    // Faces whose three cells are all inside (v ≥ 0: face k reads cells
    // k − 2, k − 1, k; v < 0: k − 1, k, k + 1), then the two next to the
    // edges, with the edge state for the missing cell.
    // One loop per limiter and direction, so that each vectorises.
    macro_rules! interior_for {
        ($l:expr) => {
            if forward {
                interior::<true, _>(d, h0, ctx.v, w, |m, p| slope($l, m, p))
            } else {
                interior::<false, _>(d, h0, ctx.v, w, |m, p| slope($l, m, p))
            }
        };
    }
    match (&d.ff, limiter) {
        (None, Limiter::Minmod) => interior_for!(Limiter::Minmod),
        (None, Limiter::VanLeer) => interior_for!(Limiter::VanLeer),
        (None, Limiter::VanAlbada) => interior_for!(Limiter::VanAlbada),
        (Some(_), _) => {
            let inner = if forward { 2..n } else { 1..n - 1 };
            for k in inner {
                one_face(d, h0, ctx.v, limiter, k, w);
            }
        }
    }
    let edges = if forward { [1, n] } else { [0, n - 1] };
    for k in edges {
        one_face(d, h0, ctx.v, limiter, k, w);
    }
}

/// One face's slope part (any face with an upwind cell inside the domain;
/// any flow factors).
#[inline(always)]
fn one_face(d: &Disc, h0: f64, v: f64, limiter: Limiter, k: usize, w: &mut Work) {
    let n = d.grid.n;
    let c = &w.cells;
    let rho = |i: isize| -> (f64, f64) {
        if i < 0 || i >= n as isize {
            (d.rho_edge, 0.0)
        } else {
            (c.rho[i as usize], c.drho[i as usize])
        }
    };
    let forward = v >= 0.0;
    let ki = k as isize;
    let (u, x, dn) = if forward {
        (ki - 1, ki - 2, ki)
    } else {
        (ki, ki + 1, ki - 1)
    };
    let ((ru, dru), (rx, drx), (rd, drd)) = (rho(u), rho(x), rho(dn));
    let (s, s_m, s_p) = slope(limiter, ru - rx, rd - ru);
    let hf = h0 + d.grid.g_face[k];
    let (ch, dch) = match &d.ff {
        Some(ff) => {
            let (phis, dphis) = ff.shear(hf);
            (hf + d.sigma * phis, 1.0 + d.sigma * dphis)
        }
        None => (hf, 1.0),
    };
    let half_v = 0.5 * v;
    let kc = half_v * ch * 0.5;
    let f = &mut w.faces;
    f.q[k] += kc * s;
    f.dqh[k] += half_v * dch * 0.5 * s;
    let (du, dd) = (kc * (s_m - s_p) * dru, kc * s_p * drd);
    if forward {
        f.dql[k] += du;
        f.dqr[k] += dd;
    } else {
        f.dqr[k] += du;
        f.dql[k] += dd;
    }
    f.dqx[k] = -kc * s_m * drx;
}

/// [`one_face`] over the faces whose cells are all inside, without flow
/// factors (h_f + σφs = h_f): one branch-free loop that vectorises.
#[inline(always)]
fn interior<const FORWARD: bool, S: Fn(f64, f64) -> (f64, f64, f64)>(
    d: &Disc,
    h0: f64,
    v: f64,
    w: &mut Work,
    slope: S,
) {
    let n = d.grid.n;
    let half_v = 0.5 * v;
    // Faces k0..k0 + m; cell offsets of the far, upwind and downwind cells.
    let (k0, m) = if FORWARD { (2, n - 2) } else { (1, n - 2) };
    let (ox, ou, od) = if FORWARD { (0, 1, 2) } else { (2, 1, 0) };
    let c = &w.cells;
    let (rx, ru, rd) = (&c.rho[ox..ox + m], &c.rho[ou..ou + m], &c.rho[od..od + m]);
    let (dx, du, dd) = (
        &c.drho[ox..ox + m],
        &c.drho[ou..ou + m],
        &c.drho[od..od + m],
    );
    let gf = &d.grid.g_face[k0..k0 + m];
    let f = &mut w.faces;
    let (q, dqh, dqx) = (
        &mut f.q[k0..k0 + m],
        &mut f.dqh[k0..k0 + m],
        &mut f.dqx[k0..k0 + m],
    );
    let (dq_up, dq_down) = if FORWARD {
        (&mut f.dql[k0..k0 + m], &mut f.dqr[k0..k0 + m])
    } else {
        (&mut f.dqr[k0..k0 + m], &mut f.dql[k0..k0 + m])
    };
    for j in 0..m {
        let (s, s_m, s_p) = slope(ru[j] - rx[j], rd[j] - ru[j]);
        let hf = h0 + gf[j];
        let kc = half_v * hf * 0.5;
        q[j] += kc * s;
        dqh[j] += half_v * 0.5 * s;
        dq_up[j] += kc * (s_m - s_p) * du[j];
        dq_down[j] += kc * s_p * dd[j];
        dqx[j] = -kc * s_m * dx[j];
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // a limiter is exactly 0 where the slopes disagree: that is the claim
mod flux_tests {
    //! The limiters' slopes and their derivatives.
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    const ALL: [Limiter; 3] = [Limiter::Minmod, Limiter::VanLeer, Limiter::VanAlbada];

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// TVD: the slope is 0 at an extremum and otherwise lies between 0
        /// and twice the smaller difference, with the differences' sign;
        /// for equal differences it is that difference (second order).
        #[test]
        fn limited_slopes_are_tvd_and_exact_on_a_line(
            dm in -10.0..10.0f64,
            dp in -10.0..10.0f64,
        ) {
            for l in ALL {
                let (s, _, _) = slope(l, dm, dp);
                if dm * dp <= 0.0 {
                    prop_assert_eq!(s, 0.0);
                } else {
                    prop_assert!(s * dm >= 0.0, "{l:?}: s = {s} for ({dm}, {dp})");
                    prop_assert!(s.abs() <= 2.0 * dm.abs().min(dp.abs()) * (1.0 + 1e-12));
                }
                let (s, _, _) = slope(l, dm, dm);
                if dm != 0.0 {
                    assert_relative_eq!(s, dm, max_relative = 1e-14);
                }
            }
        }

        /// The slopes' derivatives equal central differences (away from
        /// the sign change and minmod's switch).
        #[test]
        fn slope_derivatives_match_finite_differences(
            dm in 0.01..10.0f64,
            dp in 0.01..10.0f64,
            negative in any::<bool>(),
        ) {
            let sg = if negative { -1.0 } else { 1.0 };
            let (dm, dp) = (sg * dm, sg * dp);
            for l in ALL {
                if l == Limiter::Minmod && (dm.abs() - dp.abs()).abs() < 1e-3 {
                    continue;
                }
                let (_, a, b) = slope(l, dm, dp);
                let h = 1e-6;
                let fa = (slope(l, dm + h, dp).0 - slope(l, dm - h, dp).0) / (2.0 * h);
                let fb = (slope(l, dm, dp + h).0 - slope(l, dm, dp - h).0) / (2.0 * h);
                assert_relative_eq!(a, fa, epsilon = 1e-7, max_relative = 1e-6);
                assert_relative_eq!(b, fb, epsilon = 1e-7, max_relative = 1e-6);
            }
        }
    }
}
