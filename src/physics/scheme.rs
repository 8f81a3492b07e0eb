//! Three-level θ time discretisation (docs/model.md §6, Zienkiewicz).
//!
//! ```text
//! u'  ≈ [ (θ1+½) uⁿ − 2θ1 uⁿ⁻¹ + (θ1−½) uⁿ⁻² ] / Δt
//! u'' ≈ ( uⁿ − 2uⁿ⁻¹ + uⁿ⁻² ) / Δt²
//! forces weighted ((θ1+θ2)/2, 1−θ2, (θ2−θ1)/2) over levels n, n−1, n−2
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | θ1, θ2 | scheme parameters; (1, 1) is BDF2, (½, ·) backward Euler | – |
//! | Δt | time step | s |
//!
//! The first-derivative formula is second order for every (θ1, θ2) once the
//! forces are weighted as above. With BDF2 the three-level u'' is first order
//! at level n; it only enters through the inertia term, which is 1e-6 % of
//! the load at the paper's settings (see the inertia study).

use super::settings::TimeScheme;

/// Coefficients of one step: `u' ≈ Σ a_k u^(n−k) / Δt`, forces `Σ w_k F^(n−k)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepCoefficients {
    /// a_k, the weights of the time derivative (levels n, n−1, n−2).
    pub a: [f64; 3],
    /// w_k, the weights of the force history (levels n, n−1, n−2).
    pub w: [f64; 3],
}

impl StepCoefficients {
    /// Backward Euler (first step when no second history level exists).
    pub const BDF1: StepCoefficients = StepCoefficients {
        a: [1.0, -1.0, 0.0],
        w: [1.0, 0.0, 0.0],
    };

    /// The coefficients of `scheme` with its full history.
    pub fn for_scheme(scheme: TimeScheme) -> Self {
        let (t1, t2) = match scheme {
            TimeScheme::Bdf2 => (1.0, 1.0),
            TimeScheme::Theta { theta1, theta2 } => (theta1, theta2),
        };
        StepCoefficients {
            a: [t1 + 0.5, -2.0 * t1, t1 - 0.5],
            w: [0.5 * (t1 + t2), 1.0 - t2, 0.5 * (t2 - t1)],
        }
    }

    /// True when previous-level fluxes and forces are needed.
    pub fn uses_force_history(&self) -> bool {
        self.w[1] != 0.0 || self.w[2] != 0.0
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims (0, 1, representable sums)
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn bdf2_is_the_theta_scheme_with_unit_parameters() {
        let c = StepCoefficients::for_scheme(TimeScheme::Bdf2);
        assert_eq!(c.a, [1.5, -2.0, 0.5]);
        assert_eq!(c.w, [1.0, 0.0, 0.0]);
    }

    #[test]
    fn theta_scheme_is_exact_for_quadratics_in_first_order_odes() {
        // u' = f(t) with u = t², f = 2t, t_n = 0: Σ a u / Δt = Σ w f.
        for &(t1, t2) in &[(1.0, 1.0), (2.0, 0.8), (0.7, 1.3)] {
            let c = StepCoefficients::for_scheme(TimeScheme::Theta {
                theta1: t1,
                theta2: t2,
            });
            let dt = 0.1;
            let u = |k: f64| (-k * dt) * (-k * dt);
            let f = |k: f64| 2.0 * (-k * dt);
            let lhs = (c.a[0] * u(0.0) + c.a[1] * u(1.0) + c.a[2] * u(2.0)) / dt;
            let rhs = c.w[0] * f(0.0) + c.w[1] * f(1.0) + c.w[2] * f(2.0);
            assert_relative_eq!(lhs, rhs, epsilon = 1e-12);
            assert_relative_eq!(c.w.iter().sum::<f64>(), 1.0, epsilon = 1e-15);
        }
    }
}
