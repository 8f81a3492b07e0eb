//! The node's recordings end to end: a lockstep run and a received ROS 2
//! command decoded message by message, and real processes (SIGTERM, a
//! kill, a full disk, an unwritable path), which the tests wait on by
//! events, never by fixed sleeps.

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
    let back = Config::from_yaml(&config, &friction_node::config::Origin::Embedded, &[]).unwrap();
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
