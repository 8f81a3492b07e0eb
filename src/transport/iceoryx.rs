//! iceoryx2 transport: zero-copy shared-memory publish–subscribe on one host.
//!
//! Services (names from `iceoryx2.*`): velocity and load commands as
//! [`CommandPayload`], estimates as [`EstimatePayload`], plus an event service
//! that wakes a lockstep node when a command is sent. Payloads are `#[repr(C)]`
//! with fixed type names, so a mismatching peer gets a clean error when its
//! port opens. Publishing never blocks (safe overflow: a full subscriber
//! buffer loses its oldest sample); the node polls and publishes inline on the
//! loop thread (lock-free shared-memory operations, no system call).

use super::{NodePort, PeerPort, TransportError};
use crate::config::Iceoryx2Config;
use crate::msgs::{Command, CommandKind, EstimateRecord, StatisticsRecord};
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::PortFactory;
use std::time::Duration;

const NAME: &str = "iceoryx2";

/// A velocity or load command.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::Command")]
pub struct CommandPayload {
    /// Sender's stamp, ns.
    pub stamp_ns: u64,
    /// m/s (velocity service) or N (load service).
    pub value: f64,
}

/// One estimate (the fields of `friction_msgs/FrictionEstimate`).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("friction_node::FrictionEstimate")]
pub struct EstimatePayload {
    pub stamp_ns: u64,
    pub velocity_m_s: f64,
    pub load_n: f64,
    pub friction_force_n: f64,
    pub cof: f64,
    pub h0_m: f64,
    pub h_min_m: f64,
    pub hydrodynamic_force_n: f64,
    pub asperity_force_n: f64,
    pub asperity_load_share: f64,
    pub compute_time_ns: u64,
    pub iterations: u32,
    pub regime: u8,
    pub status: u8,
    pub reserved: [u8; 2],
}

impl From<&EstimateRecord> for EstimatePayload {
    fn from(e: &EstimateRecord) -> Self {
        Self {
            stamp_ns: e.stamp_ns,
            velocity_m_s: e.velocity_m_s,
            load_n: e.load_n,
            friction_force_n: e.friction_force_n,
            cof: e.cof,
            h0_m: e.h0_m,
            h_min_m: e.h_min_m,
            hydrodynamic_force_n: e.hydrodynamic_force_n,
            asperity_force_n: e.asperity_force_n,
            asperity_load_share: e.asperity_load_share,
            compute_time_ns: e.compute_time_ns,
            iterations: e.iterations,
            regime: e.regime,
            status: e.status,
            reserved: [0; 2],
        }
    }
}

impl From<&EstimatePayload> for EstimateRecord {
    fn from(p: &EstimatePayload) -> Self {
        Self {
            stamp_ns: p.stamp_ns,
            velocity_m_s: p.velocity_m_s,
            load_n: p.load_n,
            friction_force_n: p.friction_force_n,
            cof: p.cof,
            h0_m: p.h0_m,
            h_min_m: p.h_min_m,
            hydrodynamic_force_n: p.hydrodynamic_force_n,
            asperity_force_n: p.asperity_force_n,
            asperity_load_share: p.asperity_load_share,
            regime: p.regime,
            status: p.status,
            iterations: p.iterations,
            compute_time_ns: p.compute_time_ns,
        }
    }
}

/// Service names (Send; opened on the using thread).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IceoryxSpec {
    pub velocity: String,
    pub load: String,
    pub estimate: String,
    pub event: String,
}

impl From<&Iceoryx2Config> for IceoryxSpec {
    fn from(c: &Iceoryx2Config) -> Self {
        Self {
            velocity: c.cmd_velocity_service.clone(),
            load: c.normal_load_service.clone(),
            estimate: c.friction_service.clone(),
            event: c.cmd_event_service.clone(),
        }
    }
}

/// Depth of the command buffers: a lockstep peer may send this many commands
/// ahead of the node without loss.
const COMMAND_BUFFER: usize = 1024;
/// Depth of the estimate buffers.
const ESTIMATE_BUFFER: usize = 1024;

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

/// The node's side.
pub struct IceoryxNode {
    _node: Node<ipc::Service>,
    velocity: iceoryx2::port::subscriber::Subscriber<ipc::Service, CommandPayload, ()>,
    load: iceoryx2::port::subscriber::Subscriber<ipc::Service, CommandPayload, ()>,
    estimate: iceoryx2::port::publisher::Publisher<ipc::Service, EstimatePayload, ()>,
    listener: iceoryx2::port::listener::Listener<ipc::Service>,
}

impl IceoryxNode {
    pub fn open(spec: &IceoryxSpec) -> Result<Self, TransportError> {
        let n = node()?;
        let v = service::<CommandPayload>(&n, &spec.velocity, COMMAND_BUFFER)?;
        let l = service::<CommandPayload>(&n, &spec.load, COMMAND_BUFFER)?;
        let e = service::<EstimatePayload>(&n, &spec.estimate, ESTIMATE_BUFFER)?;
        let ev = event(&n, &spec.event)?;
        Ok(Self {
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
            listener: ev
                .listener_builder()
                .create()
                .map_err(|e| err("create the command event listener", e))?,
            _node: n,
        })
    }
}

impl NodePort for IceoryxNode {
    fn name(&self) -> &'static str {
        NAME
    }

    fn poll_command(&mut self) -> Result<Option<Command>, TransportError> {
        // Loads first: a load sent with a velocity applies to that velocity's step.
        if let Some(s) = self
            .load
            .receive()
            .map_err(|e| err("receive a load command", e))?
        {
            return Ok(Some(Command {
                kind: CommandKind::Load,
                value: s.value,
                stamp_ns: s.stamp_ns,
            }));
        }
        if let Some(s) = self
            .velocity
            .receive()
            .map_err(|e| err("receive a velocity command", e))?
        {
            return Ok(Some(Command {
                kind: CommandKind::Velocity,
                value: s.value,
                stamp_ns: s.stamp_ns,
            }));
        }
        Ok(None)
    }

    fn publish_estimate(&mut self, e: &EstimateRecord) -> bool {
        self.estimate.send_copy(EstimatePayload::from(e)).is_ok()
    }

    fn publish_statistics(&mut self, _s: &StatisticsRecord) -> bool {
        // Statistics go to ROS 2 and the recorder only.
        true
    }

    fn wait_for_command(&mut self, timeout: Duration) -> Result<(), TransportError> {
        self.listener
            .timed_wait(|_| {}, timeout)
            .map(|_| ())
            .map_err(|e| err("wait for a command event", e))
    }
}

/// A peer's side.
pub struct IceoryxPeer {
    _node: Node<ipc::Service>,
    velocity_service: PubSub<CommandPayload>,
    estimate_service: PubSub<EstimatePayload>,
    velocity: iceoryx2::port::publisher::Publisher<ipc::Service, CommandPayload, ()>,
    load: iceoryx2::port::publisher::Publisher<ipc::Service, CommandPayload, ()>,
    estimate: iceoryx2::port::subscriber::Subscriber<ipc::Service, EstimatePayload, ()>,
    notifier: iceoryx2::port::notifier::Notifier<ipc::Service>,
}

impl IceoryxPeer {
    pub fn open(spec: &IceoryxSpec) -> Result<Self, TransportError> {
        let n = node()?;
        let v = service::<CommandPayload>(&n, &spec.velocity, COMMAND_BUFFER)?;
        let l = service::<CommandPayload>(&n, &spec.load, COMMAND_BUFFER)?;
        let e = service::<EstimatePayload>(&n, &spec.estimate, ESTIMATE_BUFFER)?;
        let ev = event(&n, &spec.event)?;
        Ok(Self {
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
        let p = CommandPayload {
            stamp_ns: c.stamp_ns,
            value: c.value,
        };
        let port = match c.kind {
            CommandKind::Velocity => &self.velocity,
            CommandKind::Load => &self.load,
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
