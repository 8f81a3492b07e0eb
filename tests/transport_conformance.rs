//! One conformance suite, run against every transport backend: in-memory,
//! iceoryx2 and ROS 2 (loopback-only discovery, unique domain and names).
//!
//! A peer drives a lockstep node with a velocity profile over the real
//! command topic/service and receives the estimates, which must equal the
//! offline `simulate` of the same profile bit for bit. Then bad input: a
//! non-finite velocity is rejected (flagged, last good velocity held),
//! duplicate and out-of-order stamps produce no step. Then a flood: every
//! command is accounted for, received = applied + overwritten + rejected.
//! Waits are for events (a match, an estimate, a counter), bounded
//! generously; nothing sleeps and hopes.

use friction_node::config::{CommandType, Config, Durability, Reliability, StepMode};
use friction_node::link::LiveStatus;
use friction_node::msgs::{
    estimate_constants as codes, Command, CommandKind, EstimateRecord, StatisticsRecord,
};
use friction_node::node::{Loop, RunSummary};
use friction_node::offline;
use friction_node::signal::Signal;
use friction_node::transport::{self, BackendSpec, JointStateCommand, TransportError};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::time::Duration;

static COUNTER: AtomicU32 = AtomicU32::new(0);

/// A name unique to this process and call.
fn unique(prefix: &str) -> String {
    format!(
        "{prefix}_{}_{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )
}

fn lockstep_config() -> Config {
    let mut c = Config::default();
    c.solver.cells = 64;
    c.node.step_mode = StepMode::Lockstep;
    c.node.profile_rate_hz = 0.0;
    // Lockstep must not lose commands. DDS matching is per side: the peer
    // may see the node's writer before the node's writer has matched the
    // peer's reader (and vice versa); transient-local durability delivers
    // what was written before that.
    c.ros.qos.commands.reliability = Reliability::Reliable;
    c.ros.qos.commands.depth = 1000;
    c.ros.qos.commands.durability = Durability::TransientLocal;
    c.ros.qos.estimates.depth = 1000;
    c.ros.qos.estimates.durability = Durability::TransientLocal;
    // A domain of this process (tests of one binary share it; names differ).
    c.ros.domain_id = 100 + (std::process::id() % 100) as i64;
    c.ros.namespace = format!("/{}", unique("fn_test"));
    let base = unique("fn_test");
    c.iceoryx2.cmd_velocity_service = format!("{base}/cmd_velocity");
    c.iceoryx2.normal_load_service = format!("{base}/normal_load");
    c.iceoryx2.friction_service = format!("{base}/friction");
    c.iceoryx2.cmd_event_service = format!("{base}/cmd_event");
    c.iceoryx2.loop_statistics_service = format!("{base}/loop_statistics");
    c
}

/// Wait (at most 60 s) until `ok()` holds.
fn wait_for(what: &str, mut ok: impl FnMut() -> bool) {
    wait_for_then(what, &mut ok, String::new)
}

/// [`wait_for`], saying `state()` when it gives up.
fn wait_for_then(what: &str, mut ok: impl FnMut() -> bool, state: impl Fn() -> String) {
    let start = std::time::Instant::now();
    while !ok() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "{what} not within 60 s {}",
            state()
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

const STEPS: usize = 250;
const STAMP0: u64 = 1_700_000_000_000_000_000;

fn velocity() -> Signal {
    Signal::Sine {
        offset: 0.0,
        amplitude: 0.8,
        frequency_hz: 2.0,
        phase_rad: 0.0,
    }
}

fn start_node(
    spec: BackendSpec,
    cfg: Config,
    stop: Arc<AtomicBool>,
    live: Arc<LiveStatus>,
) -> std::thread::JoinHandle<RunSummary> {
    let (tx, rx) = std::sync::mpsc::channel();
    let h = std::thread::spawn(move || {
        let port = spec
            .open_node(Default::default())
            .expect("open the node's port");
        let mut l = Loop::new(&cfg, vec![port], None, None, live).expect("loop");
        tx.send(()).unwrap();
        l.run(&stop, Some(Duration::from_secs(120)))
    });
    rx.recv_timeout(Duration::from_secs(30))
        .expect("node started");
    h
}

fn conformance(spec: BackendSpec, cfg: Config) {
    // The reference: offline simulate of the same velocities.
    let mut reference = Vec::new();
    offline::simulate(
        &cfg,
        &velocity(),
        &Signal::Const(cfg.contact.load_n),
        STEPS as f64 * cfg.solver.dt_s,
        |e, _| {
            reference.push(*e);
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(reference.len(), STEPS);

    let stop = Arc::new(AtomicBool::new(false));
    let live = Arc::new(LiveStatus::default());
    let node = start_node(spec.clone(), cfg.clone(), stop.clone(), live.clone());
    let rejected = || live.commands_rejected.load(Ordering::Relaxed);
    let applied = || live.commands_applied.load(Ordering::Relaxed);
    let mut peer = spec.open_peer().expect("open a peer");
    transport::wait_matched(peer.as_mut(), Duration::from_secs(20)).expect("discovery");
    let recv = |peer: &mut dyn transport::PeerPort, what: &str| -> EstimateRecord {
        transport::recv_timeout(peer, Duration::from_secs(10))
            .unwrap()
            .unwrap_or_else(|| panic!("{}: no estimate for {what}", spec.name()))
    };
    let stamped = cfg.ros.command_type == CommandType::TwistStamped || spec.name() != "ros2";
    // A side opened for one contact has no joints: asking for them is the
    // same typed error on every backend.
    let no_joints = peer.send_joint_state(&JointStateCommand {
        stamp_ns: STAMP0,
        name: vec!["elbow".into()],
        velocity: vec![0.1],
    });
    assert!(
        matches!(no_joints, Err(TransportError::NotJoints { .. })),
        "{}: {no_joints:?}",
        spec.name()
    );
    assert!(matches!(
        peer.try_recv_efforts(),
        Err(TransportError::NotJoints { .. })
    ));
    for (k, want) in reference.iter().enumerate() {
        let t = (k + 1) as f64 * cfg.solver.dt_s;
        let stamp = STAMP0 + k as u64 * 1_000_000;
        peer.send(&Command {
            kind: CommandKind::Velocity,
            value: velocity().at(t),
            stamp_ns: stamp,
        })
        .unwrap();
        let got = recv(peer.as_mut(), &format!("step {k}"));
        let mut expected = EstimateRecord::from_estimate(want, got.stamp_ns, got.compute_time_ns);
        expected.temperature_c = cfg.lubricant.reference_temperature_c;
        assert_eq!(
            got,
            expected,
            "{}: step {k} differs from the offline simulation",
            spec.name()
        );
        if stamped {
            assert_eq!(
                got.stamp_ns,
                stamp,
                "{}: the estimate carries the command's stamp",
                spec.name()
            );
        }
        assert_eq!(got.status, codes::STATUS_CONVERGED);
        assert_eq!(got.command_status, codes::COMMAND_FRESH);
    }

    // A non-finite velocity: rejected, flagged, the last velocity held.
    let last_v = velocity().at(STEPS as f64 * cfg.solver.dt_s);
    let next = STAMP0 + STEPS as u64 * 1_000_000;
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: f64::NAN,
        stamp_ns: next,
    })
    .unwrap();
    let r = recv(peer.as_mut(), "the NaN command");
    assert_eq!(r.status, codes::STATUS_CONVERGED);
    assert_eq!(r.command_status, codes::COMMAND_REJECTED);
    assert_eq!(r.velocity_m_s, last_v);
    assert!(r.friction_force_n.is_finite());
    if stamped {
        // A duplicate and an out-of-order stamp: rejected, no step (the next
        // estimate below is the 0.2 m/s command's).
        for stamp in [next, next - 5] {
            peer.send(&Command {
                kind: CommandKind::Velocity,
                value: 0.1,
                stamp_ns: stamp,
            })
            .unwrap();
        }
        wait_for("the duplicate commands' rejection", || rejected() == 3);
    }
    // A load command applies to the next step (sent once it is applied:
    // load and velocity travel on different topics).
    let before = applied();
    peer.send(&Command {
        kind: CommandKind::Load,
        value: 15_000.0,
        stamp_ns: next + 1,
    })
    .unwrap();
    wait_for("the load command", || applied() == before + 1);
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: 0.2,
        stamp_ns: next + 2_000_000,
    })
    .unwrap();
    let r = recv(peer.as_mut(), "the step after a load command");
    assert_eq!(r.load_n, 15_000.0);
    assert_eq!(r.velocity_m_s, 0.2);
    assert_eq!(r.command_status, codes::COMMAND_FRESH);

    stop.store(true, Ordering::Relaxed);
    let summary = node.join().unwrap();
    assert_eq!(summary.steps, STEPS as u64 + 2);
    assert_eq!(summary.commands_rejected, if stamped { 3 } else { 1 });
    assert_eq!(
        summary.commands_received,
        STEPS as u64 + if stamped { 5 } else { 3 }
    );
    assert_eq!(summary.publish_drops, 0);
    assert_eq!(
        summary.commands_received,
        summary.commands_applied + summary.commands_overwritten + summary.commands_rejected
    );
}

/// Flood a timer-mode node through `spec`: `n` commands as fast as the
/// peer can send, every tenth one non-finite. Every command is accounted
/// for, in the loop statistics the transport carries and in the summary.
fn flood(make_spec: impl Fn(&Config) -> BackendSpec, mut cfg: Config, n: u64) -> RunSummary {
    cfg.node.step_mode = StepMode::Timer;
    cfg.node.queue_capacity = 16;
    cfg.node.statistics_rate_hz = 200.0;
    // DDS keeps every command until it is acknowledged: what is counted is
    // what reached the node.
    cfg.ros.qos.commands.depth = 100_000;
    let spec = make_spec(&cfg);
    let stop = Arc::new(AtomicBool::new(false));
    let live = Arc::new(LiveStatus::default());
    let node = start_node(spec.clone(), cfg, stop.clone(), live.clone());
    let mut peer = spec.open_peer().expect("open a peer");
    transport::wait_matched(peer.as_mut(), Duration::from_secs(20)).expect("discovery");
    // One command first: the node has seen this publisher (iceoryx2 counts
    // lost samples from a publisher's sequence numbers once it knows it).
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: 0.5,
        stamp_ns: STAMP0,
    })
    .unwrap();
    wait_for("the first command", || {
        live.commands_applied.load(Ordering::Relaxed) == 1
    });
    let n = n + 1;
    for k in 1..n {
        let value = if k % 10 == 9 { f64::NAN } else { 0.5 };
        peer.send(&Command {
            kind: CommandKind::Velocity,
            value,
            stamp_ns: STAMP0 + k,
        })
        .unwrap();
    }
    // The statistics say when every command has arrived.
    let last = std::cell::Cell::new(None::<StatisticsRecord>);
    wait_for_then(
        "every command in the loop statistics",
        || {
            while let Some(s) = peer.try_recv_statistics().unwrap() {
                last.set(Some(s));
            }
            while peer.try_recv().unwrap().is_some() {}
            last.get().is_some_and(|s| s.commands_received == n)
        },
        || format!("(last statistics: {:?})", last.get()),
    );
    let s = last.get().unwrap();
    assert_eq!(
        s.commands_received,
        s.commands_applied + s.commands_overwritten + s.commands_rejected,
        "{}: {s:?}",
        spec.name()
    );
    stop.store(true, Ordering::Relaxed);
    let summary = node.join().unwrap();
    assert_eq!(summary.commands_received, n);
    assert_eq!(
        summary.commands_received,
        summary.commands_applied + summary.commands_overwritten + summary.commands_rejected,
        "{}: {summary:?}",
        spec.name()
    );
    // Only the commands the loop saw can be rejected; the NaNs among the
    // overwritten ones never reached it.
    assert!(summary.commands_rejected <= n / 10);
    assert!(summary.commands_rejected + summary.commands_overwritten >= (n - 1) / 10);
    println!(
        "flood through {}: {} received = {} applied + {} overwritten + {} rejected",
        spec.name(),
        summary.commands_received,
        summary.commands_applied,
        summary.commands_overwritten,
        summary.commands_rejected
    );
    summary
}

#[test]
fn a_flood_through_the_memory_transport_is_accounted_for_exactly() {
    let link = transport::memory::MemoryQueues::new(100_000);
    let s = flood(
        |_| BackendSpec::Memory(link.clone()),
        lockstep_config(),
        20_000,
    );
    assert_eq!(
        s.commands_overwritten, 0,
        "the memory queue never overwrites"
    );
    assert_eq!(s.commands_rejected, 2_000);
}

#[cfg(feature = "iceoryx2")]
#[test]
fn a_flood_through_iceoryx2_is_accounted_for_exactly() {
    flood(
        |c| BackendSpec::Iceoryx2((&c.iceoryx2).into()),
        lockstep_config(),
        20_000,
    );
}

#[cfg(feature = "ros2")]
#[test]
fn a_flood_through_ros2_is_accounted_for_exactly() {
    let mut cfg = lockstep_config();
    cfg.ros.qos.estimates.durability = Durability::Volatile;
    flood(
        |c| BackendSpec::Ros2(transport::ros2::Ros2Spec::from_config(c).unwrap()),
        cfg,
        5_000,
    );
}

/// The calibrated range over `spec`: each estimate's flag, and the
/// statistics' count and latest input outside, as a commanded speed leaves
/// the range (0–0.3 m/s) and comes back.
fn calibrated_range_travels(spec: BackendSpec, mut cfg: Config) {
    cfg.node.statistics_rate_hz = 1000.0; // one LoopStatistics per step
    cfg.calibrated_range = Some(friction_node::config::CalibratedRange {
        speed_forward_min_m_s: Some(0.0),
        speed_forward_max_m_s: Some(0.3),
        speed_backward_min_m_s: Some(0.0),
        speed_backward_max_m_s: Some(0.3),
        training_rms_n: Some(1.0),
        training_samples: 100,
        ..Default::default()
    });
    let stop = Arc::new(AtomicBool::new(false));
    let node = start_node(
        spec.clone(),
        cfg.clone(),
        stop.clone(),
        Arc::new(LiveStatus::default()),
    );
    let mut peer = spec.open_peer().expect("open a peer");
    transport::wait_matched(peer.as_mut(), Duration::from_secs(20)).expect("discovery");
    let mut stats: Vec<StatisticsRecord> = Vec::new();
    let mut k = 0u64;
    let mut phase = |peer: &mut dyn transport::PeerPort, v: f64, flag: u8| -> StatisticsRecord {
        for _ in 0..10 {
            k += 1;
            peer.send(&Command {
                kind: CommandKind::Velocity,
                value: v,
                stamp_ns: STAMP0 + k * 1_000_000,
            })
            .unwrap();
            let got = transport::recv_timeout(peer, Duration::from_secs(10))
                .unwrap()
                .unwrap_or_else(|| panic!("{}: no estimate for step {k}", spec.name()));
            assert_eq!(got.calibrated_range, flag, "{}: step {k}", spec.name());
        }
        wait_for_then(
            "the statistics of the phase's last step",
            || {
                while let Ok(Some(s)) = peer.try_recv_statistics() {
                    stats.push(s);
                }
                stats.iter().any(|s| s.steps == k)
            },
            || spec.name().to_string(),
        );
        *stats.iter().find(|s| s.steps == k).unwrap()
    };
    let inside = phase(peer.as_mut(), 0.2, codes::RANGE_INSIDE);
    assert_eq!(inside.steps_outside_calibrated_range, 0);
    assert_eq!(inside.last_outside, None);
    let outside = phase(peer.as_mut(), 1.0, codes::RANGE_OUTSIDE);
    assert_eq!(
        outside.steps_outside_calibrated_range,
        10,
        "{}",
        spec.name()
    );
    let o = outside.last_outside.expect("the input outside is named");
    assert_eq!(
        (o.contact, o.input, o.value, o.lo, o.hi),
        (0, "speed forward", 1.0, 0.0, 0.3),
        "{}",
        spec.name()
    );
    let back = phase(peer.as_mut(), 0.2, codes::RANGE_INSIDE);
    assert_eq!(back.steps_outside_calibrated_range, 10);
    assert_eq!(back.last_outside, None, "{}: cleared", spec.name());
    stop.store(true, Ordering::Relaxed);
    assert_eq!(node.join().unwrap().steps_outside_calibrated_range, 10);
}

#[test]
fn memory_transport_carries_the_calibrated_range() {
    let link = transport::memory::MemoryQueues::new(4096);
    calibrated_range_travels(BackendSpec::Memory(link), lockstep_config());
}

#[cfg(feature = "iceoryx2")]
#[test]
fn iceoryx2_transport_carries_the_calibrated_range() {
    let cfg = lockstep_config();
    let spec = BackendSpec::Iceoryx2((&cfg.iceoryx2).into());
    calibrated_range_travels(spec, cfg);
}

#[cfg(feature = "ros2")]
#[test]
fn ros2_transport_carries_the_calibrated_range() {
    let mut cfg = lockstep_config();
    cfg.ros.command_type = CommandType::TwistStamped;
    let spec = BackendSpec::Ros2(transport::ros2::Ros2Spec::from_config(&cfg).unwrap());
    calibrated_range_travels(spec, cfg);
}

#[test]
fn memory_transport_conforms() {
    let link = transport::memory::MemoryQueues::new(4096);
    conformance(BackendSpec::Memory(link), lockstep_config());
}

#[cfg(feature = "iceoryx2")]
#[test]
fn iceoryx2_transport_conforms() {
    let cfg = lockstep_config();
    let spec = BackendSpec::Iceoryx2((&cfg.iceoryx2).into());
    conformance(spec, cfg);
}

#[cfg(feature = "ros2")]
#[test]
fn ros2_transport_conforms_with_twist_stamped_commands() {
    let mut cfg = lockstep_config();
    cfg.ros.command_type = CommandType::TwistStamped;
    let spec = BackendSpec::Ros2(transport::ros2::Ros2Spec::from_config(&cfg).unwrap());
    assert!(matches!(&spec, BackendSpec::Ros2(s) if s.localhost_only));
    conformance(spec, cfg);
}

#[cfg(feature = "ros2")]
#[test]
fn ros2_transport_conforms_with_float64_commands() {
    let cfg = lockstep_config();
    let spec = BackendSpec::Ros2(transport::ros2::Ros2Spec::from_config(&cfg).unwrap());
    conformance(spec, cfg);
}

/// A message of another layout published under the command's type name
/// (what a misconfigured peer does): received, rejected, counted; the loop
/// goes on.
#[cfg(feature = "ros2")]
#[test]
fn a_command_of_the_wrong_layout_over_dds_is_received_and_rejected() {
    use ros2_client::dds::rustdds::DomainParticipantBuilder;
    use ros2_client::{Context, MessageTypeName, Name, NodeName, NodeOptions};
    #[derive(Debug, serde::Serialize, serde::Deserialize)]
    struct Tiny {
        x: u8,
    }
    impl ros2_client::Message for Tiny {}
    let mut cfg = lockstep_config();
    cfg.node.step_mode = StepMode::Timer;
    let spec = transport::ros2::Ros2Spec::from_config(&cfg).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let live = Arc::new(LiveStatus::default());
    let node = start_node(
        BackendSpec::Ros2(spec.clone()),
        cfg.clone(),
        stop.clone(),
        live.clone(),
    );
    let dp = DomainParticipantBuilder::new(spec.domain_id)
        .with_only_networks([std::net::Ipv4Addr::LOCALHOST])
        .build()
        .unwrap();
    let ctx = Context::from_domain_participant(dp).unwrap();
    let mut n = ctx
        .new_node(
            NodeName::new(&spec.namespace, "wrong_peer").unwrap(),
            NodeOptions::new().enable_rosout(false),
        )
        .unwrap();
    let spinner = n.spinner().unwrap();
    std::thread::spawn(move || futures::executor::block_on(spinner.spin()));
    let q = ros2_client::QosProfile::subscription_default()
        .reliability_reliable(ros2_client::qos::WhenFull::Wait(Duration::from_millis(50)))
        .durability(ros2_client::qos::Durability::TransientLocal)
        .history(ros2_client::qos::History::KeepLast { depth: 1000 });
    let topic = n
        .create_topic(
            &Name::parse(&spec.topics.cmd_velocity).unwrap(),
            MessageTypeName::new("std_msgs", "Float64"),
            &q,
        )
        .unwrap();
    let publisher: ros2_client::Publisher<Tiny> = n.create_publisher(&topic, None).unwrap();
    wait_for("the wrong-layout peer to match", || {
        use futures::FutureExt;
        publisher.wait_for_subscription(&n).now_or_never().is_some()
    });
    publisher.publish(Tiny { x: 7 }).unwrap();
    wait_for("the rejection", || {
        live.commands_rejected.load(Ordering::Relaxed) == 1
    });
    stop.store(true, Ordering::Relaxed);
    let s = node.join().unwrap();
    assert_eq!((s.commands_received, s.commands_rejected), (1, 1));
    assert!(s.steps > 0, "the loop went on");
}
