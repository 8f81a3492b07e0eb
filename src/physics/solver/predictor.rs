//! The time step's warm start: what the solver keeps of earlier levels to
//! extrapolate the pressure and the gap (see [`Solver`]'s `predict` in
//! `step.rs`), grouped so that a reset or a restart clears it in one place.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | p^(n−2), p^(n−3) | accepted pressure fields two and three levels back | Pa |
//! | h0^(n−3) | the gap three levels back | m |
//!
//! Extrapolation (second order once three levels exist):
//!
//! ```text
//! p* = 3 (p^(n−1) − p^(n−2)) + p^(n−3)      h0* = 3 (h0^(n−1) − h0^(n−2)) + h0^(n−3)
//! p* = 2 p^(n−1) − p^(n−2)                  (one level back only)
//! ```
//!
//! Fields: read and written by `step.rs` (`step`, `predict`), cleared by
//! `history.rs`, `held_h0` taken by `newton.rs`.
//!
//! [`Solver`]: super::Solver

/// Earlier levels kept for the predictor (allocated when the solver is
/// built; a step only swaps and copies).
#[derive(Debug, Clone)]
pub(super) struct Predictor {
    /// Pressure at level n−2, Pa.
    pub(super) p_old: Vec<f64>,
    /// Pressure at level n−3, Pa.
    pub(super) p_old2: Vec<f64>,
    /// How many of `p_old`, `p_old2` are valid (0..=2).
    pub(super) levels: usize,
    /// h0 at level n−3 (valid when `levels == 2`), m.
    pub(super) h0_n3: f64,
    /// h0 of the previous state while a solve starts from the
    /// extrapolation (the restart's alternative start; taken by the solve).
    pub(super) held_h0: Option<f64>,
}

impl Predictor {
    /// No level yet; `n` cells at ambient pressure `p_amb`.
    pub(super) fn new(n: usize, p_amb: f64) -> Self {
        Self {
            p_old: vec![p_amb; n],
            p_old2: vec![p_amb; n],
            levels: 0,
            h0_n3: 0.0,
            held_h0: None,
        }
    }

    /// Forget the levels (a reset, a restart, a variable-length step).
    pub(super) fn forget(&mut self) {
        self.levels = 0;
    }

    /// A step was accepted: `previous` (the pressure it started from, the
    /// solver's backup buffer, swapped in without a copy) becomes level
    /// n−2, and `h0_n2` (the gap two levels back) becomes n−3.
    pub(super) fn push(&mut self, previous: &mut Vec<f64>, h0_n2: f64) {
        std::mem::swap(&mut self.p_old2, &mut self.p_old);
        std::mem::swap(&mut self.p_old, previous);
        self.levels = (self.levels + 1).min(2);
        self.h0_n3 = h0_n2;
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // values moved, not computed: exact
mod tests {
    use super::*;

    #[test]
    fn an_accepted_step_shifts_the_levels_and_a_reset_forgets_them() {
        let mut p = Predictor::new(2, 1e5);
        let mut backup = vec![2e5, 2e5];
        p.push(&mut backup, 1e-6);
        assert_eq!(p.levels, 1);
        assert_eq!(p.p_old, [2e5, 2e5]);
        let mut backup2 = vec![3e5, 3e5];
        p.push(&mut backup2, 2e-6);
        assert_eq!(p.levels, 2);
        assert_eq!((p.p_old[0], p.p_old2[0]), (3e5, 2e5));
        assert_eq!(p.h0_n3, 2e-6);
        let mut backup3 = vec![4e5, 4e5];
        p.push(&mut backup3, 3e-6);
        assert_eq!(p.levels, 2, "two levels at most");
        p.forget();
        assert_eq!(p.levels, 0);
    }
}
