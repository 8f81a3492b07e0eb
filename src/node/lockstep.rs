//! Lockstep mode: one step per velocity command, stamped with the
//! command's stamp; and [`Loop::feed`], the same path driven directly
//! (replay).
//!
//! `Loop`'s fields this file uses: `cmd`, `settings`, `ports`, `live`, `clock`, `last_stamp`, `summary`, `started_ns`.

use super::Loop;
use crate::msgs::{Command, CommandKind};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

impl Loop {
    /// Apply one command as lockstep mode does: a velocity command steps the
    /// model unless its stamp is not newer than the last one; a load command
    /// updates the load.
    pub fn feed(&mut self, c: Command) {
        self.lockstep_command(c);
    }

    /// Lockstep: process every command pending on the ports once; returns
    /// how many there were.
    pub fn poll_once(&mut self) -> usize {
        let mut n = 0;
        for i in 0..self.ports.len() {
            while let Some(c) = self.poll(i) {
                n += 1;
                self.lockstep_command(c);
            }
        }
        n
    }

    pub(super) fn run_lockstep(&mut self, stop: &AtomicBool, duration_ns: Option<u64>) {
        let end = duration_ns.map(|d| self.started_ns.saturating_add(d));
        let mut last_command = self.clock.now_ns();
        while !stop.load(Ordering::Relaxed) && end.is_none_or(|e| self.clock.now_ns() < e) {
            let any = self.poll_once() > 0;
            let now = self.clock.now_ns();
            if any {
                last_command = now;
            } else if now.saturating_sub(last_command) < self.settings.lockstep_spin_ns {
                std::hint::spin_loop();
            } else {
                let wait = Duration::from_millis(if self.ports.len() == 1 { 20 } else { 1 });
                if self.ports[0].wait_for_command(wait).is_err() {
                    self.summary.transport_errors += 1;
                }
            }
        }
    }

    fn lockstep_command(&mut self, c: Command) {
        let Some(k) = self.velocity_contact(c.kind) else {
            // Load and temperature: set points for the next step.
            let now = self.clock.now_ns();
            self.apply_command(c, now);
            return;
        };
        let last = match c.kind {
            CommandKind::JointVelocity { last, .. } => last,
            _ => true,
        };
        // A JointState steps every contact once, on its last joint; its
        // stamp orders the messages.
        if last && self.last_stamp.is_some_and(|s| c.stamp_ns <= s) {
            // Duplicate or out of order: counted, no step.
            self.summary.commands_rejected += 1;
            self.live.commands_rejected.fetch_add(1, Ordering::Relaxed);
            return;
        }
        let now = self.clock.now_ns();
        let v = self.contact_speed(c.kind, k, c.value);
        self.velocity_command(k, v, now);
        if last {
            self.last_stamp = Some(c.stamp_ns);
            for cmd in &mut self.cmd {
                cmd.timed_out = false;
                cmd.applied = cmd.velocity;
            }
            self.step(c.stamp_ns, 0);
        }
    }
}
