//! The border both linear solves close with (`bordered.rs`, tridiagonal;
//! `banded.rs`, pentadiagonal): the load balance's row and the scalar Schur
//! complement that gives Δh0. Its own file, so that the two solves depend
//! on it and not on each other.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | c | the border row's uniform entry ∂G/∂p | m² |
//! | ∂g/∂h0 | the load balance's derivative in the gap | N/m |
//! | g | the load balance's residual | N |
//! | s | the Schur complement ∂g/∂h0 − c Σ z | N/m |

/// The load-balance border of the system: its row (c, ∂g/∂h0) and
/// residual g, and whether the gap is solved for at all.
pub(super) struct Border {
    pub(super) balance: bool,
    pub(super) dgdh: f64,
    pub(super) c_row: f64,
    pub(super) g: f64,
}

/// Close the bordered solve from the block's two solutions y (right-hand
/// side) and z (border column), given their sums (Σ y, Σ z): Δh0 from the
/// Schur complement s = ∂g/∂h0 − c Σ z (stored in `schur`), then the
/// direction −(y + z Δh0) into `y`. Without the border, Δh0 = 0 and the
/// direction is −y. None when s is zero or non-finite.
#[inline(always)]
pub(super) fn close_border(
    b: Border,
    y: &mut [f64],
    z: impl Iterator<Item = f64>,
    (sy, sz): (f64, f64),
    schur: &mut f64,
) -> Option<f64> {
    if !b.balance {
        for v in y.iter_mut() {
            *v = -*v;
        }
        return Some(0.0);
    }
    *schur = b.dgdh - b.c_row * sz;
    if !(schur.is_finite() && *schur != 0.0) {
        return None;
    }
    let dh = (-b.g + b.c_row * sy) / *schur;
    for (v, z) in y.iter_mut().zip(z) {
        *v = -*v - z * dh;
    }
    Some(dh)
}
