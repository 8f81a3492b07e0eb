//! Columns made from another over ±`--smooth` s windows: `ddt(COLUMN)`, the
//! derivative by a local linear fit, and `smooth(COLUMN)`, the smoothing
//! that derivative implies.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | y | a column | its own |
//! | t | time | s |
//! | h | the window's half width (`--smooth`) | s |
//! | Δ | the window's mean sample spacing | s |
//! | K(s) | the smoothing kernel, s the time from the sample | s² |
//!
//! The local linear fit's slope over ±h is, by summation by parts, a
//! weighted mean of the differences y' with the parabolic weight
//! K(s) = (h + Δ/2)² − s² (exactly, on a uniform grid, at the differences'
//! midpoints): `ddt(y)` ≈ K ∗ y'. `smooth(y)` = Σ K(tⱼ − t) yⱼ / Σ K(tⱼ − t)
//! over the same window is that kernel applied to y itself, so that an
//! equation between a measured force and a derived acceleration,
//! F = M ẍ + friction, holds between `smooth(smooth(F))` and
//! `ddt(ddt(x))`: both sides filtered alike (the parallel filtering of
//! inverse-dynamic identification). Without it the acceleration is smoothed
//! and the force is not, and a force step leaves a residual of half the
//! step that no friction model can fit.

/// What a windowed column does to its source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Windowed {
    /// `ddt(COLUMN)`: the local linear fit's slope.
    Derivative,
    /// `smooth(COLUMN)`: the parabolic kernel the slope implies.
    Smoothed,
}

impl Windowed {
    /// Both, with the function name an expression calls them by.
    pub(super) const ALL: [(Windowed, &'static str); 2] = [
        (Windowed::Derivative, "ddt"),
        (Windowed::Smoothed, "smooth"),
    ];

    /// The function name (`ddt`, `smooth`).
    pub(super) fn function(self) -> &'static str {
        match self {
            Windowed::Derivative => "ddt",
            Windowed::Smoothed => "smooth",
        }
    }

    /// The column's name in an expression once it is replaced: `ddt__x`,
    /// `smooth__x`.
    pub(super) fn column_id(self, source: &str) -> String {
        format!("{}__{source}", self.function())
    }

    /// The column made from `y` at times `t` over ±`half` s.
    pub(super) fn apply(self, t: &[f64], y: &[f64], half: f64) -> Vec<f64> {
        match self {
            Windowed::Derivative => derivative(t, y, half),
            Windowed::Smoothed => smoothed(t, y, half),
        }
    }
}

/// A column an expression reads that is made from another column (or from
/// another such column: `ddt(ddt(x))`, `smooth(smooth(f))`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct WindowedColumn {
    /// Its name in the compiled expression (`ddt__x`).
    pub(super) id: String,
    /// The column it is made from (a column of the table or an earlier id).
    pub(super) source: String,
    pub(super) op: Windowed,
}

/// Each sample's window: the first and last sample within ±`half` s of it
/// (at least one sample each side where there is one).
fn windows(t: &[f64], half: f64) -> Vec<(usize, usize)> {
    let n = t.len();
    let reach = half * (1.0 + 1e-9);
    let (mut lo, mut hi) = (0usize, 0usize);
    (0..n)
        .map(|k| {
            // Samples exactly `half` away count on both sides (up to
            // rounding): on a uniform grid the window is symmetric.
            while t[k] - t[lo] > reach && lo + 1 < k {
                lo += 1;
            }
            while hi + 1 < n && (t[hi + 1] - t[k] <= reach || hi < k + 1) {
                hi += 1;
            }
            (lo.min(k.saturating_sub(1)), hi.max((k + 1).min(n - 1)))
        })
        .collect()
}

/// d/dt of `y` by a local linear fit over ±`half` s (at least ±1 sample);
/// on a uniform grid the slope is exact for a quadratic.
pub(super) fn derivative(t: &[f64], y: &[f64], half: f64) -> Vec<f64> {
    windows(t, half)
        .into_iter()
        .map(|(a, b)| {
            let m = (b - a + 1) as f64;
            let (st, sy) = (t[a..=b].iter().sum::<f64>(), y[a..=b].iter().sum::<f64>());
            let (mt, my) = (st / m, sy / m);
            let (mut num, mut den) = (0.0, 0.0);
            for j in a..=b {
                num += (t[j] - mt) * (y[j] - my);
                den += (t[j] - mt) * (t[j] - mt);
            }
            if den > 0.0 {
                num / den
            } else {
                0.0
            }
        })
        .collect()
}

/// `y` smoothed by the kernel K(s) = (H + Δ/2)² − s² over the derivative's
/// window, H its longer side from the sample and Δ its mean spacing.
pub(super) fn smoothed(t: &[f64], y: &[f64], half: f64) -> Vec<f64> {
    windows(t, half)
        .into_iter()
        .enumerate()
        .map(|(k, (a, b))| {
            if b == a {
                return y[k];
            }
            let spacing = (t[b] - t[a]) / (b - a) as f64;
            let reach = (t[k] - t[a]).max(t[b] - t[k]) + spacing / 2.0;
            let (mut num, mut den) = (0.0, 0.0);
            for j in a..=b {
                let s = t[j] - t[k];
                let w = reach * reach - s * s;
                num += w * y[j];
                den += w;
            }
            num / den
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn grid(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|k| k as f64 * dt).collect()
    }

    #[test]
    fn the_derivative_is_the_smoothing_kernel_applied_to_the_exact_derivative() {
        // ddt(y) ≈ K ∗ y': on a smooth signal the two agree to the grid's
        // second order, far closer than either is to y' itself.
        let t = grid(2000, 1e-3);
        let y: Vec<f64> = t.iter().map(|s| (9.0 * s).sin()).collect();
        let dy: Vec<f64> = t.iter().map(|s| 9.0 * (9.0 * s).cos()).collect();
        let d = derivative(&t, &y, 0.05);
        let s = smoothed(&t, &dy, 0.05);
        for k in 100..1900 {
            assert_abs_diff_eq!(d[k], s[k], epsilon = 2e-4 * 9.0);
        }
        // The window's smoothing itself is visible (9 rad/s over ±50 ms).
        let smoothing = (100..1900).fold(0.0f64, |m, k| m.max((d[k] - dy[k]).abs()));
        assert!(smoothing > 0.1, "{smoothing}");
    }

    #[test]
    fn a_force_smoothed_twice_beside_a_twice_derived_acceleration_keeps_their_balance_across_a_step(
    ) {
        // F = M ẍ with F stepping from 0 to 10 N at 0.5 s, M = 2 kg: the
        // derived acceleration spreads the step over the windows; the force
        // as measured leaves half the step (5 N) in F − M ddt(ddt(x)), the
        // force smoothed alike less than 3 % of it.
        let t = grid(1000, 1e-3);
        let (m, step) = (2.0, 10.0);
        let f: Vec<f64> = t
            .iter()
            .map(|s| if *s >= 0.5 { step } else { 0.0 })
            .collect();
        let x: Vec<f64> = t
            .iter()
            .map(|s| {
                if *s >= 0.5 {
                    0.5 * step / m * (s - 0.5).powi(2)
                } else {
                    0.0
                }
            })
            .collect();
        let h = 0.01;
        let acc = derivative(&t, &derivative(&t, &x, h), h);
        let filtered = smoothed(&t, &smoothed(&t, &f, h), h);
        let worst =
            |force: &[f64]| (100..900).fold(0.0f64, |w, k| w.max((force[k] - m * acc[k]).abs()));
        assert_abs_diff_eq!(worst(&f), step / 2.0, epsilon = 1e-6);
        assert!(worst(&filtered) < 0.03 * step, "{}", worst(&filtered));
    }

    #[test]
    fn smoothing_keeps_a_straight_line_and_a_constant_everywhere_on_a_uniform_grid() {
        // The kernel is symmetric in the interior; at the ends, where the
        // window is cut, a line is bent toward its inside but a constant is
        // kept.
        let t = grid(200, 1e-3);
        let line: Vec<f64> = t.iter().map(|s| 3.0 - 40.0 * s).collect();
        let s = smoothed(&t, &line, 0.01);
        for k in 10..190 {
            assert_abs_diff_eq!(s[k], line[k], epsilon = 1e-9);
        }
        let c = smoothed(&t, &vec![1.25; 200], 0.01);
        for v in c {
            assert_abs_diff_eq!(v, 1.25, epsilon = 1e-12);
        }
    }

    #[test]
    fn a_window_narrower_than_the_spacing_still_reaches_one_sample_each_side() {
        let t = grid(5, 0.1);
        let y = [0.0, 1.0, 4.0, 9.0, 16.0];
        // ±1 sample: the slope of (1, 4, 9) at 0.2 s is 40; the kernel
        // (1.5Δ)² − s² weighs the neighbours 1.25 and the sample 2.25.
        assert_abs_diff_eq!(derivative(&t, &y, 0.01)[2], 40.0, epsilon = 1e-9);
        let expect = (1.25 * 1.0 + 2.25 * 4.0 + 1.25 * 9.0) / 4.75;
        assert_abs_diff_eq!(smoothed(&t, &y, 0.01)[2], expect, epsilon = 1e-12);
    }
}
