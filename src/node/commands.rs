//! Commands: validation against the configured limits, the timeout rule,
//! and the command status each estimate carries.

use super::Loop;
use crate::config::TimeoutBehaviour;
use crate::msgs::{estimate_constants as codes, Command, CommandKind};
use std::sync::atomic::Ordering;

impl Loop {
    pub(super) fn poll(&mut self, i: usize) -> Option<Command> {
        match self.ports[i].poll_command() {
            Ok(c) => c,
            Err(e) => {
                self.summary.transport_errors += 1;
                if self.summary.transport_errors == 1 {
                    tracing::warn!("{}: {e}", self.ports[i].name());
                }
                None
            }
        }
    }

    pub(super) fn reject(&mut self) {
        self.summary.commands_rejected += 1;
        self.live.commands_rejected.fetch_add(1, Ordering::Relaxed);
        self.rejected_pending = true;
    }

    pub(super) fn accept(&mut self) {
        self.summary.commands_applied += 1;
        self.live.commands_applied.fetch_add(1, Ordering::Relaxed);
    }

    pub(super) fn velocity_ok(&self, v: f64) -> bool {
        v.is_finite() && v.abs() <= self.s.max_abs_velocity
    }

    pub(super) fn load_ok(&self, f: f64) -> bool {
        f.is_finite() && f >= self.s.min_load && f <= self.s.max_load
    }

    /// A load command: applied when within limits, else rejected.
    pub(super) fn load_command(&mut self, value: f64) {
        if self.load_ok(value) {
            self.load = value;
            self.accept();
        } else {
            self.reject();
        }
    }

    /// A temperature command: the viscosity follows it (Vogel), else it is
    /// only reported. Outside [-60, 300] °C (or at or below Vogel's C) it is
    /// rejected.
    pub(super) fn temperature_command(&mut self, t_c: f64) {
        let mu = self
            .viscosity_model
            .viscosity(self.mu_ref, self.t_ref_c, t_c);
        let vogel_ok = match self.viscosity_model {
            crate::physics::ViscosityModel::Vogel(v) => t_c > v.c_c,
            crate::physics::ViscosityModel::Constant => true,
        };
        if t_c.is_finite() && (-60.0..=300.0).contains(&t_c) && vogel_ok && mu > 0.0 {
            self.temperature_c = t_c;
            self.solver.set_liquid_viscosity(mu);
            self.accept();
        } else {
            self.reject();
        }
    }

    /// Timer mode: take every pending command; the latest valid velocity
    /// and load become the set points (received at `now_ns`).
    pub(super) fn drain_commands(&mut self, now_ns: u64) {
        for i in 0..self.ports.len() {
            while let Some(c) = self.poll(i) {
                match c.kind {
                    CommandKind::Velocity if self.velocity_ok(c.value) => {
                        self.velocity = c.value;
                        self.last_velocity_at_ns = now_ns;
                        self.fresh = true;
                        self.accept();
                    }
                    CommandKind::Velocity => self.reject(),
                    CommandKind::Load => self.load_command(c.value),
                    CommandKind::Temperature => self.temperature_command(c.value),
                }
            }
        }
    }

    /// The velocity the next `steps` steps (ending at `at_ns`) apply: the
    /// command, or after the timeout the held or ramped value.
    pub(super) fn apply_timeout(&mut self, at_ns: u64, steps: u64) {
        let age = at_ns.saturating_sub(self.last_velocity_at_ns);
        self.timed_out = age > self.s.command_timeout_ns;
        if !self.timed_out {
            self.applied = self.velocity;
            return;
        }
        self.summary.command_timeouts += 1;
        match self.s.timeout_behaviour {
            TimeoutBehaviour::Hold => self.applied = self.velocity,
            TimeoutBehaviour::RampToZero => {
                let dv = self.s.deceleration * self.s.dt * steps as f64;
                self.applied = if self.applied.abs() <= dv {
                    0.0
                } else {
                    self.applied - dv * self.applied.signum()
                };
            }
        }
    }

    /// The command status of the step about to be published; a pending
    /// rejection is reported once, whatever the solver did.
    pub(super) fn take_command_status(&mut self) -> u8 {
        let status = if self.rejected_pending {
            codes::COMMAND_REJECTED
        } else if self.timed_out {
            codes::COMMAND_TIMED_OUT
        } else if self.fresh {
            codes::COMMAND_FRESH
        } else {
            codes::COMMAND_HELD
        };
        self.rejected_pending = false;
        self.fresh = false;
        status
    }
}
