//! Several contacts over ROS 2: `sensor_msgs/JointState` velocities in
//! (`ros.topics.joint_commands`), and out the efforts in the configured
//! joint order as a `std_msgs/Float64MultiArray` (`ros.topics.joint_efforts`,
//! what `forward_command_controller` and the effort controllers take), the
//! same efforts as a `sensor_msgs/JointState` (`ros.topics.joint_friction`),
//! and each contact's `FrictionEstimate` on its own topic
//! (`<ros.topics.contact_friction>/<contact>/friction`).
//!
//! A JointState is expanded by joint name into one command per configured
//! joint ([`joint_commands`]): joints of other nodes are skipped, a joint
//! without a finite velocity (NaN, or fewer velocities than names) is
//! rejected for its contact only, and the first such joint is named in the
//! log.

use super::{advertise, err, subscribe, Ros2Spec};
use crate::clock::system_wall_ns;
use crate::msgs::{
    EstimateRecord, Float64MultiArray, FrictionEstimate, Header, JointState, MultiArrayDimension,
    MultiArrayLayout, Time, FLOAT64_MULTI_ARRAY, FRICTION_ESTIMATE, JOINT_STATE,
};
use crate::transport::Operation;
use crate::transport::{
    joint_commands, JointEfforts, JointStateCommand, SharedCounters, TransportError,
};
use crossbeam_queue::ArrayQueue;
use ros2_client::{Node, Publisher, QosProfile, Subscription};
use std::sync::atomic::Ordering;

/// The node's joint topics (opened on its I/O thread).
pub(super) struct JointTopics {
    joints: Vec<String>,
    pub commands: Subscription<JointState>,
    efforts: Publisher<Float64MultiArray>,
    friction: Publisher<JointState>,
    contacts: Vec<Publisher<FrictionEstimate>>,
    warned: bool,
}

impl JointTopics {
    pub(super) fn open(
        n: &mut Node,
        spec: &Ros2Spec,
        cq: &QosProfile,
        eq: &QosProfile,
    ) -> Result<Self, TransportError> {
        let mut contacts = Vec::with_capacity(spec.topics.contact_friction.len());
        for t in &spec.topics.contact_friction {
            contacts.push(advertise(
                n,
                t,
                &FRICTION_ESTIMATE,
                eq,
                "a contact's estimate",
            )?);
        }
        Ok(Self {
            joints: spec.plan.joints().to_vec(),
            commands: subscribe(
                n,
                &spec.topics.joint_commands,
                &JOINT_STATE,
                cq,
                "the joint commands",
            )?,
            efforts: advertise(
                n,
                &spec.topics.joint_efforts,
                &FLOAT64_MULTI_ARRAY,
                eq,
                "the joint efforts",
            )?,
            friction: advertise(
                n,
                &spec.topics.joint_friction,
                &JOINT_STATE,
                eq,
                "the joint friction",
            )?,
            contacts,
            warned: false,
        })
    }

    /// Take every pending JointState into the command queue (a full queue
    /// overwrites its oldest command, counted).
    pub(super) fn take(
        &mut self,
        commands: &ArrayQueue<crate::msgs::Command>,
        counters: &SharedCounters,
    ) {
        while let Ok(Some((m, _))) = self.commands.take() {
            let stamp = m.header.stamp.to_ns();
            let stamp = if stamp != 0 { stamp } else { system_wall_ns() };
            let mut bad: Option<&str> = None;
            let names = m.name.iter().map(String::as_str);
            joint_commands(&self.joints, stamp, names, &m.velocity, |c, name| {
                if !c.value.is_finite() && bad.is_none() {
                    bad = Some(name);
                }
                counters.received.fetch_add(1, Ordering::Relaxed);
                if commands.force_push(c).is_some() {
                    counters.overwritten.fetch_add(1, Ordering::Relaxed);
                }
            });
            if let (Some(name), false) = (bad, self.warned) {
                self.warned = true;
                tracing::warn!(
                    "ros2: a JointState without a finite velocity for joint `{name}` ({} names, \
                     {} velocities): that joint's command is rejected (further ones are counted, \
                     not logged)",
                    m.name.len(),
                    m.velocity.len()
                );
            }
        }
    }

    /// Contact k's estimate on its topic; false when it failed.
    pub(super) fn publish_estimate(&self, k: usize, r: &EstimateRecord, frame: &str) -> bool {
        self.contacts
            .get(k)
            .is_some_and(|p| p.publish(r.to_wire(frame)).is_ok())
    }

    /// The efforts as a Float64MultiArray and as a JointState; false when
    /// either failed.
    pub(super) fn publish_efforts(&self, e: &JointEfforts, frame: &str) -> bool {
        let data = e.as_slice().to_vec();
        let n = data.len() as u32;
        let array = Float64MultiArray {
            layout: MultiArrayLayout {
                dim: vec![MultiArrayDimension {
                    label: "joints".into(),
                    size: n,
                    stride: n,
                }],
                data_offset: 0,
            },
            data: data.clone(),
        };
        let state = JointState {
            header: Header {
                stamp: Time::from_ns(e.stamp_ns),
                frame_id: frame.to_string(),
            },
            name: self.joints.clone(),
            effort: data,
            ..Default::default()
        };
        let a = self.efforts.publish(array).is_ok();
        let b = self.friction.publish(state).is_ok();
        a && b
    }
}

/// A peer's joint topics.
pub(super) struct JointPeer {
    commands: Publisher<JointState>,
    efforts: Subscription<Float64MultiArray>,
    contacts: Vec<Subscription<FrictionEstimate>>,
    next: usize,
    frame_id: String,
}

impl JointPeer {
    pub(super) fn open(
        n: &mut Node,
        spec: &Ros2Spec,
        cq: &QosProfile,
        eq: &QosProfile,
    ) -> Result<Self, TransportError> {
        let mut contacts = Vec::with_capacity(spec.topics.contact_friction.len());
        for t in &spec.topics.contact_friction {
            contacts.push(subscribe(
                n,
                t,
                &FRICTION_ESTIMATE,
                eq,
                "a contact's estimate",
            )?);
        }
        Ok(Self {
            commands: advertise(
                n,
                &spec.topics.joint_commands,
                &JOINT_STATE,
                cq,
                "the joint commands",
            )?,
            efforts: subscribe(
                n,
                &spec.topics.joint_efforts,
                &FLOAT64_MULTI_ARRAY,
                eq,
                "the joint efforts",
            )?,
            contacts,
            next: 0,
            frame_id: spec.frame_id.clone(),
        })
    }

    pub(super) fn send(&mut self, js: &JointStateCommand) -> Result<(), TransportError> {
        let m = JointState {
            header: Header {
                stamp: Time::from_ns(js.stamp_ns),
                frame_id: self.frame_id.clone(),
            },
            name: js.name.clone(),
            velocity: js.velocity.clone(),
            ..Default::default()
        };
        self.commands
            .publish(m)
            .map_err(|e| err(Operation::Send, "publish a JointState", e))
    }

    pub(super) fn try_recv_efforts(&mut self) -> Result<Option<JointEfforts>, TransportError> {
        match self.efforts.take() {
            // The stamp travels in the JointState twin; the array has none.
            Ok(m) => Ok(m.map(|(m, _)| JointEfforts::new(0, &m.data))),
            Err(e) => Err(err(Operation::Receive, "take joint efforts", e)),
        }
    }

    /// The next contact estimate, the contacts' topics taken in turn.
    pub(super) fn try_recv_contact(
        &mut self,
    ) -> Result<Option<(usize, EstimateRecord)>, TransportError> {
        let n = self.contacts.len();
        for i in 0..n {
            let k = (self.next + i) % n;
            match self.contacts[k].take() {
                Ok(Some((m, _))) => {
                    self.next = (k + 1) % n;
                    return Ok(Some((k, EstimateRecord::from_wire(&m))));
                }
                Ok(None) => {}
                Err(e) => return Err(err(Operation::Receive, "take a contact estimate", e)),
            }
        }
        Ok(None)
    }

    /// Whether the node's joint topics are matched (see
    /// [`PeerPort::is_matched`](crate::transport::PeerPort::is_matched)).
    pub(super) fn is_matched(&self, node: &Node) -> bool {
        use futures::FutureExt;
        self.commands
            .wait_for_subscription(node)
            .now_or_never()
            .is_some()
            && self
                .efforts
                .wait_for_publisher(node)
                .now_or_never()
                .is_some()
            && self
                .contacts
                .iter()
                .all(|c| c.wait_for_publisher(node).now_or_never().is_some())
    }
}
