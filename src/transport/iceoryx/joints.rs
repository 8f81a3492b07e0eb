//! Several contacts over iceoryx2: JointState velocities in, per-contact
//! estimates and joint efforts out.
//!
//! A received [`JointStatePayload`] is expanded, by joint name, into one
//! command per configured joint it names ([`joint_commands`]); the
//! commands wait in a fixed buffer and leave one per
//! [`NodePort::poll_command`](crate::transport::NodePort::poll_command).
//! A joint without a velocity (fewer velocities than names) or with a
//! non-finite one is rejected for its contact only, and the first such
//! joint is named in the log.

use super::{err, service, ContactEstimatePayload, EffortsPayload, EstimatePayload};
use super::{IceoryxSpec, JointStatePayload, Sequences, JOINT_NAME_BYTES};
use crate::clock::system_wall_ns;
use crate::link::RecordItem;
use crate::msgs::{Command, EstimateRecord};
use crate::transport::Operation;
use crate::transport::{
    joint_commands, record_input, JointEfforts, JointStateCommand, RecordQueue, SharedCounters,
    TransportError, MAX_CONTACTS,
};
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use std::sync::atomic::Ordering;

/// Depth of the joint-state buffers (a payload is ~4.7 kB).
const JOINT_BUFFER: usize = 256;
/// Depth of the per-contact estimate and effort buffers.
const OUTPUT_BUFFER: usize = 1024;

/// The node's joint services.
pub(super) struct JointNode {
    joints: Vec<String>,
    joint_state: Subscriber<ipc::Service, JointStatePayload, ()>,
    efforts: Publisher<ipc::Service, EffortsPayload, ()>,
    contact_estimate: Publisher<ipc::Service, ContactEstimatePayload, ()>,
    sequences: Sequences,
    /// Commands of the latest JointState not yet taken by the loop.
    pending: [Option<Command>; MAX_CONTACTS],
    next: usize,
    warned: bool,
}

impl JointNode {
    pub(super) fn open(n: &Node<ipc::Service>, spec: &IceoryxSpec) -> Result<Self, TransportError> {
        let js = service::<JointStatePayload>(n, &spec.joint_state, JOINT_BUFFER)?;
        let ef = service::<EffortsPayload>(n, &spec.efforts, OUTPUT_BUFFER)?;
        let ce = service::<ContactEstimatePayload>(n, &spec.contact_estimate, OUTPUT_BUFFER)?;
        Ok(Self {
            joints: spec.plan.joints().to_vec(),
            joint_state: js
                .subscriber_builder()
                .buffer_size(JOINT_BUFFER)
                .create()
                .map_err(|e| err(Operation::Open, "create the joint-state subscriber", e))?,
            efforts: ef
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the efforts publisher", e))?,
            contact_estimate: ce
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the contact estimate publisher", e))?,
            sequences: Sequences::new(),
            pending: [None; MAX_CONTACTS],
            next: MAX_CONTACTS,
            warned: false,
        })
    }

    /// The next joint command: from the JointState being expanded, else
    /// from the next received one.
    pub(super) fn poll(
        &mut self,
        counters: &SharedCounters,
        record: &RecordQueue,
    ) -> Result<Option<Command>, TransportError> {
        loop {
            while self.next < MAX_CONTACTS {
                let c = self.pending[self.next].take();
                self.next += 1;
                if let Some(c) = c {
                    return Ok(Some(c));
                }
            }
            let Some(s) = self
                .joint_state
                .receive()
                .map_err(|e| err(Operation::Receive, "receive a joint state", e))?
            else {
                return Ok(None);
            };
            let lost = self
                .sequences
                .lost_before(s.header().publisher_id(), s.sequence);
            self.expand(&s, counters, record, lost);
        }
    }

    fn expand(
        &mut self,
        s: &JointStatePayload,
        counters: &SharedCounters,
        record: &RecordQueue,
        lost: u64,
    ) {
        let count = (s.name_count as usize).min(MAX_CONTACTS);
        let velocities = &s.velocity[..(s.velocity_count as usize).min(MAX_CONTACTS)];
        let (pending, joints) = (&mut self.pending, &self.joints);
        let mut k = 0;
        let mut first_bad: Option<&str> = None;
        let names = (0..count).map(|i| s.name(i));
        joint_commands(joints, s.stamp_ns, names, velocities, |c, name| {
            if !c.value.is_finite() && first_bad.is_none() {
                first_bad = Some(name);
            }
            pending[k] = Some(c);
            k += 1;
        });
        if lost > 0 {
            // Whole JointStates overwritten in the buffer: one command per
            // configured joint each (what they would have carried).
            let per = lost.saturating_mul(k.max(1) as u64);
            counters.received.fetch_add(per, Ordering::Relaxed);
            counters.overwritten.fetch_add(per, Ordering::Relaxed);
        }
        counters.received.fetch_add(k as u64, Ordering::Relaxed);
        if record.is_some() {
            for c in pending[..k].iter().flatten() {
                let item = RecordItem::Command {
                    command: *c,
                    received_ns: system_wall_ns(),
                };
                record_input(record, item, counters);
            }
        }
        if let Some(name) = first_bad {
            if !self.warned {
                self.warned = true;
                tracing::warn!(
                    "iceoryx2: a JointState without a finite velocity for joint `{name}` \
                     ({count} names, {} velocities): that joint's command is rejected \
                     (further ones are counted, not logged)",
                    velocities.len()
                );
            }
        }
        self.next = 0;
    }

    pub(super) fn publish_estimate(&self, contact: usize, e: &EstimateRecord) -> bool {
        self.contact_estimate
            .send_copy(ContactEstimatePayload {
                contact: u32::try_from(contact).unwrap_or(u32::MAX),
                reserved: 0,
                estimate: EstimatePayload::from(e),
            })
            .is_ok()
    }

    pub(super) fn publish_efforts(&self, stamp_ns: u64, efforts: &[f64]) -> bool {
        let e = JointEfforts::new(stamp_ns, efforts);
        self.efforts
            .send_copy(EffortsPayload {
                stamp_ns,
                len: e.len as u32,
                reserved: 0,
                effort: e.effort,
            })
            .is_ok()
    }
}

/// A peer's joint services.
pub(super) struct JointPeer {
    joint_state: Publisher<ipc::Service, JointStatePayload, ()>,
    efforts: Subscriber<ipc::Service, EffortsPayload, ()>,
    contact_estimate: Subscriber<ipc::Service, ContactEstimatePayload, ()>,
    sequence: u64,
}

impl JointPeer {
    pub(super) fn open(n: &Node<ipc::Service>, spec: &IceoryxSpec) -> Result<Self, TransportError> {
        let js = service::<JointStatePayload>(n, &spec.joint_state, JOINT_BUFFER)?;
        let ef = service::<EffortsPayload>(n, &spec.efforts, OUTPUT_BUFFER)?;
        let ce = service::<ContactEstimatePayload>(n, &spec.contact_estimate, OUTPUT_BUFFER)?;
        Ok(Self {
            joint_state: js
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the joint-state publisher", e))?,
            efforts: ef
                .subscriber_builder()
                .buffer_size(OUTPUT_BUFFER)
                .create()
                .map_err(|e| err(Operation::Open, "create the efforts subscriber", e))?,
            contact_estimate: ce
                .subscriber_builder()
                .buffer_size(OUTPUT_BUFFER)
                .create()
                .map_err(|e| err(Operation::Open, "create the contact estimate subscriber", e))?,
            sequence: 0,
        })
    }

    /// Send a JointState; more than [`MAX_CONTACTS`] joints or a name
    /// longer than [`JOINT_NAME_BYTES`] is an error naming it.
    pub(super) fn send(&mut self, js: &JointStateCommand) -> Result<(), TransportError> {
        let too_many = js.name.len().max(js.velocity.len()) > MAX_CONTACTS;
        if too_many {
            return Err(TransportError::TooLarge {
                backend: super::NAME,
                operation: "send a JointState",
                reason: format!(
                    "{} names and {} velocities: at most {MAX_CONTACTS} joints",
                    js.name.len(),
                    js.velocity.len()
                ),
            });
        }
        if let Some(long) = js.name.iter().find(|n| n.len() > JOINT_NAME_BYTES) {
            return Err(TransportError::TooLarge {
                backend: super::NAME,
                operation: "send a JointState",
                reason: format!("joint name `{long}` is longer than {JOINT_NAME_BYTES} bytes"),
            });
        }
        self.sequence += 1;
        let sample = self
            .joint_state
            .loan_uninit()
            .map_err(|e| err(Operation::Send, "loan a joint-state sample", e))?;
        let mut p = JointStatePayload {
            stamp_ns: js.stamp_ns,
            sequence: self.sequence,
            name_count: js.name.len() as u32,
            velocity_count: js.velocity.len() as u32,
            name: [[0; JOINT_NAME_BYTES]; MAX_CONTACTS],
            name_len: [0; MAX_CONTACTS],
            velocity: [0.0; MAX_CONTACTS],
        };
        for (i, n) in js.name.iter().enumerate() {
            p.name[i][..n.len()].copy_from_slice(n.as_bytes());
            p.name_len[i] = n.len() as u8;
        }
        p.velocity[..js.velocity.len()].copy_from_slice(&js.velocity);
        sample
            .write_payload(p)
            .send()
            .map_err(|e| err(Operation::Send, "send a joint state", e))?;
        Ok(())
    }

    pub(super) fn try_recv_efforts(&mut self) -> Result<Option<JointEfforts>, TransportError> {
        Ok(self
            .efforts
            .receive()
            .map_err(|e| err(Operation::Receive, "receive joint efforts", e))?
            .map(|s| {
                let n = (s.len as usize).min(MAX_CONTACTS);
                JointEfforts::new(s.stamp_ns, &s.effort[..n])
            }))
    }

    pub(super) fn try_recv_contact(
        &mut self,
    ) -> Result<Option<(usize, EstimateRecord)>, TransportError> {
        Ok(self
            .contact_estimate
            .receive()
            .map_err(|e| err(Operation::Receive, "receive a contact estimate", e))?
            .map(|s| (s.contact as usize, EstimateRecord::from(&s.estimate))))
    }
}
