//! Recording for months: split files with `metadata.yaml`, a disk budget,
//! snapshots of the last seconds, and replay of a split directory; on
//! simulated time, so every count is exact; and the node's recordings end to
//! end, in real processes ([`node_runs`]).
#![cfg(feature = "mcap")]

mod common;
use common::cli::fresh_dir;

use friction_node::bag::{rosbag2, Bag};
use friction_node::clock::SimClock;
use friction_node::config::topics::TopicNames;
use friction_node::config::{Config, StepMode};
use friction_node::link::FilmProfileSlot;
use friction_node::link::LiveStatus;
use friction_node::msgs::{Command, CommandKind};
use friction_node::node::{Loop, RunSummary};
use friction_node::record::{RecordPlan, Recorder, RecorderReport};
use friction_node::replay::{self, ReplayOptions};
use friction_node::transport::memory::MemoryQueues;
use friction_node::transport::PeerPort;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

const WALL0: u64 = 1_763_900_000_000_000_000;

fn config() -> Config {
    let mut c = Config::default();
    c.solver.cells = 16;
    c.node.step_mode = StepMode::Timer;
    c.node.profile_rate_hz = 10.0;
    // The simulated loop outruns the disk: a queue that holds a whole run.
    c.node.queue_capacity = 1_000_000;
    c.recording.chunk_size_bytes = 64 * 1024;
    c
}

/// Run the node's loop for `seconds` of simulated time into a recorder.
fn record(
    cfg: &Config,
    plan: RecordPlan,
    seconds: u64,
    snapshot_at: Option<u64>,
) -> (RunSummary, RecorderReport) {
    let clock = Arc::new(SimClock::new(WALL0));
    let slot = FilmProfileSlot::new(cfg.solver.cells);
    let rec = Recorder::start(
        plan,
        cfg,
        &TopicNames::from_config(cfg),
        Some(slot.clone()),
        clock.clone(),
    )
    .unwrap();
    let link = MemoryQueues::new(16);
    let mut peer = link.peer();
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: 0.3,
        stamp_ns: 1,
    })
    .unwrap();
    let mut l = Loop::new(
        cfg,
        vec![Box::new(
            link.node_recording(Some(rec.queue()))
                .with_clock(clock.clone()),
        )],
        Some(rec.queue()),
        Some(slot),
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
    .with_clock(clock)
    .with_recorder(rec.counters());
    let stop = AtomicBool::new(false);
    let s = match snapshot_at {
        None => l.run(&stop, Some(Duration::from_secs(seconds))),
        Some(at) => {
            l.run(&stop, Some(Duration::from_secs(at)));
            // Ask once everything so far is in the ring.
            let start = std::time::Instant::now();
            while !rec.queue().is_empty() {
                assert!(start.elapsed() < Duration::from_secs(60));
                std::thread::sleep(Duration::from_millis(1));
            }
            rec.snapshot_request().store(true, Ordering::Release);
            let start = std::time::Instant::now();
            while rec.counters().snapshots.load(Ordering::Relaxed) == 0 {
                assert!(
                    start.elapsed() < Duration::from_secs(60),
                    "the snapshot is written"
                );
                std::thread::sleep(Duration::from_millis(1));
            }
            l.run(&stop, Some(Duration::from_secs(seconds - at)))
        }
    };
    drop(l);
    let report = rec.finish();
    assert!(report.error.is_none(), "{report:?}");
    (s, report)
}

/// Every message of one MCAP file: (topic, log time, publish time, data).
fn read_file(path: &Path) -> Vec<(String, u64, u64, Vec<u8>)> {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("finalised");
    assert_eq!(
        summary.channels.len(),
        8,
        "{}: every channel (/parameter_events included)",
        path.display()
    );
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            (
                m.channel.topic.clone(),
                m.log_time,
                m.publish_time,
                m.data.into_owned(),
            )
        })
        .collect()
}

#[test]
fn a_60_s_run_split_every_5_s_loses_and_repeats_no_message_and_replays_as_one_bag() {
    let mut cfg = config();
    cfg.recording.split.max_duration_s = 5;
    let d = fresh_dir("rec", "split");
    let bag = d.join("run");
    let (s, report) = record(
        &cfg,
        RecordPlan {
            path: Some(bag.clone()),
            snapshot_dir: d.to_path_buf(),
        },
        60,
        None,
    );
    assert_eq!(s.steps, 60_000);
    assert_eq!(s.recorder_drops, 0);
    let (meta, files) = rosbag2::open_directory(&bag).unwrap();
    assert_eq!(files.len(), 12, "{files:?}");
    assert_eq!(report.files, 12);
    assert!(files[0].ends_with("run_0.mcap") && files[11].ends_with("run_11.mcap"));
    // Every file is readable alone; together they hold every message once.
    let mut per_topic: BTreeMap<String, Vec<u64>> = BTreeMap::new();
    let mut total = 0;
    for (k, f) in files.iter().enumerate() {
        let msgs = read_file(f);
        assert_eq!(meta.files[k].message_count, msgs.len() as u64);
        total += msgs.len() as u64;
        for (topic, log, publish, _) in msgs {
            let _ = log;
            per_topic.entry(topic).or_default().push(publish);
        }
    }
    assert_eq!(total, report.messages);
    assert_eq!(meta.message_count, total);
    let est = &per_topic["/friction_node/friction"];
    assert_eq!(
        est.len(),
        60_000,
        "one estimate per step, none lost, none repeated"
    );
    assert!(
        est.windows(2).all(|w| w[1] - w[0] == 1_000_000),
        "stamps continue across every split with no gap and no repeat"
    );
    assert_eq!(per_topic["/friction_node/friction_force"].len(), 60_000);
    // Profiles go through a latest-value slot (decimated, best effort): the
    // simulated loop outruns the recorder, so only some are recorded.
    assert!(!per_topic["/friction_node/film_profile"].is_empty());
    assert_eq!(per_topic["/friction_node/cmd_velocity"].len(), 1);
    // Topic counts in metadata.yaml.
    let count = |t: &str| {
        meta.topics_with_message_count
            .iter()
            .find(|x| x.topic_metadata.name == t)
            .unwrap()
            .message_count
    };
    assert_eq!(count("/friction_node/friction"), 60_000);
    // The directory replays as one run, bit-identical to the recording.
    let b = Bag::open(&bag).unwrap();
    assert_eq!(b.files().len(), 12);
    let p = replay::prepare(&b, &ReplayOptions::default()).unwrap();
    let r = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    let o = r.oracle.unwrap();
    assert!(o.identical, "{:?}", o.deviations);
    assert_eq!(o.compared, 60_000);
}

#[test]
fn a_disk_budget_deletes_the_oldest_split_files_and_metadata_forgets_them() {
    let mut cfg = config();
    cfg.recording.split.max_duration_s = 5;
    let d = fresh_dir("rec", "budget");
    let bag = d.join("run");
    // First, how big is one 5 s file?
    let (_, probe) = record(
        &cfg,
        RecordPlan {
            path: Some(d.join("probe")),
            snapshot_dir: d.to_path_buf(),
        },
        10,
        None,
    );
    let one = probe.bytes / 2;
    cfg.recording.budget_bytes = 4 * one;
    let (_, report) = record(
        &cfg,
        RecordPlan {
            path: Some(bag.clone()),
            snapshot_dir: d.to_path_buf(),
        },
        60,
        None,
    );
    assert_eq!(report.files, 12);
    assert!(report.files_deleted >= 7, "{report:?}");
    let (meta, files) = rosbag2::open_directory(&bag).unwrap();
    assert_eq!(files.len() as u64, 12 - report.files_deleted);
    assert!(
        files.last().unwrap().ends_with("run_11.mcap"),
        "the newest stay"
    );
    let on_disk: Vec<String> = std::fs::read_dir(&bag)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".mcap"))
        .collect();
    assert_eq!(on_disk.len(), files.len(), "{on_disk:?}");
    assert_eq!(meta.relative_file_paths.len(), files.len());
    let total: u64 = files
        .iter()
        .map(|f| std::fs::metadata(f).unwrap().len())
        .sum();
    assert!(
        total <= 4 * one + one,
        "{total} bytes for a budget of {}",
        4 * one
    );
}

#[test]
fn a_snapshot_holds_the_last_seconds_of_every_topic() {
    let mut cfg = config();
    cfg.recording.snapshot_s = 2;
    let d = fresh_dir("rec", "snapshot");
    let (_, report) = record(
        &cfg,
        RecordPlan {
            path: None,
            snapshot_dir: d.to_path_buf(),
        },
        12,
        Some(10),
    );
    assert_eq!(report.snapshots.len(), 1);
    let msgs = read_file(&report.snapshots[0]);
    let est: Vec<u64> = msgs
        .iter()
        .filter(|m| m.0 == "/friction_node/friction")
        .map(|m| m.2)
        .collect();
    // The 2 s before the request (10 s of steps had run): steps 8000..=10000.
    assert_eq!(est.len(), 2001);
    assert_eq!(*est.last().unwrap(), WALL0 + 10_000_000_000);
    assert!(est.windows(2).all(|w| w[1] - w[0] == 1_000_000));
    assert!(msgs.iter().any(|m| m.0 == "/friction_node/film_profile"));
    // The file is a normal friction-node bag.
    let b = Bag::open(&report.snapshots[0]).unwrap();
    let p = replay::prepare(&b, &ReplayOptions::default()).unwrap();
    assert_eq!(p.recorded.len(), 2001);
}

#[test]
fn a_split_recording_refuses_a_directory_that_is_not_empty() {
    let mut cfg = config();
    cfg.recording.split.max_duration_s = 5;
    let d = fresh_dir("rec", "nonempty");
    std::fs::write(d.join("something"), "x").unwrap();
    let e = Recorder::start(
        RecordPlan {
            path: Some(d.to_path_buf()),
            snapshot_dir: d.to_path_buf(),
        },
        &cfg,
        &TopicNames::from_config(&cfg),
        None,
        Arc::new(SimClock::new(WALL0)),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(e.contains("not empty") && e.contains("nonempty"), "{e}");
}

/// (Live parameter changes arrive through the ROS 2 parameter services.)
#[cfg(feature = "ros2")]
#[test]
fn a_run_whose_parameters_changed_midway_replays_bit_identically() {
    use friction_node::config::parameters::{apply_set, declare};
    use friction_node::link::{ParameterChannel, ParameterUpdate};
    use friction_node::msgs::ros_interfaces::{parameter_type, ParameterValue};
    use friction_node::transport::ros2::params::record_applied;
    let d = fresh_dir("rec", "params");
    let bag = d.join("params.mcap");
    let mut cfg = config();
    cfg.lubricant.viscosity_model = friction_node::config::ViscosityModelKind::Vogel;
    let clock = Arc::new(SimClock::new(WALL0));
    let rec = Recorder::start(
        RecordPlan {
            path: Some(bag.clone()),
            snapshot_dir: d.to_path_buf(),
        },
        &cfg,
        &TopicNames::from_config(&cfg),
        None,
        clock.clone(),
    )
    .unwrap();
    let link = MemoryQueues::new(16);
    let mut peer = link.peer();
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: 0.3,
        stamp_ns: 1,
    })
    .unwrap();
    let ch = Arc::new(ParameterChannel::default());
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(
            link.node_recording(Some(rec.queue()))
                .with_clock(clock.clone()),
        )],
        Some(rec.queue()),
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
    .with_clock(clock)
    .with_parameters(ch.clone());
    let stop = AtomicBool::new(false);
    let double = |x: f64| ParameterValue {
        r#type: parameter_type::DOUBLE,
        double_value: x,
        ..Default::default()
    };
    let mut current = cfg.clone();
    let declared = declare(&cfg);
    // Three changes, each between two stretches of the run: what
    // `ros2 param set` does to a running node.
    l.run(&stop, Some(Duration::from_millis(300)));
    for changes in [
        vec![("contact.load_n", double(9000.0))],
        vec![
            ("contact.boundary_friction", double(0.2)),
            ("lubricant.viscosity_pa_s", double(0.1)),
        ],
        vec![("roughness.sigma_m", double(4e-6))],
    ] {
        let changes: Vec<(String, ParameterValue)> = changes
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        let next = apply_set(&current, &declared, &changes).unwrap();
        ch.submit(ParameterUpdate::prepare(&current, next.clone(), changes).unwrap())
            .unwrap();
        current = next;
        l.run(&stop, Some(Duration::from_millis(300)));
        let u = ch.take_applied().expect("applied");
        record_applied(&rec.queue(), "/friction_node", &u, WALL0).unwrap();
    }
    assert_eq!(l.summary().parameter_updates, 3);
    drop(l);
    let report = rec.finish();
    assert!(report.error.is_none(), "{report:?}");
    // The replay re-applies each change at the step that used it.
    let b = Bag::open(&bag).unwrap();
    let prepared = replay::prepare(&b, &ReplayOptions::default()).unwrap();
    assert_eq!(prepared.parameter_changes.len(), 3);
    let r = replay::run(&prepared, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    let oracle = r.oracle.expect("a friction-node bag");
    assert!(oracle.identical, "{:?}", oracle.deviations);
    assert_eq!(oracle.compared, 1200);
    // Without the changes the replay differs: they are what made it match.
    let mut without = prepared.clone();
    without.parameter_changes.clear();
    let r = replay::run(&without, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    assert!(!r.oracle.unwrap().identical);
}

/// The node's recordings end to end: a lockstep run and a received ROS 2
/// command decoded message by message, and real processes (SIGTERM, a
/// kill, a full disk, an unwritable path), which the tests wait on by
/// events, never by fixed sleeps.
mod node_runs {
    use super::*;
    use friction_node::config::topics::TopicNames;
    use friction_node::config::CommandType;
    use friction_node::link::FilmProfileSlot;
    use friction_node::msgs;
    use friction_node::msgs::EstimateRecord;
    use friction_node::record::{RecordPlan, Recorder};

    use crate::common::{drain, timer_config};

    /// `name` in a directory of its own, removed when the guard drops.
    fn tmp(name: &str) -> (crate::common::cli::FreshDir, std::path::PathBuf) {
        let d = fresh_dir("node", name);
        let path = d.join(name);
        (d, path)
    }

    /// Decode every message of a finished MCAP file: counts per schema.
    fn decode_all(
        path: &std::path::Path,
    ) -> (BTreeMap<String, usize>, Vec<msgs::FrictionEstimate>, String) {
        let bytes = std::fs::read(path).unwrap();
        let summary = mcap::Summary::read(&bytes)
            .unwrap()
            .expect("a summary section");
        let mut counts = BTreeMap::new();
        let mut est = Vec::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(schema.encoding, "ros2msg");
            assert_eq!(m.channel.message_encoding, "cdr");
            assert!(m.channel.metadata.contains_key("offered_qos_profiles"));
            let name = schema.name.clone();
            match name.as_str() {
                "friction_msgs/msg/FrictionEstimate" => {
                    est.push(msgs::from_cdr::<msgs::FrictionEstimate>(&m.data).unwrap())
                }
                "friction_msgs/msg/FilmProfile" => {
                    let p: msgs::FilmProfile = msgs::from_cdr(&m.data).unwrap();
                    assert_eq!(p.h_m.len(), 32);
                }
                "friction_msgs/msg/LoopStatistics" => {
                    drop(msgs::from_cdr::<msgs::LoopStatistics>(&m.data).unwrap())
                }
                "std_msgs/msg/Float64" => drop(msgs::from_cdr::<msgs::Float64>(&m.data).unwrap()),
                "geometry_msgs/msg/TwistStamped" => {
                    drop(msgs::from_cdr::<msgs::TwistStamped>(&m.data).unwrap())
                }
                other => panic!("unexpected schema {other}"),
            }
            *counts
                .entry(format!("{} {}", m.channel.topic, name))
                .or_insert(0) += 1;
        }
        let mut config = String::new();
        for idx in &summary.metadata_indexes {
            let md = mcap::read::metadata(&bytes, idx).unwrap();
            if md.name == "friction_node" {
                config = md.metadata["config_yaml"].clone();
            }
        }
        (counts, est, config)
    }

    #[test]
    fn a_recorded_lockstep_run_decodes_message_by_message_with_its_config() {
        let mut cfg = timer_config();
        cfg.node.step_mode = StepMode::Lockstep;
        cfg.ros.command_type = CommandType::TwistStamped;
        cfg.node.profile_rate_hz = 100.0;
        cfg.contact.load_n = 15_000.0;
        let (_dir, path) = tmp("roundtrip.mcap");
        let slot = FilmProfileSlot::new(cfg.solver.cells);
        let rec = Recorder::start(
            RecordPlan {
                path: Some(path.clone()),
                snapshot_dir: path.parent().unwrap().to_path_buf(),
            },
            &cfg,
            &TopicNames::from_config(&cfg),
            Some(slot.clone()),
            Arc::new(SimClock::new(WALL0)),
        )
        .unwrap();
        let link = MemoryQueues::new(100_000);
        let mut peer = link.peer();
        let n = 200;
        for k in 1..=n {
            peer.send(&Command {
                kind: CommandKind::Velocity,
                value: (k as f64 * 0.01).sin(),
                stamp_ns: 1_000_000 * k,
            })
            .unwrap();
        }
        let mut l = Loop::new(
            &cfg,
            vec![Box::new(link.node_recording(Some(rec.queue())))],
            Some(rec.queue()),
            Some(slot),
            Arc::new(LiveStatus::default()),
        )
        .unwrap()
        .with_clock(Arc::new(SimClock::new(WALL0)));
        while l.poll_once() > 0 {}
        let s = l.summary();
        assert_eq!(s.steps, n);
        let live = drain(&mut peer);
        let report = rec.finish();
        assert!(report.error.is_none(), "{report:?}");
        let (counts, est, config) = decode_all(&path);
        assert_eq!(
            counts["/friction_node/cmd_velocity geometry_msgs/msg/TwistStamped"],
            n as usize
        );
        assert_eq!(
            counts["/friction_node/friction friction_msgs/msg/FrictionEstimate"],
            n as usize
        );
        assert_eq!(
            counts["/friction_node/friction_force std_msgs/msg/Float64"],
            n as usize
        );
        assert!(counts["/friction_node/film_profile friction_msgs/msg/FilmProfile"] >= 1);
        assert_eq!(report.messages as usize, counts.values().sum::<usize>());
        // The recorded estimates are the published ones, bit for bit.
        let recorded: Vec<EstimateRecord> = est.iter().map(EstimateRecord::from_wire).collect();
        assert_eq!(recorded, live);
        // The config in the file is the resolved config.
        let back =
            Config::from_yaml(&config, &friction_node::config::Origin::Embedded, &[]).unwrap();
        assert_eq!(back, cfg);
    }

    #[cfg(feature = "ros2")]
    #[test]
    fn a_received_ros2_command_is_recorded_byte_for_byte_as_it_arrived() {
        use friction_node::transport::{ros2::Ros2Peer, ros2::Ros2Spec, BackendSpec};
        let mut cfg = timer_config();
        cfg.node.step_mode = StepMode::Lockstep;
        cfg.ros.command_type = CommandType::TwistStamped;
        cfg.ros.domain_id = 100 + (std::process::id() % 100) as i64;
        cfg.ros.namespace = format!("/fn_raw_{}", std::process::id());
        cfg.ros.qos.commands.reliability = friction_node::config::Reliability::Reliable;
        cfg.ros.qos.commands.durability = friction_node::config::Durability::TransientLocal;
        cfg.ros.qos.commands.depth = 100;
        let (_dir, path) = tmp("raw.mcap");
        let rec = Recorder::start(
            RecordPlan {
                path: Some(path.clone()),
                snapshot_dir: path.parent().unwrap().to_path_buf(),
            },
            &cfg,
            &TopicNames::from_config(&cfg),
            None,
            Arc::new(SimClock::new(WALL0)),
        )
        .unwrap();
        let spec = Ros2Spec::from_config(&cfg).unwrap();
        let port = BackendSpec::Ros2(spec.clone())
            .open_node(friction_node::transport::PortIo {
                record: Some(rec.queue()),
                ..Default::default()
            })
            .unwrap();
        let mut l = Loop::new(
            &cfg,
            vec![port],
            Some(rec.queue()),
            None,
            Arc::new(LiveStatus::default()),
        )
        .unwrap();
        let mut peer = Ros2Peer::open(&spec).unwrap();
        let start = std::time::Instant::now();
        while !peer.is_matched() {
            assert!(start.elapsed() < Duration::from_secs(30), "discovery");
            std::thread::sleep(Duration::from_millis(5));
        }
        // Everything a sender may put in it: another frame, angular velocity.
        let mut sent = msgs::TwistStamped::default();
        sent.header.frame_id = "sender_frame_äö".into();
        sent.header.stamp = msgs::Time::from_ns(WALL0 + 123);
        sent.twist.linear.x = 0.25;
        sent.twist.linear.y = -1.5;
        sent.twist.angular.z = 0.7;
        peer.send_twist(&sent).unwrap();
        let start = std::time::Instant::now();
        while l.summary().steps == 0 {
            assert!(
                start.elapsed() < Duration::from_secs(30),
                "the command arrives"
            );
            l.poll_once();
            std::thread::sleep(Duration::from_millis(1));
        }
        drop(l);
        let report = rec.finish();
        assert!(report.error.is_none(), "{report:?}");
        let bytes = std::fs::read(&path).unwrap();
        let raw: Vec<Vec<u8>> = mcap::MessageStream::new(&bytes)
            .unwrap()
            .map(Result::unwrap)
            .filter(|m| m.channel.topic.ends_with("cmd_velocity"))
            .map(|m| m.data.into_owned())
            .collect();
        assert_eq!(raw.len(), 1);
        assert_eq!(raw[0], msgs::to_cdr(&sent).unwrap(), "the bytes as sent");
        let back: msgs::TwistStamped = msgs::from_cdr(&raw[0]).unwrap();
        assert_eq!(back, sent);
    }

    fn node_cmd(args: &[&str]) -> std::process::Command {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_friction-node"));
        let svc = format!("fn_node_test_{}_{}", std::process::id(), args.len());
        c.args(args)
            .arg("--set")
            .arg(format!("iceoryx2.cmd_velocity_service={svc}/v"))
            .arg("--set")
            .arg(format!("iceoryx2.normal_load_service={svc}/l"))
            .arg("--set")
            .arg(format!("iceoryx2.friction_service={svc}/f"))
            .arg("--set")
            .arg(format!("iceoryx2.cmd_event_service={svc}/e"))
            .arg("--set")
            .arg(format!("iceoryx2.loop_statistics_service={svc}/s"))
            .arg("--set")
            .arg("solver.cells=32")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        c
    }

    /// Wait (at most `limit`) until `ok()` holds; panics with `what` if not.
    fn wait_for(what: &str, limit: Duration, mut ok: impl FnMut() -> bool) {
        let start = std::time::Instant::now();
        while !ok() {
            assert!(start.elapsed() < limit, "{what} not within {limit:?}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Read the child's stderr until the loop-running line (then keep
    /// draining it in the background so the child never blocks on it).
    fn wait_running(child: &mut std::process::Child) {
        use std::io::BufRead;
        let err = child.stderr.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(err).lines().map_while(Result::ok) {
                if line.contains("loop running") {
                    let _ = tx.send(());
                }
            }
        });
        rx.recv_timeout(Duration::from_secs(60))
            .expect("the node reports its loop running");
    }

    fn messages_before_damage(path: &std::path::Path) -> (usize, bool) {
        let bytes = std::fs::read(path).unwrap();
        let mut n = 0;
        let mut damaged = false;
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            match m {
                Ok(_) => n += 1,
                Err(_) => {
                    damaged = true;
                    break;
                }
            }
        }
        (n, damaged)
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn sigterm_finalises_the_recording() {
        let (_dir, path) = tmp("sigterm.mcap");
        let mut child = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "600",
            "--quiet",
            "--record",
            path.to_str().unwrap(),
        ])
        .spawn()
        .unwrap();
        wait_running(&mut child);
        // The first chunk reached the disk: the node is recording.
        wait_for("a flushed chunk", Duration::from_secs(60), || {
            messages_before_damage(&path).0 > 100
        });
        unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
        let out = child.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        // Finalised, and the exit code says SIGTERM ended it (128 + 15).
        assert_eq!(
            out.status.code(),
            Some(143),
            "{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains("stopped by signal"), "{stdout}");
        let bytes = std::fs::read(&path).unwrap();
        assert!(
            mcap::Summary::read(&bytes).unwrap().is_some(),
            "finalised with a summary"
        );
        let (n, damaged) = messages_before_damage(&path);
        assert!(n > 100 && !damaged, "{n} messages");
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn a_killed_node_leaves_its_recording_readable_up_to_the_last_chunk() {
        let (_dir, path) = tmp("killed.mcap");
        let mut child = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "600",
            "--quiet",
            "--record",
            path.to_str().unwrap(),
        ])
        .spawn()
        .unwrap();
        wait_running(&mut child);
        let mut before = 0;
        wait_for("two flushed chunks", Duration::from_secs(60), || {
            before = messages_before_damage(&path).0;
            before > 1000
        });
        child.kill().unwrap();
        let _ = child.wait();
        // No footer, but every complete chunk (closed at least each second) reads.
        let (n, _) = messages_before_damage(&path);
        assert!(
            n >= before,
            "{n} messages readable after a crash, {before} before it"
        );
    }

    /// A child whose files cannot grow beyond `limit` bytes: writes beyond
    /// fail with EFBIG, as on a full disk (SIGXFSZ ignored).
    fn with_file_limit(mut c: std::process::Command, limit: u64) -> std::process::Command {
        use std::os::unix::process::CommandExt;
        unsafe {
            c.pre_exec(move || {
                libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
                let r = libc::rlimit {
                    rlim_cur: limit,
                    rlim_max: limit,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &r) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        c
    }

    fn summary_steps(stdout: &str) -> u64 {
        stdout
            .lines()
            .find(|l| l.trim_start().starts_with("steps"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|s| s.parse().ok())
            .unwrap()
    }

    /// ROS 2 arguments on a domain and namespace of this test's own
    /// (iceoryx2 needs shared-memory files, which a file-size limit breaks).
    fn ros2_own(name: &str) -> [String; 4] {
        [
            "--set".into(),
            format!("ros.namespace=/fn_{name}_{}", std::process::id()),
            "--set".into(),
            format!("ros.domain_id={}", 150 + std::process::id() % 50),
        ]
    }

    #[cfg(feature = "ros2")]
    #[test]
    fn a_full_disk_stops_the_recording_not_the_loop() {
        let (_dir, path) = tmp("full.mcap");
        let mut c = node_cmd(&[
            "run",
            "--transport",
            "ros2",
            "--duration",
            "1.5",
            "--quiet",
            "--set",
            "recording.chunk_size_bytes=4096",
            "--record",
            path.to_str().unwrap(),
        ]);
        c.args(ros2_own("full"));
        let out = with_file_limit(c, 60_000).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{stdout}");
        assert!(stdout.contains("recording        FAILED"), "{stdout}");
        // Model time is wall time: 1.5 s of 1 ms steps (a stall beyond
        // node.max_catch_up_s would merge steps, never lose time).
        assert!(summary_steps(&stdout) >= 10, "{stdout}");
        // What reached the disk reads, up to the last complete chunk.
        assert!(messages_before_damage(&path).0 > 10);
    }

    #[cfg(feature = "ros2")]
    #[test]
    fn a_split_recording_resumes_in_a_new_file_when_writing_fails() {
        let (_guard, dir) = tmp("resume");
        let _ = std::fs::remove_dir_all(&dir);
        let mut c = node_cmd(&[
            "run",
            "--transport",
            "ros2",
            "--duration",
            "1.5",
            "--quiet",
            "--set",
            "recording.chunk_size_bytes=4096",
            "--set",
            "recording.split.max_duration_s=3600",
            "--record",
            dir.to_str().unwrap(),
        ]);
        c.args(ros2_own("resume"));
        let out = with_file_limit(c, 60_000).output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{stdout}");
        let meta = std::fs::read_to_string(dir.join("metadata.yaml")).unwrap();
        let files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".mcap"))
            .collect();
        assert!(
            files.len() >= 2,
            "resumed in new files: {files:?}\n{stdout}"
        );
        for f in &files {
            assert!(meta.contains(f.as_str()), "{f} listed in metadata.yaml");
            assert!(messages_before_damage(&dir.join(f)).0 > 0, "{f} readable");
        }
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn an_unwritable_recording_path_is_an_error_before_the_loop_runs() {
        let out = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "0.3",
            "--quiet",
            "--record",
            "/proc/nope/x.mcap",
        ])
        .output()
        .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains("/proc/nope/x.mcap"), "{stderr}");
        assert!(!stderr.contains("loop running"), "{stderr}");
    }
}
