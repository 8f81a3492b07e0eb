//! What the loop shares with the threads around it, below `node/`,
//! `transport/` and `record/`: the settings the loop reads every step
//! ([`LoopSettings`], a pure function of the configuration), the latest
//! film profile ([`FilmProfileSlot`], written by the loop without allocating) and the
//! hand-over of live parameter changes ([`ParameterUpdate`] prepared off the
//! loop, [`ParameterChannel`] to the loop and back, [`ParameterIo`] for a
//! transport that serves parameters). The loop applies an update between two
//! steps without blocking or allocating and hands it back stamped with the
//! first step that used it (for `/parameter_events`, the recording and
//! replay). Also what the loop hands to the recorder ([`RecordItem`], through
//! a preallocated queue), the recorder's counters the loop reports
//! ([`RecorderCounters`]) and the loop's live values for a status line
//! ([`LiveStatus`]).

use crate::config::parameters::SetRefusal;
use crate::config::{Config, StepMode, TimeoutBehaviour};
use crate::msgs::ros_interfaces::ParameterValue;
use crate::msgs::{Command, EstimateRecord, Note, RawSample, RecordingStatus, StatisticsRecord};
use crate::physics::{PreparedModel, SetupError, Solver};
use crossbeam_queue::ArrayQueue;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Settings the loop reads every step (from the configuration).
#[derive(Debug, Clone, PartialEq)]
pub struct LoopSettings {
    /// Timer or lockstep (`node.step_mode`).
    pub mode: StepMode,
    /// The step, s.
    pub dt_s: f64,
    /// The step in integer nanoseconds (validated to be whole).
    pub dt_ns: u64,
    /// `node.command_timeout_s`, ns.
    pub command_timeout_ns: u64,
    /// What a timed-out command does (`node.timeout_behaviour`).
    pub timeout_behaviour: TimeoutBehaviour,
    /// What a contact publishes outside its calibrated range
    /// (`node.outside_envelope`).
    pub outside_envelope: crate::config::OutsideEnvelope,
    /// The ramp to zero after a command timeout, m/s².
    pub deceleration_m_s2: f64,
    /// The velocity and load commands accepted.
    pub limits: crate::config::InputLimits,
    /// Steps between film-profile and statistics publications (0 = never).
    pub film_profile_every_steps: u64,
    /// Steps between LoopStatistics publications (0 = never).
    pub statistics_every_steps: u64,
    /// Lockstep: busy-wait this long for the next command before sleeping, ns.
    pub lockstep_spin_ns: u64,
    /// Timer mode: busy-wait before each deadline, ns.
    pub timer_spin_ns: u64,
    /// Lost steps caught up one by one before a time jump (the lost time
    /// advanced in one step).
    pub max_catch_up_steps: u64,
}

/// Seconds to whole nanoseconds (saturating; config values are validated).
pub(crate) fn secs_to_ns(s: f64) -> u64 {
    let ns = (s * 1e9).round();
    if ns <= 0.0 {
        0
    } else if ns >= u64::MAX as f64 {
        u64::MAX
    } else {
        ns as u64
    }
}

impl LoopSettings {
    /// What the loop takes from `c` (a pure function of the configuration).
    pub fn from_config(c: &Config) -> Self {
        let dt = c.solver.dt_s;
        let dt_ns = secs_to_ns(dt).max(1);
        let every = |hz: f64| {
            if hz > 0.0 {
                ((1.0 / hz) / dt).round().max(1.0) as u64
            } else {
                0
            }
        };
        Self {
            mode: c.node.step_mode,
            dt_s: dt,
            dt_ns,
            command_timeout_ns: secs_to_ns(c.node.command_timeout_s),
            timeout_behaviour: c.node.timeout_behaviour,
            outside_envelope: c.node.outside_envelope,
            deceleration_m_s2: c.node.timeout_deceleration_m_s2,
            limits: crate::config::InputLimits::of(c),
            film_profile_every_steps: every(c.node.profile_rate_hz),
            statistics_every_steps: every(c.node.statistics_rate_hz),
            lockstep_spin_ns: c.node.lockstep_spin_us.saturating_mul(1000),
            timer_spin_ns: c.node.timer_spin_us.saturating_mul(1000),
            max_catch_up_steps: secs_to_ns(c.node.max_catch_up_s) / dt_ns,
        }
    }
}

/// A validated change, prepared for the loop.
pub struct ParameterUpdate {
    /// The whole configuration after the change.
    pub config: Config,
    /// What changed: (name, new value).
    pub changed: Vec<(String, ParameterValue)>,
    pub(crate) settings: LoopSettings,
    /// One per contact, in the configuration's order.
    pub(crate) contacts: Vec<ContactUpdate>,
    /// Set by the loop: the stamp of the first step that used the change.
    pub applied_stamp_ns: u64,
}

/// One contact's part of a [`ParameterUpdate`].
pub(crate) struct ContactUpdate {
    pub(crate) model: PreparedModel,
    pub(crate) viscosity: crate::config::ViscosityLaw,
    /// The new held load, when the contact's `contact.load_n` changed.
    pub(crate) load: Option<f64>,
}

impl ParameterUpdate {
    /// Prepare `new` (the result of [`crate::config::parameters::apply_set`] on `old`) for the loop:
    /// the model's tables are built here.
    pub fn prepare(
        old: &Config,
        new: Config,
        changed: Vec<(String, ParameterValue)>,
    ) -> Result<Box<Self>, SetupError> {
        let before = old.resolved_contacts();
        let contacts = new
            .resolved_contacts()
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let n = &c.config;
                let load_was = before.get(i).map(|b| b.config.contact.load_n);
                Ok(ContactUpdate {
                    model: Solver::prepare_model(&n.model(), &n.solver_settings())?,
                    viscosity: crate::config::ViscosityLaw::of(n),
                    load: (load_was != Some(n.contact.load_n)).then_some(n.contact.load_n),
                })
            })
            .collect::<Result<Vec<_>, SetupError>>()?;
        Ok(Box::new(Self {
            settings: LoopSettings::from_config(&new),
            contacts,
            changed,
            config: new,
            applied_stamp_ns: 0,
        }))
    }
}

/// What a transport that serves parameters needs from the node.
#[derive(Clone)]
pub struct ParameterIo {
    /// The configuration the node runs with.
    pub config: Config,
    /// Where the validated updates go.
    pub channel: std::sync::Arc<ParameterChannel>,
}

/// Capacity of the channel: changes in flight (submitted, not yet taken
/// back after the loop applied them).
pub const IN_FLIGHT: usize = 8;

/// Between the parameter service and the loop.
pub struct ParameterChannel {
    pub(crate) pending: ArrayQueue<Box<ParameterUpdate>>,
    pub(crate) applied: ArrayQueue<Box<ParameterUpdate>>,
    in_flight: AtomicUsize,
}

impl Default for ParameterChannel {
    fn default() -> Self {
        Self {
            pending: ArrayQueue::new(IN_FLIGHT),
            applied: ArrayQueue::new(IN_FLIGHT),
            in_flight: AtomicUsize::new(0),
        }
    }
}

impl ParameterChannel {
    /// Hand a prepared change to the loop; refused when [`IN_FLIGHT`]
    /// changes wait (the loop is not stepping, or nobody takes them back).
    pub fn submit(&self, u: Box<ParameterUpdate>) -> Result<(), SetRefusal> {
        if self.in_flight.fetch_add(1, Ordering::AcqRel) >= IN_FLIGHT {
            self.in_flight.fetch_sub(1, Ordering::AcqRel);
            return Err(SetRefusal::Busy);
        }
        self.pending.push(u).map_err(|_| {
            self.in_flight.fetch_sub(1, Ordering::AcqRel);
            SetRefusal::Busy
        })
    }

    /// A change the loop has applied (stamped), if any.
    pub fn take_applied(&self) -> Option<Box<ParameterUpdate>> {
        let u = self.applied.pop()?;
        self.in_flight.fetch_sub(1, Ordering::AcqRel);
        Some(u)
    }
}

/// The latest film profile, shared between the loop (writer) and the I/O
/// threads (readers) without allocation on the loop: the loop copies into a
/// preallocated buffer under a `try_lock` and bumps the sequence number.
#[derive(Debug)]
pub struct FilmProfileSlot {
    seq: AtomicU64,
    data: Mutex<FilmProfileData>,
}

/// Contents of a [`FilmProfileSlot`].
#[derive(Debug, Clone, Default)]
pub struct FilmProfileData {
    /// The step the film profile belongs to, ns.
    pub stamp_ns: u64,
    /// Cell width Δx, m.
    pub dx_m: f64,
    /// Gap h per cell, m.
    pub h_m: Vec<f64>,
    /// Pressure per cell (absolute), Pa.
    pub p_pa: Vec<f64>,
}

impl FilmProfileSlot {
    /// An empty slot for film profiles of `cells` cells (allocated here, once).
    pub fn new(cells: usize) -> Arc<Self> {
        Arc::new(Self {
            seq: AtomicU64::new(0),
            data: Mutex::new(FilmProfileData {
                stamp_ns: 0,
                dx_m: 0.0,
                h_m: vec![0.0; cells],
                p_pa: vec![0.0; cells],
            }),
        })
    }

    /// Fill the slot (non-blocking): false when a reader holds it.
    pub fn try_write(&self, f: impl FnOnce(&mut FilmProfileData)) -> bool {
        match self.data.try_lock() {
            Ok(mut d) => {
                f(&mut d);
                self.seq.fetch_add(1, Ordering::Release);
                true
            }
            Err(_) => false,
        }
    }

    /// The film profile, if newer than `seen` (updates `seen`).
    pub fn read_if_newer(&self, seen: &mut u64) -> Option<FilmProfileData> {
        let s = self.seq.load(Ordering::Acquire);
        if s == *seen {
            return None;
        }
        let d = self.data.lock().ok()?.clone();
        *seen = s;
        Some(d)
    }
}

/// What the loop and the transports hand to the recorder.
// Items travel through preallocated lock-free queues: boxing the larger
// variants would allocate on the loop.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum RecordItem {
    /// A received command (transports without a serialized form: memory,
    /// iceoryx2) and when it arrived (wall clock, ns); recorded as the
    /// configured command type.
    Command {
        /// The command as the loop takes it.
        command: Command,
        /// When it arrived (wall clock), ns.
        received_ns: u64,
    },
    /// A received ROS 2 sample, recorded byte for byte.
    Raw(RawSample),
    /// An estimate of contact `contact` (0 with one contact) and when it
    /// was published (wall clock, ns).
    Estimate {
        /// The estimate as published.
        record: EstimateRecord,
        /// When it was published (wall clock), ns.
        logged_ns: u64,
        /// The contact (0 with one contact).
        contact: u16,
    },
    /// Loop statistics and when they were published (wall clock, ns).
    Statistics {
        /// The statistics as published.
        record: StatisticsRecord,
        /// When they were published (wall clock), ns.
        logged_ns: u64,
    },
    /// An `rcl_interfaces/msg/ParameterEvent` (CDR with its encapsulation
    /// header) stamped with the first step that used the new values.
    ParameterEvent {
        /// The event, CDR with its encapsulation header.
        cdr: Vec<u8>,
        /// The first step that used the new values, ns.
        stamp_ns: u64,
        /// When it was published (wall clock), ns.
        logged_ns: u64,
    },
}

/// Counters the recorder shares with the loop (statistics) and the report.
#[derive(Debug, Default)]
pub struct RecorderCounters {
    /// Messages written.
    pub messages: AtomicU64,
    /// Files started (1 without splitting).
    pub files: AtomicU64,
    /// Files deleted to keep to the budget.
    pub files_deleted: AtomicU64,
    /// Messages lost because writing had failed (until it resumed).
    pub lost: AtomicU64,
    /// Snapshots written.
    pub snapshots: AtomicU64,
    /// The latest snapshot file and its span, s.
    pub last_snapshot: Mutex<(Note, f64)>,
}

impl RecorderCounters {
    /// A snapshot of the counters (never blocks: a busy snapshot slot
    /// reports an empty note).
    pub fn status(&self) -> RecordingStatus {
        let l = |a: &AtomicU64| a.load(Ordering::Relaxed);
        let (last_snapshot, last_snapshot_span_s) = self
            .last_snapshot
            .try_lock()
            .map(|g| *g)
            .unwrap_or_default();
        RecordingStatus {
            files: l(&self.files),
            files_deleted: l(&self.files_deleted),
            lost: l(&self.lost),
            snapshots: l(&self.snapshots),
            last_snapshot,
            last_snapshot_span_s,
        }
    }
}

/// Live values for a status line (written by the loop, read anywhere).
#[derive(Debug, Default)]
pub struct LiveStatus {
    /// Steps taken.
    pub steps: AtomicU64,
    /// Steps that ended after their deadline.
    pub deadline_misses: AtomicU64,
    /// Commands applied.
    pub commands_applied: AtomicU64,
    /// Commands rejected (out of the envelope, non-finite, wrong layout).
    pub commands_rejected: AtomicU64,
    /// Outputs dropped: publications and recorder items together.
    pub drops: AtomicU64,
    /// The last step's velocity, m/s (f64 bits).
    pub velocity_bits: AtomicU64,
    /// The last step's friction force, N (f64 bits).
    pub friction_bits: AtomicU64,
    /// The last step's coefficient of friction (f64 bits).
    pub cof_bits: AtomicU64,
    /// The last step's film thickness h0, m (f64 bits).
    pub h0_bits: AtomicU64,
    /// The last step's compute time, ns.
    pub compute_ns: AtomicU64,
    /// The last step's solver status code (see `msgs::status_name`).
    pub status: AtomicU64,
}

impl LiveStatus {
    /// The f64 stored (as its bits) in one of the `*_bits` fields.
    pub fn load_f64(v: &AtomicU64) -> f64 {
        f64::from_bits(v.load(Ordering::Relaxed))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::parameters::SetRefusal;

    #[test]
    fn the_channel_bounds_changes_in_flight_and_hands_them_back() {
        let c = Config::default();
        let ch = ParameterChannel::default();
        let mut small = c.clone();
        small.solver.cells = 16;
        for _ in 0..IN_FLIGHT {
            let u = ParameterUpdate::prepare(&small, small.clone(), vec![]).unwrap();
            ch.submit(u).unwrap();
        }
        let u = ParameterUpdate::prepare(&small, small.clone(), vec![]).unwrap();
        assert_eq!(ch.submit(u).unwrap_err(), SetRefusal::Busy);
        assert!(ch.take_applied().is_none(), "nothing applied yet");
    }
}
