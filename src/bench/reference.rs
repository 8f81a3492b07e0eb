//! The accuracy guides' reference must be finer than every setting it
//! judges: a reference on the tested grid, or one whose step is longer than
//! the tested step, measures nothing and "passes" at 0 %.

/// A reference that cannot judge the settings asked for.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceError {
    /// The reference grid is not finer than a tested grid.
    #[error("--reference-cells {reference} is not finer than the tested grid N = {tested}: the reference must have more cells than every grid tested")]
    Cells {
        /// The reference's cells.
        reference: usize,
        /// The coarsest offending tested grid.
        tested: usize,
    },
    /// The reference step is longer than a tested step.
    #[error("--reference-dt {reference} s is longer than the tested step {tested} s: the reference step must not exceed any step tested (solver.dt_s included)")]
    Step {
        /// The reference step, s.
        reference: f64,
        /// The offending tested step, s.
        tested: f64,
    },
}

/// Check `reference` (cells, step s) against the grids and steps tested.
pub fn check_reference(
    tested_cells: &[usize],
    tested_steps_s: &[f64],
    (cells, dt_s): (usize, f64),
) -> Result<(), ReferenceError> {
    if let Some(&tested) = tested_cells.iter().filter(|&&n| n >= cells).max() {
        return Err(ReferenceError::Cells {
            reference: cells,
            tested,
        });
    }
    if let Some(&tested) = tested_steps_s
        .iter()
        .filter(|&&dt| dt < dt_s)
        .min_by(|a, b| a.total_cmp(b))
    {
        return Err(ReferenceError::Step {
            reference: dt_s,
            tested,
        });
    }
    Ok(())
}

/// `items` without repeats, in their first order (a flux or grid named
/// twice is measured once).
pub fn without_repeats<T: PartialEq + Copy>(items: &[T]) -> Vec<T> {
    let mut out: Vec<T> = Vec::with_capacity(items.len());
    for &x in items {
        if !out.contains(&x) {
            out.push(x);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_as_coarse_as_a_tested_grid_or_with_a_longer_step_is_refused() {
        assert!(check_reference(&[64, 128], &[1e-3], (2048, 1.25e-4)).is_ok());
        let e = check_reference(&[64, 256], &[1e-3], (256, 1.25e-4)).unwrap_err();
        assert_eq!(
            e,
            ReferenceError::Cells {
                reference: 256,
                tested: 256
            }
        );
        assert!(e.to_string().contains("--reference-cells 256"), "{e}");
        let e = check_reference(&[64], &[1e-3, 5e-4], (2048, 2e-3)).unwrap_err();
        assert!(
            e.to_string().contains("5e-4") || e.to_string().contains("0.0005"),
            "{e}"
        );
        // An equal step with a finer grid judges the grid: allowed.
        assert!(check_reference(&[64], &[1e-3], (2048, 1e-3)).is_ok());
    }

    #[test]
    fn a_setting_named_twice_is_measured_once() {
        assert_eq!(without_repeats(&[3, 1, 3, 2, 1]), vec![3, 1, 2]);
    }
}
