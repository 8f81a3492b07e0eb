//! (Tests only.) A term added the way a new one is: this file and one line
//! in the list of `mod.rs`, nothing else. The tests below hold that the
//! model (the solver's friction), the catalogue (keys, validation, the
//! after-the-film rule) and the fit (setting its key on the terms, its
//! default bounds) see it.
//!
//! A constant drag beside the contact, signed with the motion, that the
//! pre-sliding bristle carries through a reversal:
//!
//! ```text
//! F_p = D s       s = tanh(v/v_reg) rigid, sgn v under pre-sliding
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | D | the probe's drag; 0 = off | N |

use super::term::{At, BristleMove, FrictionTerm, Place};
use super::{End, FitScale, TermKey};

/// The probe's one key.
pub(super) const KEYS: &[TermKey] = &[TermKey {
    key: "probe.drag_n",
    symbol: "D",
    unit: "N",
    lo: End::Closed(0.0),
    hi: End::Closed(1e6),
    live: true,
    fit: FitScale::Data {
        factor: 2.0,
        speed_power: 0,
        per_load: false,
        symmetric: false,
    },
    meaning: "a test term's constant drag",
}];

/// The probe term.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Probe {
    /// D, N.
    pub drag: f64,
}

impl FrictionTerm for Probe {
    const KEYS: &'static [TermKey] = KEYS;
    const PLACE: Place = Place::Axis;
    type State = ();

    fn is_on(&self) -> bool {
        self.drag != 0.0
    }

    fn force(&self, at: &At) -> f64 {
        self.drag * at.s
    }

    fn carried(&self, at: &At) -> f64 {
        self.drag * at.s
    }

    fn beside(&self, _: &At) -> f64 {
        0.0
    }

    fn cof(&self, _: &At) -> f64 {
        0.0
    }

    fn carry(&self, level: f64, _: f64, _: &mut (), _: BristleMove) -> f64 {
        level
    }

    fn steady_state(&self, _: f64, state: Self::State) -> Self::State {
        state
    }

    fn swapped(&self, _: &Self, state: Self::State, _: Option<f64>) -> Self::State {
        state
    }

    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        (key == "probe.drag_n").then_some(&mut self.drag)
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the contact's friction is unchanged exactly: a claim
mod tests {
    use super::super::{acts_after_the_film, term_key, FrictionTerms, TermStates};
    use super::*;
    use crate::physics::{ModelParams, SetupError, Solver, SolverSettings};
    use approx::assert_relative_eq;

    fn solver(drag: f64, stiffness: f64) -> Solver {
        let mut m = ModelParams::default();
        m.terms.probe.drag = drag;
        m.terms.presliding.stiffness = stiffness;
        let settings = SolverSettings {
            cells: 64,
            ..Default::default()
        };
        let mut s = Solver::new(&m, &settings).unwrap();
        s.initialize_steady(0.01, 20_762.0);
        s
    }

    #[test]
    fn the_model_adds_a_listed_terms_force_beside_the_contact() {
        let (mut off, mut on) = (solver(0.0, 0.0), solver(50.0, 0.0));
        for k in 0..20 {
            let v = 0.01 - 0.001 * k as f64;
            let (a, b) = (off.step(v, 20_762.0), on.step(v, 20_762.0));
            assert_eq!(a.contact_friction_force, b.contact_friction_force);
            assert_relative_eq!(
                b.friction_force - a.friction_force,
                50.0 * (v / 1e-4).tanh(),
                max_relative = 1e-9,
                epsilon = 1e-9
            );
        }
    }

    #[test]
    fn the_pre_sliding_bristle_carries_a_listed_terms_level() {
        // In steady sliding the bristle transmits its whole level: the
        // probe's drag with the exact sign.
        let (mut off, mut on) = (solver(0.0, 1e8), solver(50.0, 1e8));
        let (mut a, mut b) = (off.step(0.01, 20_762.0), on.step(0.01, 20_762.0));
        for _ in 0..50 {
            (a, b) = (off.step(0.01, 20_762.0), on.step(0.01, 20_762.0));
        }
        assert_relative_eq!(
            b.friction_force - a.friction_force,
            50.0,
            max_relative = 1e-6
        );
    }

    #[test]
    fn the_catalogue_lists_a_listed_terms_keys_and_the_model_checks_them() {
        let k = term_key("probe.drag_n").expect("in the catalogue");
        assert_eq!(k.unit, "N");
        assert!(acts_after_the_film("probe.drag_n"));
        let mut t = FrictionTerms::default();
        assert!(t.set("probe.drag_n", 3.0));
        assert_eq!(t.get("probe.drag_n"), Some(3.0));
        t.probe.drag = -1.0;
        match t.check() {
            Err(SetupError::InvalidParameter { field, .. }) => assert_eq!(field, "probe.drag_n"),
            other => panic!("{other:?}"),
        }
        let mut m = ModelParams::default();
        m.terms.probe.drag = f64::NAN;
        assert!(Solver::new(&m, &SolverSettings::default()).is_err());
    }

    #[test]
    fn the_composition_of_the_fit_sees_a_listed_term_set_by_key() {
        // What the fit does to evaluate a term key without a film solve:
        // set the key on the terms, compose along the film's forces.
        let mut t = FrictionTerms::default();
        let mut z = TermStates::default();
        let film = (12.0, 5000.0);
        let before = t.friction((0.01, 20_000.0), film, &mut z, BristleMove::Steady);
        t.set("probe.drag_n", 7.0);
        let after = t.friction((0.01, 20_000.0), film, &mut z, BristleMove::Steady);
        assert_eq!(before.0, after.0);
        assert_relative_eq!(after.1 - before.1, 7.0, max_relative = 1e-12);
    }
}
