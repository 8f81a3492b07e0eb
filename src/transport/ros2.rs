//! ROS 2 transport through ros2-client (pure-Rust DDS; no ROS install).
//!
//! The node's DDS entities live on an I/O thread: it waits in a `mio` poll on
//! the command subscriptions and on a waker the loop thread triggers after
//! queueing an output, moves commands into a bounded lock-free queue for the
//! loop, and publishes estimates (`FrictionEstimate` and the plain
//! `std_msgs/Float64` friction force), `FilmProfile` (from the shared profile
//! slot) and `LoopStatistics`. The loop never calls into DDS.
//!
//! Discovery follows the ROS 2 conventions: `ROS_DOMAIN_ID`, and
//! `ROS_AUTOMATIC_DISCOVERY_RANGE` / `ROS_LOCALHOST_ONLY` unless
//! `ros.discovery_range` overrides them. LOCALHOST (what shipped configs, tests
//! and CI use) builds the participant on the loopback interface only, so no
//! traffic leaves the host; discovery between processes then uses RustDDS's
//! same-host unicast announcements.

use super::{NodePort, PeerPort, ProfileSlot, TransportError};
use crate::config::{self, CommandType, Config, DiscoveryRange, QosConfig, Reliability};
use crate::msgs::{
    Command, CommandKind, EstimateRecord, FilmProfile, Float64, FrictionEstimate, Header,
    LoopStatistics, MsgType, StatisticsRecord, Time, TwistStamped, FILM_PROFILE, FLOAT64,
    FRICTION_ESTIMATE, LOOP_STATISTICS, TWIST_STAMPED,
};
use crossbeam_queue::ArrayQueue;
use ros2_client::dds::rustdds::mio1::{Events, Interest, Poll, Token, Waker};
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::{
    qos::{Durability, History, WhenFull},
    Context, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher, QosProfile,
    Subscription,
};
use std::net::Ipv4Addr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

const NAME: &str = "ros2";

fn err(op: impl Into<String>, e: impl std::fmt::Debug) -> TransportError {
    TransportError::backend(NAME, op, format!("{e:?}"))
}

/// Everything needed to open either side (Send).
#[derive(Debug, Clone, PartialEq)]
pub struct Ros2Spec {
    pub domain_id: u16,
    pub localhost_only: bool,
    pub namespace: String,
    pub node_name: String,
    pub command_type: CommandType,
    pub cmd_velocity: String,
    pub normal_load: String,
    pub friction: String,
    pub friction_force: String,
    pub film_profile: String,
    pub loop_statistics: String,
    pub command_qos: QosConfig,
    pub estimate_qos: QosConfig,
    pub frame_id: String,
    pub queue_capacity: usize,
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
            .ok_or_else(|| {
                err(
                    "read ROS_DOMAIN_ID",
                    format!("`{v}` is not a domain id in 0..=232"),
                )
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
    pub fn from_config(cfg: &Config) -> Result<Self, TransportError> {
        let r = &cfg.ros;
        let names = super::names::TopicNames::from_config(cfg);
        Ok(Self {
            domain_id: domain_id(cfg)?,
            localhost_only: localhost_only(cfg),
            namespace: r.namespace.clone(),
            node_name: r.node_name.clone(),
            command_type: r.command_type,
            cmd_velocity: names.cmd_velocity.clone(),
            normal_load: names.normal_load.clone(),
            friction: names.friction.clone(),
            friction_force: names.friction_force.clone(),
            film_profile: names.film_profile.clone(),
            loop_statistics: names.loop_statistics.clone(),
            command_qos: r.qos.commands.clone(),
            estimate_qos: r.qos.estimates.clone(),
            frame_id: cfg.node.frame_id.clone(),
            queue_capacity: cfg.node.queue_capacity,
        })
    }
}

fn qos(q: &QosConfig) -> QosProfile {
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

fn context(spec: &Ros2Spec) -> Result<Context, TransportError> {
    let mut b = DomainParticipantBuilder::new(spec.domain_id);
    if spec.localhost_only {
        b = b.with_only_networks([Ipv4Addr::LOCALHOST]);
    }
    let dp = b.build().map_err(|e| {
        err(
            format!("create a DDS participant on domain {}", spec.domain_id),
            e,
        )
    })?;
    Context::from_domain_participant(dp).map_err(|e| err("create a ROS 2 context", e))
}

fn ros_node(ctx: &Context, namespace: &str, name: &str) -> Result<Node, TransportError> {
    let nn = NodeName::new(namespace, name)
        .map_err(|e| err(format!("use node name `{namespace}` `{name}`"), e))?;
    let mut node = ctx
        .new_node(nn, NodeOptions::new().enable_rosout(false))
        .map_err(|e| err("create the ROS 2 node", e))?;
    // The spinner maintains the matched-endpoint counts (and answers
    // parameter services); it runs until the node is dropped.
    let spinner = node
        .spinner()
        .map_err(|e| err("create the node's spinner", e))?;
    std::thread::Builder::new()
        .name("ros2-spinner".into())
        .spawn(move || {
            let _ = futures::executor::block_on(spinner.spin());
        })
        .map_err(|e| err("start the spinner thread", e))?;
    Ok(node)
}

fn topic(
    node: &mut Node,
    name: &str,
    package: &str,
    ty: &str,
    q: &QosProfile,
) -> Result<ros2_client::dds::rustdds::Topic, TransportError> {
    let n = Name::parse(name).map_err(|e| err(format!("use topic name `{name}`"), e))?;
    node.create_topic(&n, MessageTypeName::new(package, ty), q)
        .map_err(|e| err(format!("create topic `{name}`"), e))
}

/// Create the topic and a publisher on it; `what` names it in errors.
fn advertise<M: serde::Serialize>(
    node: &mut Node,
    name: &str,
    ty: &MsgType,
    q: &QosProfile,
    what: &str,
) -> Result<Publisher<M>, TransportError> {
    let t = topic(node, name, ty.package, ty.name, q)?;
    node.create_publisher(&t, None)
        .map_err(|e| err(format!("advertise {what}"), e))
}

/// Create the topic and a subscription on it; `what` names it in errors.
fn subscribe<M: 'static>(
    node: &mut Node,
    name: &str,
    ty: &MsgType,
    q: &QosProfile,
    what: &str,
) -> Result<Subscription<M>, TransportError> {
    let t = topic(node, name, ty.package, ty.name, q)?;
    node.create_subscription(&t, None)
        .map_err(|e| err(format!("subscribe to {what}"), e))
}

enum VelocitySub {
    Float64(Subscription<Float64>),
    Twist(Subscription<TwistStamped>),
}

/// Output the loop hands to the I/O thread.
#[derive(Debug, Clone, Copy)]
enum Out {
    Estimate(EstimateRecord),
    Statistics(StatisticsRecord),
}

fn now_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as u64)
}

/// The node's side.
pub struct Ros2Node {
    commands: Arc<ArrayQueue<Command>>,
    outputs: Arc<ArrayQueue<Out>>,
    waker: Arc<Waker>,
    stop: Arc<AtomicBool>,
    /// Outputs the I/O thread could not publish (send window full).
    pub publish_failures: Arc<AtomicU64>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Ros2Node {
    pub fn open(
        spec: &Ros2Spec,
        profile: Option<Arc<ProfileSlot>>,
    ) -> Result<Self, TransportError> {
        let commands = Arc::new(ArrayQueue::new(spec.queue_capacity));
        let outputs = Arc::new(ArrayQueue::new(spec.queue_capacity));
        let stop = Arc::new(AtomicBool::new(false));
        let failures = Arc::new(AtomicU64::new(0));
        let (tx, rx) = std::sync::mpsc::channel::<Result<Arc<Waker>, TransportError>>();
        let (c, o, s, f, sp) = (
            commands.clone(),
            outputs.clone(),
            stop.clone(),
            failures.clone(),
            spec.clone(),
        );
        let thread = std::thread::Builder::new()
            .name("ros2-io".into())
            .spawn(move || io_thread(sp, c, o, s, f, profile, tx))
            .map_err(|e| err("start the I/O thread", e))?;
        let waker = rx.recv().map_err(|e| err("start the I/O thread", e))??;
        Ok(Self {
            commands,
            outputs,
            waker,
            stop,
            publish_failures: failures,
            thread: Some(thread),
        })
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
    }
}

impl NodePort for Ros2Node {
    fn name(&self) -> &'static str {
        NAME
    }

    fn poll_command(&mut self) -> Result<Option<Command>, TransportError> {
        Ok(self.commands.pop())
    }

    fn publish_estimate(&mut self, e: &EstimateRecord) -> bool {
        self.push(Out::Estimate(*e))
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
}

const VELOCITY: Token = Token(1);
const LOAD: Token = Token(2);
const WAKE: Token = Token(3);

fn io_thread(
    spec: Ros2Spec,
    commands: Arc<ArrayQueue<Command>>,
    outputs: Arc<ArrayQueue<Out>>,
    stop: Arc<AtomicBool>,
    failures: Arc<AtomicU64>,
    profile: Option<Arc<ProfileSlot>>,
    ready: std::sync::mpsc::Sender<Result<Arc<Waker>, TransportError>>,
) {
    // Set up; report the outcome to `open`.
    let setup = || -> Result<_, TransportError> {
        let ctx = context(&spec)?;
        let mut node = ros_node(&ctx, &spec.namespace, &spec.node_name)?;
        let cq = qos(&spec.command_qos);
        let eq = qos(&spec.estimate_qos);
        let n = &mut node;
        let mut velocity = match spec.command_type {
            CommandType::Float64 => VelocitySub::Float64(subscribe(
                n,
                &spec.cmd_velocity,
                &FLOAT64,
                &cq,
                "the velocity",
            )?),
            CommandType::TwistStamped => VelocitySub::Twist(subscribe(
                n,
                &spec.cmd_velocity,
                &TWIST_STAMPED,
                &cq,
                "the velocity",
            )?),
        };
        let mut load: Subscription<Float64> =
            subscribe(n, &spec.normal_load, &FLOAT64, &cq, "the load")?;
        let friction: Publisher<FrictionEstimate> =
            advertise(n, &spec.friction, &FRICTION_ESTIMATE, &eq, "the estimate")?;
        let force: Publisher<Float64> =
            advertise(n, &spec.friction_force, &FLOAT64, &eq, "the friction force")?;
        let film: Publisher<FilmProfile> = advertise(
            n,
            &spec.film_profile,
            &FILM_PROFILE,
            &eq,
            "the film profile",
        )?;
        let stats: Publisher<LoopStatistics> = advertise(
            n,
            &spec.loop_statistics,
            &LOOP_STATISTICS,
            &eq,
            "the statistics",
        )?;
        let poll = Poll::new().map_err(|e| err("create a poll", e))?;
        match &mut velocity {
            VelocitySub::Float64(s) => poll.registry().register(s, VELOCITY, Interest::READABLE),
            VelocitySub::Twist(s) => poll.registry().register(s, VELOCITY, Interest::READABLE),
        }
        .map_err(|e| err("register the velocity subscription", e))?;
        poll.registry()
            .register(&mut load, LOAD, Interest::READABLE)
            .map_err(|e| err("register the load subscription", e))?;
        let waker =
            Arc::new(Waker::new(poll.registry(), WAKE).map_err(|e| err("create a waker", e))?);
        Ok((
            ctx, node, velocity, load, friction, force, film, stats, poll, waker,
        ))
    };
    let (_ctx, _node, velocity, load, friction, force, film, stats, mut poll, waker) = match setup()
    {
        Ok(v) => v,
        Err(e) => {
            let _ = ready.send(Err(e));
            return;
        }
    };
    let _ = ready.send(Ok(waker));
    let mut events = Events::with_capacity(16);
    let mut seen_profile = 0u64;
    let header = |stamp_ns: u64| Header {
        stamp: Time::from_ns(stamp_ns),
        frame_id: spec.frame_id.clone(),
    };
    let fail = |ok: bool| {
        if !ok {
            failures.fetch_add(1, Ordering::Relaxed);
        }
    };
    while !stop.load(Ordering::Acquire) {
        // Wake on commands, on outputs (the waker), or every 20 ms for profiles.
        let _ = poll.poll(&mut events, Some(Duration::from_millis(20)));
        loop {
            let msg = match &velocity {
                VelocitySub::Float64(s) => s.take().ok().flatten().map(|(m, info)| {
                    let stamp = info
                        .source_timestamp()
                        .map_or_else(now_ns, |t| t.to_nanos().max(0) as u64);
                    (m.data, stamp)
                }),
                VelocitySub::Twist(s) => s
                    .take()
                    .ok()
                    .flatten()
                    .map(|(m, _)| (m.twist.linear.x, m.header.stamp.to_ns())),
            };
            let Some((value, stamp_ns)) = msg else { break };
            commands.force_push(Command {
                kind: CommandKind::Velocity,
                value,
                stamp_ns,
            });
        }
        while let Ok(Some((m, info))) = load.take() {
            let stamp = info
                .source_timestamp()
                .map_or_else(now_ns, |t| t.to_nanos().max(0) as u64);
            commands.force_push(Command {
                kind: CommandKind::Load,
                value: m.data,
                stamp_ns: stamp,
            });
        }
        while let Some(o) = outputs.pop() {
            match o {
                Out::Estimate(e) => {
                    fail(friction.publish(e.to_wire(&spec.frame_id)).is_ok());
                    fail(
                        force
                            .publish(Float64 {
                                data: e.friction_force_n,
                            })
                            .is_ok(),
                    );
                }
                Out::Statistics(s) => fail(stats.publish(s.to_wire(&spec.frame_id)).is_ok()),
            }
        }
        if let Some(slot) = &profile {
            if let Some(p) = slot.read_if_newer(&mut seen_profile) {
                fail(
                    film.publish(FilmProfile {
                        header: header(p.stamp_ns),
                        dx_m: p.dx_m,
                        h_m: p.h_m,
                        p_pa: p.p_pa,
                    })
                    .is_ok(),
                );
            }
        }
    }
}

/// A peer's side (its own participant and node on the same domain).
pub struct Ros2Peer {
    node: Node,
    _ctx: Context,
    velocity_f64: Option<Publisher<Float64>>,
    velocity_twist: Option<Publisher<TwistStamped>>,
    load: Publisher<Float64>,
    estimate: Subscription<FrictionEstimate>,
    frame_id: String,
}

static PEER_COUNTER: AtomicU64 = AtomicU64::new(0);

impl Ros2Peer {
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
                    &spec.cmd_velocity,
                    &FLOAT64,
                    &cq,
                    "the velocity",
                )?);
            }
            CommandType::TwistStamped => {
                vt = Some(advertise(
                    n,
                    &spec.cmd_velocity,
                    &TWIST_STAMPED,
                    &cq,
                    "the velocity",
                )?);
            }
        }
        let load = advertise(n, &spec.normal_load, &FLOAT64, &cq, "the load")?;
        let estimate = subscribe(n, &spec.friction, &FRICTION_ESTIMATE, &eq, "the estimate")?;
        Ok(Self {
            node,
            _ctx: ctx,
            velocity_f64: vf,
            velocity_twist: vt,
            load,
            estimate,
            frame_id: spec.frame_id.clone(),
        })
    }
}

impl PeerPort for Ros2Peer {
    fn name(&self) -> &'static str {
        NAME
    }

    fn send(&mut self, c: &Command) -> Result<(), TransportError> {
        let r = match (c.kind, &self.velocity_f64, &self.velocity_twist) {
            (CommandKind::Load, _, _) => self
                .load
                .publish(Float64 { data: c.value })
                .map_err(|e| format!("{e:?}")),
            (CommandKind::Velocity, Some(p), _) => p
                .publish(Float64 { data: c.value })
                .map_err(|e| format!("{e:?}")),
            (CommandKind::Velocity, None, Some(p)) => {
                let mut m = TwistStamped {
                    header: Header {
                        stamp: Time::from_ns(c.stamp_ns),
                        frame_id: self.frame_id.clone(),
                    },
                    ..Default::default()
                };
                m.twist.linear.x = c.value;
                p.publish(m).map_err(|e| format!("{e:?}"))
            }
            (CommandKind::Velocity, None, None) => Err("no velocity publisher".into()),
        };
        r.map_err(|e| err("publish a command", e))
    }

    fn try_recv(&mut self) -> Result<Option<EstimateRecord>, TransportError> {
        match self.estimate.take() {
            Ok(m) => Ok(m.map(|(m, _)| EstimateRecord::from_wire(&m))),
            Err(e) => Err(err("take an estimate", e)),
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
