//! One model step and its outputs: the estimate to every port and the
//! recorder, the film profile, the loop statistics.
//!
//! `Loop`'s fields this file uses: `contacts`, `cmd`, `watches`, `flags`, `velocities`, `loads`, `efforts`, `by_joint`, `settings`, `ports`, `record`, `film_profile`, `live`, `clock`, `stamps`, `temperature_c`, `summary`, `window_compute`, `window_jitter`, `hist_compute`, `hist_jitter`.

use super::Loop;
use crate::config::StepMode;
use crate::link::RecordItem;
use crate::msgs::{EstimateRecord, OutsideEvent, StatisticsRecord};
use crate::physics::Estimate;
use crate::range_watch::RangeFlag;
use std::sync::atomic::Ordering;

impl Loop {
    /// One fixed step of every contact with its applied velocity, stamped
    /// `stamp_ns`, `late_ns` after its deadline.
    pub(super) fn step(&mut self, stamp_ns: u64, late_ns: u64) {
        self.step_contacts(None, stamp_ns, late_ns);
    }

    /// A time jump: `steps` lost periods advanced in one step.
    pub(super) fn jump_time(&mut self, steps: u64, stamp_ns: u64, late_ns: u64) {
        self.step_contacts(Some(self.settings.dt_s * steps as f64), stamp_ns, late_ns);
    }

    fn step_contacts(&mut self, jump_s: Option<f64>, stamp_ns: u64, late_ns: u64) {
        self.apply_parameters(stamp_ns);
        for (k, c) in self.cmd.iter().enumerate() {
            let w = self.watches[k].watch(c.applied, c.load, self.temperature_c);
            self.velocities[k] = w.velocity_m_s;
            self.loads[k] = w.load_n;
            self.flags[k] = w.flag;
        }
        let start = self.clock.now_ns();
        let timing = self.contacts.step(&self.velocities, &self.loads, jump_s);
        let compute = self.clock.now_ns().saturating_sub(start);
        self.summary.steps += 1;
        let several = self.contacts.len() > 1;
        for k in 0..self.contacts.len() {
            let e = self.contacts.estimates()[k];
            // One contact: the step's time is the contact's (the loop's
            // clock: simulated in tests). Several: each its own.
            let own = if several {
                self.contacts.compute_ns()[k]
            } else {
                compute
            };
            self.publish(k, &e, stamp_ns, own, late_ns);
            self.efforts[k] = self.watches[k].published(self.flags[k], self.contacts.effort(k));
        }
        if self.by_joint {
            for p in self.ports.iter_mut() {
                if !p.publish_efforts(stamp_ns, &self.efforts) {
                    self.summary.publish_drops += 1;
                }
            }
        }
        self.summary.slowest_contact = timing.slowest;
        self.summary.slowest_contact_ns = timing.slowest_ns;
        if timing.slowest_ns >= self.summary.window_slowest.1 {
            self.summary.window_slowest = (timing.slowest, timing.slowest_ns);
        }
        self.after_step(stamp_ns, compute, late_ns);
    }

    fn publish(&mut self, k: usize, e: &Estimate, stamp_ns: u64, compute: u64, late_ns: u64) {
        let mut rec = EstimateRecord::from_estimate(e, stamp_ns, compute);
        rec.temperature_c = self.temperature_c;
        rec.command_status = self.take_command_status(k);
        rec.late_ns = late_ns;
        self.watched(k, &mut rec);
        self.summary.status_counts[usize::from(rec.status).min(7)] += 1;
        self.summary.command_status_counts[usize::from(rec.command_status).min(3)] += 1;
        for p in self.ports.iter_mut() {
            if !p.publish_estimate(k, &rec) {
                self.summary.publish_drops += 1;
            }
        }
        if let Some(q) = &self.record {
            let logged_ns = self.logged_ns(stamp_ns);
            if q.push(RecordItem::Estimate {
                record: rec,
                logged_ns,
                contact: u16::try_from(k).expect("at most MAX_CONTACTS contacts"),
            })
            .is_err()
            {
                self.summary.recorder_drops += 1;
            }
        }
        if k == 0 {
            let l = &self.live;
            l.velocity_bits
                .store(rec.velocity_m_s.to_bits(), Ordering::Relaxed);
            l.friction_bits
                .store(rec.friction_force_n.to_bits(), Ordering::Relaxed);
            l.cof_bits.store(rec.cof.to_bits(), Ordering::Relaxed);
            l.h0_bits.store(rec.h0_m.to_bits(), Ordering::Relaxed);
            l.status.store(u64::from(rec.status), Ordering::Relaxed);
        }
    }

    /// Contact `k`'s calibrated-range flag on its record, the friction as
    /// `node.outside_envelope` says, and the count of steps outside.
    fn watched(&mut self, k: usize, rec: &mut EstimateRecord) {
        let flag = self.flags[k];
        rec.calibrated_range = flag.code();
        if let RangeFlag::Outside {
            input,
            value,
            lo,
            hi,
            unit,
        } = flag
        {
            let w = &self.watches[k];
            rec.friction_force_n = w.published(flag, rec.friction_force_n);
            rec.contact_friction_force_n = w.published(flag, rec.contact_friction_force_n);
            self.summary.steps_outside_calibrated_range += 1;
            self.summary.window_outside = Some(OutsideEvent {
                contact: u32::try_from(k).unwrap_or(u32::MAX),
                input,
                value,
                lo,
                hi,
                unit,
            });
        }
    }

    /// Profiles, statistics and live values after a step of every contact.
    fn after_step(&mut self, stamp_ns: u64, compute: u64, late_ns: u64) {
        let n = self.summary.steps;
        if self.settings.film_profile_every_steps > 0
            && n.is_multiple_of(self.settings.film_profile_every_steps)
        {
            if let Some(slot) = self.film_profile.clone() {
                // The first contact's film (the one-contact node's film profile).
                self.contacts.with_solver(0, |solver| {
                    slot.try_write(|d| {
                        d.stamp_ns = stamp_ns;
                        d.dx_m = solver.dx();
                        for (i, f) in solver.field().enumerate() {
                            d.h_m[i] = f.h;
                            d.p_pa[i] = f.p;
                        }
                    })
                });
            }
        }
        self.window_compute.push(compute);
        self.hist_compute.record(compute);
        if self.settings.mode == StepMode::Timer {
            self.window_jitter.push(late_ns);
            self.hist_jitter.record(late_ns);
        }
        if self.settings.statistics_every_steps > 0
            && n.is_multiple_of(self.settings.statistics_every_steps)
        {
            self.publish_statistics(stamp_ns);
        }
        let l = &self.live;
        l.steps.store(n, Ordering::Relaxed);
        l.compute_ns.store(compute, Ordering::Relaxed);
        l.drops.store(
            self.summary.publish_drops + self.summary.recorder_drops,
            Ordering::Relaxed,
        );
    }

    /// The recording's log time of an output stamped `stamp_ns`: the stamp
    /// itself in timer mode (it is the step's wall time), the wall clock in
    /// lockstep (stamps are the sender's).
    fn logged_ns(&self, stamp_ns: u64) -> u64 {
        match self.settings.mode {
            StepMode::Timer => stamp_ns,
            StepMode::Lockstep => self.clock.wall_ns(),
        }
    }

    fn publish_statistics(&mut self, stamp_ns: u64) {
        let mut total = self.summary.clone();
        self.add_port_counters(&mut total);
        let s = StatisticsRecord {
            stamp_ns,
            steps: total.steps,
            deadline_misses: total.deadline_misses,
            catch_up_steps: total.catch_up_steps,
            time_jumps: total.time_jumps,
            clock_jumps: self.stamps.jumps,
            commands_received: total.commands_received,
            commands_applied: total.commands_applied,
            commands_overwritten: total.commands_overwritten,
            commands_rejected: total.commands_rejected,
            command_timeouts: total.command_timeouts,
            publish_drops: total.publish_drops,
            publish_failures: total.publish_failures,
            statistics_not_sent: total.statistics_not_sent,
            recorder_drops: total.recorder_drops,
            recording: self
                .recorder
                .as_ref()
                .map(|c| c.status())
                .unwrap_or_default(),
            compute_time_ns: self.window_compute.percentiles(),
            period_jitter_ns: if self.settings.mode == StepMode::Timer {
                self.window_jitter.percentiles()
            } else {
                [0; 3]
            },
            // Contact steps (one per contact per step) that did not converge.
            steps_not_converged: total.status_counts.iter().sum::<u64>().saturating_sub(
                total.status_counts[usize::from(crate::msgs::estimate_constants::STATUS_CONVERGED)],
            ),
            parameter_updates: total.parameter_updates,
            contacts: u32::try_from(self.contacts.len()).unwrap_or(u32::MAX),
            slowest_contact: u32::try_from(total.window_slowest.0).unwrap_or(u32::MAX),
            slowest_contact_compute_ns: total.window_slowest.1,
            steps_outside_calibrated_range: total.steps_outside_calibrated_range,
            last_outside: total.window_outside,
        };
        self.summary.window_slowest = (0, 0);
        self.summary.window_outside = None;
        self.window_compute.clear();
        self.window_jitter.clear();
        for p in self.ports.iter_mut() {
            if !p.publish_statistics(&s) {
                self.summary.statistics_not_sent += 1;
            }
        }
        if let Some(q) = &self.record {
            let logged_ns = self.logged_ns(stamp_ns);
            if q.push(RecordItem::Statistics {
                record: s,
                logged_ns,
            })
            .is_err()
            {
                self.summary.recorder_drops += 1;
            }
        }
    }
}
