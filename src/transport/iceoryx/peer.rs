//! A peer's side of iceoryx2 (a controller, a test): publishers for the
//! commands with their sequence numbers, subscribers for the outputs, the
//! notifier that wakes the node.

use super::joints::JointPeer;
use super::*;
use crate::msgs::{Command, CommandKind, EstimateRecord, StatisticsRecord};
use crate::transport::Operation;
use crate::transport::{JointEfforts, JointStateCommand, PeerPort, TransportError};
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::PortFactory;

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
                .map_err(|e| err(Operation::Open, "create the statistics subscriber", e))?,
            velocity_sequence: 0,
            load_sequence: 0,
            temperature_sequence: 0,
            temperature: service::<CommandPayload>(&n, &spec.temperature, COMMAND_BUFFER)?
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the temperature publisher", e))?,
            velocity: v
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the velocity publisher", e))?,
            load: l
                .publisher_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the load publisher", e))?,
            estimate: e
                .subscriber_builder()
                .buffer_size(ESTIMATE_BUFFER)
                .create()
                .map_err(|e| err(Operation::Open, "create the estimate subscriber", e))?,
            notifier: ev
                .notifier_builder()
                .create()
                .map_err(|e| err(Operation::Open, "create the command notifier", e))?,
            joints: if !spec.plan.by_joint() {
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
        self.joints.as_mut().ok_or(TransportError::NotJoints {
            backend: NAME,
            operation: "use the joint services",
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
        port.send_copy(p)
            .map_err(|e| err(Operation::Send, "send a command", e))?;
        self.notifier
            .notify()
            .map_err(|e| err(Operation::Send, "notify the node", e))?;
        Ok(())
    }

    fn try_recv(&mut self) -> Result<Option<EstimateRecord>, TransportError> {
        Ok(self
            .estimate
            .receive()
            .map_err(|e| err(Operation::Receive, "receive an estimate", e))?
            .map(|s| EstimateRecord::from(&*s)))
    }

    fn try_recv_statistics(&mut self) -> Result<Option<StatisticsRecord>, TransportError> {
        Ok(self
            .statistics
            .receive()
            .map_err(|e| err(Operation::Receive, "receive loop statistics", e))?
            .map(|s| StatisticsRecord::from(&*s)))
    }

    fn send_joint_state(&mut self, js: &JointStateCommand) -> Result<(), TransportError> {
        self.joint_peer()?.send(js)?;
        self.notifier
            .notify()
            .map_err(|e| err(Operation::Send, "notify the node", e))?;
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
