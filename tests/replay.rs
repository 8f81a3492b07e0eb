//! Replay over the fixture bags in bags/ (regenerated only by
//! bags/regenerate.sh): one recorded by friction-node, one written by the
//! Python mcap-ros2-support writer. Bad bags are made here from them.
#![cfg(feature = "mcap")]

mod common;
use common::cli::run;

use friction_node::bag::{Bag, BagError, SampleKind};
use friction_node::msgs::{self, CommandKind};
use friction_node::replay::{self, InputMode, ReplayError, ReplayOptions};
use std::collections::BTreeMap;
use std::path::Path;

const NODE_BAG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/bags/node_lockstep.mcap");
const FOREIGN_BAG: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/bags/foreign_joint_states.mcap"
);

/// A fresh directory for test `name`.
fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("replay", name)
}

fn opts(topic: Option<&str>, joint: Option<&str>) -> ReplayOptions {
    ReplayOptions {
        topic: topic.map(Into::into),
        joint: joint.map(Into::into),
        ..Default::default()
    }
}

fn prepare(bag: &str, o: &ReplayOptions) -> Result<replay::PreparedReplay, ReplayError> {
    replay::prepare(&Bag::open(Path::new(bag))?, o)
}

/// A bag with the given (topic, schema name, schema text) channels, each
/// holding one CDR message `data` per entry of `messages`.
fn write_bag(path: &Path, channels: &[(&str, &str, &str)], messages: &[(usize, Vec<u8>)]) {
    let mut w = mcap::Writer::new(std::io::BufWriter::new(
        std::fs::File::create(path).unwrap(),
    ))
    .unwrap();
    let ids: Vec<u16> = channels
        .iter()
        .map(|(topic, name, text)| {
            let s = w.add_schema(name, "ros2msg", text.as_bytes()).unwrap();
            w.add_channel(s, topic, "cdr", &BTreeMap::new()).unwrap()
        })
        .collect();
    for (k, (c, data)) in messages.iter().enumerate() {
        let t = 1_000_000_000 + k as u64 * 1_000_000;
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: ids[*c],
                sequence: k as u32,
                log_time: t,
                publish_time: t,
            },
            data,
        )
        .unwrap();
    }
    w.finish().unwrap();
}

fn float64(v: f64) -> Vec<u8> {
    msgs::to_cdr(&msgs::Float64 { data: v }).unwrap()
}

#[test]
fn a_foreign_joint_state_bag_replays_the_named_joint_on_the_model_time_grid() {
    let p = prepare(FOREIGN_BAG, &opts(Some("/joint_states"), Some("slider"))).unwrap();
    assert_eq!(p.config_source, "built-in default");
    match &p.mode {
        InputMode::Topics {
            velocity,
            kind,
            load,
            temperature,
        } => {
            assert_eq!(*temperature, None);
            assert_eq!(velocity, "/joint_states");
            assert!(matches!(kind, SampleKind::JointVelocity(joint) if joint == "slider"));
            assert_eq!(load.as_deref(), Some("/slider/normal_load"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(p.velocity_messages, 1001, "2 s at 500 Hz");
    let vel: Vec<_> = p
        .commands
        .iter()
        .filter(|c| c.kind == CommandKind::Velocity)
        .collect();
    assert_eq!(vel.len(), 2001, "2 s on the 1 ms grid");
    let t0 = vel[0].stamp_ns;
    for c in &vel {
        let t = (c.stamp_ns - t0) as f64 / 1e9;
        // Linear interpolation of 2 ms samples of 0.6 sin 2πt: error ≤ v''h²/8.
        let exact = 0.6 * (2.0 * std::f64::consts::PI * t).sin();
        assert!(
            (c.value - exact).abs() <= 1.2e-5,
            "t = {t}: {} vs {exact}",
            c.value
        );
    }
    let loads: Vec<(f64, f64)> = p
        .commands
        .iter()
        .filter(|c| c.kind == CommandKind::Load)
        .map(|c| ((c.stamp_ns - t0) as f64 / 1e9, c.value))
        .collect();
    assert_eq!(
        loads,
        vec![(0.0, 5762.0), (1.0, 4000.0)],
        "the load set points, held"
    );
    assert!(p.gaps.is_empty());

    let r = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    assert_eq!(r.estimates.len(), 2001);
    assert!(
        r.oracle.is_none(),
        "a foreign bag has nothing to compare with"
    );
    assert_eq!(r.commands_rejected, 0);
    for (e, rec) in &r.estimates {
        assert_eq!(
            rec.status,
            msgs::estimate_constants::STATUS_CONVERGED,
            "{e:?}"
        );
        assert!(e.friction_force.is_finite() && e.h0 > 0.0);
    }
    // The load step reaches the model: before 1 s 5762 N, after 4000 N.
    assert_eq!(r.estimates[999].1.load_n, 5762.0);
    assert_eq!(r.estimates[1000].1.load_n, 4000.0);
}

#[test]
fn a_joint_state_with_several_joints_needs_a_joint_name() {
    let e = prepare(FOREIGN_BAG, &opts(Some("/joint_states"), None)).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::JointRequired { .. })),
        "{e}"
    );
    let m = e.to_string();
    assert!(
        m.contains("base_yaw, slider, gripper") && m.contains("--joint"),
        "{m}"
    );
    let e = prepare(FOREIGN_BAG, &opts(Some("/joint_states"), Some("elbow"))).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::JointMissing { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("`elbow`"), "{e}");
}

#[test]
fn several_velocity_topics_are_listed_until_one_is_chosen() {
    let e = prepare(FOREIGN_BAG, &opts(None, None)).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, ReplayError::AmbiguousVelocity { .. }), "{m}");
    assert!(
        m.contains("/joint_states") && m.contains("/cmd_vel") && m.contains("--topic"),
        "{m}"
    );
    // A joint's name picks the bag's only JointState topic.
    let p = prepare(FOREIGN_BAG, &opts(None, Some("slider"))).unwrap();
    assert!(
        matches!(&p.mode, InputMode::Topics { velocity, .. } if velocity == "/joint_states"),
        "{:?}",
        p.mode
    );
    // TwistStamped: linear.x at 100 Hz, header stamps.
    let p = prepare(FOREIGN_BAG, &opts(Some("/cmd_vel"), None)).unwrap();
    assert!(matches!(
        &p.mode,
        InputMode::Topics {
            kind: SampleKind::TwistLinearX,
            ..
        }
    ));
    assert_eq!(p.velocity_messages, 201);
    assert_eq!(
        p.commands
            .iter()
            .filter(|c| c.kind == CommandKind::Velocity)
            .count(),
        2001
    );
    let e = prepare(FOREIGN_BAG, &opts(Some("/diagnostics_text"), None)).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::UnsupportedType { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("std_msgs/msg/String"), "{e}");
    let e = prepare(FOREIGN_BAG, &opts(Some("/nope"), None)).unwrap_err();
    assert!(
        e.to_string().contains("`/nope` is not in the bag") && e.to_string().contains("/cmd_vel"),
        "{e}"
    );
}

/// Replay `bag` on its recorded configuration and check every estimate
/// within one part per million of the recording; returns the configuration.
fn assert_replays_within_one_ppm(bag: &str) -> friction_node::config::Config {
    let p = prepare(bag, &ReplayOptions::default()).unwrap();
    assert_eq!(p.config_source, "recorded in the bag");
    assert!(
        matches!(&p.mode, InputMode::RecordedEstimates { .. }),
        "{:?}",
        p.mode
    );
    assert_eq!(p.recorded.len(), 2000);
    let r = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    let o = r.oracle.expect("a friction-node bag is compared");
    assert_eq!(o.compared, 2000);
    assert_eq!(o.count_mismatch, None);
    let load = p.recorded[0].load_n;
    for (field, dev, at) in &o.deviations {
        let bound = match *field {
            "friction_force_n" | "hydrodynamic_force_n" | "asperity_force_n" => 1e-6 * load,
            "cof" | "asperity_load_share" => 1e-6,
            "h0_m" | "h_min_m" => 1e-6 * p.recorded[*at].h0_m,
            "iterations" => continue,
            other => panic!("{other} differs by {dev} at step {at}"),
        };
        assert!(*dev <= bound, "{bag}: {field} differs by {dev:e} at step {at} (bound {bound:e}); bags/regenerate.sh after a deliberate change");
    }
    p.config
}

#[test]
fn the_node_fixture_replays_within_one_part_per_million_of_its_recording() {
    // Bit-identity holds for the binary that recorded it (tested below on a
    // fresh recording); across solver versions and CPUs the fixture must
    // still agree to the solver's tolerance.
    let c = assert_replays_within_one_ppm(NODE_BAG);
    assert_eq!(c.solver.flux, friction_node::config::FluxKind::MusclVanLeer);
}

#[test]
fn a_bag_recorded_before_solver_flux_existed_replays_with_the_upwind_flux_it_was_recorded_with() {
    // tests/fixtures/node_lockstep_before_flux.mcap: bags/node_lockstep.mcap
    // as recorded before `solver.flux` existed (upwind was the only flux);
    // kept as it was recorded, never regenerated.
    let old = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/node_lockstep_before_flux.mcap"
    );
    let c = assert_replays_within_one_ppm(old);
    assert_eq!(c.solver.flux, friction_node::config::FluxKind::Upwind);
}

#[test]
fn a_fresh_recording_replays_bit_identically_and_so_does_the_replay_output() {
    let d = dir("fresh");
    let bag = d.join("lockstep.mcap");
    let base = format!("fn_replay_{}", std::process::id());
    let (code, _, err) = run(&[
        "run",
        "--demo",
        "0.5",
        "--config",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/launch-config/lockstep-iceoryx2.yaml"
        ),
        "--set",
        "solver.cells=64",
        "--set",
        &format!("iceoryx2.cmd_velocity_service={base}/cmd"),
        "--set",
        &format!("iceoryx2.normal_load_service={base}/load"),
        "--set",
        &format!("iceoryx2.friction_service={base}/friction"),
        "--set",
        &format!("iceoryx2.cmd_event_service={base}/event"),
        "--record",
        bag.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let out = d.join("replayed.mcap");
    let (code, stdout, err) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 0, "{stdout}{err}");
    // Every recorded step is reproduced; how many the node took depends on
    // how many of the demo's 500 commands it received before the demo
    // ended, which a loaded machine changes (lockstep takes only what arrives).
    let steps: u64 = stdout
        .split("bit-identical to the recorded estimates (")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no oracle verdict: {stdout}"));
    assert!((20..=500).contains(&steps), "{stdout}");
    // The output is a friction-node bag in its own right.
    let again = d.join("again.csv");
    let (code, stdout, err) = run(&[
        "replay",
        out.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 0, "{stdout}{err}");
    assert!(stdout.contains("bit-identical"), "{stdout}");
    // A different configuration is not: the oracle says by how much.
    let (code, stdout, _) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--set",
        "contact.boundary_friction=0.2",
        "--out",
        again.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 3, "{stdout}");
    assert!(
        stdout.contains("DIFFERS") && stdout.contains("friction_force_n"),
        "{stdout}"
    );
}

#[test]
fn a_bag_without_a_velocity_topic_lists_what_it_has() {
    let d = dir("none");
    let bag = d.join("strings.mcap");
    let text = msgs::to_cdr(&"hello".to_string()).unwrap();
    write_bag(
        &bag,
        &[("/chatter", "std_msgs/msg/String", "string data\n")],
        &[(0, text)],
    );
    let e = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, ReplayError::NoVelocityTopic { .. }), "{m}");
    assert!(
        m.contains("/chatter") && m.contains("std_msgs/msg/String") && m.contains("1 messages"),
        "{m}"
    );
    let out = d.join("out.csv");
    let (code, _, err) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(err.contains("/chatter"), "{err}");
    assert!(!out.exists());
}

#[test]
fn a_schema_that_does_not_match_its_type_names_the_topic() {
    let d = dir("schema");
    let bag = d.join("bad_schema.mcap");
    write_bag(
        &bag,
        &[(
            "/axis/velocity",
            "std_msgs/msg/Float64",
            "float32 data\nuint8 flags\n",
        )],
        &[(0, float64(0.1)), (0, float64(0.2))],
    );
    let e = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap_err();
    let m = e.to_string();
    assert!(
        matches!(e, ReplayError::Bag(BagError::SchemaMismatch { .. })),
        "{m}"
    );
    assert!(
        m.contains("`/axis/velocity`") && m.contains("float32 data"),
        "{m}"
    );
}

#[test]
fn a_message_that_does_not_decode_is_damage_named_by_topic_and_index() {
    let d = dir("decode");
    let bag = d.join("short.mcap");
    let channels = [("/axis/velocity", "std_msgs/msg/Float64", "float64 data\n")];
    let garbage = vec![0, 1, 0, 0, 1];
    let good: Vec<(usize, Vec<u8>)> = (0..20).map(|k| (0, float64(0.01 * k as f64))).collect();
    let mut msgs = good.clone();
    msgs.push((0, garbage.clone()));
    msgs.extend(good);
    write_bag(&bag, &channels, &msgs);
    let p = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap();
    assert_eq!(p.velocity_messages, 20, "the messages before the bad one");
    let damage = p.scan.damage.expect("damage");
    assert_eq!(damage.after_messages, 20);
    assert!(
        damage.error.contains("`/axis/velocity`, message 21"),
        "{}",
        damage.error
    );
    // Nothing before it: the decode error itself.
    write_bag(&bag, &channels, &[(0, garbage)]);
    let e = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::Decode { index: 1, .. })),
        "{e}"
    );
    assert!(e.to_string().contains("/axis/velocity"), "{e}");
}

#[test]
fn a_truncated_bag_replays_up_to_the_damage_and_says_where() {
    let d = dir("truncated");
    let bytes = std::fs::read(NODE_BAG).unwrap();
    let bag = d.join("truncated.mcap");
    std::fs::write(&bag, &bytes[..bytes.len() * 7 / 10]).unwrap();
    let p = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap();
    let damage = p.scan.damage.clone().expect("damage reported");
    assert!(
        damage.after_messages > 0 && damage.last_log_time_ns.is_some(),
        "{damage:?}"
    );
    let steps = p.recorded.len();
    assert!(
        steps > 500 && steps < 2000,
        "{steps} steps before the damage"
    );
    let r = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    assert_eq!(r.estimates.len(), steps);
    let out = d.join("out.csv");
    let (code, stdout, err) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("damaged") && stdout.contains("damaged bag      stopped after"),
        "{stdout}{err}"
    );
    let rows = std::fs::read_to_string(&out).unwrap().lines().count();
    assert_eq!(rows, steps + 1);
}

#[test]
fn a_corrupt_chunk_stops_the_replay_there() {
    let d = dir("corrupt");
    let mut bytes = std::fs::read(FOREIGN_BAG).unwrap();
    // Scribble over the middle of the middle chunk's compressed records.
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunk = &summary.chunk_indexes[summary.chunk_indexes.len() / 2];
    let mid = (chunk.chunk_start_offset + chunk.chunk_length / 2) as usize;
    for b in &mut bytes[mid..mid + 64] {
        *b ^= 0x5a;
    }
    let bag = d.join("corrupt.mcap");
    std::fs::write(&bag, &bytes).unwrap();
    let p = prepare(
        bag.to_str().unwrap(),
        &opts(Some("/joint_states"), Some("slider")),
    )
    .unwrap();
    let damage = p.scan.damage.clone().expect("damage reported");
    assert!(
        p.velocity_messages > 0 && p.velocity_messages < 1001,
        "{}",
        p.velocity_messages
    );
    assert!(!damage.error.is_empty());
}

#[test]
fn invalid_input_writes_nothing_and_an_existing_output_survives() {
    let d = dir("atomic");
    let out = d.join("run.csv");
    std::fs::write(&out, "precious\n").unwrap();
    let not_a_bag = d.join("notes.mcap");
    std::fs::write(&not_a_bag, "not an mcap file").unwrap();
    for args in [
        vec![
            "replay",
            not_a_bag.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        vec!["replay", FOREIGN_BAG, "--out", out.to_str().unwrap()],
        vec![
            "replay",
            FOREIGN_BAG,
            "--topic",
            "/joint_states",
            "--out",
            out.to_str().unwrap(),
        ],
        vec![
            "replay",
            NODE_BAG,
            "--set",
            "solver.cells=3",
            "--out",
            out.to_str().unwrap(),
        ],
        vec![
            "replay",
            "/nonexistent/bag.mcap",
            "--out",
            out.to_str().unwrap(),
        ],
    ] {
        let (code, _, err) = run(&args);
        assert_ne!(code, 0, "{args:?}");
        assert!(err.starts_with("error:"), "{args:?}: {err}");
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            "precious\n",
            "{args:?}"
        );
    }
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--out",
        d.join("run.txt").to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(err.contains(".mcap or .csv"), "{err}");
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 2, "{leftovers:?}");
}

#[test]
fn the_report_has_a_summary_cycle_metrics_and_figures() {
    let d = dir("report");
    let out = d.join("run.mcap");
    let rep = d.join("report");
    let (code, stdout, err) = run(&[
        "replay",
        FOREIGN_BAG,
        "--topic",
        "/joint_states",
        "--joint",
        "slider",
        "--out",
        out.to_str().unwrap(),
        "--report",
        rep.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("report"), "{stdout}");
    let md = std::fs::read_to_string(rep.join("summary.md")).unwrap();
    assert!(
        md.contains("joint `slider`") && md.contains("load `/slider/normal_load`"),
        "{md}"
    );
    assert!(md.contains("## Loop metrics"), "{md}");
    let cycles = std::fs::read_to_string(rep.join("cycles.csv")).unwrap();
    let lines: Vec<&str> = cycles.lines().collect();
    assert!(lines[0].starts_with("cycle,t_start_s,t_end_s,friction_loop_area_n_m_s"));
    assert!(lines.len() >= 2, "{cycles}");
    #[cfg(feature = "plots")]
    for f in [
        "friction_velocity.svg",
        "time_series.svg",
        "regime_share.svg",
    ] {
        let svg = std::fs::read_to_string(rep.join(f)).unwrap();
        assert!(svg.contains("<svg") && svg.contains("polyline"), "{f}");
        assert!(md.contains(&format!("]({f})")), "{f} linked");
    }
    // The MCAP output carries the inputs and the estimates on the node's
    // topics, ROS 2 profile.
    let bytes = std::fs::read(&out).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("finalised");
    let topics: Vec<String> = summary.channels.values().map(|c| c.topic.clone()).collect();
    assert!(
        topics.iter().any(|t| t.ends_with("/friction")),
        "{topics:?}"
    );
    assert!(
        topics.iter().any(|t| t.ends_with("/cmd_velocity")),
        "{topics:?}"
    );
}

// ---------------------------------------------------------------------------
// rosbag2 directories written by the Python `rosbags` writer, both storages
// ---------------------------------------------------------------------------

const ROSBAGS_SQLITE3: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/bags/rosbags_sqlite3");
const ROSBAGS_MCAP: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/bags/rosbags_mcap");

/// The settings the rosbags fixtures were simulated with (bags/regenerate.sh).
const ROSBAGS_SETS: [&str; 6] = [
    "--set",
    "solver.dt_s=0.002",
    "--set",
    "solver.cells=64",
    "--set",
    "lubricant.viscosity_model=vogel",
];

#[test]
fn sqlite3_and_mcap_rosbag2_directories_from_an_independent_writer_replay_identically() {
    let d = dir("rosbags");
    let mut outputs = Vec::new();
    for (bag, name) in [
        (ROSBAGS_SQLITE3.to_string(), "sqlite3.csv"),
        (ROSBAGS_MCAP.to_string(), "mcap.csv"),
        // A .db3 file on its own is a bag too.
        (
            format!("{ROSBAGS_SQLITE3}/rosbags_sqlite3.db3"),
            "db3-file.csv",
        ),
    ] {
        let out = d.join(name);
        let mut args = vec![
            "replay",
            bag.as_str(),
            "--topic",
            "/joint_states",
            "--joint",
            "slider",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(ROSBAGS_SETS);
        let (code, stdout, stderr) = run(&args);
        assert_eq!(code, 0, "{bag}: {stdout}\n{stderr}");
        assert!(
            stderr.contains("load `/slider/normal_load`")
                && stderr.contains("temperature `/oil_temperature`"),
            "{bag}: the load and temperature topics are found: {stderr}"
        );
        assert!(stdout.contains("steps            500"), "{bag}: {stdout}");
        outputs.push(std::fs::read_to_string(&out).unwrap());
    }
    assert_eq!(
        outputs[0], outputs[1],
        "sqlite3 and mcap storage replay alike"
    );
    assert_eq!(
        outputs[0], outputs[2],
        "a .db3 file alone replays like its directory"
    );
    // The temperature ramp (20 → 60 °C over the run) reached the model.
    let rows: Vec<Vec<String>> = outputs[0]
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let col = rows[0].iter().position(|c| c == "temperature_c").unwrap();
    let first: f64 = rows[1][col].parse().unwrap();
    let last: f64 = rows[rows.len() - 1][col].parse().unwrap();
    assert!((20.0..21.0).contains(&first), "first temperature {first}");
    assert!((58.0..60.0).contains(&last), "last temperature {last}");
}

#[test]
fn a_fit_on_an_sqlite3_bag_recovers_boundary_friction_and_viscosity() {
    let d = dir("rosbags-fit");
    let out = d.join("fitted.yaml");
    let mut args = vec![
        "fit",
        ROSBAGS_SQLITE3,
        "--velocity-topic",
        "/joint_states",
        "--joint",
        "slider",
        "--friction-topic",
        "/slider/friction",
        "--fit",
        "contact.boundary_friction,lubricant.viscosity_pa_s",
        "--start",
        "contact.boundary_friction=0.1",
        "--start",
        "lubricant.viscosity_pa_s=0.2",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(ROSBAGS_SETS);
    let (code, stdout, stderr) = run(&args);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let fitted = friction_node::config::Config::load(Some(&out), &[]).unwrap();
    // The bag's truth: the shipped defaults (mu_bl 0.3, mu_l 0.0564 Pa s at
    // 40 degC). The temperature topic is sampled at 50 Hz and held, so the
    // model sees up to 0.8 degC less than the simulation did: within 5 %.
    approx::assert_relative_eq!(fitted.contact.boundary_friction, 0.3, max_relative = 0.05);
    approx::assert_relative_eq!(fitted.lubricant.viscosity_pa_s, 0.0564, max_relative = 0.05);
}

#[test]
fn a_fit_on_the_nodes_own_lockstep_recording_recovers_its_boundary_friction_though_its_load_topic_is_empty(
) {
    // The node ran without a load input: its bag has the topic
    // `/friction_node/normal_load` with no message. The load is then the
    // configuration's, as it was in the node (before: the empty topic was
    // taken by default and the fit refused it, "no message could be read").
    let d = dir("own-bag-fit");
    let out = d.join("fitted.yaml");
    let (code, stdout, stderr) = run(&[
        "fit",
        NODE_BAG,
        "--velocity-topic",
        "/friction_node/cmd_velocity",
        "--friction-topic",
        "/friction_node/friction_force",
        "--fit",
        "contact.boundary_friction",
        "--start",
        "contact.boundary_friction=0.2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    assert!(
        stderr.contains("load from the configuration (contact.load_n), temperature none"),
        "{stderr}"
    );
    let fitted = friction_node::config::Config::load(Some(&out), &[]).unwrap();
    approx::assert_relative_eq!(fitted.contact.boundary_friction, 0.3, max_relative = 1e-4);
}

#[test]
fn a_fit_on_a_bag_without_its_topics_named_lists_the_bags_topics() {
    let d = dir("rosbags-fit-untold");
    let out = d.join("fitted.yaml");
    let (code, _, stderr) = run(&[
        "fit",
        ROSBAGS_MCAP,
        "--fit",
        "contact.boundary_friction",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("needs --velocity-topic and --friction-topic; the bag has:")
            && stderr.contains("/joint_states  [sensor_msgs/msg/JointState]")
            && stderr.contains("/slider/friction"),
        "{stderr}"
    );
    assert!(!out.exists(), "nothing written");
}

#[test]
fn a_truncated_sqlite3_bag_is_refused_or_replayed_up_to_the_damage_never_a_panic() {
    let d = dir("db3-damaged");
    let bytes = std::fs::read(format!("{ROSBAGS_SQLITE3}/rosbags_sqlite3.db3")).unwrap();
    for keep in [
        16,
        100,
        4096,
        bytes.len() / 3,
        bytes.len() / 2,
        bytes.len() - 4096,
    ] {
        let bag = d.join(format!("cut{keep}.db3"));
        std::fs::write(&bag, &bytes[..keep]).unwrap();
        let out = d.join(format!("cut{keep}.csv"));
        let (code, stdout, stderr) = run(&[
            "replay",
            bag.to_str().unwrap(),
            "--topic",
            "/joint_states",
            "--joint",
            "slider",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            code == 0 || code == 2,
            "cut at {keep}: exit {code}\n{stdout}\n{stderr}"
        );
        if code == 2 {
            assert!(
                stderr.contains("cut"),
                "cut at {keep}: names the file: {stderr}"
            );
            assert!(!out.exists(), "cut at {keep}: nothing written");
        }
    }
}

#[test]
fn velocity_and_load_maps_transform_the_topics_and_bad_maps_are_named() {
    let d = dir("maps");
    let plain = d.join("plain.csv");
    let mapped = d.join("mapped.csv");
    let base = |out: &Path| -> Vec<String> {
        [
            "replay",
            ROSBAGS_MCAP,
            "--topic",
            "/joint_states",
            "--joint",
            "slider",
            "--out",
            out.to_str().unwrap(),
        ]
        .iter()
        .map(|s| s.to_string())
        .chain(ROSBAGS_SETS.iter().map(|s| s.to_string()))
        .collect()
    };
    let a = base(&plain);
    let (code, _, stderr) = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0, "{stderr}");
    let mut b = base(&mapped);
    b.extend(["--velocity-map", "0.5 * x", "--load-map", "2 * x + 100"].map(String::from));
    let (code, _, stderr) = run(&b.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0, "{stderr}");
    let col = |text: &str, name: &str| -> Vec<f64> {
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let c = head.iter().position(|h| *h == name).unwrap();
        lines
            .map(|l| l.split(',').nth(c).unwrap().parse().unwrap())
            .collect()
    };
    let (p, m) = (
        std::fs::read_to_string(&plain).unwrap(),
        std::fs::read_to_string(&mapped).unwrap(),
    );
    for (vp, vm) in col(&p, "velocity_m_s").iter().zip(col(&m, "velocity_m_s")) {
        approx::assert_relative_eq!(vm, 0.5 * vp, max_relative = 1e-12, epsilon = 1e-15);
    }
    for (lp, lm) in col(&p, "load_n").iter().zip(col(&m, "load_n")) {
        approx::assert_relative_eq!(lm, 2.0 * lp + 100.0, max_relative = 1e-12);
    }
    for (map, needle) in [
        ("0.5 * y", "`y` is unknown"),
        ("(x", "--velocity-map `(x`"),
        ("x / 0", "gives"),
    ] {
        let out = d.join("bad.csv");
        let mut c = base(&out);
        c.extend(["--velocity-map", map].map(String::from));
        let (code, _, stderr) = run(&c.iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(code, 2, "{map}: {stderr}");
        assert!(stderr.contains(needle), "{map}: {stderr}");
        assert!(!out.exists(), "{map}: nothing written");
    }
}

#[test]
fn expect_identical_on_a_bag_without_recorded_estimates_exits_5_before_writing() {
    let d = dir("nothing-to-compare");
    let out = d.join("r.csv");
    let (code, _, err) = run(&[
        "replay",
        FOREIGN_BAG,
        "--topic",
        "/joint_states",
        "--joint",
        "slider",
        "--out",
        out.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 5, "{err}");
    assert!(err.contains("nothing to compare"), "{err}");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "nothing written");
    // A recorded bag still compares (and exits 0 when identical).
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--out",
        out.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn an_output_whose_extension_contradicts_the_format_is_refused() {
    let d = dir("format-contradiction");
    let out = d.join("x.mcap");
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--out",
        out.to_str().unwrap(),
        "--format",
        "csv",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(".mcap") && err.contains("--format csv"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn a_bad_override_is_the_configurations_error_not_the_bags() {
    let d = dir("bad-override");
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--set",
        "contact.load_n=-1",
        "--out",
        d.join("r.csv").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("contact.load_n"), "{err}");
    assert!(!err.contains("bag ") && !err.contains("recorded"), "{err}");
}
