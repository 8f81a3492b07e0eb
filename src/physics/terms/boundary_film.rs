//! The boundary film's friction and its dependence on sliding speed.
//!
//! Where asperities touch, the friction is the shear of the boundary film
//! (adsorbed additives, soaps of a grease, an elastomer's surface) that
//! separates them. Its shear strength is not a constant: shearing a
//! molecular film is thermally activated (Eyring), so the stress grows with
//! the logarithm of the sliding speed — measured for boundary films by
//! Briscoe and Evans (Proc. R. Soc. A 380, 1982), and the low-speed branch
//! of rubber friction (Grosch, Proc. R. Soc. A 274, 1963). In Eyring's form
//! the coefficient of the asperity load is
//!
//! ```text
//! μ(v) sgn v = μ_bl sgn(v) + μ_r asinh(v / v_a)
//! F_bl       = F_asp (μ_bl sgn(v) + μ_r asinh(v / v_a))
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | μ_bl | boundary friction coefficient at rest (the rate-independent part) | – |
//! | μ_r | rate sensitivity: the increase of μ per e-fold of speed above v_a (kT/(V* p̄) in Eyring's terms) | – |
//! | v_a | activation speed: below it the increase is linear in v, above it logarithmic | m/s |
//! | F_asp | load carried by the asperities | N |
//! | F_bl | the boundary friction force, signed with the motion | N |
//!
//! asinh is odd and smooth, so the term passes through zero with the
//! velocity and needs no regularisation; for |v| ≫ v_a it is
//! μ_r ln(2|v|/v_a). μ_r = 0 (the default) is the paper's constant μ_bl,
//! bit for bit. Friction that grows with speed at low speed (a "negative
//! Stribeck" rise that a fitted Stribeck curve reproduces with a static
//! level below the Coulomb level) is this term's, not the film's; the film
//! adds its viscous shear on top.

use super::{End, FitScale, TermKey};

/// The boundary friction's keys: μ_bl and the rigid contact's sign
/// regularisation, the rate sensitivity and its activation speed.
pub const KEYS: &[TermKey] = &[
    TermKey {
        key: "contact.boundary_friction",
        symbol: "μ_bl",
        unit: "–",
        lo: End::Closed(0.0),
        hi: End::Closed(2.0),
        live: true,
        fit: FitScale::FromStart,
        meaning: "boundary friction coefficient of the asperity load",
    },
    TermKey {
        key: "contact.sign_regularization_m_s",
        symbol: "v_reg",
        unit: "m/s",
        lo: End::Open(1e-9),
        hi: End::Closed(1.0),
        live: true,
        fit: FitScale::FromStart,
        meaning: "the rigid contact's (and the drivetrain's) sign tanh(v/v_reg); not used by the pre-sliding bristle",
    },
    TermKey {
        key: "contact.boundary_friction_rate",
        symbol: "μ_r",
        unit: "–",
        lo: End::Closed(0.0),
        hi: End::Closed(1.0),
        live: true,
        // Up to twice the data's friction coefficient per e-fold.
        fit: FitScale::Data {
            factor: 2.0,
            speed_power: 0,
            per_load: true,
            symmetric: false,
        },
        meaning: "the boundary film's rise per e-fold of speed above v_a (Eyring); 0 = off",
    },
    TermKey {
        key: "contact.boundary_activation_speed_m_s",
        symbol: "v_a",
        unit: "m/s",
        lo: End::Open(1e-12),
        hi: End::Closed(100.0),
        live: true,
        fit: FitScale::Speed { lo: 1e-4, hi: 1.0 },
        meaning: "the rate term's activation speed: linear below, logarithmic above",
    },
];

/// The rate dependence of the boundary friction (off by default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryRate {
    /// μ_r, the increase of the coefficient per e-fold of speed; 0 = off.
    pub sensitivity: f64,
    /// v_a, the activation speed, m/s (> 0).
    pub activation_speed: f64,
}

impl Default for BoundaryRate {
    fn default() -> Self {
        Self {
            sensitivity: 0.0,
            activation_speed: 1e-3,
        }
    }
}

impl BoundaryRate {
    /// Whether the coefficient depends on speed.
    pub fn is_on(&self) -> bool {
        self.sensitivity > 0.0
    }

    /// μ_r asinh(v/v_a): the signed, rate-dependent part of the coefficient
    /// at velocity `v` (m/s).
    pub fn signed_term(&self, v: f64) -> f64 {
        self.sensitivity * (v / self.activation_speed).asinh()
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the exact zeros compared are the claims (asinh(0) = 0, the term off)
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn the_rate_term_grows_by_its_sensitivity_per_e_fold_of_speed_above_the_activation_speed() {
        let r = BoundaryRate {
            sensitivity: 0.01,
            activation_speed: 1e-6,
        };
        let e = std::f64::consts::E;
        let rise = r.signed_term(1e-2 * e) - r.signed_term(1e-2);
        assert_relative_eq!(rise, 0.01, max_relative = 1e-8);
    }

    #[test]
    fn the_rate_term_is_odd_and_linear_below_the_activation_speed() {
        let r = BoundaryRate {
            sensitivity: 0.02,
            activation_speed: 1e-3,
        };
        assert_relative_eq!(r.signed_term(-3e-3), -r.signed_term(3e-3));
        assert_eq!(r.signed_term(0.0), 0.0);
        // asinh(x) = x (1 − x²/6 + …): within 2e-7 at x = 1e-3.
        assert_relative_eq!(r.signed_term(1e-6), 0.02 * 1e-3, max_relative = 2e-7);
    }

    #[test]
    fn the_rate_dependence_is_off_by_default() {
        assert!(!BoundaryRate::default().is_on());
        assert_eq!(BoundaryRate::default().signed_term(1.0), 0.0);
    }
}
