//! The classic curves' linear regressions on a fit's training samples:
//! Coulomb + viscous is linear in its parameters; the Stribeck curve is
//! linear once its speed is fixed, and is solved on a grid of speeds
//! (variable projection). They start the classic models
//! (`baselines.rs`) and our Stribeck term (`trial.rs`).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | v | velocity | m/s (rad/s on a joint's data) |
//! | F | friction | N (N·m) |
//! | F_c, F_s | Coulomb and static levels | N (N·m) |
//! | v_s | Stribeck velocity | m/s (rad/s) |
//! | b | viscous slope | N·s/m (N·m·s/rad) |
//! | c | a level that differs by direction | N (N·m) |
//!
//! F = F_c sgn v + (F_s − F_c) sgn v e^(−(v/v_s)²) + b v (+ c).

use super::series::Series;
use crate::physics::sgn;
use crate::physics::terms::drivetrain::exp_neg;
use nalgebra::{DMatrix, DVector};

/// How a classic model's friction levels follow the normal load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadForm {
    /// No load dependence.
    Constant,
    /// F = F0 + μ N: needs data at two loads or more.
    Linear,
    /// F = μ N: Amontons; identifiable from one load.
    Proportional,
}

impl LoadForm {
    /// The form a fit gives the classic models, decided by the training
    /// data alone (never by the data held out): linear when the training
    /// loads vary; proportional when they hold one load that the data give
    /// (a load column or topic: at that load it fits exactly as a constant
    /// level, and it is the one form that carries to another load);
    /// constant when the data give no load at all.
    pub fn for_data(training_loads_vary: bool, training_has_load: bool) -> Self {
        if training_loads_vary {
            LoadForm::Linear
        } else if training_has_load {
            LoadForm::Proportional
        } else {
            LoadForm::Constant
        }
    }
}

/// The fitted samples of the training data: velocity, friction, load.
pub(super) struct Samples {
    pub(super) v: Vec<f64>,
    pub(super) f: Vec<f64>,
    pub(super) n: Vec<f64>,
}

impl Samples {
    pub(super) fn of(series: &[Series]) -> Self {
        let (mut v, mut f, mut n) = (Vec::new(), Vec::new(), Vec::new());
        for s in series {
            for k in (0..s.len()).filter(|&k| s.fit[k]) {
                v.push(s.velocity[k]);
                f.push(s.friction[k]);
                n.push(s.load_at(k, 1.0));
            }
        }
        Self { v, f, n }
    }
}

/// The level columns of a regression: one per level coefficient of the
/// load form, each times `shape` (a level multiplies sgn v, or sgn v · E).
pub(super) fn level_columns(form: LoadForm, shape: f64, load: f64) -> Vec<f64> {
    match form {
        LoadForm::Constant => vec![shape],
        LoadForm::Proportional => vec![shape * load],
        LoadForm::Linear => vec![shape, shape * load],
    }
}

/// Least squares of `rows` (each a row of the design matrix) against `y`:
/// the coefficients and the residual sum of squares (None: degenerate).
pub(super) fn least_squares(rows: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, f64)> {
    let m = rows.len();
    let n = rows.first()?.len();
    if m <= n {
        return None;
    }
    let a = DMatrix::from_fn(m, n, |i, j| rows[i][j]);
    let b = DVector::from_column_slice(y);
    let x = a.clone().svd(true, true).solve(&b, 1e-12).ok()?;
    let ss = (a * &x - b).norm_squared();
    (x.iter().all(|c| c.is_finite()) && ss.is_finite()).then(|| (x.iter().copied().collect(), ss))
}

/// The rows of the design matrix of Coulomb + viscous (`vs` None) or of
/// the Stribeck curve at the Stribeck velocity `vs`, each level in the
/// load form `form`, then the viscous slope, then (with `offset`) a
/// constant: a level that differs by direction.
pub(super) fn design_rows(
    s: &Samples,
    form: LoadForm,
    vs: Option<f64>,
    offset: bool,
) -> Vec<Vec<f64>> {
    (0..s.v.len())
        .map(|k| {
            let (v, n) = (s.v[k], s.n[k]);
            let sg = sgn(v);
            let mut row = Vec::with_capacity(6);
            match vs {
                None => row.extend(level_columns(form, sg, n)),
                Some(vs) => {
                    let e = exp_neg((v / vs).powi(2));
                    row.extend(level_columns(form, sg * (1.0 - e), n));
                    row.extend(level_columns(form, sg * e, n));
                }
            }
            row.push(v);
            if offset {
                row.push(1.0);
            }
            row
        })
        .collect()
}

/// The best Stribeck curve of a log grid of 49 Stribeck velocities from
/// 1e-3 × `v_scale` to `v_scale`, each solved by linear least squares
/// (variable projection): the velocity, the coefficients and the residual
/// sum of squares (None: too few samples).
pub(super) fn stribeck_grid(
    s: &Samples,
    form: LoadForm,
    v_scale: f64,
    offset: bool,
) -> Option<(f64, Vec<f64>, f64)> {
    let (lo, hi) = (1e-3 * v_scale, v_scale);
    (0..49)
        .map(|k| lo * (hi / lo).powf(k as f64 / 48.0))
        .filter_map(|vs| {
            least_squares(&design_rows(s, form, Some(vs), offset), &s.f).map(|(x, ss)| (vs, x, ss))
        })
        .min_by(|a, b| a.2.total_cmp(&b.2))
}

/// A Stribeck curve F = F_c sgn v + (F_s − F_c) sgn v e^{−(v/v_s)²}
/// + b v + c, in the data's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridCurve {
    /// v_s.
    pub speed: f64,
    /// F_s − F_c.
    pub amplitude: f64,
    /// c: a level that differs by direction (0 without one).
    pub offset: f64,
}

/// Where a term that bends a curve at a speed (our drivetrain Stribeck
/// curve) is best started on the training samples of `series`: the best
/// curve of `stribeck_grid` (a log grid of 49 speeds) over the data's speeds, its levels and
/// slope solved at each speed, with a constant beside them when `offset`
/// (a level that differs by direction, which otherwise moves the best
/// speed). None: too few samples.
pub fn stribeck_curve_by_grid(series: &[Series], offset: bool) -> Option<GridCurve> {
    let samples = Samples::of(series);
    let top = samples.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if top <= 0.0 {
        return None;
    }
    let (speed, x, _) = stribeck_grid(&samples, LoadForm::Constant, top, offset)?;
    // Columns: F_c, F_s, b, then c.
    Some(GridCurve {
        speed,
        amplitude: x[1] - x[0],
        offset: if offset { x[3] } else { 0.0 },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn series(steady: bool) -> Series {
        Series {
            name: "s".into(),
            steady,
            t: Vec::new(),
            velocity: Vec::new(),
            friction: Vec::new(),
            load: None,
            temperature: None,
            fit: Vec::new(),
        }
    }

    #[test]
    fn the_grid_finds_a_rise_beside_a_direction_offset() {
        // A rise (F_s 1.5 below F_c 2) bending at a speed of the grid
        // (0.4 × 10^-0.5), a slope and an offset of 0.3, both ways.
        let (fc, fs, vs, b, c) = (2.0, 1.5, 0.4 * 10f64.powf(-0.5), 0.5, 0.3);
        let mut s = series(true);
        s.velocity = [0.01, 0.02, 0.05, 0.08, 0.12, 0.16, 0.2, 0.26, 0.32, 0.4]
            .iter()
            .flat_map(|v| [*v, -*v])
            .collect();
        let n = s.velocity.len();
        s.friction = s
            .velocity
            .iter()
            .map(|&v| sgn(v) * (fc + (fs - fc) * exp_neg((v / vs).powi(2))) + b * v + c)
            .collect();
        s.t = (0..n).map(|k| k as f64).collect();
        s.fit = vec![true; n];
        let with = stribeck_curve_by_grid(std::slice::from_ref(&s), true).unwrap();
        assert_relative_eq!(with.speed, vs, max_relative = 1e-9);
        assert_relative_eq!(with.amplitude, fs - fc, max_relative = 1e-6);
        assert_relative_eq!(with.offset, c, max_relative = 1e-6);
        // Without the offset column: speeds taken both ways make the
        // offset (even in v) orthogonal to the curve (odd), which is found
        // all the same.
        let paired = stribeck_curve_by_grid(std::slice::from_ref(&s), false).unwrap();
        assert_eq!(paired.offset, 0.0);
        assert_relative_eq!(paired.amplitude, fs - fc, max_relative = 1e-6);
        // One way more often than the other: the offset moves the curve
        // found without its column.
        s.velocity.extend([0.01, 0.02, 0.05]);
        s.friction.extend(
            s.friction[..5]
                .iter()
                .step_by(2)
                .copied()
                .collect::<Vec<_>>(),
        );
        s.t = (0..s.velocity.len()).map(|k| k as f64).collect();
        s.fit = vec![true; s.velocity.len()];
        let with = stribeck_curve_by_grid(std::slice::from_ref(&s), true).unwrap();
        assert_relative_eq!(with.amplitude, fs - fc, max_relative = 1e-6);
        let without = stribeck_curve_by_grid(std::slice::from_ref(&s), false).unwrap();
        assert!((without.amplitude - (fs - fc)).abs() > 1e-3, "{without:?}");
    }
}
