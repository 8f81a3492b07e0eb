//! Recording for months: split files with `metadata.yaml`, a disk budget,
//! snapshots of the last seconds, and replay of a split directory; on
//! simulated time, so every count is exact; and the node's recordings end to
//! end, in real processes ([`node_runs`]).
#![cfg(feature = "mcap")]

#[path = "../common/mod.rs"]
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

mod node_runs;
