//! iceoryx2 transport: zero-copy shared-memory publish–subscribe on one host.
//!
//! Services (names from `iceoryx2.*`): velocity and load commands as
//! [`CommandPayload`], estimates as [`EstimatePayload`], loop statistics as
//! [`StatisticsPayload`], plus an event service that wakes a lockstep node
//! when a command is sent. Commands carry a per-publisher sequence number:
//! samples a full subscriber buffer overwrote show as gaps and are counted
//! (`commands_overwritten`), so every command is accounted for. Samples lost
//! before a publisher's first sample reached the node are not counted: a
//! node that starts after its peers cannot tell them from samples sent
//! before it existed. Payloads are `#[repr(C)]`
//! with fixed type names, so a mismatching peer gets a clean error when its
//! port opens. Publishing never blocks (safe overflow: a full subscriber
//! buffer loses its oldest sample); the node polls and publishes inline on the
//! loop thread (lock-free shared-memory operations, no system call).
//!
//! | file | job |
//! |---|---|
//! | `mod.rs` | the single-contact services: commands in, estimates and loop statistics out (iceoryx2 publishes no film profile) |
//! | `payloads.rs` | the `#[repr(C)]` payloads and their conversions |
//! | `joints.rs` | several contacts: JointState velocities in, per-contact estimates out |

mod joints;
pub mod payloads;

use super::{
    record_input, JointEfforts, JointStateCommand, NodePort, PeerPort, PortCounters, RecordQueue,
    SharedCounters, TransportError,
};
use crate::clock::system_wall_ns;
use crate::config::Iceoryx2Config;
use crate::link::RecordItem;
use crate::msgs::{Command, CommandKind, EstimateRecord, StatisticsRecord};
use iceoryx2::identifiers::UniquePublisherId;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::PortFactory;
use joints::{JointNode, JointPeer};
pub use payloads::*;
use std::sync::atomic::Ordering;
use std::time::Duration;

const NAME: &str = "iceoryx2";

/// Service names (Send; opened on the using thread).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IceoryxSpec {
    /// The commanded-velocity service.
    pub velocity: String,
    /// The normal-load service.
    pub load: String,
    /// The temperature service.
    pub temperature: String,
    /// The estimate service.
    pub estimate: String,
    /// The loop-statistics service.
    pub statistics: String,
    /// The event service that wakes the node on a command.
    pub event: String,
    /// Several contacts: the configured joints (empty: one contact) and
    /// the joint services.
    pub joints: Vec<String>,
    /// Several contacts: the joint-velocity service.
    pub joint_state: String,
    /// Several contacts: the efforts service.
    pub efforts: String,
    /// Several contacts: every contact's estimates, tagged with its index.
    pub contact_estimate: String,
}

impl IceoryxSpec {
    /// The spec of a node serving several contacts with these joints.
    pub fn with_joints(mut self, joints: Vec<String>) -> Self {
        self.joints = joints;
        self
    }
}

impl From<&Iceoryx2Config> for IceoryxSpec {
    fn from(c: &Iceoryx2Config) -> Self {
        Self {
            velocity: c.cmd_velocity_service.clone(),
            load: c.normal_load_service.clone(),
            temperature: c.temperature_service.clone(),
            estimate: c.friction_service.clone(),
            statistics: c.loop_statistics_service.clone(),
            event: c.cmd_event_service.clone(),
            joints: Vec::new(),
            joint_state: c.joint_state_service.clone(),
            efforts: c.efforts_service.clone(),
            contact_estimate: c.contact_friction_service.clone(),
        }
    }
}

/// Depth of the command buffers: a lockstep peer may send this many commands
/// ahead of the node without loss.
const COMMAND_BUFFER: usize = 1024;
/// Depth of the estimate buffers.
const ESTIMATE_BUFFER: usize = 1024;
/// Depth of the statistics buffers.
const STATISTICS_BUFFER: usize = 64;

fn err(op: &str, e: impl std::fmt::Debug) -> TransportError {
    TransportError::backend(NAME, op.to_string(), format!("{e:?}"))
}

fn node() -> Result<Node<ipc::Service>, TransportError> {
    set_log_level(LogLevel::Error);
    NodeBuilder::new()
        // The node handles SIGINT/SIGTERM itself (to finalise recordings).
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| err("create an iceoryx2 node", e))
}

type PubSub<T> =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>;
type EventService = iceoryx2::service::port_factory::event::PortFactory<ipc::Service>;

fn service<T: std::fmt::Debug + ZeroCopySend>(
    n: &Node<ipc::Service>,
    name: &str,
    buffer: usize,
) -> Result<PubSub<T>, TransportError> {
    let sn: ServiceName = name
        .try_into()
        .map_err(|e| err(&format!("use service name `{name}`"), e))?;
    n.service_builder(&sn)
        .publish_subscribe::<T>()
        .enable_safe_overflow(true)
        .subscriber_max_buffer_size(buffer)
        .history_size(0)
        .max_publishers(8)
        .max_subscribers(8)
        .open_or_create()
        .map_err(|e| err(&format!("open service `{name}`"), e))
}

fn event(n: &Node<ipc::Service>, name: &str) -> Result<EventService, TransportError> {
    let sn: ServiceName = name
        .try_into()
        .map_err(|e| err(&format!("use service name `{name}`"), e))?;
    n.service_builder(&sn)
        .event()
        .open_or_create()
        .map_err(|e| err(&format!("open event service `{name}`"), e))
}

/// Sequence numbers seen per publisher (fixed size: no allocation).
#[derive(Debug)]
struct Sequences {
    seen: [(Option<UniquePublisherId>, u64); MAX_PUBLISHERS],
}

impl Sequences {
    fn new() -> Self {
        Self {
            seen: [(None, 0); MAX_PUBLISHERS],
        }
    }

    /// Samples lost before this one (a gap in the publisher's sequence).
    fn lost_before(&mut self, publisher: UniquePublisherId, sequence: u64) -> u64 {
        let slot = match self.seen.iter().position(|(p, _)| *p == Some(publisher)) {
            Some(k) => k,
            None => match self.seen.iter().position(|(p, _)| p.is_none()) {
                Some(k) => {
                    // A publisher's first sample: samples before it were sent
                    // before this node subscribed (not lost here).
                    self.seen[k] = (Some(publisher), sequence);
                    return 0;
                }
                None => return 0,
            },
        };
        let last = self.seen[slot].1;
        self.seen[slot].1 = sequence.max(last);
        sequence.saturating_sub(last).saturating_sub(1)
    }
}

/// Most publishers a command service accepts.
const MAX_PUBLISHERS: usize = 8;

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
                .map_err(|e| err("create the temperature subscriber", e))?,
            temperature_sequences: Sequences::new(),
            velocity: v
                .subscriber_builder()
                .buffer_size(COMMAND_BUFFER)
                .create()
                .map_err(|e| err("create the velocity subscriber", e))?,
            load: l
                .subscriber_builder()
                .buffer_size(COMMAND_BUFFER)
                .create()
                .map_err(|e| err("create the load subscriber", e))?,
            estimate: e
                .publisher_builder()
                .create()
                .map_err(|e| err("create the estimate publisher", e))?,
            statistics: st
                .publisher_builder()
                .create()
                .map_err(|e| err("create the statistics publisher", e))?,
            listener: ev
                .listener_builder()
                .create()
                .map_err(|e| err("create the command event listener", e))?,
            velocity_sequences: Sequences::new(),
            load_sequences: Sequences::new(),
            joints: if spec.joints.is_empty() {
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
            .map_err(|e| err(&format!("receive {what}"), e))?
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
            .map_err(|e| err("wait for a command event", e))
    }

    fn counters(&self) -> PortCounters {
        self.counters.snapshot()
    }
}

/// A peer's side.
pub struct IceoryxPeer {
    _node: Node<ipc::Service>,
    velocity_service: PubSub<CommandPayload>,
    estimate_service: PubSub<EstimatePayload>,
    velocity: iceoryx2::port::publisher::Publisher<ipc::Service, CommandPayload, ()>,
    load: iceoryx2::port::publisher::Publisher<ipc::Service, CommandPayload, ()>,
    temperature: iceoryx2::port::publisher::Publisher<ipc::Service, CommandPayload, ()>,
    estimate: iceoryx2::port::subscriber::Subscriber<ipc::Service, EstimatePayload, ()>,
    statistics: iceoryx2::port::subscriber::Subscriber<ipc::Service, StatisticsPayload, ()>,
    notifier: iceoryx2::port::notifier::Notifier<ipc::Service>,
    velocity_sequence: u64,
    load_sequence: u64,
    temperature_sequence: u64,
    /// Several contacts: the joint services.
    joints: Option<JointPeer>,
}

impl IceoryxPeer {
    /// Open the peer side (a controller, a test): publishers for the commands, subscribers for the
    /// outputs.
    pub fn open(spec: &IceoryxSpec) -> Result<Self, TransportError> {
        let n = node()?;
        let v = service::<CommandPayload>(&n, &spec.velocity, COMMAND_BUFFER)?;
        let l = service::<CommandPayload>(&n, &spec.load, COMMAND_BUFFER)?;
        let e = service::<EstimatePayload>(&n, &spec.estimate, ESTIMATE_BUFFER)?;
        let st = service::<StatisticsPayload>(&n, &spec.statistics, STATISTICS_BUFFER)?;
        let ev = event(&n, &spec.event)?;
        Ok(Self {
            statistics: st
                .subscriber_builder()
                .buffer_size(STATISTICS_BUFFER)
                .create()
                .map_err(|e| err("create the statistics subscriber", e))?,
            velocity_sequence: 0,
            load_sequence: 0,
            temperature_sequence: 0,
            temperature: service::<CommandPayload>(&n, &spec.temperature, COMMAND_BUFFER)?
                .publisher_builder()
                .create()
                .map_err(|e| err("create the temperature publisher", e))?,
            velocity: v
                .publisher_builder()
                .create()
                .map_err(|e| err("create the velocity publisher", e))?,
            load: l
                .publisher_builder()
                .create()
                .map_err(|e| err("create the load publisher", e))?,
            estimate: e
                .subscriber_builder()
                .buffer_size(ESTIMATE_BUFFER)
                .create()
                .map_err(|e| err("create the estimate subscriber", e))?,
            notifier: ev
                .notifier_builder()
                .create()
                .map_err(|e| err("create the command notifier", e))?,
            joints: if spec.joints.is_empty() {
                None
            } else {
                Some(JointPeer::open(&n, spec)?)
            },
            velocity_service: v,
            estimate_service: e,
            _node: n,
        })
    }
}

impl IceoryxPeer {
    fn joint_peer(&mut self) -> Result<&mut JointPeer, TransportError> {
        self.joints.as_mut().ok_or_else(|| {
            TransportError::backend(
                NAME,
                "use the joint services",
                "this peer was opened for one contact (IceoryxSpec::with_joints opens them)",
            )
        })
    }
}

impl PeerPort for IceoryxPeer {
    fn name(&self) -> &'static str {
        NAME
    }

    fn send(&mut self, c: &Command) -> Result<(), TransportError> {
        let (port, sequence) = match c.kind {
            CommandKind::Velocity | CommandKind::JointVelocity { .. } => {
                (&self.velocity, &mut self.velocity_sequence)
            }
            CommandKind::Load => (&self.load, &mut self.load_sequence),
            CommandKind::Temperature => (&self.temperature, &mut self.temperature_sequence),
        };
        *sequence += 1;
        let p = CommandPayload {
            stamp_ns: c.stamp_ns,
            value: c.value,
            sequence: *sequence,
        };
        port.send_copy(p).map_err(|e| err("send a command", e))?;
        self.notifier
            .notify()
            .map_err(|e| err("notify the node", e))?;
        Ok(())
    }

    fn try_recv(&mut self) -> Result<Option<EstimateRecord>, TransportError> {
        Ok(self
            .estimate
            .receive()
            .map_err(|e| err("receive an estimate", e))?
            .map(|s| EstimateRecord::from(&*s)))
    }

    fn try_recv_statistics(&mut self) -> Result<Option<StatisticsRecord>, TransportError> {
        Ok(self
            .statistics
            .receive()
            .map_err(|e| err("receive loop statistics", e))?
            .map(|s| StatisticsRecord::from(&*s)))
    }

    fn send_joint_state(&mut self, js: &JointStateCommand) -> Result<(), TransportError> {
        self.joint_peer()?.send(js)?;
        self.notifier
            .notify()
            .map_err(|e| err("notify the node", e))?;
        Ok(())
    }

    fn try_recv_efforts(&mut self) -> Result<Option<JointEfforts>, TransportError> {
        self.joint_peer()?.try_recv_efforts()
    }

    fn try_recv_contact(&mut self) -> Result<Option<(usize, EstimateRecord)>, TransportError> {
        self.joint_peer()?.try_recv_contact()
    }

    fn is_matched(&mut self) -> bool {
        // The node subscribes to velocities and publishes estimates.
        self.velocity_service
            .dynamic_config()
            .number_of_subscribers()
            >= 1
            && self
                .estimate_service
                .dynamic_config()
                .number_of_publishers()
                >= 1
    }
}
