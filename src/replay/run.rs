//! Running a prepared replay: the node's own loop in lockstep, fed one
//! command at a time, with the recorded parameter changes re-applied.

use super::oracle;
use super::{InputMode, Oracle, ParameterChange, PreparedReplay, ReplayError};
use crate::config::Config;
use crate::link::LiveStatus;
use crate::msgs::{CommandKind, EstimateRecord};
use crate::node::Loop;
use crate::physics::Estimate;
use crate::transport::memory::{MemoryPeer, MemoryQueues};
use crate::transport::PeerPort;
use std::sync::Arc;

/// The replayed estimates.
#[derive(Debug, Clone)]
pub struct ReplayResult {
    /// One per step: the core estimate and the published record (the first
    /// contact's when there are several).
    pub estimates: Vec<(Estimate, EstimateRecord)>,
    /// Commands the loop rejected.
    pub commands_rejected: u64,
    /// Contact steps whose input lay outside the contact's calibrated range
    /// (counted as the node counts them).
    pub steps_outside_calibrated_range: u64,
    /// Every contact's verdict together (all identical, deviations of all).
    pub oracle: Option<Oracle>,
    /// Several contacts: each contact's name, estimates and oracle.
    pub contacts: Vec<ContactReplay>,
}

/// One contact of a replay of several.
#[derive(Debug, Clone)]
pub struct ContactReplay {
    /// The contact's name.
    pub name: String,
    /// Its estimates, one per step.
    pub estimates: Vec<(Estimate, EstimateRecord)>,
    /// Its determinism verdict (recorded contacts only).
    pub oracle: Option<Oracle>,
}

/// The recorded parameter changes, re-applied before the step that used
/// them.
struct Changes<'p> {
    current: Config,
    declared: Vec<crate::config::parameters::Declared>,
    pending: std::iter::Peekable<std::slice::Iter<'p, ParameterChange>>,
}

impl<'p> Changes<'p> {
    fn new(p: &'p PreparedReplay) -> Self {
        Self {
            current: p.config.clone(),
            declared: crate::config::parameters::declare(&p.config),
            pending: p.parameter_changes.iter().peekable(),
        }
    }

    /// Apply every change stamped at or before `stamp_ns` to the loop.
    fn apply_up_to(&mut self, l: &mut Loop, stamp_ns: u64) -> Result<(), ReplayError> {
        while let Some(ch) = self.pending.next_if(|ch| ch.stamp_ns <= stamp_ns) {
            let next =
                crate::config::parameters::apply_set(&self.current, &self.declared, &ch.changed)
                    .map_err(|e| ReplayError::Parameters {
                        stamp_ns: ch.stamp_ns,
                        message: e.to_string(),
                    })?;
            let mut u = crate::link::ParameterUpdate::prepare(
                &self.current,
                next.clone(),
                ch.changed.clone(),
            )?;
            l.apply_update(&mut u);
            self.current = next;
        }
        Ok(())
    }
}

/// The estimates as they come out of the loop: the first contact's, and
/// each contact's with several.
struct Collected {
    first: Vec<(Estimate, EstimateRecord)>,
    per_contact: Vec<Vec<(Estimate, EstimateRecord)>>,
}

impl Collected {
    /// Take what the loop published for the last command.
    fn take(
        &mut self,
        l: &Loop,
        peer: &mut MemoryPeer,
        on_step: &mut dyn FnMut(&Estimate, &EstimateRecord, u16),
    ) {
        if self.per_contact.is_empty() {
            if let Ok(Some(rec)) = peer.try_recv() {
                let e = l.contacts().estimates()[0];
                on_step(&e, &rec, 0);
                self.first.push((e, rec));
            }
            return;
        }
        while let Ok(Some((i, rec))) = peer.try_recv_contact() {
            let e = l.contacts().estimates()[i];
            let contact = u16::try_from(i).expect("at most MAX_CONTACTS contacts");
            on_step(&e, &rec, contact);
            if i == 0 {
                self.first.push((e, rec));
            }
            self.per_contact[i].push((e, rec));
        }
        while let Ok(Some(_)) = peer.try_recv_efforts() {}
    }
}

/// The determinism verdicts: each contact's, and all together.
fn verdicts(
    p: &PreparedReplay,
    cfg: &Config,
    first: &[(Estimate, EstimateRecord)],
    per_contact: Vec<Vec<(Estimate, EstimateRecord)>>,
) -> (Option<Oracle>, Vec<ContactReplay>) {
    let contacts: Vec<ContactReplay> = cfg
        .contacts
        .0
        .iter()
        .zip(per_contact)
        .enumerate()
        .map(|(k, (c, estimates))| ContactReplay {
            name: c.name.clone(),
            oracle: p
                .recorded_contacts
                .get(k)
                .map(|(_, recorded)| oracle::compare(&estimates, recorded)),
            estimates,
        })
        .collect();
    let oracle = match &p.mode {
        InputMode::RecordedEstimates { .. } => Some(oracle::compare(first, &p.recorded)),
        InputMode::RecordedContacts { .. } => Some(oracle::combine(
            contacts.iter().filter_map(|c| c.oracle.as_ref()),
        )),
        InputMode::Topics { .. } | InputMode::JointStates { .. } => None,
    };
    (oracle, contacts)
}

/// Run the model over the prepared input; `progress(done, total)` now and
/// then, `on_step` after every step of every contact (with the contact's
/// index; e.g. [`super::OutputStream::push`]).
pub fn run(
    p: &PreparedReplay,
    progress: &mut dyn FnMut(usize, usize) -> Result<(), crate::interrupt::Interrupted>,
    on_step: &mut dyn FnMut(&Estimate, &EstimateRecord, u16),
) -> Result<ReplayResult, ReplayError> {
    let mut cfg = p.config.clone();
    cfg.node.step_mode = crate::config::StepMode::Lockstep;
    let plan = cfg.output_plan();
    let joints = plan.joints();
    let by_joint = plan.by_joint();
    let link = MemoryQueues::new(16).for_plan(&plan);
    let mut peer = link.peer();
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )?;
    let mut out = Collected {
        first: Vec::with_capacity(p.commands.len()),
        per_contact: if by_joint {
            vec![Vec::new(); joints.len()]
        } else {
            Vec::new()
        },
    };
    let total = p.commands.len();
    let mut changes = Changes::new(p);
    for (k, c) in p.commands.iter().enumerate() {
        if c.kind == CommandKind::Velocity {
            changes.apply_up_to(&mut l, c.stamp_ns)?;
        }
        l.feed(*c);
        out.take(&l, &mut peer, on_step);
        if k % 4096 == 0 {
            progress(k, total)?;
        }
    }
    progress(total, total)?;
    let (oracle, contacts) = verdicts(p, &cfg, &out.first, out.per_contact);
    Ok(ReplayResult {
        estimates: out.first,
        commands_rejected: l.summary().commands_rejected,
        steps_outside_calibrated_range: l.summary().steps_outside_calibrated_range,
        oracle,
        contacts,
    })
}
