//! Friction terms: what the contact's friction is made of besides the
//! film's shear, each in a file of its own, and composed here in one
//! documented order ([`FrictionTerms`]). Each term file declares its
//! configuration keys ([`TermKey`]: unit, valid range, whether it may
//! change while running, the scale of its default fit bounds); the
//! catalogue ([`catalogue`]) is what the configuration's validation, the
//! node's runtime-key list, the fit's default bounds and the README's key
//! table are derived from.
//!
//! | file | term |
//! |---|---|
//! | `mod.rs` | the list of terms, the catalogue, the sign function, the COF's definition |
//! | `term.rs` | the interface every term implements ([`FrictionTerm`]): its force, its level under pre-sliding, what acts beside the bristle, its COF part, its state, its keys and their check |
//! | `keys.rs` | a key's catalogue entry: its range, unit and fit scale |
//! | `compose.rs` | the composition: one loop over the terms per part, in the order below |
//! | `boundary_film.rs` | the boundary film: friction μ_bl on the asperity load, the rigid contact's sign regularisation, and the boundary film's rise with the logarithm of speed (Eyring) |
//! | `presliding.rs` | the contact's elastic displacement before gross sliding (a bristle on the model's own level) |
//! | `soft_width.rs` | a soft contact whose width follows the load |
//! | `drivetrain.rs` | losses beside the contact (bearings, seals, gears, a motor) |
//! | `test_term.rs` | (tests only) a term added as a new one is: its file and one line of the list |
//!
//! Composition, every step, once the film is solved (F_visc, F_asp are the
//! film's forces on the width B(F) of `soft_width.rs`):
//!
//! ```text
//! 1. level     L_c = F_visc + μ_bl F_asp s(v) + F_asp μ_r asinh(v/v_a)
//!                    s(v) = tanh(v/v_reg) for the rigid contact, sgn(v) with pre-sliding
//! rigid contact:
//! 2. contact   F_c = L_c
//! 3. total     F_f = F_c + F_dt(v, F_ext)
//! with pre-sliding (the compliance at a reversal is the whole axis's):
//! 2. level     L   = L_c + (F_cd + c_N F_ext) sgn(v) + ΔF_cd |sgn(v)|   (what acts at zero speed)
//!              F_b = σ0 z + σ1 ż on L                                  (the bristle)
//!              F_c = F_b L_c / L   (the contact's share; F_b when L = 0)
//! 3. total     F_f = F_b + b v + c_q v |v|
//! 4. COF           = (|F_visc| + (μ_bl + μ_r asinh(|v|/v_a)) F_asp) / F_ext (rigid)
//!                    |F_c| / F_ext (pre-sliding)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_visc | the film's shear force | N |
//! | F_asp | the load the asperities carry | N |
//! | F_ext | the normal load | N |
//! | L | the contact's friction in gross sliding | N |
//! | F_c | the friction the contact transmits | N |
//! | F_dt | the drivetrain's terms | N |
//! | F_f | the friction estimate | N |
//!
//! Every term is off by default (0) and then leaves every number of the
//! paper's model unchanged, bit for bit (a term is applied only when on).
//!
//! Adding a term: its file (a type implementing [`FrictionTerm`], with its
//! equation, symbol table and `KEYS`), one line in the list below, and its
//! keys in the configuration (`config/model.rs`, `config/mod.rs`) with its
//! tests. The composition, the states, `get`/`set`/`check`, validation,
//! live-ness, the fit's bounds and the docs' table follow from the list
//! and `KEYS`; `test_term.rs` is such a term, seen by the model, the
//! catalogue and the fit.

pub mod boundary_film;
mod compose;
pub mod drivetrain;
pub mod keys;
pub mod presliding;
pub mod soft_width;
pub mod term;
#[cfg(test)]
mod test_term;

use boundary_film::{BoundaryFilm, BoundaryRate};
use compose::friction_terms;
use drivetrain::Drivetrain;
pub use keys::{End, FitScale, Interval, TermKey};
use presliding::Presliding;
use soft_width::WidthLaw;
pub use term::{At, BristleMove, FrictionTerm, Kept, Place};

// The list of terms, in the composition's order: adding a term is its file
// (its type implementing `FrictionTerm`, its equation, symbol table and
// `KEYS`), one line here, and its keys' YAML (`config/model.rs`).
friction_terms! {
    boundary_film: BoundaryFilm,
    boundary_rate: BoundaryRate,
    presliding: Presliding,
    soft_width: WidthLaw,
    drivetrain: Drivetrain,
    #[cfg(test)]
    probe: test_term::Probe,
}

/// The coefficient of friction as users read it, in one line of ASCII:
/// the text every shape of the estimate carries beside its `cof` field
/// (`msg/msg/FrictionEstimate.msg`, the C header, the wire, record and
/// iceoryx2 structs, Python's stubs); `tests/cof_definition.rs` holds them
/// to it. [`FrictionTerms::cof`] computes it.
pub const COF_DEFINITION: &str =
    "contact friction per unit load: rigid (|F_visc| + (mu_bl + mu_r asinh(|v|/v_a)) F_asp) / F_ext; with pre-sliding |F_c| / F_ext; drivetrain terms excluded";

/// sgn(v): ±1, and 0 at rest (`f64::signum` gives ±1 at ±0). The sign of
/// gross sliding in the pre-sliding level, and of the classic models'
/// Coulomb terms.
pub fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Every friction term's keys, term by term, in the composition's order.
pub fn catalogue() -> impl Iterator<Item = &'static TermKey> {
    TERM_KEYS.iter().copied().flatten()
}

/// The catalogue's keys that the configuration holds: all of them but a
/// test build's test term's (`test_term.rs`, which has no YAML).
pub fn configured_catalogue() -> impl Iterator<Item = &'static TermKey> {
    catalogue().filter(|k| !of_the_test_term(k))
}

/// Whether `k` is the test term's (never in a build that is not a test).
#[cfg(test)]
fn of_the_test_term(k: &TermKey) -> bool {
    test_term::KEYS.contains(k)
}

/// Whether `k` is the test term's (never in a build that is not a test).
#[cfg(not(test))]
fn of_the_test_term(_: &TermKey) -> bool {
    false
}

/// The catalogue's entry for `key`.
pub fn term_key(key: &str) -> Option<&'static TermKey> {
    catalogue().find(|k| k.key == key)
}

/// Whether configuration key `key` acts after the film: a friction term's
/// key that the film's solution (pressure, gap, the film's forces) does not
/// depend on: every term's keys but those of a term on the film
/// ([`Place::Film`], the soft width, which scales the film's forces). A
/// change of such keys alone leaves the film as it was, and the friction
/// follows from the film's forces step by step through
/// [`FrictionTerms::friction`] (what a calibration uses to evaluate them
/// without solving the film again).
pub fn acts_after_the_film(key: &str) -> bool {
    TERM_PLACES
        .iter()
        .any(|(keys, place)| *place != Place::Film && keys.iter().any(|k| k.key == key))
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims
mod tests {
    use super::*;

    #[test]
    fn every_key_of_the_catalogue_is_named_once_with_a_unit_and_an_ordered_range() {
        let keys: Vec<&str> = catalogue().map(|k| k.key).collect();
        let mut unique = keys.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), keys.len(), "{keys:?}");
        for k in catalogue() {
            assert!(!k.unit.is_empty() && !k.symbol.is_empty(), "{}", k.key);
            assert!(k.lo.value() < k.hi.value(), "{}", k.key);
        }
        assert_eq!(
            term_key("contact.boundary_friction").unwrap().symbol,
            "μ_bl"
        );
        assert!(term_key("contact.load_n").is_none());
    }

    #[test]
    fn off_terms_leave_the_rigid_contact_as_the_paper_has_it() {
        let t = crate::physics::ModelParams::default().terms;
        let mut z = TermStates::default();
        let (v, f_visc, f_asp, load) = (0.01, 12.0, 5000.0, 20_000.0);
        let (c, total) = t.friction((v, load), (f_visc, f_asp), &mut z, BristleMove::Step(1e-3));
        assert_eq!(c, f_visc + 0.3 * f_asp * (v / 1e-4).tanh());
        assert_eq!(total, c);
        assert_eq!(
            t.cof(v, f_visc, f_asp, c, load),
            ((12.0 + 0.3 * 5000.0) / load, 0.0)
        );
        assert_eq!(z, TermStates::default());
        assert_eq!(sgn(-0.0), 0.0);
        assert_eq!(sgn(-2.0), -1.0);
    }

    #[test]
    fn every_listed_terms_keys_read_and_write_their_own_field_and_its_defaults_pass_its_check() {
        let base = FrictionTerms::default();
        assert!(base.check().is_ok());
        for k in catalogue() {
            let v = base
                .get(k.key)
                .unwrap_or_else(|| panic!("{} cannot be read", k.key));
            let mut t = base;
            let moved = if v == 0.0 { 0.5 } else { v * 0.5 };
            assert!(t.set(k.key, moved), "{} cannot be written", k.key);
            assert_eq!(t.get(k.key), Some(moved), "{}", k.key);
            // Every other key is where it was: each key has a field of its own.
            for other in catalogue().filter(|o| o.key != k.key) {
                assert_eq!(
                    t.get(other.key),
                    base.get(other.key),
                    "{} moved {}",
                    k.key,
                    other.key
                );
            }
        }
        assert!(base.get("contact.load_n").is_none());
    }

    #[test]
    fn a_term_outside_its_keys_range_is_refused_by_the_model_naming_the_catalogue_key() {
        let mut m = crate::physics::ModelParams::default();
        m.terms.boundary_rate.sensitivity = -0.1;
        match m.check() {
            Err(crate::physics::SetupError::InvalidParameter { field, value, .. }) => {
                assert_eq!(field, "contact.boundary_friction_rate");
                assert_eq!(value, -0.1);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn switching_pre_sliding_on_while_running_starts_the_bristle_at_the_last_level() {
        let off = FrictionTerms::default();
        let mut on = off;
        on.presliding.stiffness = 1e6;
        let states = TermStates::default();
        let swapped = on.swapped(&off, states, Some(25.0));
        assert_eq!(swapped.presliding, 25.0 / 1e6);
        // Already on: the displacement is kept; off again: kept (unused).
        let kept = TermStates {
            presliding: 3e-6,
            ..states
        };
        assert_eq!(on.swapped(&on, kept, Some(25.0)).presliding, 3e-6);
        assert_eq!(off.swapped(&on, kept, Some(25.0)).presliding, 3e-6);
        assert_eq!(on.swapped(&off, states, None).presliding, 0.0);
    }
}
