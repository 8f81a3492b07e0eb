//! The ROS 2 node's I/O thread: commands in (raw samples, decoded here and
//! recorded unchanged), estimates, film profiles and statistics out.

use super::raw::{RawAdapter, RawCdr};
use super::{advertise, context, err, qos, ros_node, topic, Out, Ros2Spec};
use crate::clock::system_wall_ns;
use crate::config::CommandType;
use crate::link::FilmProfileSlot;
use crate::link::RecordItem;
use crate::msgs::{
    self, command_codec, Command, CommandKind, FilmProfile, Float64, FrictionEstimate, Header,
    LoopStatistics, RawSample, Time, FILM_PROFILE, FLOAT64, FRICTION_ESTIMATE, LOOP_STATISTICS,
    TWIST_STAMPED,
};
use crate::transport::Operation;
use crate::transport::{record_input, RecordQueue, SharedCounters, TransportError};
use crossbeam_queue::ArrayQueue;
use ros2_client::dds::rustdds::mio1::{Events, Interest, Poll, Token, Waker};
use ros2_client::dds::rustdds::no_key::SimpleDataReader;
use ros2_client::dds::rustdds::QosPolicies;
use ros2_client::Publisher;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// What the I/O thread shares with the node's port.
pub(super) struct Shared {
    pub spec: Ros2Spec,
    pub commands: Arc<ArrayQueue<Command>>,
    pub outputs: Arc<ArrayQueue<Out>>,
    pub stop: Arc<AtomicBool>,
    pub counters: Arc<SharedCounters>,
    pub film_profile: Option<Arc<FilmProfileSlot>>,
    pub record: RecordQueue,
    pub snapshot: Option<Arc<AtomicBool>>,
    /// `use_sim_time`: the clock `/clock` drives.
    pub sim_time: Option<Arc<crate::clock::ExternalClock>>,
}

type RawReader = SimpleDataReader<RawCdr, RawAdapter>;

const VELOCITY: Token = Token(1);
const LOAD: Token = Token(2);
const WAKE: Token = Token(3);
const TEMPERATURE: Token = Token(4);
const CLOCK: Token = Token(5);
const JOINTS: Token = Token(6);

/// The DDS entities of the node.
struct Entities {
    ctx: ros2_client::Context,
    _node: ros2_client::Node,
    velocity: RawReader,
    load: RawReader,
    temperature: RawReader,
    out: Publishers,
    snapshot: Option<ros2_client::Subscription<msgs::Empty>>,
    clock: Option<ros2_client::Subscription<msgs::ros_interfaces::Clock>>,
    poll: Poll,
    waker: Arc<Waker>,
    /// Several contacts: the joint topics.
    joints: Option<super::joints::JointTopics>,
}

/// The node's publishers (one contact's; several contacts' are in
/// `joints`).
struct Publishers {
    friction: Publisher<FrictionEstimate>,
    force: Publisher<Float64>,
    film: Publisher<FilmProfile>,
    stats: Publisher<LoopStatistics>,
    rosout: Publisher<msgs::ros_interfaces::Log>,
    diagnostics: Publisher<msgs::ros_interfaces::DiagnosticArray>,
}

/// The three command readers: velocity, load, temperature.
fn command_readers(
    ctx: &ros2_client::Context,
    n: &mut ros2_client::Node,
    spec: &Ros2Spec,
) -> Result<[RawReader; 3], TransportError> {
    let cq = qos(&spec.command_qos);
    let velocity_type = match spec.command_type {
        CommandType::Float64 => &FLOAT64,
        CommandType::TwistStamped => &TWIST_STAMPED,
    };
    let subscriber = ctx
        .domain_participant()
        .create_subscriber(&QosPolicies::from(&cq))
        .map_err(|e| err(Operation::Open, "create a DDS subscriber", e))?;
    let mut raw_reader = |name: &str, ty: &msgs::MsgType, what: &str| {
        let t = topic(n, name, ty.package, ty.name, &cq)?;
        subscriber
            .create_simple_datareader_no_key::<RawCdr, RawAdapter>(&t, Some(QosPolicies::from(&cq)))
            .map_err(|e| err(Operation::Open, format!("subscribe to {what}"), e))
    };
    Ok([
        raw_reader(&spec.topics.cmd_velocity, velocity_type, "the velocity")?,
        raw_reader(&spec.topics.normal_load, &FLOAT64, "the load")?,
        raw_reader(
            &spec.topics.temperature,
            &msgs::TEMPERATURE,
            "the temperature",
        )?,
    ])
}

impl Publishers {
    fn open(n: &mut ros2_client::Node, spec: &Ros2Spec) -> Result<Self, TransportError> {
        let eq = qos(&spec.estimate_qos);
        let t = &spec.topics;
        // /rosout as rcl offers it: reliable, transient local, keep last 1000.
        let rosout_qos = ros2_client::QosProfile::publisher_default()
            .durability(ros2_client::qos::Durability::TransientLocal)
            .history(ros2_client::qos::History::KeepLast { depth: 1000 });
        let diagnostics_qos = ros2_client::QosProfile::publisher_default()
            .history(ros2_client::qos::History::KeepLast { depth: 10 });
        Ok(Self {
            friction: advertise(n, &t.friction, &FRICTION_ESTIMATE, &eq, "the estimate")?,
            force: advertise(n, &t.friction_force, &FLOAT64, &eq, "the friction force")?,
            film: advertise(n, &t.film_profile, &FILM_PROFILE, &eq, "the film profile")?,
            stats: advertise(
                n,
                &t.loop_statistics,
                &LOOP_STATISTICS,
                &eq,
                "the statistics",
            )?,
            rosout: advertise(
                n,
                "/rosout",
                &msgs::ros_interfaces::LOG,
                &rosout_qos,
                "/rosout",
            )?,
            diagnostics: advertise(
                n,
                "/diagnostics",
                &msgs::ros_interfaces::DIAGNOSTIC_ARRAY,
                &diagnostics_qos,
                "/diagnostics",
            )?,
        })
    }
}

fn setup(spec: &Ros2Spec, snapshots: bool, sim_time: bool) -> Result<Entities, TransportError> {
    let ctx = context(spec)?;
    let mut node = ros_node(&ctx, &spec.namespace, &spec.node_name)?;
    let cq = qos(&spec.command_qos);
    let eq = qos(&spec.estimate_qos);
    let n = &mut node;
    let [mut velocity, mut load, mut temperature] = command_readers(&ctx, n, spec)?;
    let out = Publishers::open(n, spec)?;
    let snapshot = snapshots
        .then(|| {
            let what = "the snapshot request";
            super::subscribe(n, &spec.topics.snapshot, &msgs::EMPTY, &cq, what)
        })
        .transpose()?;
    // /clock for use_sim_time: keep last 1, best effort (matches every
    // publisher), polled with the commands so that time moves at once.
    let mut clock = sim_time
        .then(|| {
            let q = ros2_client::QosProfile::subscription_default();
            super::subscribe(n, "/clock", &msgs::ros_interfaces::CLOCK, &q, "/clock")
        })
        .transpose()?;
    let mut joints = (spec.plan.by_joint())
        .then(|| super::joints::JointTopics::open(n, spec, &cq, &eq))
        .transpose()?;
    let poll = Poll::new().map_err(|e| err(Operation::Open, "create a poll", e))?;
    let registry = poll.registry();
    let register = |source: &mut dyn ros2_client::dds::rustdds::mio1::event::Source,
                    token: Token,
                    what: &str| {
        registry
            .register(source, token, Interest::READABLE)
            .map_err(|e| err(Operation::Open, format!("register {what}"), e))
    };
    register(&mut velocity, VELOCITY, "the velocity reader")?;
    register(&mut load, LOAD, "the load reader")?;
    register(&mut temperature, TEMPERATURE, "the temperature reader")?;
    if let Some(c) = clock.as_mut() {
        register(c, CLOCK, "/clock")?;
    }
    if let Some(j) = joints.as_mut() {
        register(&mut j.commands, JOINTS, "the joint commands")?;
    }
    let waker = Arc::new(
        Waker::new(registry, WAKE).map_err(|e| err(Operation::Open, "create a waker", e))?,
    );
    Ok(Entities {
        ctx,
        _node: node,
        velocity,
        load,
        temperature,
        out,
        snapshot,
        clock,
        poll,
        waker,
        joints,
    })
}

/// Decode a raw command sample: (value, stamp by the stamp rule, the
/// sender's publish time, else now). An undecodable sample becomes a NaN
/// command, which the loop rejects and counts.
fn decode(kind: CommandKind, ty: CommandType, raw: &[u8], source_ns: Option<u64>) -> (f64, u64) {
    let fallback = || source_ns.unwrap_or_else(system_wall_ns);
    match command_codec::decode(kind, ty, raw) {
        Ok((value, header_ns)) => (value, command_codec::stamp_or(header_ns, fallback)),
        Err(_) => (f64::NAN, fallback()),
    }
}

/// An RTPS timestamp (seconds, 2^-32 s fraction) in ns since the epoch.
fn ticks_to_ns(ticks: u64) -> u64 {
    let seconds = ticks >> 32;
    let fraction = ticks & 0xFFFF_FFFF;
    seconds * 1_000_000_000 + ((fraction * 1_000_000_000) >> 32)
}

/// Take every pending sample of one reader.
fn take_all(sh: &Shared, reader: &RawReader, kind: CommandKind) {
    reader.drain_read_notifications();
    loop {
        let sample = match reader.try_take_one() {
            Ok(Some(s)) => s,
            Ok(None) => break,
            Err(e) => {
                tracing::debug!("ros2: taking a command failed: {e:?}");
                break;
            }
        };
        let received_ns = system_wall_ns();
        let source_ns = sample.source_timestamp().map(|t| ticks_to_ns(t.to_ticks()));
        let RawCdr(cdr) = sample.into_value();
        let (value, stamp_ns) = decode(kind, sh.spec.command_type, &cdr, source_ns);
        SharedCounters::bump(&sh.counters.received);
        if sh
            .commands
            .force_push(Command {
                kind,
                value,
                stamp_ns,
            })
            .is_some()
        {
            SharedCounters::bump(&sh.counters.overwritten);
        }
        if sh.record.is_some() {
            let item = RecordItem::Raw(RawSample {
                kind,
                cdr,
                publish_ns: source_ns.unwrap_or(stamp_ns),
                received_ns,
            });
            record_input(&sh.record, item, &sh.counters);
        }
    }
}

pub(super) fn run(
    sh: Shared,
    ready: std::sync::mpsc::Sender<Result<(Arc<Waker>, ros2_client::Context), TransportError>>,
) {
    let mut e = match setup(&sh.spec, sh.snapshot.is_some(), sh.sim_time.is_some()) {
        Ok(e) => e,
        Err(x) => {
            let _ = ready.send(Err(x));
            return;
        }
    };
    let _ = ready.send(Ok((e.waker.clone(), e.ctx.clone())));
    let mut events = Events::with_capacity(16);
    let mut outgoing = Outgoing::new(&sh.spec);
    while !sh.stop.load(Ordering::Acquire) {
        // Wake on commands, on outputs (the waker), or every 20 ms for film profiles.
        let _ = e.poll.poll(&mut events, Some(Duration::from_millis(20)));
        take_inputs(&sh, &mut e);
        while let Some(o) = sh.outputs.pop() {
            outgoing.publish(&e, o, &sh.counters);
        }
        outgoing.rosout(&e.out);
        if let Some(slot) = &sh.film_profile {
            outgoing.film_profile(&e.out, slot, &sh.counters);
        }
    }
    drop(e);
}

/// Everything that came in: the clock, the commands, the snapshot request.
fn take_inputs(sh: &Shared, e: &mut Entities) {
    if let (Some(sub), Some(clock)) = (&e.clock, &sh.sim_time) {
        while let Ok(Some((m, _))) = sub.take() {
            clock.set(m.clock.to_ns());
        }
    }
    take_all(sh, &e.velocity, CommandKind::Velocity);
    take_all(sh, &e.load, CommandKind::Load);
    take_all(sh, &e.temperature, CommandKind::Temperature);
    if let Some(j) = e.joints.as_mut() {
        j.take(&sh.commands, &sh.counters);
    }
    if let (Some(sub), Some(flag)) = (&e.snapshot, &sh.snapshot) {
        while let Ok(Some(_)) = sub.take() {
            flag.store(true, Ordering::Release);
        }
    }
}

/// Counts a failed publish in `which`.
fn count(ok: bool, which: &std::sync::atomic::AtomicU64) {
    if !ok {
        SharedCounters::bump(which);
    }
}

/// What goes out, and what publishing remembers between turns.
struct Outgoing {
    frame: String,
    fqn: String,
    /// rcl's logger name: the node's name with `.` between namespace tokens.
    logger: String,
    diagnostics: super::diagnostics::HealthReporter,
    last_diagnostics: Option<std::time::Instant>,
    seen_film_profile: u64,
}

impl Outgoing {
    fn new(spec: &Ros2Spec) -> Self {
        let fqn = spec.fully_qualified_name();
        Self {
            frame: spec.frame_id.clone(),
            logger: fqn.trim_start_matches('/').replace('/', "."),
            fqn,
            diagnostics: Default::default(),
            last_diagnostics: None,
            seen_film_profile: 0,
        }
    }

    /// One output of the loop.
    fn publish(&mut self, e: &Entities, o: Out, counters: &SharedCounters) {
        let frame = &self.frame;
        match o {
            Out::Estimate(r) => {
                count(
                    e.out.friction.publish(r.to_wire(frame)).is_ok(),
                    &counters.publish_failures,
                );
                let force = Float64 {
                    data: r.friction_force_n,
                };
                count(
                    e.out.force.publish(force).is_ok(),
                    &counters.publish_failures,
                );
            }
            Out::ContactEstimate(k, r) => count(
                e.joints
                    .as_ref()
                    .is_some_and(|j| j.publish_estimate(k, &r, frame)),
                &counters.publish_failures,
            ),
            Out::Efforts(x) => count(
                e.joints
                    .as_ref()
                    .is_some_and(|j| j.publish_efforts(&x, frame)),
                &counters.publish_failures,
            ),
            Out::Statistics(s) => {
                count(
                    e.out.stats.publish(s.to_wire(frame)).is_ok(),
                    &counters.statistics_failures,
                );
                // /diagnostics at most once a second.
                let a = self.diagnostics.update(&s, &self.fqn, frame);
                if self
                    .last_diagnostics
                    .is_none_or(|t| t.elapsed() >= Duration::from_millis(990))
                {
                    self.last_diagnostics = Some(std::time::Instant::now());
                    count(
                        e.out.diagnostics.publish(a).is_ok(),
                        &counters.publish_failures,
                    );
                }
            }
        }
    }

    /// The log lines waiting for /rosout.
    fn rosout(&self, out: &Publishers) {
        super::rosout::drain(|l| {
            let m = msgs::ros_interfaces::Log {
                stamp: Time::from_ns(l.stamp_ns),
                level: l.level,
                name: self.logger.clone(),
                msg: l.message,
                file: l.file,
                function: l.target,
                line: l.line,
            };
            let _ = out.rosout.publish(m);
        });
    }

    /// The film profile, when the slot holds a newer one.
    fn film_profile(
        &mut self,
        out: &Publishers,
        slot: &FilmProfileSlot,
        counters: &SharedCounters,
    ) {
        if let Some(p) = slot.read_if_newer(&mut self.seen_film_profile) {
            let m = FilmProfile {
                header: Header {
                    stamp: Time::from_ns(p.stamp_ns),
                    frame_id: self.frame.clone(),
                },
                dx_m: p.dx_m,
                h_m: p.h_m,
                p_pa: p.p_pa,
            };
            count(out.film.publish(m).is_ok(), &counters.publish_failures);
        }
    }
}
