//! The composition of the friction terms: [`friction_terms!`] turns the one
//! list of terms (in `mod.rs`) into [`super::FrictionTerms`] (the terms'
//! parameters, a field per term), [`super::TermStates`] (their states) and
//! one loop per part of [`FrictionTerm`]; [`super::FrictionTerms::friction`]
//! and [`super::FrictionTerms::cof`] compose those parts in the order of the
//! module documentation. Nothing here names a term but the one the sign's
//! regularisation v_reg belongs to (the boundary film) and the boundary
//! rate's own part of the COF, which the estimate reports.
//!
//! Sums skip the terms that are off and start from the first term that is
//! on (not from 0.0), so that a model whose terms are off computes every
//! number as without them, bit for bit, signed zeros included.

use super::term::{At, BristleMove, FrictionTerm, Kept, Place};

/// `acc + x`, or `x` when nothing was summed yet.
#[inline(always)]
pub(super) fn add(acc: Option<f64>, x: f64) -> Option<f64> {
    Some(match acc {
        Some(a) => a + x,
        None => x,
    })
}

/// Whether `t` is on and acts in `place`.
#[inline(always)]
pub(super) fn acts<T: FrictionTerm>(t: &T, place: Place) -> bool {
    T::PLACE == place && t.is_on()
}

/// Generates, from the list of terms (`field: Type`, each line optionally
/// under a `#[cfg(..)]`): the terms' struct, their states' struct, the
/// catalogue of their keys, `get`/`set`/`check` by key, and one summing
/// loop per part of [`FrictionTerm`].
macro_rules! friction_terms {
    ($( $(#[$cfg:meta])* $field:ident : $ty:ty ),* $(,)?) => {
        /// The friction terms of one contact, one field per term of the
        /// list in `physics/terms/mod.rs`, composed in the order of the
        /// module documentation. All off by default but the boundary film.
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        pub struct FrictionTerms {
            $(
                $(#[$cfg])*
                #[doc = concat!("The `", stringify!($field), "` term.")]
                pub $field: $ty,
            )*
        }

        /// The terms' states (the pre-sliding displacement, the soft
        /// width's scale of the solve in progress), owned beside the terms
        /// by whoever advances them; the default is a solver's at its start.
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        pub struct TermStates {
            $(
                $(#[$cfg])*
                #[doc = concat!("The state of the `", stringify!($field), "` term.")]
                pub $field: <$ty as $crate::physics::terms::FrictionTerm>::State,
            )*
        }

        /// Every term's keys, term by term in the list's order.
        pub(crate) const TERM_KEYS: &[&[TermKey]] = &[
            $( $(#[$cfg])* <$ty as $crate::physics::terms::FrictionTerm>::KEYS, )*
        ];

        /// Every term's keys with where the term acts.
        pub(crate) const TERM_PLACES: &[(&[TermKey], Place)] = &[
            $( $(#[$cfg])* (
                <$ty as $crate::physics::terms::FrictionTerm>::KEYS,
                <$ty as $crate::physics::terms::FrictionTerm>::PLACE,
            ), )*
        ];

        impl FrictionTerms {
            /// The value of term key `key` (None: no term's key).
            pub fn get(&self, key: &str) -> Option<f64> {
                $( $(#[$cfg])* if let Some(v) = self.$field.get(key) { return Some(v); } )*
                None
            }

            /// Set term key `key` to `value`; false for any other key. The
            /// value is taken as it is (the caller keeps it in the key's
            /// valid range).
            pub fn set(&mut self, key: &str, value: f64) -> bool {
                $( $(#[$cfg])* if self.$field.set(key, value) { return true; } )*
                false
            }

            /// Every term's values against its keys' ranges.
            pub fn check(&self) -> Result<(), $crate::physics::SetupError> {
                $( $(#[$cfg])* self.$field.check()?; )*
                Ok(())
            }

            /// Σ force over the terms on in `place`, after `acc`.
            #[inline(always)]
            fn sum_force(&self, place: Place, at: &At, acc: Option<f64>) -> Option<f64> {
                #[allow(unused_mut)]
                let mut acc = acc;
                $( $(#[$cfg])* if compose::acts(&self.$field, place) {
                    acc = compose::add(acc, self.$field.force(at));
                } )*
                acc
            }

            /// Σ carried over the terms on in `place`, after `acc`.
            #[inline(always)]
            fn sum_carried(&self, place: Place, at: &At, acc: Option<f64>) -> Option<f64> {
                #[allow(unused_mut)]
                let mut acc = acc;
                $( $(#[$cfg])* if compose::acts(&self.$field, place) {
                    acc = compose::add(acc, self.$field.carried(at));
                } )*
                acc
            }

            /// Σ beside over the terms on in `place`.
            #[inline(always)]
            fn sum_beside(&self, place: Place, at: &At) -> Option<f64> {
                #[allow(unused_mut)]
                let mut acc = None;
                $( $(#[$cfg])* if compose::acts(&self.$field, place) {
                    acc = compose::add(acc, self.$field.beside(at));
                } )*
                acc
            }

            /// Σ of the COF's coefficients over the contact's terms that are on.
            #[inline(always)]
            fn sum_cof(&self, at: &At) -> Option<f64> {
                #[allow(unused_mut)]
                let mut acc = None;
                $( $(#[$cfg])* if compose::acts(&self.$field, Place::Contact) {
                    acc = compose::add(acc, self.$field.cof(at));
                } )*
                acc
            }

            /// Whether any term is on in `place`.
            #[inline(always)]
            fn any_on(&self, place: Place) -> bool {
                #[allow(unused_mut)]
                let mut on = false;
                $( $(#[$cfg])* { on |= compose::acts(&self.$field, place); } )*
                on
            }

            /// The level carried through every carrier that is on, their
            /// states moved as `how` says.
            #[inline(always)]
            fn carry(&self, level: f64, v: f64, states: &mut TermStates, how: BristleMove) -> f64 {
                #[allow(unused_mut)]
                let mut f = level;
                $( $(#[$cfg])* if compose::acts(&self.$field, Place::Carrier) {
                    f = self.$field.carry(f, v, &mut states.$field, how);
                } )*
                f
            }

            /// The states after swapping `old` for these terms while
            /// running, from `states` and the last step's contact friction.
            pub fn swapped(&self, old: &Self, states: TermStates, last_level: Option<f64>) -> TermStates {
                TermStates {
                    $( $(#[$cfg])* $field: self.$field.swapped(&old.$field, states.$field, last_level), )*
                }
            }
        }
    };
}
pub(super) use friction_terms;

impl super::FrictionTerms {
    /// The rigid contact's s (tanh(v/v_reg), v_reg the boundary film's).
    #[inline(always)]
    fn regularised_sign(&self, v: f64) -> f64 {
        (v / self.boundary_film.sign_regularization).tanh()
    }

    /// Whether a carrier (the pre-sliding bristle) is on.
    #[inline(always)]
    pub fn has_carrier(&self) -> bool {
        self.any_on(Place::Carrier)
    }

    /// (F_c, F_f): the contact's friction and the total at load `load`,
    /// from the film's forces (steps 1–3 of the module documentation);
    /// the carriers' states (the bristle z) move as `how` says. Axis terms
    /// off leave F_f = F_c, bit for bit.
    #[inline(always)]
    pub fn friction(
        &self,
        inputs: (f64, f64),
        film: (f64, f64),
        states: &mut super::TermStates,
        how: BristleMove,
    ) -> (f64, f64) {
        self.friction_with_kept(inputs, film, Kept::default(), states, how)
    }

    /// [`friction`](Self::friction) with the factors of the speed the
    /// caller holds ([`Kept`]: the boundary rate's asinh(v/v_a), the
    /// Stribeck fall): the same numbers, bit for bit, without computing
    /// them.
    #[inline(always)]
    pub fn friction_with_kept(
        &self,
        (v, load): (f64, f64),
        (f_visc, f_asp): (f64, f64),
        kept: Kept,
        states: &mut super::TermStates,
        how: BristleMove,
    ) -> (f64, f64) {
        let mut at = At {
            v,
            load,
            f_visc,
            f_asp,
            s: 0.0,
            kept,
        };
        if !self.has_carrier() {
            at.s = self.regularised_sign(v);
            let contact = self
                .sum_force(Place::Contact, &at, Some(f_visc))
                .unwrap_or(f_visc);
            let total = match self.sum_force(Place::Axis, &at, None) {
                Some(axis) => contact + axis,
                None => contact,
            };
            return (contact, total);
        }
        at.s = super::sgn(v);
        let level_c = self
            .sum_carried(Place::Contact, &at, Some(f_visc))
            .unwrap_or(f_visc);
        let Some(axis_level) = self.sum_carried(Place::Axis, &at, None) else {
            let f = self.carry(level_c, v, states, how);
            return (f, f);
        };
        // What acts at zero speed rides on the bristle; the contact's share
        // of its force is its share of the level.
        let level = level_c + axis_level;
        let f = self.carry(level, v, states, how);
        let contact = if level == 0.0 {
            f
        } else {
            f * (level_c / level)
        };
        let total = match self.sum_beside(Place::Axis, &at) {
            Some(b) => f + b,
            None => f,
        };
        (contact, total)
    }

    /// The COF and the boundary rate's part of it (step 4): the magnitude
    /// of the friction the contact transmits per unit load. Rigid contact:
    /// it always slides, so (|F_visc| + μ(|v|) F_asp) / F_ext, μ the sum of
    /// the contact terms' coefficients, the sign's regularisation not
    /// applied; with pre-sliding, |F_c| / F_ext. The rate's part
    /// μ_r asinh(|v|/v_a) F_asp / F_ext is 0 at v = 0 and steep near it: the
    /// one-sided limits at v = 0 are taken without it.
    #[inline(always)]
    pub fn cof(&self, v: f64, f_visc: f64, f_asp: f64, contact: f64, load: f64) -> (f64, f64) {
        if self.has_carrier() {
            return (contact.abs() / load, 0.0);
        }
        let at = At {
            v: v.abs(),
            load,
            f_visc,
            f_asp,
            s: 1.0,
            kept: Kept::default(),
        };
        let mu = self.sum_cof(&at).unwrap_or(0.0);
        let rate = if self.boundary_rate.is_on() {
            self.boundary_rate.cof(&at) * f_asp / load
        } else {
            0.0
        };
        ((f_visc.abs() + mu * f_asp) / load, rate)
    }
}
