//! The interface every friction term implements ([`FrictionTerm`]): how it
//! acts in the rigid contact, what of it the pre-sliding bristle carries and
//! what acts beside it, its part of the COF, its state and its keys. The
//! composition (`compose.rs`) is one loop over the terms through this trait;
//! a term that lacks a part does not compile.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | v | sliding velocity | m/s |
//! | F_ext | the normal load | N |
//! | F_visc, F_asp | the film's shear force, the load the asperities carry | N |
//! | s | the sign of sliding: tanh(v/v_reg) in the rigid contact, sgn v with pre-sliding | – |
//! | L | the level the pre-sliding bristle carries | N |

use super::keys::{Interval, TermKey};
use crate::physics::SetupError;

/// Where a term acts, which decides where the composition adds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Place {
    /// In the contact, on the film's forces: part of the contact's friction
    /// F_c and of the COF.
    Contact,
    /// Beside the contact (bearings, seals, a motor): part of the total F_f
    /// only, not of F_c or the COF.
    Axis,
    /// The carrier of the level at zero speed (the pre-sliding bristle): it
    /// transmits the level of the force terms, [`FrictionTerm::carry`].
    Carrier,
    /// On the film itself (the soft width): it scales the film's forces
    /// before any friction term acts, so its keys are not "after the film".
    Film,
}

/// The state a term is evaluated at (one step's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct At {
    /// v, m/s.
    pub v: f64,
    /// F_ext, N.
    pub load: f64,
    /// F_visc, N.
    pub f_visc: f64,
    /// F_asp, N.
    pub f_asp: f64,
    /// s: tanh(v/v_reg) for the rigid contact's force, sgn v for the level
    /// pre-sliding carries.
    pub s: f64,
    /// The factors of this `v` the caller holds ([`Kept`]).
    pub kept: Kept,
}

/// Factors of the speed alone that a caller may hold for a term: a fit
/// recomposes the friction along a kept film, whose speeds do not change,
/// many times at the same few values of a term's speed keys
/// (`fit/film_run.rs`). `None`: the term computes the factor. Either way
/// the same number, bit for bit.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Kept {
    /// asinh(v/v_a) of the boundary rate.
    pub rate_asinh: Option<f64>,
    /// The drivetrain's Stribeck fall e^(−|v/v_s|^α_s).
    pub stribeck_fall: Option<f64>,
    /// The drivetrain's viscous bend |v/v_b|^δ.
    pub viscous_bend: Option<f64>,
}

/// How the carrier's state moves in one evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BristleMove {
    /// A step of this length, s: the state advances.
    Step(f64),
    /// A steady state: the state takes its steady value.
    Steady,
    /// Neither (a solve that does not advance time): the state is held.
    Hold,
}

/// One friction term. Every part is required: a term says how it acts in
/// each place of the composition, even where that is "not at all" (0, or
/// the level passed through), so the compiler refuses a term that forgot
/// one. Off (`is_on` false) a term is skipped, and every number is the
/// one without it, bit for bit.
pub trait FrictionTerm: Copy + PartialEq + Default + std::fmt::Debug {
    /// Its configuration keys: the catalogue's entries for it.
    const KEYS: &'static [TermKey];
    /// Where it acts.
    const PLACE: Place;
    /// What it carries from step to step (`()` when nothing); its default
    /// is the state of a solver just built.
    type State: Copy + PartialEq + Default + std::fmt::Debug;

    /// Whether it acts.
    fn is_on(&self) -> bool;

    /// Its force in the rigid contact at `at` (at.s = tanh(v/v_reg)), N
    /// (0 for a carrier or a film term).
    fn force(&self, at: &At) -> f64;

    /// Its part of the level L that pre-sliding carries, with the exact
    /// sign (at.s = sgn v): what of it acts at zero speed, N.
    fn carried(&self, at: &At) -> f64;

    /// Its part beside the bristle under pre-sliding: what of it vanishes
    /// with the speed, N (0 for a contact term: the contact's friction is
    /// all carried).
    fn beside(&self, at: &At) -> f64;

    /// Its part of the COF's coefficient on the asperity load at |v|
    /// (at.v ≥ 0; 0 for a term outside the contact), –.
    fn cof(&self, at: &At) -> f64;

    /// The force a carrier transmits on `level` at velocity `v`, its state
    /// moved as `how` says (any other term: the level, state untouched).
    fn carry(&self, level: f64, v: f64, state: &mut Self::State, how: BristleMove) -> f64;

    /// Its state in steady sliding on `level`, from `state` (a stateless
    /// term, or one whose state does not depend on the level: `state`).
    fn steady_state(&self, level: f64, state: Self::State) -> Self::State;

    /// Its state when a running model swaps `old` for `self` between two
    /// steps: `state` kept, or started as if the term had always been on,
    /// from the last step's contact friction `last_level` (None before the
    /// first step).
    fn swapped(&self, old: &Self, state: Self::State, last_level: Option<f64>) -> Self::State;

    /// The field of its key `key` (None: not its key): the one place a
    /// term maps its keys onto its fields ([`FrictionTerm::get`] and
    /// [`FrictionTerm::set`] follow from it).
    fn slot(&mut self, key: &str) -> Option<&mut f64>;

    /// The value of its key `key` (None: not its key).
    fn get(&self, key: &str) -> Option<f64> {
        let mut copy = *self;
        copy.slot(key).map(|v| *v)
    }

    /// Set its key `key` to `value` (false: not its key; the value is taken
    /// as it is).
    fn set(&mut self, key: &str, value: f64) -> bool {
        match self.slot(key) {
            Some(v) => {
                *v = value;
                true
            }
            None => false,
        }
    }

    /// Its values against the ranges its keys declare, the offending key
    /// named as the catalogue (and the configuration) spells it.
    fn check(&self) -> Result<(), SetupError> {
        for k in Self::KEYS {
            let v = self.get(k.key).unwrap_or(f64::NAN);
            if !(Interval { lo: k.lo, hi: k.hi }).contains(v) {
                return Err(SetupError::invalid(
                    k.key,
                    v,
                    "must be finite and inside the key's range (see the README's term keys)",
                ));
            }
        }
        Ok(())
    }
}
