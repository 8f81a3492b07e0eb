//! The node's side of iceoryx2: subscribers for the commands (gaps in each
//! publisher's sequence counted as overwritten), publishers for estimates
//! and loop statistics, the listener that wakes a lockstep loop.

use super::joints::JointNode;
use super::*;
use crate::clock::system_wall_ns;
use crate::link::RecordItem;
use crate::msgs::{Command, CommandKind, EstimateRecord, StatisticsRecord};
use crate::transport::Operation;
use crate::transport::{
    record_input, NodePort, PortCounters, RecordQueue, SharedCounters, TransportError,
};
use iceoryx2::prelude::*;
use std::sync::atomic::Ordering;
use std::time::Duration;

type CommandSubscriber = iceoryx2::port::subscriber::Subscriber<ipc::Service, CommandPayload, ()>;

/// The node's side.
pub struct IceoryxNode {
    _node: Node<ipc::Service>,
    velocity: CommandSubscriber,
    load: CommandSubscriber,
    temperature: CommandSubscriber,
    estimate: iceoryx2::port::publisher::Publisher<ipc::Service, EstimatePayload, ()>,
    statistics: iceoryx2::port::publisher::Publisher<ipc::Service, StatisticsPayload, ()>,
    listener: iceoryx2::port::listener::Listener<ipc::Service>,
    velocity_sequences: Sequences,
    load_sequences: Sequences,
    temperature_sequences: Sequences,
    record: RecordQueue,
    counters: SharedCounters,
    /// Several contacts: the joint services.
    joints: Option<JointNode>,
}

impl IceoryxNode {
    /// Open the node side: subscribers for the commands, publishers for the outputs.
    pub fn open(spec: &IceoryxSpec, record: RecordQueue) -> Result<Self, TransportError> {
        let n = node()?;
        let v = service::<CommandPayload>(&n, &spec.velocity, COMMAND_BUFFER)?;
        let l = service::<CommandPayload>(&n, &spec.load, COMMAND_BUFFER)?;
        let tp = service::<CommandPayload>(&n, &spec.temperature, COMMAND_BUFFER)?;
        let e = service::<EstimatePayload>(&n, &spec.estimate, ESTIMATE_BUFFER)?;
        let st = service::<StatisticsPayload>(&n, &spec.statistics, STATISTICS_BUFFER)?;
        let ev = event(&n, &spec.event)?;
        Ok(Self {
            temperature: tp
                .subscriber_builder()
                .buffer_size(COMMAND_BUFFER)
                .create()
                .map_err(|e| err(Operation::Open, "create the temperature subscriber", e))?,
            temperature_sequences: Sequences::new(),
            velocity: v
                .subscriber_builder()
                .buffer_size(COMMAND_BUFFER)
                .create()
                .map_err(|e| err(Operation::Open, "create the velocity subscriber", e))?,
            load: l
                .subscriber_builder()
                .buffer_size(COMMAND_BUFFER)
                .create()
                .map_err(|e| err(Operation::Open, "create the load subscriber", e))?,
            estimate: e
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the estimate publisher", e))?,
            statistics: st
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the statistics publisher", e))?,
            listener: ev
                .listener_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the command event listener", e))?,
            velocity_sequences: Sequences::new(),
            load_sequences: Sequences::new(),
            joints: if !spec.plan.by_joint() {
                None
            } else {
                Some(JointNode::open(&n, spec)?)
            },
            record,
            counters: SharedCounters::default(),
            _node: n,
        })
    }

    fn take(&mut self, kind: CommandKind) -> Result<Option<Command>, TransportError> {
        let (sub, seqs, what) = match kind {
            CommandKind::Load => (&self.load, &mut self.load_sequences, "a load command"),
            CommandKind::Temperature => (
                &self.temperature,
                &mut self.temperature_sequences,
                "a temperature",
            ),
            CommandKind::Velocity | CommandKind::JointVelocity { .. } => (
                &self.velocity,
                &mut self.velocity_sequences,
                "a velocity command",
            ),
        };
        let Some(s) = sub
            .receive()
            .map_err(|e| err(Operation::Receive, &format!("receive {what}"), e))?
        else {
            return Ok(None);
        };
        let lost = seqs.lost_before(s.header().publisher_id(), s.sequence);
        if lost > 0 {
            // Delivered into the buffer, then overwritten there.
            self.counters.received.fetch_add(lost, Ordering::Relaxed);
            self.counters.overwritten.fetch_add(lost, Ordering::Relaxed);
        }
        SharedCounters::bump(&self.counters.received);
        let command = Command {
            kind,
            value: s.value,
            stamp_ns: s.stamp_ns,
        };
        if self.record.is_some() {
            let item = RecordItem::Command {
                command,
                received_ns: system_wall_ns(),
            };
            record_input(&self.record, item, &self.counters);
        }
        Ok(Some(command))
    }
}

impl NodePort for IceoryxNode {
    fn name(&self) -> &'static str {
        NAME
    }

    fn poll_command(&mut self) -> Result<Option<Command>, TransportError> {
        // Loads first: a load sent with a velocity applies to that velocity's step.
        if let Some(c) = self.take(CommandKind::Load)? {
            return Ok(Some(c));
        }
        if let Some(c) = self.take(CommandKind::Temperature)? {
            return Ok(Some(c));
        }
        if let Some(j) = &mut self.joints {
            if let Some(c) = j.poll(&self.counters, &self.record)? {
                return Ok(Some(c));
            }
        }
        self.take(CommandKind::Velocity)
    }

    fn publish_estimate(&mut self, contact: usize, e: &EstimateRecord) -> bool {
        let ok = match &self.joints {
            Some(j) => j.publish_estimate(contact, e),
            None => self.estimate.send_copy(EstimatePayload::from(e)).is_ok(),
        };
        if !ok {
            SharedCounters::bump(&self.counters.publish_failures);
        }
        ok
    }

    fn publish_efforts(&mut self, stamp_ns: u64, efforts: &[f64]) -> bool {
        let ok = self
            .joints
            .as_ref()
            .is_some_and(|j| j.publish_efforts(stamp_ns, efforts));
        if !ok {
            SharedCounters::bump(&self.counters.publish_failures);
        }
        ok
    }

    fn publish_statistics(&mut self, s: &StatisticsRecord) -> bool {
        let ok = self
            .statistics
            .send_copy(StatisticsPayload::from(s))
            .is_ok();
        if !ok {
            SharedCounters::bump(&self.counters.statistics_failures);
        }
        ok
    }

    fn wait_for_command(&mut self, timeout: Duration) -> Result<(), TransportError> {
        self.listener
            .timed_wait(|_| {}, timeout)
            .map(|_| ())
            .map_err(|e| err(Operation::Receive, "wait for a command event", e))
    }

    fn counters(&self) -> PortCounters {
        self.counters.snapshot()
    }
}
