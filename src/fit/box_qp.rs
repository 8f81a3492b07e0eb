//! The minimum of a convex quadratic over a box, exactly: the linear
//! keys' solve (`separable.rs`) and the cheap keys' steps (`profile.rs`).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | y | the unknowns (columns scaled to unit norm) | theirs × column norm |
//! | G | the Gram matrix of the scaled columns (unit diagonal, or above 1 with damping) | 1 |
//! | b | the scaled columns' products with the residuals | N² per unit of y |
//! | [lo_j, hi_j] | y_j's bounds | as y |
//!
//! minimise 2 bᵀy + yᵀ G y over lo ≤ y ≤ hi: the unconstrained minimum
//! when it lies in the box, else the best of the minima on the box's faces
//! (each y_j free, at lo_j or at hi_j: 3ᵏ faces; the box's minimum is one
//! of them).

use nalgebra::{DMatrix, DVector};

/// A Cholesky pivot below this (on a Gram matrix with unit diagonal) is a
/// face whose free columns are dependent: that face is skipped (the box's
/// minimum is then on a face where one of them sits at a bound).
const PIVOT_FLOOR: f64 = 1e-12;

/// y minimising 2 bᵀy + yᵀ G y over the box `boxed` (lo ≤ y_j ≤ hi), G
/// positive semidefinite: the unconstrained minimum when it lies in the
/// box, else the best minimum over the faces (each y_j free, at its lower
/// or at its upper bound).
pub(super) fn box_minimum(gram: &DMatrix<f64>, b: &DVector<f64>, boxed: &[(f64, f64)]) -> Vec<f64> {
    let k = boxed.len();
    let free: Vec<Option<f64>> = vec![None; k];
    if let Some(y) = face_minimum(gram, b, &free) {
        if inside(&y, boxed) {
            return y;
        }
    }
    let objective = |y: &[f64]| {
        let y = DVector::from_column_slice(y);
        2.0 * b.dot(&y) + (y.transpose() * gram * &y)[(0, 0)]
    };
    let mut best: Option<(f64, Vec<f64>)> = None;
    let mut face = vec![None; k];
    for code in 0..3usize.pow(k as u32) {
        let mut c = code;
        for (j, f) in face.iter_mut().enumerate() {
            *f = match c % 3 {
                0 => None,
                1 => Some(boxed[j].0),
                _ => Some(boxed[j].1),
            };
            c /= 3;
        }
        let Some(y) = face_minimum(gram, b, &face) else {
            continue;
        };
        if !inside(&y, boxed) {
            continue;
        }
        let value = objective(&y);
        if best.as_ref().is_none_or(|(v, _)| value < *v) {
            best = Some((value, y));
        }
    }
    let y = best.map(|(_, y)| y).unwrap_or_else(|| vec![0.0; k]);
    y.iter()
        .zip(boxed)
        .map(|(v, (lo, hi))| v.clamp(*lo, *hi))
        .collect()
}

/// Whether `y` lies in the box (to rounding).
fn inside(y: &[f64], boxed: &[(f64, f64)]) -> bool {
    y.iter().zip(boxed).all(|(v, (lo, hi))| {
        let slack = 1e-12 * (hi - lo).abs().max(v.abs());
        *v >= lo - slack && *v <= hi + slack
    })
}

/// The minimum of 2 bᵀy + yᵀ G y with the components of `face` that are
/// `Some` fixed there; None when the free columns are dependent.
fn face_minimum(gram: &DMatrix<f64>, b: &DVector<f64>, face: &[Option<f64>]) -> Option<Vec<f64>> {
    let free: Vec<usize> = (0..face.len()).filter(|j| face[*j].is_none()).collect();
    let mut y: Vec<f64> = face.iter().map(|f| f.unwrap_or(0.0)).collect();
    if free.is_empty() {
        return Some(y);
    }
    let m = free.len();
    let g = DMatrix::from_fn(m, m, |a, c| gram[(free[a], free[c])]);
    let rhs = DVector::from_fn(m, |a, _| {
        let i = free[a];
        let fixed: f64 = (0..face.len())
            .filter_map(|j| face[j].map(|v| gram[(i, j)] * v))
            .sum();
        -(b[i] + fixed)
    });
    let chol = g.cholesky()?;
    if chol
        .l_dirty()
        .diagonal()
        .iter()
        .any(|d| d * d < PIVOT_FLOOR)
    {
        return None;
    }
    let sol = chol.solve(&rhs);
    for (a, i) in free.iter().enumerate() {
        y[*i] = sol[a];
    }
    Some(y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The box's minimum by brute force on a grid (for checking).
    fn grid_minimum(g: &DMatrix<f64>, b: &DVector<f64>, boxed: &[(f64, f64)]) -> f64 {
        let steps = 200;
        let mut best = f64::INFINITY;
        for i in 0..=steps {
            for j in 0..=steps {
                let y = DVector::from_vec(vec![
                    boxed[0].0 + (boxed[0].1 - boxed[0].0) * i as f64 / steps as f64,
                    boxed[1].0 + (boxed[1].1 - boxed[1].0) * j as f64 / steps as f64,
                ]);
                best = best.min(2.0 * b.dot(&y) + (y.transpose() * g * &y)[(0, 0)]);
            }
        }
        best
    }

    #[test]
    fn the_box_minimum_is_the_unconstrained_one_when_that_lies_inside() {
        let g = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.5, 1.0]);
        let b = DVector::from_vec(vec![-1.0, 0.25]);
        let y = box_minimum(&g, &b, &[(-10.0, 10.0), (-10.0, 10.0)]);
        // G y = −b: y = (1.5, −1.0).
        assert_relative_eq!(y[0], 1.5, epsilon = 1e-12);
        assert_relative_eq!(y[1], -1.0, epsilon = 1e-12);
    }

    #[test]
    fn the_box_minimum_on_a_face_is_no_worse_than_any_point_of_the_box() {
        // Strongly correlated columns (a viscous against a quadratic
        // loss), the unconstrained minimum outside the box.
        let g = DMatrix::from_row_slice(2, 2, &[1.0, 0.95, 0.95, 1.0]);
        for (b, boxed) in [
            (vec![-1.0, 0.8], [(0.0, 5.0), (0.0, 5.0)]),
            (vec![2.0, 1.0], [(0.0, 1.0), (-0.5, 3.0)]),
            (vec![-3.0, -3.0], [(0.0, 0.5), (0.0, 0.5)]),
        ] {
            let b = DVector::from_vec(b);
            let y = box_minimum(&g, &b, &boxed);
            assert!(inside(&y, &boxed), "{y:?} outside {boxed:?}");
            let yv = DVector::from_vec(y.clone());
            let value = 2.0 * b.dot(&yv) + (yv.transpose() * &g * &yv)[(0, 0)];
            let grid = grid_minimum(&g, &b, &boxed);
            assert!(
                value <= grid + 1e-12,
                "{value} above the grid's {grid} at {y:?}"
            );
        }
    }

    #[test]
    fn dependent_columns_still_give_the_box_minimum() {
        // Two identical columns: G singular; the minimum sets their sum.
        let g = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let b = DVector::from_vec(vec![-0.6, -0.6]);
        let boxed = [(0.0, 0.4), (0.0, 0.4)];
        let y = box_minimum(&g, &b, &boxed);
        assert_relative_eq!(y[0] + y[1], 0.6, epsilon = 1e-12);
        assert!(inside(&y, &boxed));
    }
}
