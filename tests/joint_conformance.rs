//! The multi-contact conformance suite, run against every transport
//! backend: a peer drives a lockstep node serving three contacts with
//! JointStates over the real services, and receives every contact's
//! estimate and the joint efforts, which must equal, contact by contact,
//! the offline `simulate` of that contact's configuration and velocity,
//! bit for bit. Then a JointState with fewer velocities than names rejects
//! only the joint without one. ROS 2 does not carry several contacts yet:
//! its test checks the refusal names the way out. Waits are for events,
//! bounded generously.

use friction_node::config::{Config, ContactList, Origin};
use friction_node::link::LiveStatus;
use friction_node::msgs::{estimate_constants as codes, EstimateRecord};
use friction_node::node::{Loop, RunSummary};
use friction_node::offline;
use friction_node::signal::Signal;
use friction_node::transport::{self, BackendSpec, JointEfforts, JointStateCommand, PeerPort};
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

static COUNTER: AtomicU32 = AtomicU32::new(0);

fn unique(prefix: &str) -> String {
    format!(
        "{prefix}_{}_{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    )
}

const STEPS: usize = 150;
const STAMP0: u64 = 1_700_000_000_000_000_000;

fn config() -> Config {
    let mut c = Config::from_yaml(
        "/**:
  ros__parameters:
    solver: {cells: 48}
    node: {step_mode: lockstep, profile_rate_hz: 0.0}
    contacts:
      x_left: {joint: x_left, contact: {load_n: 4000.0}}
      x_right: {joint: x_right}
      wrist: {joint: wrist, gain: 0.0625, solver: {cells: 24}}
",
        &Origin::Embedded,
        &[],
    )
    .unwrap();
    let base = unique("fn_joints");
    let i = &mut c.iceoryx2;
    i.cmd_velocity_service = format!("{base}/cmd_velocity");
    i.normal_load_service = format!("{base}/normal_load");
    i.temperature_service = format!("{base}/temperature");
    i.friction_service = format!("{base}/friction");
    i.cmd_event_service = format!("{base}/cmd_event");
    i.loop_statistics_service = format!("{base}/loop_statistics");
    i.joint_state_service = format!("{base}/joint_states");
    i.efforts_service = format!("{base}/joint_efforts");
    i.contact_friction_service = format!("{base}/contact_friction");
    c.ros.domain_id = 100 + (std::process::id() % 100) as i64;
    c
}

fn joints(c: &Config) -> Vec<String> {
    c.resolved_contacts().into_iter().map(|r| r.joint).collect()
}

/// Contact k's velocity signal (0 at t = 0: the node starts at rest, as
/// `simulate` starts at the signal's first value).
fn velocity(k: usize) -> Signal {
    Signal::Sine {
        offset: 0.0,
        amplitude: 0.5 + 0.3 * k as f64,
        frequency_hz: 2.0 + k as f64,
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
        let port = spec
            .open_node(Default::default())
            .expect("open the node's port");
        let live = Arc::new(LiveStatus::default());
        let mut l = Loop::new(&cfg, vec![port], None, None, live).expect("loop");
        tx.send(()).unwrap();
        l.run(&stop, Some(Duration::from_secs(120)))
    });
    rx.recv_timeout(Duration::from_secs(30))
        .expect("node started");
    h
}

/// One step's outputs: every contact's estimate and the efforts.
fn receive_step(
    peer: &mut dyn PeerPort,
    n: usize,
    what: &str,
) -> (Vec<EstimateRecord>, JointEfforts) {
    let start = Instant::now();
    let mut got: Vec<Option<EstimateRecord>> = vec![None; n];
    let mut efforts = None;
    while got.iter().any(Option::is_none) || efforts.is_none() {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{what}: outputs not within 20 s"
        );
        let mut any = false;
        if let Some((k, e)) = peer.try_recv_contact().unwrap() {
            assert!(got[k].is_none(), "{what}: two estimates of contact {k}");
            got[k] = Some(e);
            any = true;
        }
        if let Some(e) = peer.try_recv_efforts().unwrap() {
            efforts = Some(e);
            any = true;
        }
        if !any {
            std::thread::sleep(Duration::from_micros(50));
        }
    }
    (
        got.into_iter().map(Option::unwrap).collect(),
        efforts.unwrap(),
    )
}

// Step i indexes every contact's reference and the stamps.
#[allow(clippy::needless_range_loop)]
fn joint_conformance(spec: BackendSpec, cfg: Config) {
    let resolved = cfg.resolved_contacts();
    let names = joints(&cfg);
    // The reference: each contact alone, offline.
    let reference: Vec<Vec<_>> = resolved
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let mut one = r.config.clone();
            one.contacts = ContactList::default();
            let mut out = Vec::new();
            // The contact slides at gain × its joint's velocity (the gain
            // is a power of two: scaling the sine's amplitude by it is the
            // node's product bit for bit).
            let Signal::Sine {
                offset,
                amplitude,
                frequency_hz,
                phase_rad,
            } = velocity(k)
            else {
                unreachable!("a sine")
            };
            let contact_speed = Signal::Sine {
                offset: r.gain * offset,
                amplitude: r.gain * amplitude,
                frequency_hz,
                phase_rad,
            };
            offline::simulate(
                &one,
                &contact_speed,
                &Signal::Const(one.contact.load_n),
                STEPS as f64 * one.solver.dt_s,
                |e, _| {
                    out.push(*e);
                    Ok(())
                },
            )
            .unwrap();
            out
        })
        .collect();
    let stop = Arc::new(AtomicBool::new(false));
    let node = start_node(spec.clone(), cfg.clone(), stop.clone());
    let mut peer = spec.open_peer().expect("open a peer");
    transport::wait_matched(peer.as_mut(), Duration::from_secs(20)).expect("discovery");
    for i in 0..STEPS {
        let t = (i + 1) as f64 * cfg.solver.dt_s;
        let stamp = STAMP0 + i as u64 * 1_000_000;
        // The joints in reverse order, with one that is not the node's.
        let mut m = JointStateCommand {
            stamp_ns: stamp,
            name: vec!["gripper".into()],
            velocity: vec![3.0],
        };
        for k in (0..names.len()).rev() {
            m.name.push(names[k].clone());
            m.velocity.push(velocity(k).at(t));
        }
        peer.send_joint_state(&m).unwrap();
        let (got, efforts) = receive_step(peer.as_mut(), names.len(), &format!("step {i}"));
        for (k, r) in resolved.iter().enumerate() {
            let want = &reference[k][i];
            let mut expected =
                EstimateRecord::from_estimate(want, got[k].stamp_ns, got[k].compute_time_ns);
            expected.temperature_c = cfg.lubricant.reference_temperature_c;
            assert_eq!(got[k], expected, "{}: step {i}, contact {k}", spec.name());
            assert_eq!(got[k].stamp_ns, stamp);
            assert_eq!(got[k].command_status, codes::COMMAND_FRESH);
            assert_eq!(efforts.as_slice()[k], r.gain * want.friction_force);
        }
        if spec.name() != "ros2" {
            // A Float64MultiArray has no header (its JointState twin has).
            assert_eq!(efforts.stamp_ns, stamp);
        }
    }
    // Fewer velocities than names: the joint without one is rejected, its
    // contact holds its last velocity; the others step as commanded.
    let stamp = STAMP0 + STEPS as u64 * 1_000_000;
    peer.send_joint_state(&JointStateCommand {
        stamp_ns: stamp,
        name: names.clone(),
        velocity: vec![0.1, 0.2],
    })
    .unwrap();
    let (got, _) = receive_step(peer.as_mut(), names.len(), "the short JointState");
    let status: Vec<u8> = got.iter().map(|e| e.command_status).collect();
    assert_eq!(
        status,
        [
            codes::COMMAND_FRESH,
            codes::COMMAND_FRESH,
            codes::COMMAND_REJECTED
        ]
    );
    assert_eq!((got[0].velocity_m_s, got[1].velocity_m_s), (0.1, 0.2));
    let last = resolved[2].gain * velocity(2).at(STEPS as f64 * cfg.solver.dt_s);
    assert_eq!(got[2].velocity_m_s, last, "the last good velocity held");
    stop.store(true, Ordering::Relaxed);
    let s = node.join().unwrap();
    assert_eq!(s.steps, STEPS as u64 + 1);
    assert_eq!(s.contacts, 3);
    assert_eq!(s.commands_received, 3 * STEPS as u64 + 3);
    assert_eq!(s.commands_rejected, 1);
    assert_eq!(s.publish_drops, 0);
    assert_eq!(
        s.commands_received,
        s.commands_applied + s.commands_overwritten + s.commands_rejected
    );
}

#[test]
fn memory_transport_carries_several_contacts() {
    let cfg = config();
    let link = transport::memory::MemoryQueues::new(4096).for_plan(&cfg.output_plan());
    joint_conformance(BackendSpec::Memory(link), cfg);
}

#[cfg(feature = "iceoryx2")]
#[test]
fn iceoryx2_transport_carries_several_contacts() {
    let cfg = config();
    let spec = transport::iceoryx::IceoryxSpec::from(&cfg.iceoryx2).for_plan(cfg.output_plan());
    joint_conformance(BackendSpec::Iceoryx2(spec), cfg);
}

#[cfg(feature = "ros2")]
#[test]
fn ros2_transport_carries_several_contacts() {
    use friction_node::config::{Durability, Reliability};
    let mut cfg = config();
    // Lockstep must not lose commands (as in the one-contact suite).
    cfg.ros.qos.commands.reliability = Reliability::Reliable;
    cfg.ros.qos.commands.depth = 1000;
    cfg.ros.qos.commands.durability = Durability::TransientLocal;
    cfg.ros.qos.estimates.depth = 1000;
    cfg.ros.qos.estimates.durability = Durability::TransientLocal;
    cfg.ros.namespace = format!("/{}", unique("fn_joints"));
    let spec = transport::ros2::Ros2Spec::from_config(&cfg).unwrap();
    assert!(spec.localhost_only, "tests keep discovery on loopback");
    assert_eq!(
        spec.topics.contact_friction[2],
        format!(
            "{}/friction_node/contacts/wrist/friction",
            cfg.ros.namespace
        )
    );
    joint_conformance(BackendSpec::Ros2(spec), cfg);
}
