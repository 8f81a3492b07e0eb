//! Drivetrain losses beside the contact: what a motor current or a load
//! cell measures besides the lubricated contact (support bearings, seals,
//! gear mesh), which no contact model should be asked to absorb.
//!
//! ```text
//! F_dt = (F_c + c_N F_ext) tanh(v / v_reg) + ΔF_c |tanh(v / v_reg)| + b v + c_q v |v|
//! F_total = F_f + F_dt
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_c | constant (Coulomb) drivetrain friction | N |
//! | ΔF_c | direction asymmetry: the level is F_c + ΔF_c moving forward, F_c − ΔF_c backward (a screw lifting or lowering a load, a seal's lip) | N |
//! | c_N | friction proportional to the normal load (rolling elements carrying it) | – |
//! | b | viscous drivetrain friction | N·s/m |
//! | c_q | loss growing with the square of the speed (churning, windage, iron and eddy losses of a motor, reflected to the slider) | N·s²/m² |
//! | v_reg | the contact's sign regularisation (the same tanh) | m/s |
//!
//! All zero by default: the estimate is then the contact's alone, bit for bit.
//! With pre-sliding on (`presliding.rs`) the terms that act at zero speed,
//! (F_c + c_N F_ext) sgn v + ΔF_c |sgn v|, are part of the bristle's level
//! (a reversal's compliance is the whole axis's), and only b v + c_q v|v|
//! is added beside it.

use super::{End, FitScale, TermKey};

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
pub const KEYS: &[TermKey] = &[
    TermKey {
        key: "drivetrain.coulomb_n",
        symbol: "F_c",
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
        key: "drivetrain.coulomb_asymmetry_n",
        symbol: "ΔF_c",
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
        meaning: "direction asymmetry: the level is F_c + ΔF_c forward, F_c − ΔF_c backward",
    },
];

/// The drivetrain terms.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Drivetrain {
    /// F_c, N.
    pub coulomb: f64,
    /// b, N·s/m.
    pub viscous: f64,
    /// c_N, dimensionless.
    pub load_coefficient: f64,
    /// c_q, N·s²/m².
    pub quadratic: f64,
    /// ΔF_c, N.
    pub coulomb_asymmetry: f64,
}

impl Drivetrain {
    /// Whether every term is zero (the estimate is then the contact's alone).
    pub fn is_zero(&self) -> bool {
        self.coulomb == 0.0
            && self.viscous == 0.0
            && self.load_coefficient == 0.0
            && self.quadratic == 0.0
            && self.coulomb_asymmetry == 0.0
    }

    /// F_dt at velocity `v` (m/s) and load `load` (N), with the contact's
    /// sign regularisation `v_reg` (m/s).
    pub fn force(&self, v: f64, load: f64, v_reg: f64) -> f64 {
        let s = (v / v_reg).tanh();
        (self.coulomb + self.load_coefficient * load) * s
            + self.coulomb_asymmetry * s.abs()
            + self.viscous * v
            + self.quadratic * v * v.abs()
    }

    /// The terms that act at zero speed, with the sign `s` of gross sliding
    /// (−1, 0 or 1): (F_c + c_N F) s + ΔF_c |s|. With pre-sliding on they
    /// are part of the bristle's level: the compliance at a reversal is the
    /// whole axis's, not the contact's alone.
    pub fn level_at_rest(&self, s: f64, load: f64) -> f64 {
        (self.coulomb + self.load_coefficient * load) * s + self.coulomb_asymmetry * s.abs()
    }

    /// The terms that vanish with the speed: b v + c_q v |v| (outside the
    /// bristle, as LuGre's viscous term is).
    pub fn rate_terms(&self, v: f64) -> f64 {
        self.viscous * v + self.quadratic * v * v.abs()
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims (0, 1, representable sums)
mod tests {
    use super::*;

    #[test]
    fn the_drivetrain_force_is_odd_in_velocity_and_linear_in_each_term() {
        let d = Drivetrain {
            coulomb: 10.0,
            viscous: 50.0,
            load_coefficient: 0.002,
            ..Default::default()
        };
        let f = d.force(0.2, 1000.0, 1e-4);
        approx::assert_relative_eq!(f, 10.0 + 2.0 + 10.0, max_relative = 1e-12);
        approx::assert_relative_eq!(d.force(-0.2, 1000.0, 1e-4), -f, max_relative = 1e-12);
        assert_eq!(d.force(0.0, 1000.0, 1e-4), 0.0);
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
        let (a, b) = (d.force(0.1, 0.0, 1e-6), d.force(0.2, 0.0, 1e-6));
        // Above the constant level the loss quadruples when speed doubles.
        approx::assert_relative_eq!(b - 5.0, 4.0 * (a - 5.0), max_relative = 1e-12);
        // Forward 4 + 1, backward 4 − 1 (in magnitude).
        approx::assert_relative_eq!(d.force(1e-3, 0.0, 1e-6), 5.0 + 1e-4, max_relative = 1e-12);
        approx::assert_relative_eq!(d.force(-1e-3, 0.0, 1e-6), -3.0 - 1e-4, max_relative = 1e-12);
        assert_eq!(d.force(0.0, 0.0, 1e-6), 0.0);
        assert!(!d.is_zero());
    }
}
