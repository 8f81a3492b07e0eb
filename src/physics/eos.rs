//! Homogeneous-mixture cavitation equation of state (docs/model.md §3).
//!
//! ```text
//! α(p) = ½ [1 − tanh(β (p − p0))]
//! ρ = ρl (1−α) + ρg α ,   μ = μl (1−α) + μg α
//! β  = ln[ α_v (1−α_s) / (α_s (1−α_v)) ] / (2 (p_s − p_v))
//! p0 = p_s + ln[ α_s / (1−α_s) ] / (2 β)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | p | absolute pressure | Pa |
//! | α | vapour volume fraction | – |
//! | β | steepness of the liquid–vapour transition | 1/Pa |
//! | p0 | pressure at α = ½ | Pa |
//! | ρ, ρl, ρg | mixture, liquid, gas density | kg/m³ |
//! | μ, μl, μg | mixture, liquid, gas viscosity | Pa·s |
//!
//! The formulas for β and p0 are the corrected eqs. 12–13 of the paper
//! (as printed they give β < 0).

use super::params::Lubricant;

/// Beyond |β (p − p0)| > this, tanh is ±1 to double precision.
const SATURATED: f64 = 19.5;

/// e^x for |x| ≤ 2·[`SATURATED`] (the EOS's range; larger |x| is clamped
/// there, NaN stays NaN), within 2 ulp of the correctly rounded value.
///
/// Written for the compiler to vectorise (no call, no table, no branch):
/// x = k ln2 + r with k = round(x/ln2) (Cody–Waite: ln2 in two parts so that
/// k·ln2_hi is exact), |r| ≤ ln2/2, e^r by its Taylor polynomial of degree
/// 13 (truncation below 5e-18 relative), 2^k built in the exponent bits.
/// Only + and × (never fused by Rust), so every instruction set computes
/// the same bits.
#[inline(always)]
pub(crate) fn exp_fast(x: f64) -> f64 {
    const LIMIT: f64 = 2.0 * SATURATED + 1.0;
    const LOG2E: f64 = std::f64::consts::LOG2_E;
    // ln 2 = LN2_HI + LN2_LO, LN2_HI with 32 trailing zero bits.
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    // 1.5·2^52: adding it rounds to an integer held in the low mantissa bits.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let x = x.clamp(-LIMIT, LIMIT);
    let t = x * LOG2E + SHIFT;
    let kf = t - SHIFT;
    let r = (x - kf * LN2_HI) - kf * LN2_LO;
    // Taylor coefficients 1/j!, Horner from the top.
    const C: [f64; 14] = [
        1.0,
        1.0,
        0.5,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
        1.0 / 40320.0,
        1.0 / 362_880.0,
        1.0 / 3_628_800.0,
        1.0 / 39_916_800.0,
        1.0 / 479_001_600.0,
        1.0 / 6_227_020_800.0,
    ];
    let mut q = C[13];
    let mut j = 13;
    while j > 0 {
        j -= 1;
        q = q * r + C[j];
    }
    // 2^k: k is t's low mantissa bits (two's complement around SHIFT).
    let k = t.to_bits().wrapping_sub(SHIFT.to_bits());
    let scale = f64::from_bits(k.wrapping_add(1023) << 52);
    q * scale
}

/// Mixture properties at one pressure, with pressure derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MixtureState {
    /// α, the vapour volume fraction (0 liquid, 1 gas).
    pub alpha: f64,
    /// ρ, kg/m³.
    pub rho: f64,
    /// dρ/dp, kg/(m³·Pa)
    pub drho: f64,
    /// μ, Pa·s.
    pub mu: f64,
    /// dμ/dp, Pa·s/Pa
    pub dmu: f64,
}

/// The mixture EOS with its derived constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MixtureEos {
    /// ρl, liquid density, kg/m³.
    pub rho_l: f64,
    /// ρg, gas density, kg/m³.
    pub rho_g: f64,
    /// μl, liquid viscosity, Pa·s.
    pub mu_l: f64,
    /// μg, gas viscosity, Pa·s.
    pub mu_g: f64,
    /// β, the transition's steepness, 1/Pa.
    pub beta: f64,
    /// p0, the pressure at α = ½, Pa.
    pub p0: f64,
}

impl MixtureEos {
    /// The EOS of a lubricant (β and p0 from its saturation and vapour points).
    pub fn new(l: &Lubricant) -> Self {
        let (a_s, a_v) = (l.vapour_fraction_saturation, l.vapour_fraction_vapour);
        let beta = ((a_v * (1.0 - a_s)) / (a_s * (1.0 - a_v))).ln()
            / (2.0 * (l.saturation_pressure - l.vapour_pressure));
        let p0 = l.saturation_pressure + (a_s / (1.0 - a_s)).ln() / (2.0 * beta);
        Self {
            rho_l: l.density,
            rho_g: l.gas_density,
            mu_l: l.viscosity,
            mu_g: l.gas_viscosity,
            beta,
            p0,
        }
    }

    /// Vapour fraction α(p).
    #[inline]
    pub fn alpha(&self, p: f64) -> f64 {
        let z = self.beta * (p - self.p0);
        if z > SATURATED {
            0.0
        } else if z < -SATURATED {
            1.0
        } else {
            // ½ (1 − tanh z) = 1 / (1 + e^(2z)): one exp, no cancellation.
            1.0 / (1.0 + exp_fast(2.0 * z))
        }
    }

    /// α(p) without a branch (for loops that vectorise): the exponential's
    /// clamp leaves saturated states within 1e-17 of 0 or 1 instead of
    /// exactly there; NaN stays NaN.
    #[inline(always)]
    pub(crate) fn alpha_branchless(&self, p: f64) -> f64 {
        1.0 / (1.0 + exp_fast(2.0 * self.beta * (p - self.p0)))
    }

    /// Full state with derivatives.
    #[inline]
    pub fn eval(&self, p: f64) -> MixtureState {
        let z = self.beta * (p - self.p0);
        if z > SATURATED {
            return MixtureState {
                alpha: 0.0,
                rho: self.rho_l,
                drho: 0.0,
                mu: self.mu_l,
                dmu: 0.0,
            };
        }
        if z < -SATURATED {
            return MixtureState {
                alpha: 1.0,
                rho: self.rho_g,
                drho: 0.0,
                mu: self.mu_g,
                dmu: 0.0,
            };
        }
        let e = exp_fast(2.0 * z);
        let inv = 1.0 / (1.0 + e);
        let alpha = inv;
        // 1 − α without cancellation.
        let liquid = e * inv;
        // dα/dp = −½ β sech²z = −2 β α (1 − α)
        let dalpha = -2.0 * self.beta * alpha * liquid;
        MixtureState {
            alpha,
            rho: self.rho_l * liquid + self.rho_g * alpha,
            drho: (self.rho_g - self.rho_l) * dalpha,
            mu: self.mu_l * liquid + self.mu_g * alpha,
            dmu: (self.mu_g - self.mu_l) * dalpha,
        }
    }
}

/// Cell properties needed by the discretisation: ρ, dρ/dp, ρ/μ, d(ρ/μ)/dp,
/// μ, dμ/dp. Same function as [`MixtureEos::eval`], arranged around
/// e = exp(2z) so that one division serves α and 1/μ:
///
/// ```text
/// α = 1/(1+e),  ρ = (ρl e + ρg)/(1+e),  μ = (μl e + μg)/(1+e),
/// ρ/μ = (ρl e + ρg)/(μl e + μg),  d(ρ/μ)/dp = 2β e (ρl μg − μl ρg)/(μl e + μg)²
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellState {
    /// ρ, kg/m³.
    pub rho: f64,
    /// dρ/dp, kg/(m³·Pa).
    pub drho: f64,
    /// ρ/μ, kg/(m³·Pa·s).
    pub gr: f64,
    /// d(ρ/μ)/dp.
    pub dgr: f64,
    /// μ, Pa·s.
    pub mu: f64,
    /// dμ/dp, Pa·s/Pa.
    pub dmu: f64,
}

/// Whether |z| = |β (p − p0)| is beyond [`SATURATED`] (pure liquid or gas
/// to double precision, no exponential needed). NaN is not saturated.
#[inline(always)]
#[allow(clippy::manual_range_contains)] // a range would call NaN saturated
pub(crate) fn saturated(z: f64) -> bool {
    z > SATURATED || z < -SATURATED
}

impl MixtureEos {
    #[inline(always)]
    /// The cell properties at pressure `p` (Pa).
    pub fn cell(&self, p: f64) -> CellState {
        let z = self.beta * (p - self.p0);
        let e = if saturated(z) { 0.0 } else { exp_fast(2.0 * z) };
        self.cell_from_exp(p, e)
    }

    /// [`MixtureEos::cell`] given e = exp(2β(p − p0)) (any value where
    /// saturated).
    #[inline(always)]
    pub fn cell_from_exp(&self, p: f64, e: f64) -> CellState {
        self.constants().state(p, e)
    }

    /// The constants of [`MixtureEos::cell`], computed once for a loop over
    /// cells.
    #[inline(always)]
    pub fn constants(&self) -> CellConstants {
        CellConstants {
            eos: *self,
            gr_liquid: self.rho_l / self.mu_l,
            gr_gas: self.rho_g / self.mu_g,
        }
    }
}

/// [`MixtureEos`] with the constants of its saturated states.
#[derive(Debug, Clone, Copy)]
pub struct CellConstants {
    eos: MixtureEos,
    gr_liquid: f64,
    gr_gas: f64,
}

impl CellConstants {
    /// The pure liquid's state (β(p − p0) beyond saturation).
    #[inline(always)]
    pub fn liquid(&self) -> CellState {
        CellState {
            rho: self.eos.rho_l,
            drho: 0.0,
            gr: self.gr_liquid,
            dgr: 0.0,
            mu: self.eos.mu_l,
            dmu: 0.0,
        }
    }

    /// Whether `p` is pure liquid to double precision (false for NaN).
    #[inline(always)]
    pub fn is_liquid(&self, p: f64) -> bool {
        self.eos.beta * (p - self.eos.p0) > SATURATED
    }

    /// [`MixtureEos::cell`] at `p` given e = exp(2β(p − p0)) (any value
    /// where saturated). Branch-free: the saturated states are selected, so a
    /// loop over cells vectorises.
    #[inline(always)]
    pub fn state(&self, p: f64, e: f64) -> CellState {
        let k = &self.eos;
        let z = k.beta * (p - k.p0);
        let one_e = 1.0 + e;
        let num = k.rho_l * e + k.rho_g;
        let den = k.mu_l * e + k.mu_g;
        let inv = 1.0 / (one_e * den);
        let alpha = den * inv;
        let inv_den = one_e * inv;
        // dα/dp = −2β α (1−α), with 1 − α = e α
        let dalpha = -2.0 * k.beta * alpha * (e * alpha);
        let gr = num * inv_den;
        let mixed = CellState {
            rho: k.rho_l * (e * alpha) + k.rho_g * alpha,
            drho: (k.rho_g - k.rho_l) * dalpha,
            gr,
            dgr: 2.0 * k.beta * e * (k.rho_l * k.mu_g - k.mu_l * k.rho_g) * inv_den * inv_den,
            mu: k.mu_l * (e * alpha) + k.mu_g * alpha,
            dmu: (k.mu_g - k.mu_l) * dalpha,
        };
        let pure = |rho: f64, gr: f64, mu: f64| CellState {
            rho,
            drho: 0.0,
            gr,
            dgr: 0.0,
            mu,
            dmu: 0.0,
        };
        if z > SATURATED {
            self.liquid()
        } else if z < -SATURATED {
            pure(k.rho_g, self.gr_gas, k.mu_g)
        } else {
            mixed
        }
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims (0, 1, representable sums)
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The vectorisable exponential is within 2 ulp of libm's over the
    /// EOS's whole range, and NaN stays NaN.
    #[test]
    fn fast_exponential_is_within_two_ulp_of_libm() {
        let limit = 2.0 * SATURATED;
        let n = 400_000;
        let mut worst = 0.0f64;
        for i in 0..=n {
            let x = -limit + 2.0 * limit * i as f64 / n as f64;
            let (a, b) = (exp_fast(x), x.exp());
            worst = worst.max((a - b).abs() / (b * f64::EPSILON));
        }
        assert!(worst <= 2.0, "worst error {worst} ulp");
        assert!(exp_fast(f64::NAN).is_nan());
        assert_eq!(exp_fast(0.0), 1.0);
    }

    #[test]
    fn default_constants_match_model_md() {
        let eos = MixtureEos::new(&Lubricant::default());
        assert_relative_eq!(eos.beta, 4.641535e-5, max_relative = 1e-6);
        assert_relative_eq!(eos.p0, 50_500.0, max_relative = 1e-9);
    }

    #[test]
    fn vapour_fractions_are_reproduced_at_anchor_pressures() {
        let l = Lubricant::default();
        let eos = MixtureEos::new(&l);
        assert_relative_eq!(eos.alpha(l.saturation_pressure), 0.01, max_relative = 1e-9);
        assert_relative_eq!(eos.alpha(l.vapour_pressure), 0.99, max_relative = 1e-9);
    }

    #[test]
    fn cell_state_agrees_with_the_plain_evaluation() {
        let eos = MixtureEos::new(&Lubricant::default());
        for &p in &[-5e5, -2e4, 1e3, 3e4, 5.05e4, 8e4, 1e5, 3e5, 1e6] {
            let s = eos.eval(p);
            let c = eos.cell(p);
            assert_relative_eq!(c.rho, s.rho, max_relative = 1e-14);
            assert_relative_eq!(c.mu, s.mu, max_relative = 1e-14);
            assert_relative_eq!(c.gr, s.rho / s.mu, max_relative = 1e-14);
            let dgr = (s.drho - s.rho * s.dmu / s.mu) / s.mu;
            assert_relative_eq!(c.dgr, dgr, max_relative = 1e-10, epsilon = 1e-30);
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let eos = MixtureEos::new(&Lubricant::default());
        for &p in &[-2e4, 1e3, 3e4, 5.05e4, 8e4, 1e5, 3e5] {
            // Step small against the transition width 1/β ≈ 21 kPa, large
            // against rounding of ρ ≈ 850.
            let h = 50.0;
            let (a, b) = (eos.eval(p + h), eos.eval(p - h));
            let s = eos.eval(p);
            assert_relative_eq!(
                s.drho,
                (a.rho - b.rho) / (2.0 * h),
                max_relative = 1e-5,
                epsilon = 1e-15
            );
            assert_relative_eq!(
                s.dmu,
                (a.mu - b.mu) / (2.0 * h),
                max_relative = 1e-5,
                epsilon = 1e-18
            );
        }
    }
}
