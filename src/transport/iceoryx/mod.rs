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
//! | `mod.rs` | the transport: service names, the participant, opening services (iceoryx2 publishes no film profile) |
//! | `node.rs` | the node's side: commands in (sequence gaps counted), estimates and loop statistics out |
//! | `peer.rs` | a peer's side (a controller, a test): commands out, estimates in |
//! | `payloads.rs` | the `#[repr(C)]` payloads and their conversions |
//! | `joints.rs` | several contacts: JointState velocities in, per-contact estimates out |

mod joints;
mod node;
pub mod payloads;
mod peer;

use super::TransportError;
use crate::config::Iceoryx2Config;
use crate::config::OutputPlan;
use crate::transport::Operation;
use iceoryx2::identifiers::UniquePublisherId;
use iceoryx2::prelude::*;
pub use node::IceoryxNode;
pub use payloads::*;
pub use peer::IceoryxPeer;

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
    /// One contact, or joints (their configured order) on the joint
    /// services.
    pub plan: OutputPlan,
    /// Several contacts: the joint-velocity service.
    pub joint_state: String,
    /// Several contacts: the efforts service.
    pub efforts: String,
    /// Several contacts: every contact's estimates, tagged with its index.
    pub contact_estimate: String,
}

impl IceoryxSpec {
    /// The spec of a node following `plan`.
    pub fn for_plan(mut self, plan: OutputPlan) -> Self {
        self.plan = plan;
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
            plan: OutputPlan::OneContact,
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

fn err(kind: Operation, op: &str, e: impl std::fmt::Debug) -> TransportError {
    TransportError::middleware(NAME, kind, op, e)
}

fn node() -> Result<Node<ipc::Service>, TransportError> {
    set_log_level(LogLevel::Error);
    NodeBuilder::new()
        // The node handles SIGINT/SIGTERM itself (to finalise recordings).
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| err(Operation::Open, "create an iceoryx2 node", e))
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
        .map_err(|e| err(Operation::Open, &format!("use service name `{name}`"), e))?;
    n.service_builder(&sn)
        .publish_subscribe::<T>()
        .enable_safe_overflow(true)
        .subscriber_max_buffer_size(buffer)
        .history_size(0)
        .max_publishers(8)
        .max_subscribers(8)
        .open_or_create()
        .map_err(|e| err(Operation::Open, &format!("open service `{name}`"), e))
}

fn event(n: &Node<ipc::Service>, name: &str) -> Result<EventService, TransportError> {
    let sn: ServiceName = name
        .try_into()
        .map_err(|e| err(Operation::Open, &format!("use service name `{name}`"), e))?;
    n.service_builder(&sn)
        .event()
        .open_or_create()
        .map_err(|e| err(Operation::Open, &format!("open event service `{name}`"), e))
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
