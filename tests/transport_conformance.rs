//! One conformance suite, run against every transport backend: in-memory,
//! iceoryx2 and ROS 2 (loopback-only discovery, unique domain and names).
//!
//! A peer drives a lockstep node with a velocity profile over the real
//! command topic/service and receives the estimates, which must equal the
//! offline `simulate` of the same profile bit for bit. Then bad input: a
//! non-finite velocity is rejected (flagged, last good velocity held),
//! duplicate and out-of-order stamps produce no step.

use friction_node::config::{CommandType, Config, Durability, Reliability, StepMode};
use friction_node::msgs::{estimate_constants as codes, Command, CommandKind, EstimateRecord};
use friction_node::node::{LiveStatus, Loop, RunSummary};
use friction_node::offline;
use friction_node::signal::Signal;
use friction_node::transport::{self, BackendSpec};
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
    c
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
) -> std::thread::JoinHandle<RunSummary> {
    let (tx, rx) = std::sync::mpsc::channel();
    let h = std::thread::spawn(move || {
        let port = spec.open_node(None).expect("open the node's port");
        let mut l = Loop::new(
            &cfg,
            vec![port],
            None,
            None,
            Arc::new(LiveStatus::default()),
        )
        .expect("loop");
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
    let node = start_node(spec.clone(), cfg.clone(), stop.clone());
    let mut peer = spec.open_peer().expect("open a peer");
    transport::wait_matched(peer.as_mut(), Duration::from_secs(20)).expect("discovery");
    let recv = |peer: &mut dyn transport::PeerPort, what: &str| -> EstimateRecord {
        transport::recv_timeout(peer, Duration::from_secs(10))
            .unwrap()
            .unwrap_or_else(|| panic!("{}: no estimate for {what}", spec.name()))
    };
    let stamped = cfg.ros.command_type == CommandType::TwistStamped || spec.name() != "ros2";
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
        let expected = EstimateRecord::from_estimate(want, got.stamp_ns, got.compute_time_ns);
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
    assert_eq!(r.status, codes::STATUS_COMMAND_REJECTED);
    assert_eq!(r.velocity_m_s, last_v);
    assert!(r.friction_force_n.is_finite());
    if stamped {
        // A duplicate and an out-of-order stamp: no step, no estimate.
        for stamp in [next, next - 5] {
            peer.send(&Command {
                kind: CommandKind::Velocity,
                value: 0.1,
                stamp_ns: stamp,
            })
            .unwrap();
        }
        let extra = transport::recv_timeout(peer.as_mut(), Duration::from_millis(300)).unwrap();
        assert!(
            extra.is_none(),
            "{}: a duplicate/out-of-order command produced {extra:?}",
            spec.name()
        );
    }
    // A load command applies to the next step.
    peer.send(&Command {
        kind: CommandKind::Load,
        value: 15_000.0,
        stamp_ns: next + 1,
    })
    .unwrap();
    std::thread::sleep(Duration::from_millis(if spec.name() == "ros2" {
        200
    } else {
        20
    }));
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: 0.2,
        stamp_ns: next + 2_000_000,
    })
    .unwrap();
    let r = recv(peer.as_mut(), "the step after a load command");
    assert_eq!(r.load_n, 15_000.0);
    assert_eq!(r.velocity_m_s, 0.2);

    stop.store(true, Ordering::Relaxed);
    let summary = node.join().unwrap();
    assert_eq!(summary.steps, STEPS as u64 + 2);
    assert_eq!(summary.commands_rejected, if stamped { 3 } else { 1 });
    assert_eq!(
        summary.commands_received,
        STEPS as u64 + if stamped { 5 } else { 3 }
    );
    assert_eq!(summary.publish_drops, 0);
}

#[test]
fn memory_transport_conforms() {
    let link = transport::memory::MemoryLink::new(4096);
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
