//! ROS 2 transport through ros2-client (pure-Rust DDS; no ROS install).
//!
//! The node's DDS entities live on an I/O thread (`io.rs`): it waits in a
//! `mio` poll on the command readers and on a waker the loop thread triggers
//! after queueing an output, moves commands into a bounded lock-free queue
//! for the loop (counting the ones a full queue overwrites), hands each
//! received sample's CDR bytes unchanged to the recorder (`raw.rs`), and
//! publishes estimates (`FrictionEstimate` and the plain `std_msgs/Float64`
//! friction force), `FilmProfile` (from the shared profile slot) and
//! `LoopStatistics`, counting what fails. The loop never calls into DDS.
//! With several contacts (`joints.rs`), JointState commands by joint name
//! in, and the efforts (`Float64MultiArray`, `JointState`) and each
//! contact's `FrictionEstimate` out.
//!
//! Discovery follows the ROS 2 conventions: `ROS_DOMAIN_ID`, and
//! `ROS_AUTOMATIC_DISCOVERY_RANGE` / `ROS_LOCALHOST_ONLY` unless
//! `ros.discovery_range` overrides them. LOCALHOST (what shipped configs, tests
//! and CI use) builds the participant on the loopback interface only, so no
//! traffic leaves the host; discovery between processes then uses RustDDS's
//! same-host unicast announcements.
//!
//! | file | job |
//! |---|---|
//! | `mod.rs` | the transport: participant, topics, QoS, the loop's side |
//! | `io.rs` | the I/O thread: commands in, estimates and statistics out |
//! | `raw.rs` | command samples as raw CDR bytes, decoded off the loop |
//! | `joints.rs` | several contacts: JointState in, per-contact estimates out |
//! | `rosout.rs` | the node's log lines for `/rosout` (a `tracing` layer) |
//! | `diagnostics.rs` | `/diagnostics`: the loop's health as a DiagnosticArray |
//! | `params.rs` | the node's services: parameters, reset, on their own thread |
//! | `service.rs` | one service served in both DDS layouts ROS 2 uses |
//! | `peer.rs` | a peer's side (tests, demo driver): its own participant on loopback |

pub mod diagnostics;
mod io;
mod joints;
pub mod params;
mod peer;
pub mod raw;
pub mod rosout;
pub mod service;

pub use peer::Ros2Peer;

use super::{NodePort, PortCounters, PortIo, SharedCounters, TransportError};
use crate::config::topics::TopicNames;
use crate::config::OutputPlan;
use crate::config::{self, CommandType, Config, DiscoveryRange, QosConfig, Reliability};
use crate::msgs::{Command, EstimateRecord, MsgType, StatisticsRecord};
use crate::transport::Operation;
use crossbeam_queue::ArrayQueue;
use ros2_client::dds::rustdds::mio1::Waker;
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::{
    qos::{Durability, History, WhenFull},
    Context, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher, QosProfile,
    Subscription,
};
use std::net::Ipv4Addr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

pub(super) const NAME: &str = "ros2";

pub(super) fn err(
    kind: Operation,
    op: impl Into<String>,
    e: impl std::fmt::Debug,
) -> TransportError {
    TransportError::middleware(NAME, kind, op, e)
}

/// Everything needed to open either side (Send).
#[derive(Debug, Clone, PartialEq)]
pub struct Ros2Spec {
    /// The DDS domain.
    pub domain_id: u16,
    /// Discovery and traffic on loopback only.
    pub localhost_only: bool,
    /// The node's namespace.
    pub namespace: String,
    /// The node's name.
    pub node_name: String,
    /// Float64 or TwistStamped velocity commands.
    pub command_type: CommandType,
    /// Every topic, resolved from the configuration.
    pub topics: TopicNames,
    /// QoS of the command topics.
    pub command_qos: QosConfig,
    /// QoS of the output topics.
    pub estimate_qos: QosConfig,
    /// The frame id of published messages.
    pub frame_id: String,
    /// Capacity of each output queue.
    pub queue_capacity: usize,
    /// One contact, or joints (their configured order).
    pub plan: OutputPlan,
}

/// The domain id: the config's, else `ROS_DOMAIN_ID`, else 0.
pub fn domain_id(cfg: &Config) -> Result<u16, TransportError> {
    if cfg.ros.domain_id >= 0 {
        return Ok(cfg.ros.domain_id as u16);
    }
    match std::env::var("ROS_DOMAIN_ID") {
        Ok(v) if !v.trim().is_empty() => v
            .trim()
            .parse::<u16>()
            .ok()
            .filter(|d| *d <= 232)
            .ok_or_else(|| TransportError::Open {
                backend: NAME,
                operation: "read ROS_DOMAIN_ID".into(),
                message: format!("`{v}` is not a domain id in 0..=232"),
            }),
        _ => Ok(0),
    }
}

/// Whether discovery stays on loopback: the config's range, or (range `env`)
/// `ROS_AUTOMATIC_DISCOVERY_RANGE` / `ROS_LOCALHOST_ONLY` as in ROS 2.
pub fn localhost_only(cfg: &Config) -> bool {
    match cfg.ros.discovery_range {
        DiscoveryRange::Localhost | DiscoveryRange::Off => true,
        DiscoveryRange::Subnet => false,
        DiscoveryRange::Env => {
            match std::env::var("ROS_AUTOMATIC_DISCOVERY_RANGE").map(|s| s.to_ascii_uppercase()) {
                Ok(r) if r == "LOCALHOST" || r == "OFF" => true,
                Ok(r) if r == "SUBNET" || r == "SYSTEM_DEFAULT" => false,
                _ => std::env::var("ROS_LOCALHOST_ONLY").is_ok_and(|v| v.trim() == "1"),
            }
        }
    }
}

impl Ros2Spec {
    /// `/<namespace>/<node_name>`.
    pub fn fully_qualified_name(&self) -> String {
        let ns = self.namespace.trim_end_matches('/');
        format!("{ns}/{}", self.node_name)
    }

    /// The spec of `cfg`.
    pub fn from_config(cfg: &Config) -> Result<Self, TransportError> {
        let r = &cfg.ros;
        Ok(Self {
            domain_id: domain_id(cfg)?,
            localhost_only: localhost_only(cfg),
            namespace: r.namespace.clone(),
            node_name: r.node_name.clone(),
            command_type: r.command_type,
            topics: TopicNames::from_config(cfg),
            command_qos: r.qos.commands.clone(),
            estimate_qos: r.qos.estimates.clone(),
            frame_id: cfg.node.frame_id.clone(),
            queue_capacity: cfg.node.queue_capacity,
            plan: cfg.output_plan(),
        })
    }
}

pub(super) fn qos(q: &QosConfig) -> QosProfile {
    let base = QosProfile::subscription_default()
        .durability(match q.durability {
            config::Durability::Volatile => Durability::Volatile,
            config::Durability::TransientLocal => Durability::TransientLocal,
        })
        .history(History::KeepLast { depth: q.depth });
    match q.reliability {
        Reliability::BestEffort => base.reliability_best_effort(),
        // The I/O thread may wait a little for the send window, never the loop.
        Reliability::Reliable => {
            base.reliability_reliable(WhenFull::Wait(Duration::from_millis(5)))
        }
    }
}

pub(super) fn context(spec: &Ros2Spec) -> Result<Context, TransportError> {
    let mut b = DomainParticipantBuilder::new(spec.domain_id);
    if spec.localhost_only {
        b = b.with_only_networks([Ipv4Addr::LOCALHOST]);
    }
    let dp = b.build().map_err(|e| {
        err(
            Operation::Open,
            format!("create a DDS participant on domain {}", spec.domain_id),
            e,
        )
    })?;
    Context::from_domain_participant(dp)
        .map_err(|e| err(Operation::Open, "create a ROS 2 context", e))
}

pub(super) fn ros_node(ctx: &Context, namespace: &str, name: &str) -> Result<Node, TransportError> {
    let nn = NodeName::new(namespace, name).map_err(|e| {
        err(
            Operation::Open,
            format!("use node name `{namespace}` `{name}`"),
            e,
        )
    })?;
    let mut node = ctx
        .new_node(
            nn,
            NodeOptions::new()
                .enable_rosout(false)
                // Parameters are served by `params.rs`, in both DDS layouts.
                .start_parameter_services(false),
        )
        .map_err(|e| err(Operation::Open, "create the ROS 2 node", e))?;
    // The spinner maintains the matched-endpoint counts (and answers
    // parameter services); it runs until the node is dropped.
    let spinner = node
        .spinner()
        .map_err(|e| err(Operation::Open, "create the node's spinner", e))?;
    std::thread::Builder::new()
        .name("ros2-spinner".into())
        .spawn(move || {
            let _ = futures::executor::block_on(spinner.spin());
        })
        .map_err(|e| err(Operation::Open, "start the spinner thread", e))?;
    Ok(node)
}

pub(super) fn topic(
    node: &mut Node,
    name: &str,
    package: &str,
    ty: &str,
    q: &QosProfile,
) -> Result<ros2_client::dds::rustdds::Topic, TransportError> {
    let n = Name::parse(name)
        .map_err(|e| err(Operation::Open, format!("use topic name `{name}`"), e))?;
    node.create_topic(&n, MessageTypeName::new(package, ty), q)
        .map_err(|e| err(Operation::Open, format!("create topic `{name}`"), e))
}

/// Create the topic and a publisher on it; `what` names it in errors.
pub(super) fn advertise<M: serde::Serialize>(
    node: &mut Node,
    name: &str,
    ty: &MsgType,
    q: &QosProfile,
    what: &str,
) -> Result<Publisher<M>, TransportError> {
    let t = topic(node, name, ty.package, ty.name, q)?;
    node.create_publisher(&t, None)
        .map_err(|e| err(Operation::Open, format!("advertise {what}"), e))
}

/// Create the topic and a subscription on it; `what` names it in errors.
pub(super) fn subscribe<M: 'static>(
    node: &mut Node,
    name: &str,
    ty: &MsgType,
    q: &QosProfile,
    what: &str,
) -> Result<Subscription<M>, TransportError> {
    let t = topic(node, name, ty.package, ty.name, q)?;
    node.create_subscription(&t, None)
        .map_err(|e| err(Operation::Open, format!("subscribe to {what}"), e))
}

/// Output the loop hands to the I/O thread (through a preallocated
/// queue: boxing the statistics would allocate on the loop).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy)]
enum Out {
    Estimate(EstimateRecord),
    /// Several contacts: contact k's estimate.
    ContactEstimate(usize, EstimateRecord),
    /// Several contacts: the efforts in joint order.
    Efforts(crate::transport::JointEfforts),
    Statistics(StatisticsRecord),
}

/// The node's side.
pub struct Ros2Node {
    commands: Arc<ArrayQueue<Command>>,
    outputs: Arc<ArrayQueue<Out>>,
    waker: Arc<Waker>,
    stop: Arc<AtomicBool>,
    counters: Arc<SharedCounters>,
    thread: Option<std::thread::JoinHandle<()>>,
    /// The services thread (parameters, ~/snapshot).
    services: Option<std::thread::JoinHandle<()>>,
    /// Driven by joints (the output plan): estimates go to the per-contact topics.
    by_joint: bool,
}

impl Ros2Node {
    /// Open the node side on its own I/O thread.
    pub fn open(spec: &Ros2Spec, io: PortIo) -> Result<Self, TransportError> {
        let commands = Arc::new(ArrayQueue::new(spec.queue_capacity));
        let outputs = Arc::new(ArrayQueue::new(spec.queue_capacity));
        let stop = Arc::new(AtomicBool::new(false));
        let counters = Arc::new(SharedCounters::default());
        let (tx, rx) = std::sync::mpsc::channel::<Result<(Arc<Waker>, Context), TransportError>>();
        let shared = io::Shared {
            spec: spec.clone(),
            commands: commands.clone(),
            outputs: outputs.clone(),
            stop: stop.clone(),
            counters: counters.clone(),
            film_profile: io.film_profile,
            record: io.record.clone(),
            snapshot: io.snapshot.clone(),
            sim_time: io.sim_time.clone(),
        };
        let thread = std::thread::Builder::new()
            .name("ros2-io".into())
            .spawn(move || io::run(shared, tx))
            .map_err(|e| err(Operation::Open, "start the I/O thread", e))?;
        let (waker, ctx) = rx
            .recv()
            .map_err(|e| err(Operation::Open, "start the I/O thread", e))??;
        let mut node = Self {
            commands,
            outputs,
            waker,
            stop,
            counters,
            thread: Some(thread),
            services: None,
            by_joint: spec.plan.by_joint(),
        };
        if let Some(p) = io.parameters {
            let (tx, rx) = std::sync::mpsc::channel();
            let fqn = spec.fully_qualified_name();
            let (record, snapshot, stop) = (io.record, io.snapshot, node.stop.clone());
            let t = std::thread::Builder::new()
                .name("ros2-services".into())
                .spawn(move || params::run(ctx, fqn, p, record, snapshot, stop, tx))
                .map_err(|e| err(Operation::Open, "start the services thread", e))?;
            node.services = Some(t);
            rx.recv()
                .map_err(|e| err(Operation::Open, "start the services thread", e))??;
        }
        Ok(node)
    }

    fn push(&mut self, o: Out) -> bool {
        let ok = self.outputs.push(o).is_ok();
        let _ = self.waker.wake();
        ok
    }
}

impl Drop for Ros2Node {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        let _ = self.waker.wake();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        if let Some(t) = self.services.take() {
            let _ = t.join();
        }
    }
}

impl NodePort for Ros2Node {
    fn name(&self) -> &'static str {
        NAME
    }

    fn poll_command(&mut self) -> Result<Option<Command>, TransportError> {
        Ok(self.commands.pop())
    }

    fn publish_estimate(&mut self, contact: usize, e: &EstimateRecord) -> bool {
        if self.by_joint {
            self.push(Out::ContactEstimate(contact, *e))
        } else {
            self.push(Out::Estimate(*e))
        }
    }

    fn publish_efforts(&mut self, stamp_ns: u64, efforts: &[f64]) -> bool {
        self.push(Out::Efforts(crate::transport::JointEfforts::new(
            stamp_ns, efforts,
        )))
    }

    fn publish_statistics(&mut self, s: &StatisticsRecord) -> bool {
        self.push(Out::Statistics(*s))
    }

    fn wait_for_command(&mut self, timeout: Duration) -> Result<(), TransportError> {
        let start = Instant::now();
        while self.commands.is_empty() && start.elapsed() < timeout {
            std::thread::sleep(Duration::from_micros(20));
        }
        Ok(())
    }

    fn counters(&self) -> PortCounters {
        self.counters.snapshot()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shipped_config_keeps_discovery_on_localhost_whatever_the_environment() {
        let c = Config::default();
        assert_eq!(c.ros.discovery_range, DiscoveryRange::Localhost);
        assert!(localhost_only(&c));
    }
}
