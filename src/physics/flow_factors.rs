//! Patir–Cheng average-flow factors (docs/model.md §2, paper Table A1).
//!
//! ```text
//! pressure:  φx = 1 − C e^(−r H)   (γ ≤ 1)      φx = 1 + C H^(−r)   (γ > 1)
//! shear:     φs = A1 H^α1 e^(−α2 H + α3 H²)   (H ≤ 5)      φs = A2 e^(−0.25 H)   (H > 5)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | H = h/σ | film thickness over combined RMS roughness | – |
//! | γ | surface lay parameter (1 = isotropic) | – |
//! | C, r, A1, α1, α2, α3, A2 | Table A1 coefficients | – |
//!
//! The case split is on γ, not Λ (the paper's eq. 8 is misprinted). Below the
//! table's validity limit H is clamped, so φx is constant there. The paper's
//! own simulations use φx = 1, φs = 0: flow factors are off by default.

use super::error::SetupError;

/// One row of Table A1.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Row {
    gamma: f64,
    c: f64,
    r: f64,
    h_min: f64,
    a1: f64,
    alpha1: f64,
    alpha2: f64,
    alpha3: f64,
    a2: f64,
}

#[rustfmt::skip]
const TABLE: [Row; 7] = [
    Row { gamma: 1.0 / 9.0, c: 1.48, r: 0.42, h_min: 1.0, a1: 2.046, alpha1: 1.12, alpha2: 0.78, alpha3: 0.03, a2: 1.856 },
    Row { gamma: 1.0 / 6.0, c: 1.38, r: 0.42, h_min: 1.0, a1: 1.962, alpha1: 1.08, alpha2: 0.77, alpha3: 0.03, a2: 1.754 },
    Row { gamma: 1.0 / 3.0, c: 1.18, r: 0.42, h_min: 0.75, a1: 1.858, alpha1: 1.01, alpha2: 0.76, alpha3: 0.03, a2: 1.561 },
    Row { gamma: 1.0, c: 0.90, r: 0.56, h_min: 0.5, a1: 1.899, alpha1: 0.98, alpha2: 0.92, alpha3: 0.05, a2: 1.126 },
    Row { gamma: 3.0, c: 0.225, r: 1.5, h_min: 0.5, a1: 1.560, alpha1: 0.85, alpha2: 1.13, alpha3: 0.08, a2: 0.556 },
    Row { gamma: 6.0, c: 0.520, r: 1.5, h_min: 0.5, a1: 1.290, alpha1: 0.62, alpha2: 1.09, alpha3: 0.08, a2: 0.388 },
    Row { gamma: 9.0, c: 0.870, r: 1.5, h_min: 0.5, a1: 1.011, alpha1: 0.54, alpha2: 1.07, alpha3: 0.08, a2: 0.295 },
];

/// The lay parameters Table A1 provides, for error messages.
pub const SUPPORTED_GAMMAS: &str = "1/9, 1/6, 1/3, 1, 3, 6, 9";

/// Flow factors for one lay parameter and roughness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlowFactors {
    row: Row,
    inv_sigma: f64,
}

impl FlowFactors {
    /// `gamma` must match a Table A1 row within 1 %.
    pub fn new(gamma: f64, sigma: f64) -> Result<Self, SetupError> {
        let row = TABLE
            .iter()
            .find(|r| (gamma - r.gamma).abs() <= 0.01 * r.gamma)
            .copied()
            .ok_or(SetupError::invalid(
                "roughness.lay_gamma",
                gamma,
                "Table A1 covers gamma = 1/9, 1/6, 1/3, 1, 3, 6, 9 only",
            ))?;
        Ok(Self {
            row,
            inv_sigma: 1.0 / sigma,
        })
    }

    /// Pressure flow factor φx(h) and dφx/dh.
    #[inline]
    pub fn pressure(&self, h: f64) -> (f64, f64) {
        let r = &self.row;
        let hh = h * self.inv_sigma;
        if hh <= r.h_min {
            let (v, _) = self.pressure_at(r.h_min);
            return (v, 0.0);
        }
        let (v, d) = self.pressure_at(hh);
        (v, d * self.inv_sigma)
    }

    #[inline]
    fn pressure_at(&self, hh: f64) -> (f64, f64) {
        let r = &self.row;
        if r.gamma <= 1.0 {
            let e = (-r.r * hh).exp();
            (1.0 - r.c * e, r.c * r.r * e)
        } else {
            let e = hh.powf(-r.r);
            (1.0 + r.c * e, -r.r * r.c * e / hh)
        }
    }

    /// Shear flow factor φs(h) and dφs/dh.
    #[inline]
    pub fn shear(&self, h: f64) -> (f64, f64) {
        let r = &self.row;
        let hh = (h * self.inv_sigma).max(1e-12);
        let (v, d) = if hh <= 5.0 {
            let v = r.a1 * hh.powf(r.alpha1) * (-r.alpha2 * hh + r.alpha3 * hh * hh).exp();
            (v, v * (r.alpha1 / hh - r.alpha2 + 2.0 * r.alpha3 * hh))
        } else {
            let v = r.a2 * (-0.25 * hh).exp();
            (v, -0.25 * v)
        };
        (v, d * self.inv_sigma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn pressure_factor_tends_to_one_for_thick_films() {
        let ff = FlowFactors::new(1.0, 1e-6).unwrap();
        assert_relative_eq!(ff.pressure(50e-6).0, 1.0, epsilon = 1e-10);
        let ff3 = FlowFactors::new(3.0, 1e-6).unwrap();
        assert_relative_eq!(ff3.pressure(1e-3).0, 1.0, epsilon = 1e-4);
    }

    #[test]
    fn isotropic_pressure_factor_reduces_flow_in_thin_films() {
        let ff = FlowFactors::new(1.0, 1e-6).unwrap();
        // H = 1: 1 − 0.9 e^(−0.56)
        assert_relative_eq!(
            ff.pressure(1e-6).0,
            1.0 - 0.9 * (-0.56f64).exp(),
            epsilon = 1e-12
        );
    }

    #[test]
    fn flow_factor_derivatives_match_finite_differences() {
        for &g in &[1.0 / 9.0, 1.0, 6.0] {
            let ff = FlowFactors::new(g, 2e-6).unwrap();
            for &h in &[3e-6, 6e-6, 9e-6, 14e-6] {
                let e = 1e-12;
                let fd_p = (ff.pressure(h + e).0 - ff.pressure(h - e).0) / (2.0 * e);
                let fd_s = (ff.shear(h + e).0 - ff.shear(h - e).0) / (2.0 * e);
                assert_relative_eq!(ff.pressure(h).1, fd_p, max_relative = 1e-5, epsilon = 1e-3);
                assert_relative_eq!(ff.shear(h).1, fd_s, max_relative = 1e-5, epsilon = 1e-3);
            }
        }
    }

    #[test]
    fn unsupported_lay_parameter_is_rejected_with_its_value() {
        let e = FlowFactors::new(2.0, 1e-6).unwrap_err();
        assert!(e.to_string().contains("lay_gamma"));
        assert!(e.to_string().contains('2'));
    }
}
