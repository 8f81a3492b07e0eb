//! Greenwood–Williamson asperity contact (docs/model.md §4).
//!
//! ```text
//! F_n(Λ) = ∫_Λ^∞ (s − Λ)^n φ(s) ds ,   φ(s) = e^(−s²/2) / √(2π)
//! p_asp(Λ) = (4/3) E* η √β_a σ^(3/2) F_3/2(Λ)
//! A_r/A_0  = π η β_a σ F_1(Λ)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | Λ = h/σ | specific film thickness | – |
//! | σ | combined RMS roughness | m |
//! | E* | effective elastic modulus | Pa |
//! | η | asperity density | 1/m² |
//! | β_a | asperity tip radius | m |
//! | p_asp | nominal asperity contact pressure | Pa |
//! | A_r/A_0 | real-to-nominal contact area ratio | – |
//!
//! `F_n` is computed once by Gauss–Legendre quadrature after the substitution
//! `s = Λ + w²` (which removes the endpoint singularity of `(s−Λ)^½`) and
//! tabulated on Λ ∈ [0, 12] with cubic Hermite interpolation whose node
//! slopes are the exact identity `dF_n/dΛ = −n F_(n−1)`. Beyond Λ = 12 the
//! contact pressure is below 1e-20 of the prefactor and is taken as zero.
//! The Jacobian uses the derivative of the interpolant, so it is exact for
//! the function actually used.

use std::sync::OnceLock;

const LAMBDA_MAX: f64 = 12.0;
const NODES_PER_UNIT: usize = 128;

/// 8-point Gauss–Legendre nodes and weights on [−1, 1].
const GL_X: [f64; 8] = [
    -0.960_289_856_497_536_3,
    -0.796_666_477_413_626_7,
    -0.525_532_409_916_329,
    -0.183_434_642_495_649_8,
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GL_W: [f64; 8] = [
    0.101_228_536_290_376_26,
    0.222_381_034_453_374_47,
    0.313_706_645_877_887_3,
    0.362_683_783_378_362,
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_47,
    0.101_228_536_290_376_26,
];

/// Standard normal density.
#[inline]
pub fn std_normal_pdf(s: f64) -> f64 {
    (-0.5 * s * s).exp() * (1.0 / (2.0 * core::f64::consts::PI).sqrt())
}

/// `F_n(Λ)` by quadrature (accurate to ~1e-14 relative for n ≥ 0, Λ ≥ −2).
///
/// Closed forms exist for n = 0 (`½ erfc(Λ/√2)`) and n = 1 (`φ − Λ F_0`); the
/// quadrature is used for all n so that the half-integer orders share one
/// tested code path.
#[allow(clippy::float_cmp)] // n is an exact order (0, ½, 1, 3/2, …), not a measured value
pub fn gw_integral(n: f64, lambda: f64) -> f64 {
    if n == 0.0 {
        return 0.5 * libm::erfc(lambda / core::f64::consts::SQRT_2);
    }
    if n == 1.0 {
        return std_normal_pdf(lambda) - lambda * gw_integral(0.0, lambda);
    }
    // s = Λ + w², ds = 2w dw, (s−Λ)^n = w^(2n).
    // Integrand 2 w^(2n+1) φ(Λ + w²); negligible once Λ w² + w⁴/2 > 60.
    let w_max = if lambda >= 0.0 {
        (120.0f64).sqrt().sqrt() + 0.5
    } else {
        (-lambda).sqrt() + (120.0f64).sqrt().sqrt() + 0.5
    };
    let panels = 64;
    let hw = w_max / panels as f64;
    let mut sum = 0.0;
    for k in 0..panels {
        let a = k as f64 * hw;
        let mid = a + 0.5 * hw;
        for j in 0..8 {
            let w = mid + 0.5 * hw * GL_X[j];
            let f = 2.0 * pow_w(w, 2.0 * n + 1.0) * std_normal_pdf(lambda + w * w);
            sum += GL_W[j] * f;
        }
    }
    sum * 0.5 * hw
}

#[inline]
fn pow_w(w: f64, e: f64) -> f64 {
    if e.fract() == 0.0 {
        w.powi(e as i32)
    } else {
        w.powf(e)
    }
}

/// Cubic Hermite table on x ∈ [0, X) with uniform spacing and exact node
/// slopes; linear continuation below 0, zero from X on.
#[derive(Debug, Clone)]
pub struct HermiteTable {
    /// (value, slope) per node.
    nodes: Vec<[f64; 2]>,
    per_unit: f64,
}

impl HermiteTable {
    /// Tabulate `f` (returning value and slope) on `count` nodes spaced 1/`per_unit`.
    pub fn from_fn(count: usize, per_unit: f64, f: impl Fn(f64) -> [f64; 2]) -> Self {
        Self {
            nodes: (0..count).map(|i| f(i as f64 / per_unit)).collect(),
            per_unit,
        }
    }

    fn build(n: f64) -> Self {
        Self::from_fn(
            (LAMBDA_MAX as usize) * NODES_PER_UNIT + 1,
            NODES_PER_UNIT as f64,
            |lam| [gw_integral(n, lam), -n * gw_integral(n - 1.0, lam)],
        )
    }

    /// Value and derivative of the interpolant.
    #[inline]
    pub fn eval(&self, x: f64) -> (f64, f64) {
        let h = 1.0 / self.per_unit;
        if x < 0.0 {
            // Unphysical (h < 0); linear continuation keeps Newton finite.
            let [f0, d0] = self.nodes[0];
            return (f0 + d0 * x, d0);
        }
        let u = x * self.per_unit;
        if u.is_nan() || u >= (self.nodes.len() - 1) as f64 {
            // Beyond the table (or NaN, which propagates through u).
            return (0.0 * u, 0.0 * u);
        }
        let i = u as usize;
        let Some(&[[f0, d0], [f1, d1]]) = self.nodes.get(i..i + 2) else {
            return (0.0, 0.0);
        };
        let t = u - i as f64;
        let t2 = t * t;
        let t3 = t2 * t;
        let (d0, d1) = (d0 * h, d1 * h);
        let v = (2.0 * t3 - 3.0 * t2 + 1.0) * f0
            + (t3 - 2.0 * t2 + t) * d0
            + (-2.0 * t3 + 3.0 * t2) * f1
            + (t3 - t2) * d1;
        let dv = (6.0 * t2 - 6.0 * t) * f0
            + (3.0 * t2 - 4.0 * t + 1.0) * d0
            + (-6.0 * t2 + 6.0 * t) * f1
            + (3.0 * t2 - 2.0 * t) * d1;
        (v, dv * self.per_unit)
    }
}

struct Tables {
    f32: HermiteTable,
    f1: HermiteTable,
}

fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| Tables {
        f32: HermiteTable::build(1.5),
        f1: HermiteTable::build(1.0),
    })
}

/// Tabulated `F_3/2(Λ)` and its derivative (the function the solver uses).
pub fn f32_table(lam: f64) -> (f64, f64) {
    tables().f32.eval(lam)
}

/// Tabulated `F_1(Λ)`.
pub fn f1_table(lam: f64) -> f64 {
    tables().f1.eval(lam).0
}

/// GW contact of the configured surfaces.
#[derive(Debug, Clone, Copy)]
pub struct Greenwood {
    f32: &'static HermiteTable,
    f1: &'static HermiteTable,
    sigma: f64,
    inv_sigma: f64,
    pressure_scale: f64,
    area_scale: f64,
}

impl Greenwood {
    /// The Greenwood–Williamson contact of a roughness.
    pub fn new(r: &super::params::Roughness) -> Self {
        let t = tables();
        Self {
            f32: &t.f32,
            f1: &t.f1,
            sigma: r.sigma,
            inv_sigma: 1.0 / r.sigma,
            pressure_scale: 4.0 / 3.0
                * r.effective_modulus
                * r.asperity_density
                * r.asperity_radius.sqrt()
                * r.sigma.powf(1.5),
            area_scale: core::f64::consts::PI * r.asperity_density * r.asperity_radius * r.sigma,
        }
    }

    /// σ, the combined RMS roughness, m.
    pub fn sigma(&self) -> f64 {
        self.sigma
    }

    /// Asperity pressure at film thickness `h` and its derivative dp/dh.
    #[inline]
    pub fn pressure(&self, h: f64) -> (f64, f64) {
        let (f, df) = self.f32.eval(h * self.inv_sigma);
        (
            self.pressure_scale * f,
            self.pressure_scale * df * self.inv_sigma,
        )
    }

    /// Tabulate the contact summed over a fixed film shape `g` (one value per
    /// cell): `Σ_i p_asp(h0 + g_i)` and `Σ_i A_r/A_0(h0 + g_i)` as functions of
    /// h0 alone. The node values and slopes are the exact sums of the
    /// per-cell interpolants, so the sum is as accurate as the F_n tables and
    /// costs O(1) per evaluation instead of O(N).
    pub fn summed(&self, g: &[f64]) -> SummedContact {
        let inv_sigma = self.inv_sigma;
        let count = (LAMBDA_MAX as usize) * NODES_PER_UNIT + 1;
        let per_unit = NODES_PER_UNIT as f64;
        let pressure = HermiteTable::from_fn(count, per_unit, |lam0| {
            g.iter().fold([0.0, 0.0], |[v, dv], gi| {
                let (f, df) = self.f32.eval(lam0 + gi * inv_sigma);
                [v + f, dv + df]
            })
        });
        let area = HermiteTable::from_fn(count, per_unit, |lam0| {
            g.iter().fold([0.0, 0.0], |[v, dv], gi| {
                let (f, df) = self.f1.eval(lam0 + gi * inv_sigma);
                [v + f, dv + df]
            })
        });
        SummedContact {
            pressure,
            area,
            pressure_scale: self.pressure_scale,
            area_scale: self.area_scale,
            inv_sigma,
        }
    }
}

/// GW contact summed over the cells of a fixed film shape (see
/// [`Greenwood::summed`]).
#[derive(Debug, Clone)]
pub struct SummedContact {
    pressure: HermiteTable,
    area: HermiteTable,
    pressure_scale: f64,
    area_scale: f64,
    inv_sigma: f64,
}

impl SummedContact {
    /// `Σ_i p_asp(h0 + g_i)` (Pa) and its derivative in h0 (Pa/m).
    #[inline]
    pub fn pressure_sum(&self, h0: f64) -> (f64, f64) {
        let (v, dv) = self.pressure.eval(h0 * self.inv_sigma);
        (
            self.pressure_scale * v,
            self.pressure_scale * dv * self.inv_sigma,
        )
    }

    /// `Σ_i A_r/A_0(h0 + g_i)`.
    #[inline]
    pub fn area_sum(&self, h0: f64) -> f64 {
        self.area_scale * self.area.eval(h0 * self.inv_sigma).0
    }
}
