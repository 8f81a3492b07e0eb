//! Timer mode: one step per period against absolute deadlines, catching up
//! the steps of a late wake-up so that model time stays wall time.
//!
//! `Loop`'s fields this file uses: `settings`, `live`, `clock`, `stamps`, `summary`, `started_ns`, `first_step`.

use super::Loop;
use std::sync::atomic::{AtomicBool, Ordering};

impl Loop {
    pub(super) fn run_timer(&mut self, stop: &AtomicBool, duration_ns: Option<u64>) {
        let dt = self.settings.dt_ns;
        let end = duration_ns.map(|d| self.started_ns.saturating_add(d));
        // Steps taken so far; step k + 1 is due at t0 + (k + 1)·Δt.
        let mut k: u64 = self.first_step;
        let t0 = self.started_ns.saturating_sub(k.saturating_mul(dt));
        while let Some(due) = k
            .checked_add(1)
            .and_then(|n| n.checked_mul(dt))
            .and_then(|x| t0.checked_add(x))
        {
            if end.is_some_and(|e| due > e) || stop.load(Ordering::Relaxed) {
                break;
            }
            if self.settings.timer_spin_ns > 0 {
                self.clock
                    .sleep_until_ns(due.saturating_sub(self.settings.timer_spin_ns));
                self.clock.spin_until_ns(due);
            } else {
                self.clock.sleep_until_ns(due);
            }
            let woke = self.clock.now_ns();
            let late = woke.saturating_sub(due);
            if k == self.first_step {
                // Anchor the stamps at the first wake-up: an external clock
                // (/clock) has no time at all before its first message.
                self.stamps = crate::clock::WallStamps::new(self.clock.as_ref());
            }
            if self.stamps.check(self.clock.as_ref()) {
                tracing::warn!("the wall clock jumped; stamps stay monotonic");
            }
            self.drain_commands(woke);
            if late / dt > self.settings.max_catch_up_steps {
                // Too far behind to catch up step by step: advance the lost
                // time (to the last deadline that has passed) in one step.
                let last_due = (woke - t0) / dt;
                let lost = last_due - k;
                let due_last = t0 + last_due * dt;
                self.apply_timeout(due_last, lost);
                let stamp = self.stamps.stamp(due_last);
                self.summary.time_jumps += 1;
                self.jump_time(lost, stamp, woke.saturating_sub(due_last));
                k = last_due;
            } else {
                self.apply_timeout(due, 1);
                if late >= dt {
                    self.summary.catch_up_steps += 1;
                }
                let stamp = self.stamps.stamp(due);
                self.step(stamp, late);
                k += 1;
            }
            let done = self.clock.now_ns();
            if done > t0.saturating_add(k.saturating_add(1).saturating_mul(dt)) {
                self.summary.deadline_misses += 1;
                self.live.deadline_misses.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}
