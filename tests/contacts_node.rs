//! Several contacts in one loop (on simulated time or in lockstep: exact
//! step counts): JointState commands by joint name, per-contact estimates
//! and command status, efforts in joint order, results independent of the
//! worker threads and equal, contact by contact, to a one-contact loop.

use friction_node::clock::SimClock;
use friction_node::config::{Config, ContactList, Origin};
use friction_node::link::LiveStatus;
use friction_node::msgs::{estimate_constants as codes, Command, CommandKind, EstimateRecord};
use friction_node::node::{Loop, RunSummary};
use friction_node::transport::memory::MemoryQueues;
use friction_node::transport::{JointEfforts, JointStateCommand, PeerPort};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

const WALL0: u64 = 1_763_900_000_000_000_000;
const MS: u64 = 1_000_000;

const THREE: &str = "/**:
  ros__parameters:
    solver: {cells: 32}
    node: {step_mode: timer, statistics_rate_hz: 100.0, command_timeout_s: 0.05}
    contacts:
      left: {joint: j_left, contact: {load_n: 4000.0}}
      right: {joint: j_right, gain: 0.05}
      wrist: {joint: j_wrist, gain: 0.02, solver: {cells: 16}}
";

fn three() -> Config {
    Config::from_yaml(THREE, &Origin::Embedded, &[]).unwrap()
}

fn joints(c: &Config) -> Vec<String> {
    c.resolved_contacts().into_iter().map(|r| r.joint).collect()
}

fn js(stamp_ns: u64, names: &[&str], velocity: &[f64]) -> JointStateCommand {
    JointStateCommand {
        stamp_ns,
        name: names.iter().map(|n| n.to_string()).collect(),
        velocity: velocity.to_vec(),
    }
}

/// Per-contact estimates in publication order, and the efforts.
fn outputs(peer: &mut dyn PeerPort) -> (Vec<Vec<EstimateRecord>>, Vec<JointEfforts>) {
    let mut per: Vec<Vec<EstimateRecord>> = vec![Vec::new(); 3];
    while let Some((k, e)) = peer.try_recv_contact().unwrap() {
        per[k].push(e);
    }
    let efforts = std::iter::from_fn(|| peer.try_recv_efforts().unwrap()).collect();
    (per, efforts)
}

/// A loop over `cfg` on the node side of `link`.
fn new_loop(cfg: &Config, link: &MemoryQueues) -> Loop {
    Loop::new(
        cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
}

fn run_timer(cfg: &Config, link: &MemoryQueues, ms: u64) -> RunSummary {
    let clock = Arc::new(SimClock::starting_at(0, WALL0));
    let mut l = Loop::new(
        cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
    .with_clock(clock);
    l.run(&AtomicBool::new(false), Some(Duration::from_millis(ms)))
}

#[test]
fn a_joint_state_drives_each_contact_by_joint_name_at_gain_times_its_velocity_and_efforts_are_gain_times_friction(
) {
    let cfg = three();
    let link = MemoryQueues::new(1000).for_plan(&cfg.output_plan());
    let mut peer = link.peer();
    // Out of order, with a joint that is not this node's.
    let m = js(
        1,
        &["j_right", "gripper", "j_left", "j_wrist"],
        &[0.2, 9.0, 0.4, -0.3],
    );
    peer.send_joint_state(&m).unwrap();
    let s = run_timer(&cfg, &link, 10);
    assert_eq!(s.steps, 10);
    assert_eq!(s.contacts, 3);
    assert_eq!(
        (s.commands_received, s.commands_applied, s.commands_rejected),
        (3, 3, 0),
        "the unknown joint is not a command of this node"
    );
    let (per, efforts) = outputs(&mut peer);
    let gains = [1.0, 0.05, 0.02];
    for (k, v) in [0.4, 0.2, -0.3].into_iter().enumerate() {
        assert_eq!(per[k].len(), 10, "contact {k}");
        // The joint's transmission: the contact slides at gain × the joint's velocity.
        assert!(
            per[k].iter().all(|e| e.velocity_m_s == gains[k] * v),
            "contact {k}"
        );
        assert_eq!(per[k][0].command_status, codes::COMMAND_FRESH);
        assert_eq!(per[k][1].command_status, codes::COMMAND_HELD);
        assert!(per[k].iter().all(|e| e.status == codes::STATUS_CONVERGED));
    }
    assert_eq!(per[0][0].load_n, 4000.0, "left's own load");
    assert_eq!(efforts.len(), 10);
    for (step, ef) in efforts.iter().enumerate() {
        assert_eq!(ef.as_slice().len(), 3);
        assert_eq!(ef.stamp_ns, per[0][step].stamp_ns);
        for k in 0..3 {
            assert_eq!(
                ef.as_slice()[k],
                gains[k] * per[k][step].friction_force_n,
                "step {step} contact {k}"
            );
        }
    }
    // Friction opposes each contact's own motion.
    assert!(efforts[9].as_slice()[0] > 0.0 && efforts[9].as_slice()[2] < 0.0);
}

#[test]
fn a_joint_without_a_finite_velocity_is_rejected_alone_and_the_others_apply() {
    let cfg = three();
    let link = MemoryQueues::new(1000).for_plan(&cfg.output_plan());
    let mut peer = link.peer();
    // Two velocities for three names: j_wrist has none.
    peer.send_joint_state(&js(1, &["j_left", "j_right", "j_wrist"], &[0.4, 0.2]))
        .unwrap();
    // NaN for j_left; j_right updated; j_wrist left out.
    peer.send_joint_state(&js(2, &["j_left", "j_right"], &[f64::NAN, 0.1]))
        .unwrap();
    let s = run_timer(&cfg, &link, 3);
    let (per, _) = outputs(&mut peer);
    let first: Vec<u8> = per.iter().map(|p| p[0].command_status).collect();
    assert_eq!(
        first,
        [
            codes::COMMAND_REJECTED,
            codes::COMMAND_FRESH,
            codes::COMMAND_REJECTED
        ]
    );
    let v: Vec<f64> = per.iter().map(|p| p[0].velocity_m_s).collect();
    // Contact speeds: gain × the joint's velocity (gains 1, 0.05, 0.02).
    assert_eq!(
        v,
        [0.4, 0.05 * 0.1, 0.0],
        "left keeps its last good velocity"
    );
    assert!(per
        .iter()
        .all(|p| p[1].command_status == codes::COMMAND_HELD));
    assert_eq!(
        (s.commands_received, s.commands_applied, s.commands_rejected),
        (5, 3, 2)
    );
    assert_eq!(
        s.commands_received,
        s.commands_applied + s.commands_overwritten + s.commands_rejected
    );
}

/// A memory port whose sender commands `j_left` (contact 0) at every step
/// and the other joints never again: one extra command per drain.
struct LeftOnly {
    inner: friction_node::transport::memory::MemoryNode,
    polls: u64,
}

impl friction_node::transport::NodePort for LeftOnly {
    fn name(&self) -> &'static str {
        "left-only"
    }
    fn poll_command(
        &mut self,
    ) -> Result<Option<Command>, friction_node::transport::TransportError> {
        if let Some(c) = self.inner.poll_command()? {
            return Ok(Some(c));
        }
        self.polls += 1;
        Ok(self.polls.is_multiple_of(2).then_some(Command {
            kind: CommandKind::JointVelocity {
                contact: 0,
                last: true,
                joint: true,
            },
            value: 0.4,
            stamp_ns: self.polls,
        }))
    }
    fn publish_estimate(&mut self, k: usize, e: &EstimateRecord) -> bool {
        self.inner.publish_estimate(k, e)
    }
    fn publish_efforts(&mut self, stamp_ns: u64, efforts: &[f64]) -> bool {
        self.inner.publish_efforts(stamp_ns, efforts)
    }
    fn publish_statistics(&mut self, s: &friction_node::msgs::StatisticsRecord) -> bool {
        self.inner.publish_statistics(s)
    }
    fn wait_for_command(
        &mut self,
        t: Duration,
    ) -> Result<(), friction_node::transport::TransportError> {
        self.inner.wait_for_command(t)
    }
    fn counters(&self) -> friction_node::transport::PortCounters {
        self.inner.counters()
    }
}

#[test]
fn a_contact_left_out_of_the_joint_states_is_held_then_times_out_alone() {
    let cfg = three();
    let link = MemoryQueues::new(100_000).for_plan(&cfg.output_plan());
    let mut peer = link.peer();
    peer.send_joint_state(&js(1, &["j_left", "j_right", "j_wrist"], &[0.4, 0.2, 0.1]))
        .unwrap();
    let clock = Arc::new(SimClock::starting_at(0, WALL0));
    let port = LeftOnly {
        inner: link.node(),
        polls: 0,
    };
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(port)],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
    .with_clock(clock);
    l.run(&AtomicBool::new(false), Some(Duration::from_millis(80)));
    let (per, _) = outputs(&mut peer);
    let status = |k: usize, step: usize| per[k][step].command_status;
    // Step 2: the others are held; step 80: 80 ms old, timed out (50 ms).
    assert_eq!(status(1, 1), codes::COMMAND_HELD);
    assert_eq!(status(2, 1), codes::COMMAND_HELD);
    assert_eq!(status(1, 79), codes::COMMAND_TIMED_OUT);
    assert_eq!(status(2, 79), codes::COMMAND_TIMED_OUT);
    // wrist's last command, 0.1 rad/s at its 0.02 m lever.
    assert_eq!(
        per[2][79].velocity_m_s,
        0.02 * 0.1,
        "hold: the last command"
    );
    // The commanded contact is fresh at every step.
    assert!(per[0]
        .iter()
        .all(|e| e.command_status == codes::COMMAND_FRESH));
}

/// A lockstep loop over `cfg` fed `steps` JointStates; contact k's
/// velocity at step i is `v(k, i)`.
fn lockstep(cfg: &Config, steps: u64, v: impl Fn(usize, u64) -> f64) -> Vec<Vec<EstimateRecord>> {
    lockstep_with_change(cfg, steps, v, 0, &[]).0
}

fn profile(k: usize, i: u64) -> f64 {
    (1.0 + 0.3 * k as f64) * (2.0 * std::f64::consts::PI * (i as f64 * 1e-3 + 0.1 * k as f64)).sin()
}

#[test]
fn each_contact_of_a_lockstep_loop_equals_a_one_contact_loop_bit_for_bit() {
    let cfg = three();
    let many = lockstep(&cfg, 300, profile);
    for (k, r) in cfg.resolved_contacts().iter().enumerate() {
        let mut one = r.config.clone();
        one.contacts = ContactList::default();
        one.node.step_mode = friction_node::config::StepMode::Lockstep;
        let link = MemoryQueues::new(100_000);
        let mut peer = link.peer();
        let mut l = new_loop(&one, &link);
        for i in 0..300u64 {
            // The one-contact loop takes the contact's own speed: gain ×
            // the joint's velocity.
            l.feed(Command {
                kind: CommandKind::Velocity,
                value: r.gain * profile(k, i),
                stamp_ns: (i + 1) * MS,
            });
        }
        let single: Vec<EstimateRecord> = std::iter::from_fn(|| peer.try_recv().unwrap()).collect();
        assert_eq!(single.len(), 300);
        assert_eq!(many[k].len(), 300, "contact {k}");
        for (a, b) in many[k].iter().zip(&single) {
            assert_eq!(a.friction_force_n.to_bits(), b.friction_force_n.to_bits());
            assert_eq!(a.h0_m.to_bits(), b.h0_m.to_bits());
            assert_eq!(a.iterations, b.iterations);
        }
    }
}

#[test]
fn worker_threads_change_no_result() {
    let cfg = three();
    let alone = lockstep(&cfg, 200, profile);
    let mut two = cfg.clone();
    two.node.contact_workers = 2;
    let shared = lockstep(&two, 200, profile);
    for k in 0..3 {
        let a: Vec<u64> = alone[k]
            .iter()
            .map(|e| e.friction_force_n.to_bits())
            .collect();
        let b: Vec<u64> = shared[k]
            .iter()
            .map(|e| e.friction_force_n.to_bits())
            .collect();
        assert_eq!(a, b, "contact {k}");
    }
}

#[test]
fn a_lockstep_joint_state_with_an_old_stamp_takes_no_step() {
    let mut cfg = three();
    cfg.node.step_mode = friction_node::config::StepMode::Lockstep;
    let link = MemoryQueues::new(1000).for_plan(&cfg.output_plan());
    let mut peer = link.peer();
    let mut l = new_loop(&cfg, &link);
    let all = ["j_left", "j_right", "j_wrist"];
    peer.send_joint_state(&js(5 * MS, &all, &[0.1, 0.2, 0.3]))
        .unwrap();
    peer.send_joint_state(&js(5 * MS, &all, &[0.1, 0.2, 0.3]))
        .unwrap();
    peer.send_joint_state(&js(6 * MS, &all, &[0.1, 0.2, 0.3]))
        .unwrap();
    l.poll_once();
    assert_eq!(l.summary().steps, 2, "the duplicate stamp takes no step");
    assert_eq!(l.summary().commands_rejected, 1);
}

#[test]
fn bad_contact_settings_for_the_node_are_errors_naming_the_key() {
    let mut c = three();
    c.node.contact_workers = 3;
    let e = c.validate().unwrap_err().to_string();
    assert!(
        e.contains("node.contact_workers") && e.contains("at most 2"),
        "{e}"
    );
    let mut many = String::from("/**:\n  ros__parameters:\n    contacts:\n");
    for i in 0..65 {
        many.push_str(&format!("      c{i}: {{}}\n"));
    }
    let e = Config::from_yaml(&many, &Origin::Embedded, &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("contacts") && e.contains("at most 64"), "{e}");
    let long = format!(
        "/**:\n  ros__parameters:\n    contacts:\n      a: {{joint: {}}}\n      b: {{}}\n",
        "j".repeat(65)
    );
    let e = Config::from_yaml(&long, &Origin::Embedded, &[])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("contacts.a.joint") && e.contains("65 bytes"),
        "{e}"
    );
}

/// Lockstep run of `cfg` for `steps` steps; before step `at`, the
/// parameter changes `changes` are applied the way the ROS 2 service does
/// (validated by `apply_set`, prepared, applied between two steps).
fn lockstep_with_change(
    cfg: &Config,
    steps: u64,
    v: impl Fn(usize, u64) -> f64,
    at: u64,
    changes: &[(&str, f64)],
) -> (Vec<Vec<EstimateRecord>>, RunSummary) {
    use friction_node::config::parameters::{apply_set, declare};
    use friction_node::link::ParameterUpdate;
    use friction_node::msgs::ros_interfaces::{parameter_type, ParameterValue};
    let mut cfg = cfg.clone();
    cfg.node.step_mode = friction_node::config::StepMode::Lockstep;
    let names = joints(&cfg);
    let link = MemoryQueues::new(100_000).for_plan(&cfg.output_plan());
    let mut peer = link.peer();
    let mut l = new_loop(&cfg, &link);
    let mut per: Vec<Vec<EstimateRecord>> = vec![Vec::new(); names.len()];
    for i in 0..steps {
        if i == at && !changes.is_empty() {
            let changes: Vec<(String, ParameterValue)> = changes
                .iter()
                .map(|(k, x)| {
                    let v = ParameterValue {
                        r#type: parameter_type::DOUBLE,
                        double_value: *x,
                        ..Default::default()
                    };
                    (k.to_string(), v)
                })
                .collect();
            let next = apply_set(&cfg, &declare(&cfg), &changes).unwrap();
            let mut u = ParameterUpdate::prepare(&cfg, next, changes).unwrap();
            l.apply_update(&mut u);
        }
        let velocity: Vec<f64> = (0..names.len()).map(|k| v(k, i)).collect();
        let refs: Vec<&str> = names.iter().map(String::as_str).collect();
        peer.send_joint_state(&js((i + 1) * MS, &refs, &velocity))
            .unwrap();
        l.poll_once();
        while let Some((k, e)) = peer.try_recv_contact().unwrap() {
            per[k].push(e);
        }
    }
    (per, l.summary())
}

#[test]
fn a_runtime_change_of_one_contacts_key_changes_that_contact_alone() {
    let cfg = three();
    let (base, s0) = lockstep_with_change(&cfg, 200, profile, 100, &[]);
    assert_eq!(s0.parameter_updates, 0);
    let (changed, s1) = lockstep_with_change(
        &cfg,
        200,
        profile,
        100,
        &[
            ("contacts.right.lubricant.viscosity_pa_s", 0.2),
            ("contacts.wrist.contact.load_n", 3000.0),
        ],
    );
    assert_eq!(s1.parameter_updates, 1);
    let same = |a: &EstimateRecord, b: &EstimateRecord| {
        a.friction_force_n.to_bits() == b.friction_force_n.to_bits()
            && a.h0_m.to_bits() == b.h0_m.to_bits()
    };
    // `left` is untouched: bit for bit the run without the change.
    assert!(base[0].iter().zip(&changed[0]).all(|(a, b)| same(a, b)));
    for k in [1, 2] {
        assert_eq!(changed[k].len(), 200, "contact {k}");
        assert!(
            base[k][..100]
                .iter()
                .zip(&changed[k][..100])
                .all(|(a, b)| same(a, b)),
            "contact {k} before the change"
        );
        assert!(
            base[k][100..]
                .iter()
                .zip(&changed[k][100..])
                .all(|(a, b)| !same(a, b)),
            "contact {k} after the change"
        );
    }
    // The wrist now holds its new load; the others keep theirs.
    assert!(changed[2][100..].iter().all(|e| e.load_n == 3000.0));
    assert!(changed[0].iter().all(|e| e.load_n == 4000.0));
}

#[test]
fn with_several_contacts_each_contacts_model_keys_are_runtime_and_the_defaults_read_only() {
    use friction_node::config::parameters::declare;
    let cfg = three();
    let declared = declare(&cfg);
    let read_only = |name: &str| {
        declared
            .iter()
            .find(|d| d.name == name)
            .unwrap_or_else(|| panic!("{name} is declared"))
            .read_only
    };
    for key in [
        "contacts.right.lubricant.viscosity_pa_s",
        "contacts.left.contact.load_n",
        "contacts.wrist.roughness.sigma_m",
        "drivetrain.viscous_n_s_m",
    ] {
        assert!(!read_only(key), "{key} changes at runtime");
    }
    for key in [
        "contacts.right.joint",
        "contacts.right.gain",
        "contacts.wrist.solver.cells",
        "lubricant.viscosity_pa_s",
        "contact.load_n",
        "roughness.sigma_m",
    ] {
        assert!(read_only(key), "{key} is read-only");
    }
    // Without contacts the top-level keys are the model's, and runtime.
    let one = Config::default();
    let d1 = declare(&one);
    let lub = d1
        .iter()
        .find(|d| d.name == "lubricant.viscosity_pa_s")
        .unwrap();
    assert!(!lub.read_only);
}

#[test]
fn a_configuration_with_one_listed_contact_publishes_its_joint_effort_as_several_do() {
    // The shape `fit --rotary` writes: the joint as the one listed contact,
    // driven by its JointState and answered with its effort (gain × friction).
    let cfg = Config::from_yaml(
        "/**:
  ros__parameters:
    solver: {cells: 32}
    node: {step_mode: timer, statistics_rate_hz: 100.0, command_timeout_s: 0.05}
    contacts:
      elbow: {joint: elbow, gain: 0.04}
",
        &Origin::Embedded,
        &[],
    )
    .unwrap();
    let link = MemoryQueues::new(1000).for_plan(&cfg.output_plan());
    let mut peer = link.peer();
    peer.send_joint_state(&js(1, &["elbow"], &[2.0])).unwrap();
    let s = run_timer(&cfg, &link, 5);
    assert_eq!((s.steps, s.contacts), (5, 1));
    let (per, efforts) = outputs(&mut peer);
    assert_eq!(per[0].len(), 5);
    assert!(per[0].iter().all(|e| e.velocity_m_s == 0.04 * 2.0));
    assert_eq!(efforts.len(), 5, "one effort array per step");
    for (ef, e) in efforts.iter().zip(&per[0]) {
        assert_eq!(ef.as_slice(), [0.04 * e.friction_force_n]);
        assert_eq!(ef.stamp_ns, e.stamp_ns);
    }
}

#[test]
fn each_contact_is_watched_by_its_own_calibrated_range_and_one_without_is_not() {
    let yaml = THREE.replace(
        "left: {joint: j_left, contact: {load_n: 4000.0}}",
        "left: {joint: j_left, contact: {load_n: 4000.0}, calibrated_range: \
         {speed_forward_min_m_s: 0.0, speed_forward_max_m_s: 0.5, speed_backward_min_m_s: 0.0, \
         speed_backward_max_m_s: 0.5, training_rms_n: 1.0, training_samples: 10}}",
    ) + "    node: {step_mode: timer, statistics_rate_hz: 100.0, command_timeout_s: 0.05, outside_envelope: zero}\n";
    let yaml = yaml.replacen(
        "    node: {step_mode: timer, statistics_rate_hz: 100.0, command_timeout_s: 0.05}\n",
        "",
        1,
    );
    // The wrist (a rotary joint, gain 0.02 m/rad) in the joint's rad/s.
    let yaml = yaml.replace(
        "wrist: {joint: j_wrist, gain: 0.02, solver: {cells: 16}}",
        "wrist: {joint: j_wrist, gain: 0.02, solver: {cells: 16}, calibrated_range: \
         {speed_forward_min_rad_s: 0.0, speed_forward_max_rad_s: 1.0, speed_backward_min_rad_s: 0.0, \
         speed_backward_max_rad_s: 1.0, training_rms_n_m: 0.01, training_samples: 10}}",
    );
    let cfg = Config::from_yaml(&yaml, &Origin::Embedded, &[]).unwrap();
    let per = lockstep(&cfg, 300, profile);
    let left = &per[0];
    let outside = left
        .iter()
        .filter(|e| e.calibrated_range == codes::RANGE_OUTSIDE)
        .count();
    // |1.0 sin| > 0.5 for two thirds of the cycle; 300 steps hold 0.3 of it.
    assert!(outside > 50, "{outside}");
    for e in left {
        let out = e.velocity_m_s.abs() > 0.5;
        assert_eq!(
            e.calibrated_range,
            if out {
                codes::RANGE_OUTSIDE
            } else {
                codes::RANGE_INSIDE
            },
            "v = {}",
            e.velocity_m_s
        );
        if out || e.velocity_m_s != 0.0 {
            assert_eq!(e.friction_force_n == 0.0, out, "v = {}", e.velocity_m_s);
        }
    }
    assert!(per[1]
        .iter()
        .all(|e| e.calibrated_range == codes::RANGE_NOT_WATCHED && e.friction_force_n != 0.0));
    // The wrist: judged on the joint's speed, the contact's ÷ 0.02.
    let wrist_outside = per[2]
        .iter()
        .filter(|e| {
            let out = (e.velocity_m_s / 0.02).abs() > 1.0;
            assert_eq!(
                e.calibrated_range,
                if out {
                    codes::RANGE_OUTSIDE
                } else {
                    codes::RANGE_INSIDE
                },
                "wrist at {} rad/s",
                e.velocity_m_s / 0.02
            );
            out
        })
        .count();
    assert!(wrist_outside > 20, "{wrist_outside}");
}
