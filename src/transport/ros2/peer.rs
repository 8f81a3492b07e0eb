//! A peer's side of the ROS 2 transport: its own participant and node on
//! the same domain (drivers, tests, benchmarks).

use super::{advertise, context, err, qos, ros_node, subscribe, Ros2Spec, NAME};
use crate::config::CommandType;
use crate::msgs::command_codec::CommandMessage;
use crate::msgs::{
    self, Command, CommandKind, EstimateRecord, Float64, FrictionEstimate, LoopStatistics,
    StatisticsRecord, TwistStamped, FLOAT64, FRICTION_ESTIMATE, LOOP_STATISTICS, TWIST_STAMPED,
};
use crate::transport::Operation;
use crate::transport::{JointEfforts, JointStateCommand, PeerPort, TransportError};
use ros2_client::{Context, Node, Publisher, Subscription};
use std::sync::atomic::{AtomicU64, Ordering};

/// A peer's side (its own participant and node on the same domain).
pub struct Ros2Peer {
    node: Node,
    _ctx: Context,
    velocity_f64: Option<Publisher<Float64>>,
    velocity_twist: Option<Publisher<TwistStamped>>,
    load: Publisher<Float64>,
    temperature: Publisher<msgs::Temperature>,
    estimate: Subscription<FrictionEstimate>,
    statistics: Subscription<LoopStatistics>,
    frame_id: String,
    /// Several contacts: the joint topics.
    joints: Option<super::joints::JointPeer>,
}

static PEER_COUNTER: AtomicU64 = AtomicU64::new(0);

impl Ros2Peer {
    /// Open the peer side (a controller, a test).
    pub fn open(spec: &Ros2Spec) -> Result<Self, TransportError> {
        let ctx = context(spec)?;
        let name = format!(
            "{}_peer_{}_{}",
            spec.node_name,
            std::process::id(),
            PEER_COUNTER.fetch_add(1, Ordering::Relaxed)
        );
        let mut node = ros_node(&ctx, &spec.namespace, &name)?;
        let cq = qos(&spec.command_qos);
        let eq = qos(&spec.estimate_qos);
        let n = &mut node;
        let (mut vf, mut vt) = (None, None);
        match spec.command_type {
            CommandType::Float64 => {
                vf = Some(advertise(
                    n,
                    &spec.topics.cmd_velocity,
                    &FLOAT64,
                    &cq,
                    "the velocity",
                )?);
            }
            CommandType::TwistStamped => {
                vt = Some(advertise(
                    n,
                    &spec.topics.cmd_velocity,
                    &TWIST_STAMPED,
                    &cq,
                    "the velocity",
                )?);
            }
        }
        let load = advertise(n, &spec.topics.normal_load, &FLOAT64, &cq, "the load")?;
        let temperature = advertise(
            n,
            &spec.topics.temperature,
            &msgs::TEMPERATURE,
            &cq,
            "the temperature",
        )?;
        let estimate = subscribe(
            n,
            &spec.topics.friction,
            &FRICTION_ESTIMATE,
            &eq,
            "the estimate",
        )?;
        let statistics = subscribe(
            n,
            &spec.topics.loop_statistics,
            &LOOP_STATISTICS,
            &eq,
            "the statistics",
        )?;
        let joints = if !spec.plan.by_joint() {
            None
        } else {
            Some(super::joints::JointPeer::open(n, spec, &cq, &eq)?)
        };
        Ok(Self {
            joints,
            node,
            _ctx: ctx,
            velocity_f64: vf,
            velocity_twist: vt,
            load,
            temperature,
            estimate,
            statistics,
            frame_id: spec.frame_id.clone(),
        })
    }
}

impl Ros2Peer {
    /// Publish a whole TwistStamped as given (its frame, angular velocity,
    /// …), on a node configured for `twist_stamped` commands.
    pub fn send_twist(&mut self, m: &TwistStamped) -> Result<(), TransportError> {
        let p = self
            .velocity_twist
            .as_ref()
            .ok_or_else(|| TransportError::Send {
                backend: NAME,
                operation: "publish a TwistStamped".into(),
                message: "the node takes Float64 commands".into(),
            })?;
        p.publish(m.clone())
            .map_err(|e| err(Operation::Send, "publish a TwistStamped", e))
    }
}

/// What a one-contact peer says when asked for the joint topics.
fn several_contacts() -> TransportError {
    TransportError::NotJoints {
        backend: NAME,
        operation: "use the joint topics",
    }
}

impl PeerPort for Ros2Peer {
    fn name(&self) -> &'static str {
        NAME
    }

    fn send(&mut self, c: &Command) -> Result<(), TransportError> {
        let velocity = if self.velocity_f64.is_some() {
            CommandType::Float64
        } else {
            CommandType::TwistStamped
        };
        // A joint velocity has no joint's name here: None.
        let Some(message) = CommandMessage::of(c, velocity, &self.frame_id, None) else {
            return Err(TransportError::Send {
                backend: NAME,
                operation: "send a joint velocity".into(),
                message: "send a JointState (send_joint_state) instead".into(),
            });
        };
        let show = |e: &dyn std::fmt::Debug| format!("{e:?}");
        let r = match (c.kind, message, &self.velocity_f64, &self.velocity_twist) {
            (CommandKind::Load, CommandMessage::Float64(m), _, _) => {
                self.load.publish(m).map_err(|e| show(&e))
            }
            (_, CommandMessage::Float64(m), Some(p), _) => p.publish(m).map_err(|e| show(&e)),
            (_, CommandMessage::Twist(m), _, Some(p)) => p.publish(m).map_err(|e| show(&e)),
            (_, CommandMessage::Temperature(m), _, _) => {
                self.temperature.publish(m).map_err(|e| show(&e))
            }
            _ => Err("no publisher for this command".into()),
        };
        r.map_err(|e| err(Operation::Send, "publish a command", e))
    }

    fn try_recv(&mut self) -> Result<Option<EstimateRecord>, TransportError> {
        match self.estimate.take() {
            Ok(m) => Ok(m.map(|(m, _)| EstimateRecord::from_wire(&m))),
            Err(e) => Err(err(Operation::Receive, "take an estimate", e)),
        }
    }

    fn send_joint_state(&mut self, js: &JointStateCommand) -> Result<(), TransportError> {
        self.joints.as_mut().ok_or_else(several_contacts)?.send(js)
    }

    fn try_recv_efforts(&mut self) -> Result<Option<JointEfforts>, TransportError> {
        self.joints
            .as_mut()
            .ok_or_else(several_contacts)?
            .try_recv_efforts()
    }

    fn try_recv_contact(&mut self) -> Result<Option<(usize, EstimateRecord)>, TransportError> {
        self.joints
            .as_mut()
            .ok_or_else(several_contacts)?
            .try_recv_contact()
    }

    fn try_recv_statistics(&mut self) -> Result<Option<StatisticsRecord>, TransportError> {
        match self.statistics.take() {
            Ok(m) => Ok(m.map(|(m, _)| StatisticsRecord::from_wire(&m))),
            Err(e) => Err(err(Operation::Receive, "take loop statistics", e)),
        }
    }

    fn is_matched(&mut self) -> bool {
        // The wait futures resolve at once when a match exists; polled once
        // they answer without the error ros2-client logs for a writer or
        // reader it has not matched yet (get_*_count does).
        use futures::FutureExt;
        let node = &self.node;
        let vel = match (&self.velocity_f64, &self.velocity_twist) {
            (Some(p), _) => p.wait_for_subscription(node).now_or_never().is_some(),
            (_, Some(p)) => p.wait_for_subscription(node).now_or_never().is_some(),
            _ => false,
        };
        vel && self
            .load
            .wait_for_subscription(node)
            .now_or_never()
            .is_some()
            && self
                .estimate
                .wait_for_publisher(node)
                .now_or_never()
                .is_some()
            && self.joints.as_ref().is_none_or(|j| j.is_matched(node))
    }
}
