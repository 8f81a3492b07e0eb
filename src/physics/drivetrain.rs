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
