//! The liquid's viscosity against temperature (Vogel's equation).
//!
//! ```text
//! μ(T) = A exp(B / (T − C)),  A = μ_ref exp(−B / (T_ref − C))
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | μ, μ_ref | dynamic viscosity at T, at the reference temperature | Pa·s |
//! | T, T_ref | temperature, reference temperature | °C |
//! | B | Vogel's temperature constant | °C (K) |
//! | C | Vogel's temperature offset | °C |
//!
//! The form is Vogel's (1921); it is exact at T_ref by construction and
//! valid for T > C. Typical constants of 95-VI straight-grade engine oils
//! are in [`VogelModel::SAE`].

/// How the viscosity follows temperature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ViscosityModel {
    /// μ_ref at every temperature.
    Constant,
    /// Vogel's equation.
    Vogel(VogelModel),
}

/// Vogel's equation through μ_ref at T_ref.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VogelModel {
    /// B, Vogel's temperature constant, °C.
    pub b_c: f64,
    /// C, Vogel's temperature offset, °C.
    pub c_c: f64,
}

impl VogelModel {
    /// Vogel constants (B, C in °C) of 95-VI straight-grade engine oils, from a
    /// least-squares fit between 20 and 120 °C of the ASTM D341 (Walther)
    /// line through their kinematic viscosities at 40 °C (ISO 3448 grade:
    /// SAE 20 ≈ ISO VG 68, SAE 30 ≈ VG 100, SAE 40 ≈ VG 150) and at 100 °C
    /// (inside the SAE J300 ranges: 8.6, 11.2, 14.5 mm²/s), density
    /// 870 kg/m³; the fit is within 0.7 % of the Walther line over
    /// 20–120 °C. Each: (grade, μ at 40 °C in Pa·s, B, C).
    pub const SAE: [(&'static str, f64, f64, f64); 3] = [
        ("SAE 20", 0.0592, 905.6, -95.0),
        ("SAE 30", 0.0870, 970.6, -96.0),
        ("SAE 40", 0.1305, 1035.4, -96.0),
    ];

    /// μ at `t_c`, given μ_ref at `t_ref_c`.
    pub fn viscosity(&self, mu_ref: f64, t_ref_c: f64, t_c: f64) -> f64 {
        mu_ref * (self.b_c / (t_c - self.c_c) - self.b_c / (t_ref_c - self.c_c)).exp()
    }

    /// The constants through three (T °C, μ Pa·s) points, if they define a
    /// Vogel curve (μ falling with T).
    pub fn through(points: [(f64, f64); 3]) -> Option<(Self, f64)> {
        // ln μ = ln A + B / (T − C): solve for C by bisection on the
        // consistency of the two slopes, then B and A.
        let [(t1, m1), (t2, m2), (t3, m3)] = points;
        let (l1, l2, l3) = (m1.ln(), m2.ln(), m3.ln());
        let b_of = |c: f64| (l1 - l2) / (1.0 / (t1 - c) - 1.0 / (t2 - c));
        let g = |c: f64| {
            let b = b_of(c);
            l1 + b / (t3 - c) - b / (t1 - c) - l3
        };
        let tmin = t1.min(t2).min(t3);
        let (mut lo, mut hi) = (tmin - 2000.0, tmin - 1e-6);
        let (glo, ghi) = (g(lo), g(hi));
        if !(glo.is_finite() && ghi.is_finite()) || glo.signum() == ghi.signum() {
            return None;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if g(mid).signum() == glo.signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let c = 0.5 * (lo + hi);
        let b = b_of(c);
        let a = (l1 - b / (t1 - c)).exp();
        (b > 0.0).then_some((Self { b_c: b, c_c: c }, a))
    }
}

impl ViscosityModel {
    /// μ at `t_c` for a liquid of μ_ref at `t_ref_c`.
    pub fn viscosity(&self, mu_ref: f64, t_ref_c: f64, t_c: f64) -> f64 {
        match self {
            ViscosityModel::Constant => mu_ref,
            ViscosityModel::Vogel(v) => v.viscosity(mu_ref, t_ref_c, t_c),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn vogel_through_three_tabulated_points_reproduces_the_table() {
        // Stachowiak & Batchelor, Engineering Tribology (4th ed.), Table 2.3:
        // heavy machine oil, dynamic viscosity 153, 34, 9.1 mPa·s at 30, 60,
        // 100 °C; cylinder oil 810, 135, 26.8 mPa·s.
        for pts in [
            [(30.0, 0.153), (60.0, 0.034), (100.0, 0.0091)],
            [(30.0, 0.810), (60.0, 0.135), (100.0, 0.0268)],
        ] {
            let (v, _) = VogelModel::through(pts).unwrap();
            for (t, mu) in pts {
                assert_relative_eq!(v.viscosity(pts[0].1, pts[0].0, t), mu, max_relative = 1e-9);
            }
            // Between the points it stays between them.
            let m45 = v.viscosity(pts[0].1, pts[0].0, 45.0);
            assert!(m45 < pts[0].1 && m45 > pts[1].1);
        }
    }

    #[test]
    fn the_sae_constants_reproduce_the_grades_viscosities_at_40_and_100_c() {
        // Kinematic at 100 °C (mm²/s) × 870 kg/m³ → Pa·s.
        for ((name, mu40, b, c), nu100) in VogelModel::SAE.iter().zip([8.6, 11.2, 14.5]) {
            let v = VogelModel { b_c: *b, c_c: *c };
            assert_relative_eq!(v.viscosity(*mu40, 40.0, 40.0), *mu40, max_relative = 1e-12);
            let mu100 = nu100 * 1e-6 * 870.0;
            let got = v.viscosity(*mu40, 40.0, 100.0);
            assert!(
                (got / mu100 - 1.0).abs() < 0.01,
                "{name}: {got} Pa·s at 100 °C, the grade's {mu100}"
            );
        }
    }
}
