//! Drivetrain losses beside the contact: what a motor current or a load
//! cell measures besides the lubricated contact (support bearings, seals,
//! gear mesh), which no contact model should be asked to absorb.
//!
//! ```text
//! F_dt = (F_cd + c_N F_ext + ΔF_s e^(−|v/v_s|^α_s)) tanh(v / v_reg) + ΔF_cd |tanh(v / v_reg)| + F_v(v) + c_q v |v|
//! F_v(v) = b v_b sgn v |v / v_b|^δ   (δ = 1: b v, whatever v_b)
//! F_total = F_f + F_dt
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_cd | constant (Coulomb) drivetrain friction | N |
//! | ΔF_cd | direction asymmetry: the level is F_cd + ΔF_cd moving forward, F_cd − ΔF_cd backward (a screw lifting or lowering a load, a seal's lip) | N |
//! | c_N | friction proportional to the normal load (rolling elements carrying it) | – |
//! | ΔF_s | the static level's excess over the Coulomb level (Stribeck): F_cd + ΔF_s at rest, decaying to F_cd over v_s; negative: a friction that rises with speed to F_cd | N |
//! | v_s | the Stribeck speed | m/s |
//! | α_s | the Stribeck fall's exponent: 2 (the default) the Gaussian fall of the classic curve and LuGre; measured falls 0.5–2, whose tails are longer | – |
//! | b | viscous drivetrain friction (bent: F_v(v_b) / v_b) | N·s/m |
//! | δ | the viscous rise's exponent: 1 a straight rise; below 1 a rise that bends below the line as speed grows, as a rolling bearing's viscous moment grows with (ν n)^(2/3) (Palmgren) and a film's shear over a film that thickens with speed | – |
//! | v_b | the speed at which F_v = b v_b: where b is read (a fit sets it to the data's top speed, so that b and δ are told apart) | m/s |
//! | c_q | loss growing with the square of the speed (churning, windage, iron and eddy losses of a motor, reflected to the slider) | N·s²/m² |
//! | v_reg | the contact's sign regularisation (the same tanh) | m/s |
//!
//! All zero by default: the estimate is then the contact's alone, bit for bit.
//! With pre-sliding on (`presliding.rs`) the terms that act at zero speed,
//! (F_cd + c_N F_ext + ΔF_s e^(−|v/v_s|^α_s)) sgn v + ΔF_cd |sgn v|, are part of
//! the bristle's level (a reversal's compliance is the whole axis's), and
//! only F_v(v) + c_q v|v| is added beside it.
//!
//! With these terms the classic models are special cases of ours: Coulomb +
//! viscous (F_cd, b), Stribeck with its static level above or below the
//! Coulomb level (F_cd, ΔF_s, v_s, b), and LuGre (the same on the pre-sliding
//! bristle, σ0 and σ1): a calibration can always reach the best classic's
//! training error, and the data say where the film adds to it.

use super::term::{At, BristleMove, FrictionTerm, Kept, Place};
use super::{End, FitScale, TermKey};

/// Past this a, e^(−a) is 0 in f64 (e^(−745.14) is below the smallest
/// subnormal).
const EXP_NEG_ZERO: f64 = 745.2;

/// e^(−a), the Stribeck fall's factor, for a ≥ 0 (NaN passes through).
/// Bit for bit `(-a).exp()`: past [`EXP_NEG_ZERO`] that is 0, which this
/// returns without the math library's underflow path (its error
/// handling: a fifth of a fit's time in `exp` on the EMPS record, whose
/// speeds lie far past its Stribeck speed).
#[inline(always)]
pub(crate) fn exp_neg(a: f64) -> f64 {
    if a > EXP_NEG_ZERO {
        0.0
    } else {
        (-a).exp()
    }
}

/// Bounds up to `factor` times the data's friction over speed^`power`.
const fn data(factor: f64, speed_power: i32) -> FitScale {
    FitScale::Data {
        factor,
        speed_power,
        per_load: false,
        symmetric: false,
    }
}

/// The drivetrain's keys.
const KEYS: &[TermKey] = &[
    TermKey {
        key: "drivetrain.coulomb_n",
        symbol: "F_cd",
        unit: "N",
        lo: End::Closed(0.0),
        hi: End::Closed(1e9),
        live: true,
        fit: data(2.0, 0),
        meaning: "constant (Coulomb) drivetrain friction",
    },
    TermKey {
        key: "drivetrain.viscous_n_s_m",
        symbol: "b",
        unit: "N·s/m",
        lo: End::Closed(0.0),
        hi: End::Closed(1e9),
        live: true,
        fit: data(2.0, 1),
        meaning: "viscous drivetrain friction",
    },
    TermKey {
        key: "drivetrain.viscous_exponent",
        symbol: "δ",
        unit: "–",
        lo: End::Closed(0.1),
        hi: End::Closed(1.0),
        live: true,
        fit: FitScale::FromStart,
        meaning: "the viscous rise's exponent: 1 straight, below 1 bending below the line as speed grows",
    },
    TermKey {
        key: "drivetrain.viscous_reference_speed_m_s",
        symbol: "v_b",
        unit: "m/s",
        lo: End::Open(0.0),
        hi: End::Closed(100.0),
        live: true,
        fit: FitScale::FromStart,
        meaning: "the speed at which the bent viscous rise equals b v_b",
    },
    TermKey {
        key: "drivetrain.load_coefficient",
        symbol: "c_N",
        unit: "–",
        lo: End::Closed(0.0),
        hi: End::Closed(10.0),
        live: true,
        fit: FitScale::Data {
            factor: 2.0,
            speed_power: 0,
            per_load: true,
            symmetric: false,
        },
        meaning: "friction proportional to the normal load (rolling elements carrying it)",
    },
    TermKey {
        key: "drivetrain.quadratic_n_s2_m2",
        symbol: "c_q",
        unit: "N·s²/m²",
        lo: End::Closed(0.0),
        hi: End::Closed(1e9),
        live: true,
        fit: data(2.0, 2),
        meaning: "loss growing with the square of speed (churning, windage, a motor's iron losses)",
    },
    TermKey {
        key: "drivetrain.stribeck_n",
        symbol: "ΔF_s",
        unit: "N",
        lo: End::Closed(-1e9),
        hi: End::Closed(1e9),
        live: true,
        fit: FitScale::Data {
            factor: 1.0,
            speed_power: 0,
            per_load: false,
            symmetric: true,
        },
        meaning: "Stribeck: the static level's excess over the Coulomb level, decaying over v_s (negative: rising to it)",
    },
    TermKey {
        key: "drivetrain.stribeck_speed_m_s",
        symbol: "v_s",
        unit: "m/s",
        lo: End::Open(1e-9),
        hi: End::Closed(100.0),
        live: true,
        // At most the data's top speed: there the data still show 63 % of
        // the fall (e^(−1) left). A Stribeck speed past every measured speed
        // shows the data only the start of a fall, a curvature, and puts the
        // level it falls (or rises) to past the data, a regime change they
        // do not show: with up to 3 × the top speed allowed, a Coulomb +
        // viscous joint fitted at 0.5–20 deg/s chose such a curve and
        // predicted 25–90 deg/s up to 6.5× worse than Coulomb + viscous.
        fit: FitScale::Speed { lo: 1e-3, hi: 1.0 },
        meaning: "the Stribeck speed: the static excess decays as e^(−(speed/v_s)^α_s)",
    },
    TermKey {
        key: "drivetrain.stribeck_exponent",
        symbol: "α_s",
        unit: "–",
        lo: End::Closed(0.3),
        hi: End::Closed(4.0),
        live: true,
        fit: FitScale::FromStart,
        meaning: "the Stribeck fall's exponent α_s of that decay; 2 (the default) the Gaussian fall of the classic curve and LuGre",
    },
    TermKey {
        key: "drivetrain.coulomb_asymmetry_n",
        symbol: "ΔF_cd",
        unit: "N",
        lo: End::Closed(-1e9),
        hi: End::Closed(1e9),
        live: true,
        fit: FitScale::Data {
            factor: 1.0,
            speed_power: 0,
            per_load: false,
            symmetric: true,
        },
        meaning: "direction asymmetry: the level is F_cd + ΔF_cd forward, F_cd − ΔF_cd backward",
    },
];

/// The drivetrain terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drivetrain {
    /// F_cd, N.
    pub coulomb: f64,
    /// b, N·s/m.
    pub viscous: f64,
    /// δ, dimensionless (1: a straight rise).
    pub viscous_exponent: f64,
    /// v_b, m/s.
    pub viscous_reference_speed: f64,
    /// c_N, dimensionless.
    pub load_coefficient: f64,
    /// c_q, N·s²/m².
    pub quadratic: f64,
    /// ΔF_cd, N.
    pub coulomb_asymmetry: f64,
    /// ΔF_s, N.
    pub stribeck: f64,
    /// v_s, m/s.
    pub stribeck_speed: f64,
    /// α_s, dimensionless (2: the Gaussian fall).
    pub stribeck_exponent: f64,
}

/// The viscous rise's reference speed when none is set, m/s.
pub const DEFAULT_VISCOUS_REFERENCE_SPEED_M_S: f64 = 1.0;

/// The Stribeck speed when none is set, m/s.
pub const DEFAULT_STRIBECK_SPEED_M_S: f64 = 0.01;

impl Default for Drivetrain {
    /// Every term off.
    fn default() -> Self {
        Self {
            coulomb: 0.0,
            viscous: 0.0,
            viscous_exponent: 1.0,
            viscous_reference_speed: DEFAULT_VISCOUS_REFERENCE_SPEED_M_S,
            load_coefficient: 0.0,
            quadratic: 0.0,
            coulomb_asymmetry: 0.0,
            stribeck: 0.0,
            stribeck_speed: DEFAULT_STRIBECK_SPEED_M_S,
            stribeck_exponent: 2.0,
        }
    }
}

impl FrictionTerm for Drivetrain {
    const KEYS: &'static [TermKey] = KEYS;
    const PLACE: Place = Place::Axis;
    type State = ();

    /// Whether any of its terms is not zero (all zero: the estimate is the
    /// contact's alone).
    fn is_on(&self) -> bool {
        !self.is_zero()
    }

    /// F_dt with the rigid contact's s = tanh(v/v_reg).
    #[inline(always)]
    fn force(&self, at: &At) -> f64 {
        self.force_kept(at.v, at.load, at.s, &at.kept)
    }

    /// (F_cd + c_N F + ΔF_s e^(−|v/v_s|^α_s)) s + ΔF_cd |s| with s = sgn v.
    #[inline(always)]
    fn carried(&self, at: &At) -> f64 {
        self.level_at_rest_kept(at.v, at.s, at.load, at.kept.stribeck_fall)
    }

    /// F_v(v) + c_q v |v|.
    #[inline(always)]
    fn beside(&self, at: &At) -> f64 {
        self.rate_terms_kept(at.v, at.kept.viscous_bend)
    }

    /// None: the COF is the contact's.
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
        match key {
            "drivetrain.coulomb_n" => Some(&mut self.coulomb),
            "drivetrain.viscous_n_s_m" => Some(&mut self.viscous),
            "drivetrain.viscous_exponent" => Some(&mut self.viscous_exponent),
            "drivetrain.viscous_reference_speed_m_s" => Some(&mut self.viscous_reference_speed),
            "drivetrain.load_coefficient" => Some(&mut self.load_coefficient),
            "drivetrain.quadratic_n_s2_m2" => Some(&mut self.quadratic),
            "drivetrain.stribeck_n" => Some(&mut self.stribeck),
            "drivetrain.stribeck_speed_m_s" => Some(&mut self.stribeck_speed),
            "drivetrain.stribeck_exponent" => Some(&mut self.stribeck_exponent),
            "drivetrain.coulomb_asymmetry_n" => Some(&mut self.coulomb_asymmetry),
            _ => None,
        }
    }
}

impl Drivetrain {
    /// Whether every term is zero (the estimate is then the contact's alone).
    pub fn is_zero(&self) -> bool {
        self.coulomb == 0.0
            && self.viscous == 0.0
            && self.load_coefficient == 0.0
            && self.quadratic == 0.0
            && self.coulomb_asymmetry == 0.0
            && self.stribeck == 0.0
    }

    /// The Coulomb level at speed `v` and load `load` (N): F_cd + c_N F +
    /// ΔF_s e^(−|v/v_s|^α_s) (the Stribeck part only when it is on: off,
    /// the level is the one before it, bit for bit), with the fall `fall`
    /// if the caller holds it.
    #[inline(always)]
    fn level(&self, v: f64, load: f64, fall: Option<f64>) -> f64 {
        let base = self.coulomb + self.load_coefficient * load;
        if self.stribeck == 0.0 {
            base
        } else {
            let fall = match fall {
                Some(f) => f,
                None => self.stribeck_fall(v),
            };
            base + self.stribeck * fall
        }
    }

    /// The Stribeck fall e^(−|v/v_s|^α_s) at velocity `v` (m/s): the part
    /// of the term a fit may hold for a whole film trace
    /// ([`Kept::stribeck_fall`]); the Gaussian
    /// e^(−(v/v_s)²) when α_s = 2.
    #[inline(always)]
    #[allow(clippy::float_cmp)] // α_s = 2 exactly is the Gaussian fall, the default, bit for bit
    pub fn stribeck_fall(&self, v: f64) -> f64 {
        if self.stribeck_exponent == 2.0 {
            let x = v / self.stribeck_speed;
            exp_neg(x * x)
        } else {
            let x = (v / self.stribeck_speed).abs();
            exp_neg(x.powf(self.stribeck_exponent))
        }
    }

    /// The key of the fall's shape (v_s, α_s): two drivetrains with the
    /// same key have the same [`stribeck_fall`](Self::stribeck_fall) at
    /// every speed.
    pub fn stribeck_fall_key(&self) -> [u64; 2] {
        [
            self.stribeck_speed.to_bits(),
            self.stribeck_exponent.to_bits(),
        ]
    }

    /// Whether the Stribeck part is on (ΔF_s ≠ 0).
    pub fn has_stribeck(&self) -> bool {
        self.stribeck != 0.0
    }

    /// F_dt at velocity `v` (m/s) and load `load` (N), with the sign `s`
    /// (the rigid contact's tanh(v/v_reg)).
    #[inline(always)]
    pub fn force_at(&self, v: f64, load: f64, s: f64) -> f64 {
        self.force_kept(v, load, s, &Kept::default())
    }

    /// [`force_at`](Self::force_at) with the factors `kept` holds.
    #[inline(always)]
    fn force_kept(&self, v: f64, load: f64, s: f64, kept: &Kept) -> f64 {
        self.level(v, load, kept.stribeck_fall) * s
            + self.coulomb_asymmetry * s.abs()
            + self.rate_terms_kept(v, kept.viscous_bend)
    }

    /// The terms that act at zero speed, at speed `v` with the sign `s` of
    /// gross sliding (−1, 0 or 1): (F_cd + c_N F + ΔF_s e^(−(v/v_s)²)) s +
    /// ΔF_cd |s|. With pre-sliding on they are part of the bristle's level:
    /// the compliance at a reversal is the whole axis's, not the contact's
    /// alone.
    pub fn level_at_rest(&self, v: f64, s: f64, load: f64) -> f64 {
        self.level_at_rest_kept(v, s, load, None)
    }

    /// [`level_at_rest`](Self::level_at_rest) with the fall `fall` if held.
    #[inline(always)]
    fn level_at_rest_kept(&self, v: f64, s: f64, load: f64, fall: Option<f64>) -> f64 {
        self.level(v, load, fall) * s + self.coulomb_asymmetry * s.abs()
    }

    /// The terms that vanish with the speed: F_v(v) + c_q v |v| (outside
    /// the bristle, as LuGre's viscous term is).
    #[inline(always)]
    pub fn rate_terms(&self, v: f64) -> f64 {
        self.rate_terms_kept(v, None)
    }

    /// [`rate_terms`](Self::rate_terms) with the bend `bend` if held.
    #[inline(always)]
    fn rate_terms_kept(&self, v: f64, bend: Option<f64>) -> f64 {
        self.viscous_rise_kept(v, bend) + self.quadratic * v * v.abs()
    }

    /// F_v(v) = b v_b sgn v |v/v_b|^δ: b v, bit for bit, when δ = 1.
    #[inline(always)]
    pub fn viscous_rise(&self, v: f64) -> f64 {
        self.viscous_rise_kept(v, None)
    }

    /// [`viscous_rise`](Self::viscous_rise) with the bend |v/v_b|^δ if held.
    #[inline(always)]
    #[allow(clippy::float_cmp)] // δ = 1 exactly is the straight rise, the default, bit for bit
    fn viscous_rise_kept(&self, v: f64, bend: Option<f64>) -> f64 {
        if self.viscous_exponent == 1.0 {
            self.viscous * v
        } else {
            let bend = match bend {
                Some(b) => b,
                None => self.viscous_bend(v),
            };
            self.viscous * self.viscous_reference_speed * bend.copysign(v)
        }
    }

    /// The bend |v/v_b|^δ at velocity `v` (m/s): the part of a bent
    /// viscous rise a fit may hold for a whole film trace
    /// ([`Kept::viscous_bend`]).
    #[inline(always)]
    pub fn viscous_bend(&self, v: f64) -> f64 {
        (v.abs() / self.viscous_reference_speed).powf(self.viscous_exponent)
    }

    /// The key of the bend's shape (δ, v_b): two drivetrains with the same
    /// key have the same [`viscous_bend`](Self::viscous_bend) at every
    /// speed.
    pub fn viscous_bend_key(&self) -> [u64; 2] {
        [
            self.viscous_exponent.to_bits(),
            self.viscous_reference_speed.to_bits(),
        ]
    }

    /// Whether the viscous rise is on (b ≠ 0) and bends (δ ≠ 1).
    #[allow(clippy::float_cmp)] // δ = 1 exactly is the straight rise
    pub fn has_bend(&self) -> bool {
        self.viscous != 0.0 && self.viscous_exponent != 1.0
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims (0, 1, representable sums)
mod tests {
    use super::*;

    #[test]
    fn the_falls_factor_is_exp_of_minus_a_bit_for_bit_underflow_included() {
        for a in [
            0.0,
            1e-300,
            0.5,
            2.0,
            30.0,
            700.0,
            708.5,
            744.0,
            745.1,
            745.2,
            745.3,
            800.0,
            1e6,
            f64::INFINITY,
        ] {
            assert_eq!(exp_neg(a).to_bits(), (-a).exp().to_bits(), "a = {a}");
        }
        assert!(exp_neg(f64::NAN).is_nan());
    }

    /// F_dt with the contact's regularisation `v_reg`.
    fn force(d: &Drivetrain, v: f64, load: f64, v_reg: f64) -> f64 {
        d.force_at(v, load, (v / v_reg).tanh())
    }

    #[test]
    fn the_drivetrain_force_is_odd_in_velocity_and_linear_in_each_term() {
        let d = Drivetrain {
            coulomb: 10.0,
            viscous: 50.0,
            load_coefficient: 0.002,
            ..Default::default()
        };
        let f = force(&d, 0.2, 1000.0, 1e-4);
        approx::assert_relative_eq!(f, 10.0 + 2.0 + 10.0, max_relative = 1e-12);
        approx::assert_relative_eq!(force(&d, -0.2, 1000.0, 1e-4), -f, max_relative = 1e-12);
        assert_eq!(force(&d, 0.0, 1000.0, 1e-4), 0.0);
        assert!(Drivetrain::default().is_zero());
    }

    #[test]
    fn the_quadratic_loss_grows_with_the_square_of_speed_and_the_asymmetry_shifts_both_levels() {
        let d = Drivetrain {
            coulomb: 4.0,
            quadratic: 100.0,
            coulomb_asymmetry: 1.0,
            ..Default::default()
        };
        let (a, b) = (force(&d, 0.1, 0.0, 1e-6), force(&d, 0.2, 0.0, 1e-6));
        // Above the constant level the loss quadruples when speed doubles.
        approx::assert_relative_eq!(b - 5.0, 4.0 * (a - 5.0), max_relative = 1e-12);
        // Forward 4 + 1, backward 4 − 1 (in magnitude).
        approx::assert_relative_eq!(force(&d, 1e-3, 0.0, 1e-6), 5.0 + 1e-4, max_relative = 1e-12);
        approx::assert_relative_eq!(
            force(&d, -1e-3, 0.0, 1e-6),
            -3.0 - 1e-4,
            max_relative = 1e-12
        );
        assert_eq!(force(&d, 0.0, 0.0, 1e-6), 0.0);
        assert!(!d.is_zero());
    }

    #[test]
    fn a_bent_viscous_rise_equals_b_v_b_at_v_b_and_grows_with_the_power_delta_of_speed() {
        let d = Drivetrain {
            viscous: 50.0,
            viscous_exponent: 2.0 / 3.0,
            viscous_reference_speed: 0.1,
            ..Default::default()
        };
        approx::assert_relative_eq!(d.rate_terms(0.1), 5.0, max_relative = 1e-12);
        // Eight times the speed: four times the force (8^(2/3)), odd in v.
        approx::assert_relative_eq!(d.rate_terms(0.8), 20.0, max_relative = 1e-12);
        approx::assert_relative_eq!(d.rate_terms(-0.8), -20.0, max_relative = 1e-12);
        assert_eq!(d.rate_terms(0.0), 0.0);
        // Below the line b v past v_b, above it inside.
        assert!(d.rate_terms(0.8) < 50.0 * 0.8 && d.rate_terms(0.01) > 50.0 * 0.01);
        // δ = 1: b v, whatever the reference speed, bit for bit.
        let straight = Drivetrain {
            viscous: 50.0,
            viscous_reference_speed: 0.1,
            ..Default::default()
        };
        assert_eq!(straight.rate_terms(0.37), 50.0 * 0.37);
    }

    #[test]
    fn a_stribeck_fall_with_its_own_exponent_keeps_its_level_at_rest_and_at_v_s_and_a_longer_tail_below_2(
    ) {
        let gauss = Drivetrain {
            coulomb: 10.0,
            stribeck: 3.0,
            stribeck_speed: 0.01,
            ..Default::default()
        };
        let tail = Drivetrain {
            stribeck_exponent: 1.0,
            ..gauss
        };
        // At v_s both have e^-1 of the excess; at rest both the static level.
        approx::assert_relative_eq!(
            tail.level_at_rest(0.01, 1.0, 0.0),
            10.0 + 3.0 / std::f64::consts::E,
            max_relative = 1e-12
        );
        approx::assert_relative_eq!(tail.level_at_rest(0.0, 1.0, 0.0), 13.0);
        // At 3 v_s: e^-3 of it against the Gaussian's e^-9; odd in v.
        approx::assert_relative_eq!(
            tail.level_at_rest(0.03, 1.0, 0.0),
            10.0 + 3.0 * (-3.0f64).exp(),
            max_relative = 1e-12
        );
        approx::assert_relative_eq!(
            gauss.level_at_rest(0.03, 1.0, 0.0),
            10.0 + 3.0 * (-9.0f64).exp(),
            max_relative = 1e-12
        );
        assert_eq!(
            tail.force_at(-0.03, 0.0, -1.0),
            -tail.force_at(0.03, 0.0, 1.0)
        );
    }

    #[test]
    fn a_stribeck_term_starts_at_its_static_level_and_decays_to_the_coulomb_level_over_v_s() {
        for excess in [3.0, -3.0] {
            let d = Drivetrain {
                coulomb: 10.0,
                stribeck: excess,
                stribeck_speed: 0.01,
                ..Default::default()
            };
            // At rest (well past v_reg): F_cd + ΔF_s; at v_s: e^-1 of the excess.
            approx::assert_relative_eq!(
                force(&d, 1e-5, 0.0, 1e-9),
                10.0 + excess,
                max_relative = 1e-5
            );
            approx::assert_relative_eq!(
                force(&d, 0.01, 0.0, 1e-9),
                10.0 + excess / std::f64::consts::E,
                max_relative = 1e-12
            );
            approx::assert_relative_eq!(force(&d, 0.1, 0.0, 1e-9), 10.0, max_relative = 1e-12);
            approx::assert_relative_eq!(force(&d, -0.01, 0.0, 1e-9), -force(&d, 0.01, 0.0, 1e-9));
            approx::assert_relative_eq!(d.level_at_rest(0.0, 1.0, 0.0), 10.0 + excess);
        }
        // Off, the level is the one before the term, bit for bit.
        let off = Drivetrain {
            coulomb: 10.0,
            ..Default::default()
        };
        assert_eq!(
            force(&off, 0.003, 0.0, 1e-4),
            10.0 * (0.003f64 / 1e-4).tanh()
        );
    }
}
