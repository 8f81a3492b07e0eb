//! Whether a fit's residual follows the acceleration: a measured drive
//! force (a motor current times its constant) still holds the inertia
//! m·a, which no friction term carries. The fit then ends "converged" far
//! above the noise; this says why, with the mass the residual points to.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_k, F̂_k | measured and model friction at training sample k | N (N·m) |
//! | r_k | F_k − F̂_k, the residual | N (N·m) |
//! | v_k, t_k | velocity and time of the sample | m/s (rad/s), s |
//! | a_k | acceleration: central differences of v over t (one-sided at the ends) | m/s² (rad/s²) |
//! | m̂ | Σ r a / Σ a², the mass whose inertia the residual holds | kg (kg·m²) |
//! | s | (Σ r a)² / (Σ a² Σ r²), the share of Σ r² that subtracting m̂ a removes | 1 |
//!
//! Over the time series' training samples together (a steady curve has no
//! acceleration). A warning when s > [`INERTIA_SHARE`]: a quarter of the
//! residual's sum of squares is inertia. Where the fit already subtracts
//! a fitted mass, s is zero at its optimum (the residual is orthogonal to
//! its slope). On the real recordings as `docs/real-data-benchmarks.sh`
//! fits them, s is 0.003 (seal) and 1e-7 (EMPS, its mass fitted); on EMPS
//! fitted without its mass 0.985 (m̂ 97 kg; the benchmark's is 95).

use super::driver::FitOutcome;
use super::Units;

/// Above this share of the residual's sum of squares the fit warns.
pub const INERTIA_SHARE: f64 = 0.25;

/// (m̂, s) over `o`'s training time series, or None when there is no
/// acceleration or no residual.
pub fn inertia_in_residual(o: &FitOutcome) -> Option<(f64, f64)> {
    let (mut ra, mut aa, mut rr) = (0.0, 0.0, 0.0);
    for f in &o.train {
        let s = &f.series;
        let n = s.len();
        if s.steady || n < 3 {
            continue;
        }
        for k in 0..n {
            let (i, j) = (k.saturating_sub(1), (k + 1).min(n - 1));
            let a = (s.velocity[j] - s.velocity[i]) / (s.t[j] - s.t[i]);
            let r = s.friction[k] - f.predicted[k];
            if !(s.fit[k] && a.is_finite() && r.is_finite()) {
                continue;
            }
            ra += r * a;
            aa += a * a;
            rr += r * r;
        }
    }
    (aa > 0.0 && rr > 0.0).then(|| (ra / aa, ra * ra / (aa * rr)))
}

/// The warning, when the residual holds inertia (see the module).
pub fn inertia_warning(o: &FitOutcome) -> Option<String> {
    let (m, share) = inertia_in_residual(o)?;
    if share <= INERTIA_SHARE {
        return None;
    }
    let (mass, unit) = match o.units {
        Units::Linear => ("a mass", "kg"),
        Units::Rotary => ("an inertia", "kg·m²"),
    };
    Some(format!(
        "warning: the residual follows the acceleration: {mass} of {} {unit} times it would remove {:.0} % of the residual's sum of squares. If the measured force includes the inertia (a motor's current times its constant does), subtract it: --friction 'EXPR - m * ddt(V)' with V the velocity column (ddt(ddt(X)) for a position X; smooth(smooth(F)) beside it keeps the force filtered alike), --map m={} and m in --fit",
        crate::text::Num::sig(m, 4),
        100.0 * share,
        crate::text::Num::sig(m, 3)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::problem::SeriesFit;
    use crate::fit::series::Series;
    use std::sync::Arc;

    /// A sine motion whose measured friction is `friction(v) + mass·a`
    /// and whose model gives `friction(v)`.
    fn outcome(mass: f64, steady: bool) -> FitOutcome {
        let t: Vec<f64> = (0..2000).map(|k| k as f64 * 1e-3).collect();
        let w = 2.0 * std::f64::consts::PI;
        let v: Vec<f64> = t.iter().map(|t| 0.1 * (w * t).sin()).collect();
        let a: Vec<f64> = t.iter().map(|t| 0.1 * w * (w * t).cos()).collect();
        let model: Vec<f64> = v.iter().map(|v| 5.0 * v.signum() + 20.0 * v).collect();
        // Noise that is not inertia: a ripple at another frequency.
        let measured: Vec<f64> = (0..t.len())
            .map(|k| model[k] + mass * a[k] + 0.05 * (37.0 * t[k]).sin())
            .collect();
        let series = Series {
            name: "s".into(),
            steady,
            fit: vec![true; t.len()],
            t,
            velocity: v,
            friction: measured,
            load: None,
            temperature: None,
        };
        crate::fit::driver::tests_outcome(vec![SeriesFit {
            series: Arc::new(series),
            predicted: model,
        }])
    }

    #[test]
    fn a_residual_that_is_inertia_gives_its_mass_and_a_warning() {
        let (m, share) = inertia_in_residual(&outcome(95.0, false)).unwrap();
        approx::assert_relative_eq!(m, 95.0, max_relative = 1e-3);
        assert!(share > 0.99, "{share}");
        let w = inertia_warning(&outcome(95.0, false)).unwrap();
        assert!(
            w.contains("a mass of 95 kg") && w.contains("--map m=95"),
            "{w}"
        );
    }

    #[test]
    fn a_residual_without_inertia_gives_no_warning_and_a_steady_curve_none_at_all() {
        let (_, share) = inertia_in_residual(&outcome(0.0, false)).unwrap();
        assert!(share < 0.01, "{share}");
        assert_eq!(inertia_warning(&outcome(0.0, false)), None);
        assert_eq!(inertia_in_residual(&outcome(95.0, true)), None);
    }
}
