//! Commands: validation against the configured limits, the timeout rule,
//! and the command status each contact's estimate carries.
//!
//! Each contact has its own command state ([`ContactCommand`]): a
//! `JointState` that leaves a joint out leaves that contact's command as it
//! was (held, then timed out), and a rejected joint flags only its contact.
//! Load and temperature commands apply to every contact (one load topic,
//! one oil sump); each contact's viscosity follows the temperature by its
//! own lubricant's law.
//!
//! `Loop`'s fields this file uses: `contacts`, `cmd`, `watches`, `settings`, `ports`, `live`, `temperature_c`, `viscosity`, `summary`.

use super::Loop;
use crate::config::TimeoutBehaviour;
use crate::msgs::{estimate_constants as codes, Command, CommandKind};
use std::sync::atomic::Ordering;

/// One contact's command state.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct ContactCommand {
    /// The latest valid velocity command, m/s.
    pub velocity: f64,
    /// The velocity the steps apply (the command, or held/ramped after a
    /// timeout), m/s.
    pub applied: f64,
    /// Normal load, N.
    pub load: f64,
    /// When the latest velocity command was taken (monotonic), ns.
    pub last_velocity_at_ns: u64,
    /// A velocity command was applied since the previous step.
    pub fresh: bool,
    pub rejected_pending: bool,
    pub timed_out: bool,
}

impl ContactCommand {
    pub(super) fn new(v0: f64, load: f64) -> Self {
        Self {
            velocity: v0,
            applied: v0,
            load,
            last_velocity_at_ns: 0,
            fresh: false,
            rejected_pending: false,
            timed_out: false,
        }
    }
}

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

    /// A command rejected; `contact` (None: every contact) reports it.
    pub(super) fn reject(&mut self, contact: Option<usize>) {
        self.summary.commands_rejected += 1;
        self.live.commands_rejected.fetch_add(1, Ordering::Relaxed);
        match contact {
            Some(k) => self.cmd[k].rejected_pending = true,
            None => self.cmd.iter_mut().for_each(|c| c.rejected_pending = true),
        }
    }

    pub(super) fn accept(&mut self) {
        self.summary.commands_applied += 1;
        self.live.commands_applied.fetch_add(1, Ordering::Relaxed);
    }

    pub(super) fn velocity_ok(&self, v: f64) -> bool {
        self.settings.limits.check_velocity(v).is_ok()
    }

    pub(super) fn load_ok(&self, f: f64) -> bool {
        self.settings.limits.check_load(f).is_ok()
    }

    /// The contact a velocity command is for (None: not a velocity, or a
    /// joint index beyond the contacts, which no port produces).
    pub(super) fn velocity_contact(&self, kind: CommandKind) -> Option<usize> {
        match kind {
            CommandKind::Velocity => Some(0),
            CommandKind::JointVelocity { contact, .. } => {
                Some(usize::from(contact)).filter(|&k| k < self.cmd.len())
            }
            CommandKind::Load | CommandKind::Temperature => None,
        }
    }

    /// The sliding speed of contact `k`, m/s, for a velocity command's
    /// value: a joint's velocity (m/s, or rad/s for a rotary joint) times
    /// the contact's `gain`; a plain velocity command is the speed itself.
    pub(super) fn contact_speed(&self, kind: CommandKind, k: usize, value: f64) -> f64 {
        match kind {
            CommandKind::JointVelocity { joint: true, .. } => self.contacts.gains()[k] * value,
            _ => value,
        }
    }

    /// A velocity command for contact `k` (m/s), taken at `now_ns`: applied when
    /// within limits, else rejected (that contact only).
    pub(super) fn velocity_command(&mut self, k: usize, value: f64, now_ns: u64) {
        if self.velocity_ok(value) {
            let c = &mut self.cmd[k];
            c.velocity = value;
            c.last_velocity_at_ns = now_ns;
            c.fresh = true;
            self.accept();
        } else {
            self.reject(Some(k));
        }
    }

    /// A load command: applied to every contact when within limits, else
    /// rejected.
    pub(super) fn load_command(&mut self, value: f64) {
        if self.load_ok(value) {
            self.cmd.iter_mut().for_each(|c| c.load = value);
            self.accept();
        } else {
            self.reject(None);
        }
    }

    /// A temperature command: each contact's viscosity follows it (Vogel),
    /// else it is only reported. A temperature any contact's law refuses
    /// ([`crate::config::ViscosityLaw::viscosity_at`]) is rejected.
    pub(super) fn temperature_command(&mut self, t_c: f64) {
        if self
            .viscosity
            .iter()
            .any(|law| law.viscosity_at(t_c).is_err())
        {
            self.reject(None);
            return;
        }
        self.temperature_c = t_c;
        for k in 0..self.viscosity.len() {
            let law = self.viscosity[k];
            // Under `node.outside_envelope: hold`, at the calibrated range's edge.
            let t_model = self.watches[k].temperature_c(t_c);
            if let (true, Ok(mu)) = (law.follows_temperature(), law.viscosity_at(t_model)) {
                self.contacts.with_solver(k, |s| s.set_liquid_viscosity(mu));
            }
        }
        self.accept();
    }

    /// A command that is not a velocity (load, temperature), or a velocity
    /// for contact `k` taken at `now_ns`.
    pub(super) fn apply_command(&mut self, c: Command, now_ns: u64) {
        match (c.kind, self.velocity_contact(c.kind)) {
            (CommandKind::Load, _) => self.load_command(c.value),
            (CommandKind::Temperature, _) => self.temperature_command(c.value),
            (kind, Some(k)) => {
                self.velocity_command(k, self.contact_speed(kind, k, c.value), now_ns)
            }
            (_, None) => self.reject(None),
        }
    }

    /// Timer mode: take every pending command; the latest valid velocity
    /// of each contact and the load become the set points (received at
    /// `now_ns`).
    pub(super) fn drain_commands(&mut self, now_ns: u64) {
        for i in 0..self.ports.len() {
            while let Some(c) = self.poll(i) {
                self.apply_command(c, now_ns);
            }
        }
    }

    /// The velocity each contact's next `steps` steps (ending at `at_ns`)
    /// apply: the command, or after the timeout the held or ramped value.
    pub(super) fn apply_timeout(&mut self, at_ns: u64, steps: u64) {
        let (timeout, behaviour) = (
            self.settings.command_timeout_ns,
            self.settings.timeout_behaviour,
        );
        let dv = self.settings.deceleration_m_s2 * self.settings.dt_s * steps as f64;
        let mut any = false;
        for c in &mut self.cmd {
            let age = at_ns.saturating_sub(c.last_velocity_at_ns);
            c.timed_out = age > timeout;
            if !c.timed_out {
                c.applied = c.velocity;
                continue;
            }
            any = true;
            match behaviour {
                TimeoutBehaviour::Hold => c.applied = c.velocity,
                TimeoutBehaviour::RampToZero => {
                    c.applied = if c.applied.abs() <= dv {
                        0.0
                    } else {
                        c.applied - dv * c.applied.signum()
                    };
                }
            }
        }
        if any {
            self.summary.command_timeouts += 1;
        }
    }

    /// The command status of contact `k`'s step about to be published; a
    /// pending rejection is reported once, whatever the solver did.
    pub(super) fn take_command_status(&mut self, k: usize) -> u8 {
        let c = &mut self.cmd[k];
        let status = if c.rejected_pending {
            codes::COMMAND_REJECTED
        } else if c.timed_out {
            codes::COMMAND_TIMED_OUT
        } else if c.fresh {
            codes::COMMAND_FRESH
        } else {
            codes::COMMAND_HELD
        };
        c.rejected_pending = false;
        c.fresh = false;
        status
    }
}
