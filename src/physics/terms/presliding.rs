//! Pre-sliding compliance: the contact's elastic tangential displacement
//! before gross sliding (asperity junctions, an elastomer's body), in
//! series with the contact, with LuGre's bristle dynamics and the model's
//! own friction in gross sliding as its level.
//!
//! ```text
//! L  = F_visc + μ_bl F_asp sgn(v) + F_asp μ_r asinh(v/v_a)
//!      + (F_cd + c_N F_ext) sgn(v) + ΔF_cd |sgn(v)|   the friction in gross sliding that acts at zero speed
//! ż  = |v| sgn(L) − σ0 |v| z / |L|  = a (z_ss − z),   a = σ0 |v| / |L|,  z_ss = L / σ0
//! F  = σ0 z + σ1 ż
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | z | mean elastic (bristle) displacement of the contact | m |
//! | σ0 | tangential (pre-sliding) stiffness; 0 = off | N/m |
//! | σ1 | damping of the displacement | N·s/m |
//! | v | sliding velocity of the slider | m/s |
//! | L | the friction of gross sliding at this state that acts at zero speed: fluid shear, boundary friction and its rate, and the drivetrain's Coulomb, load-proportional and asymmetric levels (`drivetrain.rs`), signed; the compliance at a reversal is the whole axis's | N |
//! | F | the contact's friction force | N |
//!
//! With L = g(v) sgn v this is LuGre's ż = v − σ0 |v| z / g(v), but its
//! steady curve is not fitted: it is the lubrication model's own, so it
//! follows load, viscosity, temperature, roughness and the squeeze film.
//! Through a reversal the force passes zero gradually, over a displacement
//! of about |L|/σ0, instead of switching within ±v_reg; in steady sliding
//! z = z_ss and F = L, the model's friction without the sign's
//! regularisation.
//!
//! The bristle replaces the rigid contact's sign regularisation
//! tanh(v / v_reg) (`contact.sign_regularization_m_s`, a numerical device):
//! its level L uses the exact sign, so a very stiff bristle reaches the
//! rigid model *without* regularisation, i.e. the rigid contact's limit
//! v_reg → 0. At speeds near v_reg the two differ by design (a 1 mm/s
//! motion by up to ~30 % between v_reg = 1e-4 and 3e-4 m/s, all of it in
//! the rigid contact); v_reg still shapes the drivetrain's terms.
//!
//! The damping is LuGre's, unbounded by the level: while the bristle moves
//! (a reversal, a start) σ1 ż carries |F| past |L|, by at most 2 σ1 |v|
//! (|ż| ≤ 2 |v| while |σ0 z| ≤ |L|), and by nothing in steady sliding or at
//! rest. It is a viscous coefficient that acts only while the bristle
//! moves, and its size is its key's range, as a viscous coefficient's is.
//! An earlier bound at max(|L|, |σ0 z|) kept a damping far above critical
//! from giving large forces at speed, but it also kept LuGre out of the
//! model: on a joint's time series made by LuGre (σ1/σ0 = 0.0086 s)
//! predicted at 2.5× the speed, the bound cut the overshoot at the fast
//! reversals (1.9 N·m measured, 1.17 predicted) and ours predicted 0.0501
//! N·m against LuGre's 0.0319; without it, 0.0325
//! (`docs/joint-series-draws.sh`, draw 8).
//!
//! Integration: over a step the velocity and the level are taken at its
//! end, so ż is linear in z and the step is exact for them:
//! `z ← z_ss + (z − z_ss) e^(−a Δt)`, and the damping term takes ż at the
//! step's end, a (z_ss − z) — LuGre's ż = v − σ0 |v| z / g(v) there, not
//! the step's mean rate Δz/Δt, which exceeds it by the factor
//! (e^(a Δt) − 1)/(a Δt) while the bristle moves.
//! This is stable for any σ0 and Δt: a bristle stiffer than the step can
//! resolve (a Δt ≫ 1) relaxes within the step, and the rigid model
//! results. At rest (v = 0) z is held.

use super::term::{At, BristleMove, FrictionTerm, Place};
use super::{End, FitScale, TermKey};

/// The bristle's keys: stiffness and damping.
const KEYS: &[TermKey] = &[
    TermKey {
        key: "contact.presliding_stiffness_n_m",
        symbol: "σ0",
        unit: "N/m",
        lo: End::Closed(0.0),
        hi: End::Closed(1e15),
        live: true,
        // Searched over its physical range: the force builds over a
        // displacement between 0.1 µm (hard metal asperities) and 1 mm (an
        // elastomer's body); a stiffness that is off starts at the data's
        // stiffness through its reversals (the fit's own rule).
        fit: FitScale::Stiffness {
            x_lo: 1e-7,
            x_hi: 1e-3,
        },
        meaning: "tangential stiffness before gross sliding (a bristle on the model's own level); 0 = rigid",
    },
    TermKey {
        key: "contact.presliding_damping_n_s_m",
        symbol: "σ1",
        unit: "N·s/m",
        lo: End::Closed(0.0),
        hi: End::Closed(1e9),
        live: true,
        fit: FitScale::Data {
            factor: 100.0,
            speed_power: 1,
            per_load: false,
            symmetric: false,
        },
        meaning: "damping of that displacement's rate (LuGre's): while the bristle moves it adds at most 2 σ1 times the speed to the level",
    },
];

/// The pre-sliding parameters (both zero by default: the contact is rigid
/// and its estimate bit-identical to a model without this module).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Presliding {
    /// σ0, N/m.
    pub stiffness: f64,
    /// σ1, N·s/m.
    pub damping: f64,
}

impl FrictionTerm for Presliding {
    const KEYS: &'static [TermKey] = KEYS;
    const PLACE: Place = Place::Carrier;
    /// z, the displacement, m (0 while off).
    type State = f64;

    /// Whether the bristle is in (a stiffness above zero).
    fn is_on(&self) -> bool {
        self.stiffness > 0.0
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

    /// The bristle's force on `level`, z moved as `how` says.
    #[inline(always)]
    fn carry(&self, level: f64, v: f64, z: &mut f64, how: BristleMove) -> f64 {
        match how {
            BristleMove::Step(dt) => {
                let (z_new, f) = self.advance(*z, level, v, dt);
                *z = z_new;
                f
            }
            BristleMove::Steady => {
                *z = self.steady_displacement(level);
                level
            }
            BristleMove::Hold => level,
        }
    }

    fn steady_state(&self, level: f64, _: f64) -> f64 {
        self.steady_displacement(level)
    }

    /// Switched on while running: as if it had always been, the displacement
    /// of the last state's level (0 before the first step).
    fn swapped(&self, old: &Self, z: f64, last_level: Option<f64>) -> f64 {
        if !old.is_on() && self.is_on() {
            last_level.map_or(0.0, |l| self.steady_displacement(l))
        } else {
            z
        }
    }

    fn slot(&mut self, key: &str) -> Option<&mut f64> {
        match key {
            "contact.presliding_stiffness_n_m" => Some(&mut self.stiffness),
            "contact.presliding_damping_n_s_m" => Some(&mut self.damping),
            _ => None,
        }
    }
}

impl Presliding {
    /// The displacement in steady sliding at level `level` (N), m.
    pub fn steady_displacement(&self, level: f64) -> f64 {
        level / self.stiffness
    }

    /// The displacement after a step of `dt` (s) at velocity `v` (m/s) and
    /// level `level` (N), from `z` (m), and the friction force then (N).
    pub fn advance(&self, z: f64, level: f64, v: f64, dt: f64) -> (f64, f64) {
        let z_ss = self.steady_displacement(level);
        let rate = if level == 0.0 {
            f64::INFINITY
        } else {
            self.stiffness * v.abs() / level.abs()
        };
        let decay = (-rate * dt).exp();
        // e^(−∞) = 0 (no level: no displacement); 0 · ∞ never arises.
        let z_new = z_ss + (z - z_ss) * decay;
        // ż at the step's end, exact for the step: a (z_ss − z). A bristle
        // that relaxed within the step (a infinite: no level) stands still.
        let z_dot = if rate.is_finite() {
            rate * (z_ss - z_new)
        } else {
            0.0
        };
        (z_new, self.stiffness * z_new + self.damping * z_dot)
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims (0, 1, representable sums)
mod tests {
    use super::super::sgn;
    use super::*;
    use approx::assert_relative_eq;

    const P: Presliding = Presliding {
        stiffness: 2e4,
        damping: 0.0,
    };

    #[test]
    fn in_steady_sliding_the_force_is_the_level() {
        let mut z = 0.0;
        let mut f = 0.0;
        for _ in 0..2000 {
            (z, f) = P.advance(z, 5.0, 0.01, 1e-3);
        }
        assert_relative_eq!(f, 5.0, max_relative = 1e-12);
        assert_relative_eq!(z, P.steady_displacement(5.0), max_relative = 1e-12);
    }

    #[test]
    fn through_a_reversal_the_force_follows_lugre_over_the_displacement_level_over_stiffness() {
        // From steady sliding at −L, moving at +v: the exact solution is
        // F(x) = L − 2L e^(−σ0 x / L) after a displacement x.
        let (level, v, dt) = (5.0, 0.01, 1e-4);
        let mut z = P.steady_displacement(-level);
        let mut x = 0.0;
        for _ in 0..500 {
            let (zn, f) = P.advance(z, level, v, dt);
            z = zn;
            x += v * dt;
            assert_relative_eq!(
                f,
                level - 2.0 * level * (-P.stiffness * x / level).exp(),
                max_relative = 1e-9,
                epsilon = 1e-9
            );
        }
        // The force passes zero after a displacement of L/σ0 · ln 2.
        assert!(x > level / P.stiffness * 2f64.ln());
    }

    #[test]
    fn any_stiffness_is_stable_and_a_very_stiff_contact_is_the_rigid_model() {
        for stiffness in [1.0, 1e6, 1e12, 1e300] {
            let p = Presliding {
                stiffness,
                damping: 0.0,
            };
            let mut z = p.steady_displacement(-3.0);
            for k in 0..100 {
                let v: f64 = if k < 50 { -0.1 } else { 0.1 };
                let level = 3.0 * v.signum();
                let (zn, f) = p.advance(z, level, v, 1e-3);
                assert!(zn.is_finite() && f.is_finite(), "σ0 {stiffness}");
                assert!(f.abs() <= 3.0 * (1.0 + 1e-12), "σ0 {stiffness}: {f}");
                z = zn;
            }
        }
        let stiff = Presliding {
            stiffness: 1e12,
            damping: 0.0,
        };
        let (_, f) = stiff.advance(stiff.steady_displacement(-3.0), 3.0, 0.1, 1e-3);
        assert_relative_eq!(f, 3.0, max_relative = 1e-12);
    }

    #[test]
    fn the_damping_carries_the_force_past_the_level_by_at_most_twice_sigma1_v_and_only_while_the_bristle_moves(
    ) {
        // LuGre's overshoot at a reversal, not cut at the level: a sine of
        // 1 m/s through two reversals a second. F = L + (1 − z/z_ss)(σ1 v − L)
        // while the bristle crosses: past the level once σ1 |v| > |L|
        // (here above 0.03 m/s, reached within the crossing).
        let p = Presliding {
            stiffness: 1e5,
            damping: 2000.0,
        };
        let level = 60.0;
        let mut z = p.steady_displacement(-level);
        let mut worst_excess: f64 = 0.0;
        let mut past_level = false;
        for k in 1..2000 {
            let t = k as f64 * 1e-3;
            let v = (std::f64::consts::TAU * t).sin();
            let l = level * sgn(v);
            let (zn, f) = p.advance(z, l, v, 1e-3);
            past_level |= f.abs() > level * 1.01;
            worst_excess = worst_excess.max((f.abs() - level) / (2.0 * 2000.0 * v.abs()));
            z = zn;
        }
        assert!(past_level, "the damping's overshoot at a reversal");
        assert!(worst_excess <= 1.0 + 1e-12, "{worst_excess}");
        // Steady sliding: the bristle at rest on its level, no damping force.
        let z_ss = p.steady_displacement(level);
        let (_, f) = p.advance(z_ss, level, 0.7, 1e-3);
        assert_relative_eq!(f, level, max_relative = 1e-12);
        // A NaN level is a NaN force, not a panic.
        assert!(p.advance(0.0, f64::NAN, 0.1, 1e-3).1.is_nan());
    }

    #[test]
    fn at_rest_the_displacement_is_held_and_damping_acts_on_its_rate() {
        let p = Presliding {
            stiffness: 1e4,
            damping: 50.0,
        };
        let (z, f) = p.advance(1e-4, 2.0, 0.0, 1e-3);
        assert_eq!(z, 1e-4);
        assert_relative_eq!(f, 1.0, max_relative = 1e-12);
        // Pre-sliding from z = 0: ż ≈ v, so damping adds about σ1 v.
        let (z, f) = p.advance(0.0, 2.0, 1e-3, 1e-3);
        let z_dot = 1e-3 - 1e4 * 1e-3 * z / 2.0;
        assert_relative_eq!(f, 1e4 * z + 50.0 * z_dot, max_relative = 1e-12);
        assert!((z_dot - 1e-3).abs() < 1e-5, "{z_dot}");
        // No level: no displacement.
        assert_eq!(p.advance(1e-4, 0.0, 0.1, 1e-3).0, 0.0);
    }

    #[test]
    fn the_force_is_lugres_with_the_displacement_rate_at_the_step_end() {
        // F = σ0 z + σ1 ż, ż = v − σ0 |v| z / g(v) at the step's end, on a
        // step the bristle takes a visible part of (a Δt = 0.5): the step's
        // mean rate Δz/Δt, (e^(a Δt) − 1)/(a Δt) times ż at the end, would be
        // 30 % higher here.
        let p = Presliding {
            stiffness: 1e6,
            damping: 2e3,
        };
        let (level, v, dt) = (200.0, 0.1, 1e-3);
        let z0 = p.steady_displacement(-level);
        let (z, f) = p.advance(z0, level, v, dt);
        let z_dot = v - 1e6 * v * z / level;
        assert_relative_eq!(f, 1e6 * z + 2e3 * z_dot, max_relative = 1e-12);
        let mean = (z - z0) / dt;
        assert_relative_eq!(
            mean / z_dot,
            (0.5f64.exp() - 1.0) / 0.5,
            max_relative = 1e-9
        );
    }
}
