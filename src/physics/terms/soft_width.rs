//! A soft contact whose width follows the load.
//!
//! A soft contact's width against the normal load:
//!
//! ```text
//! B(F) = B (F / F_ref)^κ
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | B | `Geometry::width`, the width at the reference load | m |
//! | F, F_ref | normal load, the load at which the width is B | N |
//! | κ | `exponent`: 0 a rigid contact of constant width; 1 a contact whose nominal area grows in proportion to the load (an elastomer conforming at constant mean pressure); ½ Hertz's line contact | – |
//!
//! The model is one-dimensional: the film problem is per unit width, so a
//! wider contact carries the same film at the load per unit width
//! F / B(F), and every force scales with B(F). The solver solves the film
//! for the load F (B/B(F)) on the width B and scales the forces by
//! B(F)/B; the squeeze film's history is per unit width and unaffected.
//! The slider's mass is taken per the reference width (its inertia is a
//! millionth of the load at the paper's conditions).

use super::term::{At, BristleMove, FrictionTerm, Place};
use super::{End, FitScale, TermKey};

/// The soft contact's keys: the exponent and the reference load.
const KEYS: &[TermKey] = &[
    TermKey {
        key: "contact.width_load_exponent",
        symbol: "κ",
        unit: "–",
        lo: End::Closed(0.0),
        hi: End::Closed(1.0),
        live: true,
        fit: FitScale::FromStart,
        meaning: "the width follows (F/F_ref)^κ: 0 rigid, 1 area proportional to the load (elastomer seals)",
    },
    TermKey {
        key: "contact.width_reference_load_n",
        symbol: "F_ref",
        unit: "N",
        lo: End::Open(0.0),
        hi: End::Closed(1e9),
        live: true,
        fit: FitScale::FromStart,
        meaning: "the load at which the width is `contact.width_m`",
    },
];

/// A soft contact's width against the normal load (see the module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WidthLaw {
    /// κ, in [0, 1]: 0 rigid, 1 a width proportional to the load.
    pub exponent: f64,
    /// F_ref, the load at which the width is the configured B, N.
    pub reference_load: f64,
}

impl Default for WidthLaw {
    fn default() -> Self {
        Self {
            exponent: 0.0,
            reference_load: 20_762.0,
        }
    }
}

/// B(F)/B of the solve in progress (1: the reference width).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WidthScale(pub f64);

impl Default for WidthScale {
    fn default() -> Self {
        Self(1.0)
    }
}

impl FrictionTerm for WidthLaw {
    const KEYS: &'static [TermKey] = KEYS;
    const PLACE: Place = Place::Film;
    /// The scale the solve in progress reports the film's forces with,
    /// set by the solver from the load ([`WidthLaw::scale`]).
    type State = WidthScale;

    fn is_on(&self) -> bool {
        self.exponent != 0.0
    }

    fn force(&self, _: &At) -> f64 {
        0.0
    }

    fn carried(&self, _: &At) -> f64 {
        0.0
    }

    fn beside(&self, _: &At) -> f64 {
        0.0
    }

    fn cof(&self, _: &At) -> f64 {
        0.0
    }

    fn carry(&self, level: f64, _: f64, _: &mut WidthScale, _: BristleMove) -> f64 {
        level
    }

    fn steady_state(&self, _: f64, state: WidthScale) -> WidthScale {
        state
    }

    fn swapped(&self, _: &Self, state: WidthScale, _: Option<f64>) -> WidthScale {
        state
    }

    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        match key {
            "contact.width_load_exponent" => Some(&mut self.exponent),
            "contact.width_reference_load_n" => Some(&mut self.reference_load),
            _ => None,
        }
    }
}

impl WidthLaw {
    /// B(F)/B at load `load` (1 for a rigid contact, or a load that is not
    /// a positive number: the step's input check reports it).
    pub fn scale(&self, load: f64) -> f64 {
        if self.exponent == 0.0 || !(load.is_finite() && load > 0.0) {
            1.0
        } else {
            (load / self.reference_load).powf(self.exponent)
        }
    }
}
