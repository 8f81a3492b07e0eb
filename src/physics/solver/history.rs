//! Starting states and the stored time levels (BDF2 and the θ scheme use
//! two past levels).
//!
//! `Solver`'s fields this file uses: `d`, `p`, `h0`, `velocity`, `hist`, `hist_len`, `w`, `predictor`, `last`.

use super::Solver;
use crate::physics::error::SetupError;

impl Solver {
    /// Place the slider at gap `h0` with p = p_amb, at rest, time 0. The
    /// first step is backward Euler (only one history level exists).
    pub fn initialize_gap(&mut self, h0: f64) {
        self.p.fill(self.d.p_amb);
        self.h0 = h0;
        self.velocity = 0.0;
        self.set_time(0.0);
        self.hist_len = 0;
        // Both levels at rest (so h0'' starts at 0), but only one counts:
        // the first step is backward Euler.
        self.push_history_current(0.0);
        self.push_history_current(0.0);
        self.hist_len = 1;
        self.predictor.forget();
        self.last = None;
    }

    /// Start from a given pressure field (Pa, one value per cell) and gap
    /// (m), time 0. The first step is backward Euler. Non-finite or
    /// wrongly-sized input is rejected.
    pub fn initialize_state(&mut self, p: &[f64], h0: f64) -> Result<(), SetupError> {
        if p.len() != self.d.grid.n {
            return Err(SetupError::invalid(
                "initial_state.pressure.len",
                p.len() as f64,
                "must equal the number of cells",
            ));
        }
        if let Some(bad) = p.iter().find(|x| !x.is_finite()) {
            return Err(SetupError::invalid(
                "initial_state.pressure",
                *bad,
                "must be finite",
            ));
        }
        if !(h0.is_finite() && h0 > 0.0) {
            return Err(SetupError::invalid(
                "initial_state.h0",
                h0,
                "must be finite and > 0",
            ));
        }
        self.initialize_gap(h0);
        self.p.copy_from_slice(p);
        self.hist_len = 0;
        self.push_history_current(0.0);
        self.push_history_current(0.0);
        self.hist_len = 1;
        Ok(())
    }

    pub(super) fn fill_history_with_current(&mut self) {
        self.hist_len = 0;
        self.predictor.forget();
        let f_net = self
            .last
            .map_or(0.0, |e| e.hydrodynamic_force + e.asperity_force - e.load);
        self.push_history_current(f_net);
        self.push_history_current(f_net);
    }

    /// Push the current state as level n−1.
    pub(super) fn push_history_current(&mut self, f_net: f64) {
        self.hist.swap(0, 1);
        self.w.hist_term_valid = None;
        let lvl = &mut self.hist[0];
        for i in 0..self.d.grid.n {
            let h = self.h0 + self.d.grid.g_cell[i];
            lvl.rho_h[i] = self.d.eos.eval(self.p[i]).rho * h;
        }
        lvl.f_net = f_net;
        lvl.h0 = self.h0;
        // Flux divergence at this level (only the θ scheme reads it).
        lvl.div.fill(0.0);
        self.hist_len = (self.hist_len + 1).min(2);
    }

    /// Forget all but the newest level: the next step is backward Euler
    /// from it, with the gap at rest (used around a variable-length step).
    pub(super) fn restart_history(&mut self) {
        let (newest, older) = self.hist.split_at_mut(1);
        older[0].copy_from(&newest[0]);
        self.hist_len = self.hist_len.min(1);
        self.predictor.forget();
        self.w.hist_term_valid = None;
    }
}
