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

use super::term::{At, BristleMove, FrictionTerm, Place};
use super::{End, FitScale, TermKey};

/// The boundary film's keys: μ_bl and the rigid contact's sign
/// regularisation.
const FILM_KEYS: &[TermKey] = &[
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
];

/// The rate dependence's keys: the sensitivity and its activation speed.
const RATE_KEYS: &[TermKey] = &[
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

/// The boundary film's friction μ_bl F_asp s(v) (always in: the paper's
/// term), and the sign's regularisation v_reg that the rigid contact and
/// the drivetrain use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryFilm {
    /// μ_bl, the boundary friction coefficient.
    pub friction: f64,
    /// v_reg of the rigid contact's (and the drivetrain's) tanh sign, m/s.
    pub sign_regularization: f64,
}

impl Default for BoundaryFilm {
    /// The paper's μ_bl = 0.3, v_reg = 1e-4 m/s.
    fn default() -> Self {
        Self {
            friction: 0.3,
            sign_regularization: 1e-4,
        }
    }
}

impl FrictionTerm for BoundaryFilm {
    const KEYS: &'static [TermKey] = FILM_KEYS;
    const PLACE: Place = Place::Contact;
    type State = ();

    /// Always: μ_bl = 0 adds a zero, as the paper's model does.
    fn is_on(&self) -> bool {
        true
    }

    fn force(&self, at: &At) -> f64 {
        self.friction * at.f_asp * at.s
    }

    fn carried(&self, at: &At) -> f64 {
        self.friction * at.f_asp * at.s
    }

    fn beside(&self, _: &At) -> f64 {
        0.0
    }

    fn cof(&self, _: &At) -> f64 {
        self.friction
    }

    fn carry(&self, level: f64, _: f64, _: &mut Self::State, _: BristleMove) -> f64 {
        level
    }

    fn steady_state(&self, _: f64, state: Self::State) -> Self::State {
        state
    }

    fn swapped(&self, _: &Self, state: Self::State, _: Option<f64>) -> Self::State {
        state
    }

    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        match key {
            "contact.boundary_friction" => Some(&mut self.friction),
            "contact.sign_regularization_m_s" => Some(&mut self.sign_regularization),
            _ => None,
        }
    }
}

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
    /// μ_r asinh(v/v_a): the signed, rate-dependent part of the coefficient
    /// at velocity `v` (m/s).
    pub fn signed_term(&self, v: f64) -> f64 {
        self.sensitivity * self.asinh_at(v)
    }

    /// asinh(v/v_a) at velocity `v` (m/s): the part of the term a fit may
    /// hold for a whole film trace ([`Kept::rate_asinh`](super::Kept::rate_asinh)).
    pub fn asinh_at(&self, v: f64) -> f64 {
        (v / self.activation_speed).asinh()
    }

    /// μ_r asinh(v/v_a) at `at`, with the asinh `at` holds if any.
    fn signed_at(&self, at: &At) -> f64 {
        match at.kept.rate_asinh {
            Some(a) => self.sensitivity * a,
            None => self.signed_term(at.v),
        }
    }
}

impl FrictionTerm for BoundaryRate {
    const KEYS: &'static [TermKey] = RATE_KEYS;
    const PLACE: Place = Place::Contact;
    type State = ();

    fn is_on(&self) -> bool {
        self.sensitivity > 0.0
    }

    /// F_asp μ_r asinh(v/v_a): odd in v, no sign needed.
    fn force(&self, at: &At) -> f64 {
        at.f_asp * self.signed_at(at)
    }

    fn carried(&self, at: &At) -> f64 {
        at.f_asp * self.signed_at(at)
    }

    fn beside(&self, _: &At) -> f64 {
        0.0
    }

    fn cof(&self, at: &At) -> f64 {
        self.signed_term(at.v)
    }

    fn carry(&self, level: f64, _: f64, _: &mut Self::State, _: BristleMove) -> f64 {
        level
    }

    fn steady_state(&self, _: f64, state: Self::State) -> Self::State {
        state
    }

    fn swapped(&self, _: &Self, state: Self::State, _: Option<f64>) -> Self::State {
        state
    }

    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        match key {
            "contact.boundary_friction_rate" => Some(&mut self.sensitivity),
            "contact.boundary_activation_speed_m_s" => Some(&mut self.activation_speed),
            _ => None,
        }
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
