//! The loop's side of live parameters: changes prepared off the loop
//! (`link.rs`) are applied between two steps, without blocking or
//! allocating, and handed back stamped with the first step that used them.

use crate::link::{ParameterChannel, ParameterUpdate};

impl super::Loop {
    /// Use `channel` for parameter changes while running.
    pub fn with_parameters(mut self, channel: std::sync::Arc<ParameterChannel>) -> Self {
        self.parameters = Some(channel);
        self
    }

    /// Apply every pending change before the step stamped `stamp_ns`.
    pub(super) fn apply_parameters(&mut self, stamp_ns: u64) {
        let Some(ch) = self.parameters.clone() else {
            return;
        };
        while let Some(mut u) = ch.pending.pop() {
            self.apply_update(&mut u);
            u.applied_stamp_ns = stamp_ns;
            // In flight ≤ IN_FLIGHT = the capacity: this never fails.
            let _ = ch.applied.push(u);
        }
    }

    /// One change: the model swapped in, the settings replaced, the
    /// viscosity re-derived at the current temperature, the load held.
    pub fn apply_update(&mut self, u: &mut ParameterUpdate) {
        // Every contact's model must fit its solver (geometry and grid are
        // read-only, so apply_set cannot build a mismatch; the contact list
        // itself cannot change): all of them change, or none.
        let n = self.contacts.len();
        let fits = u.contacts.len() == n
            && (0..n).all(|i| {
                self.contacts
                    .with_solver(i, |s| s.fits(&u.contacts[i].model))
            });
        if !fits {
            return;
        }
        self.settings = u.settings.clone();
        for w in &mut self.watches {
            w.set_policy(self.settings.outside_envelope);
        }
        for (i, c) in u.contacts.iter_mut().enumerate() {
            let _ = self.contacts.with_solver(i, |s| s.swap_model(&mut c.model));
            self.viscosity[i] = c.viscosity;
            if c.viscosity.follows_temperature() {
                // A temperature the new law refuses (its C moved above it)
                // gives the law's reference viscosity.
                let mu = c
                    .viscosity
                    .viscosity_at(self.watches[i].temperature_c(self.temperature_c))
                    .unwrap_or(c.viscosity.mu_ref);
                self.contacts.with_solver(i, |s| s.set_liquid_viscosity(mu));
            }
            if let Some(l) = c.load {
                self.cmd[i].load = l;
            }
        }
        self.summary.parameter_updates += 1;
    }
}
