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

use super::{
    record_input, NodePort, PeerPort, PortCounters, RecordQueue, SharedCounters, TransportError,
};
use crate::clock::system_wall_ns;
use crate::config::Iceoryx2Config;
use crate::msgs::{Command, CommandKind, EstimateRecord, RecordItem, StatisticsRecord};
use iceoryx2::identifiers::UniquePublisherId;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::PortFactory;
use std::sync::atomic::Ordering;
use std::time::Duration;

const NAME: &str = "iceoryx2";

/// A velocity or load command.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::Command_v2")]
pub struct CommandPayload {
    /// Sender's stamp, ns.
    pub stamp_ns: u64,
    /// m/s (velocity service) or N (load service).
    pub value: f64,
    /// 1, 2, 3, … per publisher: a gap is a sample lost to a full buffer.
    pub sequence: u64,
}

/// One estimate (the fields of `friction_msgs/FrictionEstimate`).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::FrictionEstimate_v2")]
pub struct EstimatePayload {
    pub stamp_ns: u64,
    pub velocity_m_s: f64,
    pub load_n: f64,
    pub temperature_c: f64,
    pub friction_force_n: f64,
    pub contact_friction_force_n: f64,
    pub cof: f64,
    pub h0_m: f64,
    pub h_min_m: f64,
    pub hydrodynamic_force_n: f64,
    pub asperity_force_n: f64,
    pub asperity_load_share: f64,
    pub compute_time_ns: u64,
    pub late_ns: u64,
    pub iterations: u32,
    pub regime: u8,
    pub status: u8,
    pub command_status: u8,
    pub reserved: u8,
}

/// Loop statistics (the fields of `friction_msgs/LoopStatistics`).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::LoopStatistics_v4")]
pub struct StatisticsPayload {
    pub stamp_ns: u64,
    pub steps: u64,
    pub deadline_misses: u64,
    pub catch_up_steps: u64,
    pub time_jumps: u64,
    pub clock_jumps: u64,
    pub commands_received: u64,
    pub commands_applied: u64,
    pub commands_overwritten: u64,
    pub commands_rejected: u64,
    pub command_timeouts: u64,
    pub publish_drops: u64,
    pub publish_failures: u64,
    pub statistics_not_sent: u64,
    pub recorder_drops: u64,
    pub recording_files: u64,
    pub recording_files_deleted: u64,
    pub recording_lost: u64,
    pub snapshots: u64,
    pub last_snapshot_span_s: f64,
    /// UTF-8, `last_snapshot_len` bytes used.
    pub last_snapshot: [u8; 255],
    pub last_snapshot_len: u8,
    pub compute_time_ns: [u64; 3],
    pub period_jitter_ns: [u64; 3],
    pub steps_not_converged: u64,
    pub parameter_updates: u64,
}

impl From<&StatisticsRecord> for StatisticsPayload {
    fn from(s: &StatisticsRecord) -> Self {
        Self {
            stamp_ns: s.stamp_ns,
            steps: s.steps,
            deadline_misses: s.deadline_misses,
            catch_up_steps: s.catch_up_steps,
            time_jumps: s.time_jumps,
            clock_jumps: s.clock_jumps,
            commands_received: s.commands_received,
            commands_applied: s.commands_applied,
            commands_overwritten: s.commands_overwritten,
            commands_rejected: s.commands_rejected,
            command_timeouts: s.command_timeouts,
            publish_drops: s.publish_drops,
            publish_failures: s.publish_failures,
            statistics_not_sent: s.statistics_not_sent,
            recorder_drops: s.recorder_drops,
            recording_files: s.recording.files,
            recording_files_deleted: s.recording.files_deleted,
            recording_lost: s.recording.lost,
            snapshots: s.recording.snapshots,
            last_snapshot_span_s: s.recording.last_snapshot_span_s,
            last_snapshot: {
                let mut b = [0u8; 255];
                let t = s.recording.last_snapshot.as_str().as_bytes();
                b[..t.len()].copy_from_slice(t);
                b
            },
            last_snapshot_len: s.recording.last_snapshot.as_str().len() as u8,
            compute_time_ns: s.compute_time_ns,
            period_jitter_ns: s.period_jitter_ns,
            steps_not_converged: s.steps_not_converged,
            parameter_updates: s.parameter_updates,
        }
    }
}

impl From<&StatisticsPayload> for StatisticsRecord {
    fn from(s: &StatisticsPayload) -> Self {
        Self {
            stamp_ns: s.stamp_ns,
            steps: s.steps,
            deadline_misses: s.deadline_misses,
            catch_up_steps: s.catch_up_steps,
            time_jumps: s.time_jumps,
            clock_jumps: s.clock_jumps,
            commands_received: s.commands_received,
            commands_applied: s.commands_applied,
            commands_overwritten: s.commands_overwritten,
            commands_rejected: s.commands_rejected,
            command_timeouts: s.command_timeouts,
            publish_drops: s.publish_drops,
            publish_failures: s.publish_failures,
            statistics_not_sent: s.statistics_not_sent,
            recorder_drops: s.recorder_drops,
            recording: crate::msgs::RecordingStatus {
                files: s.recording_files,
                files_deleted: s.recording_files_deleted,
                lost: s.recording_lost,
                snapshots: s.snapshots,
                last_snapshot: crate::msgs::Note::new(
                    std::str::from_utf8(&s.last_snapshot[..usize::from(s.last_snapshot_len)])
                        .unwrap_or(""),
                ),
                last_snapshot_span_s: s.last_snapshot_span_s,
            },
            compute_time_ns: s.compute_time_ns,
            period_jitter_ns: s.period_jitter_ns,
            steps_not_converged: s.steps_not_converged,
            parameter_updates: s.parameter_updates,
        }
    }
}

impl From<&EstimateRecord> for EstimatePayload {
    fn from(e: &EstimateRecord) -> Self {
        Self {
            stamp_ns: e.stamp_ns,
            velocity_m_s: e.velocity_m_s,
            load_n: e.load_n,
            temperature_c: e.temperature_c,
            friction_force_n: e.friction_force_n,
            contact_friction_force_n: e.contact_friction_force_n,
            cof: e.cof,
            h0_m: e.h0_m,
            h_min_m: e.h_min_m,
            hydrodynamic_force_n: e.hydrodynamic_force_n,
            asperity_force_n: e.asperity_force_n,
            asperity_load_share: e.asperity_load_share,
            compute_time_ns: e.compute_time_ns,
            late_ns: e.late_ns,
            iterations: e.iterations,
            regime: e.regime,
            status: e.status,
            command_status: e.command_status,
            reserved: 0,
        }
    }
}

impl From<&EstimatePayload> for EstimateRecord {
    fn from(p: &EstimatePayload) -> Self {
        Self {
            stamp_ns: p.stamp_ns,
            velocity_m_s: p.velocity_m_s,
            load_n: p.load_n,
            temperature_c: p.temperature_c,
            friction_force_n: p.friction_force_n,
            contact_friction_force_n: p.contact_friction_force_n,
            cof: p.cof,
            h0_m: p.h0_m,
            h_min_m: p.h_min_m,
            hydrodynamic_force_n: p.hydrodynamic_force_n,
            asperity_force_n: p.asperity_force_n,
            asperity_load_share: p.asperity_load_share,
            regime: p.regime,
            status: p.status,
            command_status: p.command_status,
            iterations: p.iterations,
            compute_time_ns: p.compute_time_ns,
            late_ns: p.late_ns,
        }
    }
}

/// Service names (Send; opened on the using thread).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IceoryxSpec {
    pub velocity: String,
    pub load: String,
    pub temperature: String,
    pub estimate: String,
    pub statistics: String,
    pub event: String,
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
}

impl IceoryxNode {
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
            CommandKind::Velocity => (
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
        self.take(CommandKind::Velocity)
    }

    fn publish_estimate(&mut self, e: &EstimateRecord) -> bool {
        let ok = self.estimate.send_copy(EstimatePayload::from(e)).is_ok();
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
}

impl IceoryxPeer {
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
            velocity_service: v,
            estimate_service: e,
            _node: n,
        })
    }
}

impl PeerPort for IceoryxPeer {
    fn name(&self) -> &'static str {
        NAME
    }

    fn send(&mut self, c: &Command) -> Result<(), TransportError> {
        let (port, sequence) = match c.kind {
            CommandKind::Velocity => (&self.velocity, &mut self.velocity_sequence),
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
