//! Drivetrain losses beside the contact: what a motor current or a load
//! cell measures besides the lubricated contact (support bearings, seals,
//! gear mesh), which no contact model should be asked to absorb.
//!
//! ```text
//! F_dt = (F_c + c_N F_ext) tanh(v / v_reg) + b v
//! F_total = F_f + F_dt
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_c | constant (Coulomb) drivetrain friction | N |
//! | c_N | friction proportional to the normal load (rolling elements carrying it) | – |
//! | b | viscous drivetrain friction | N·s/m |
//! | v_reg | the contact's sign regularisation (the same tanh) | m/s |
//!
//! All zero by default: the estimate is then the contact's alone, bit for bit.

/// The drivetrain terms.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Drivetrain {
    pub coulomb: f64,
    pub viscous: f64,
    pub load_coefficient: f64,
}

impl Drivetrain {
    pub fn is_zero(&self) -> bool {
        self.coulomb == 0.0 && self.viscous == 0.0 && self.load_coefficient == 0.0
    }

    /// F_dt at velocity `v` (m/s) and load `load` (N), with the contact's
    /// sign regularisation `v_reg` (m/s).
    pub fn force(&self, v: f64, load: f64, v_reg: f64) -> f64 {
        (self.coulomb + self.load_coefficient * load) * (v / v_reg).tanh() + self.viscous * v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_drivetrain_force_is_odd_in_velocity_and_linear_in_each_term() {
        let d = Drivetrain {
            coulomb: 10.0,
            viscous: 50.0,
            load_coefficient: 0.002,
        };
        let f = d.force(0.2, 1000.0, 1e-4);
        approx::assert_relative_eq!(f, 10.0 + 2.0 + 10.0, max_relative = 1e-12);
        approx::assert_relative_eq!(d.force(-0.2, 1000.0, 1e-4), -f, max_relative = 1e-12);
        assert_eq!(d.force(0.0, 1000.0, 1e-4), 0.0);
        assert!(Drivetrain::default().is_zero());
    }
}
