//! The real-time loop: timer-mode behaviour, command validation, timeouts,
//! statistics, and MCAP recording (round trip, signals, crashes, full disks).

use friction_node::config::{Config, StepMode, TimeoutBehaviour};
use friction_node::msgs::{estimate_constants as codes, Command, CommandKind, EstimateRecord};
use friction_node::node::{LiveStatus, Loop};
use friction_node::transport::memory::MemoryLink;
use friction_node::transport::{NodePort, PeerPort};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

fn timer_config() -> Config {
    let mut c = Config::default();
    c.solver.cells = 32;
    c.node.step_mode = StepMode::Timer;
    c.node.statistics_rate_hz = 10.0;
    c.node.command_timeout_s = 0.05;
    c
}

fn drain(peer: &mut dyn PeerPort) -> Vec<EstimateRecord> {
    std::iter::from_fn(|| peer.try_recv().unwrap()).collect()
}

#[test]
fn timer_mode_holds_the_last_command_and_flags_the_timeout() {
    let cfg = timer_config();
    let link = MemoryLink::new(100_000);
    let mut peer = link.peer();
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: 0.4,
        stamp_ns: 1,
    })
    .unwrap();
    let ports: Vec<Box<dyn NodePort>> = vec![Box::new(link.node())];
    let mut l = Loop::new(&cfg, ports, None, None, Arc::new(LiveStatus::default())).unwrap();
    let s = l.run(&AtomicBool::new(false), Some(Duration::from_millis(400)));
    let est = drain(&mut peer);
    // At most one step per millisecond; how many depends on the machine's load.
    assert!(
        s.steps >= 100 && s.steps <= 400,
        "{} steps in 400 ms",
        s.steps
    );
    assert_eq!(est.len() as u64, s.steps);
    // Zero-order hold of 0.4 m/s throughout; fresh for the first 50 ms, then timed out.
    assert!(est.iter().all(|e| e.velocity_m_s == 0.4));
    assert_eq!(est[0].status, codes::STATUS_CONVERGED);
    assert_eq!(est.last().unwrap().status, codes::STATUS_COMMAND_TIMEOUT);
    assert!(s.command_timeouts > 0);
    // Statistics at 10 Hz.
    let stats = link.take_statistics();
    assert!(!stats.is_empty() && stats[0].steps == 100, "{stats:?}");
    assert!(
        stats[0].compute_time_ns[0] > 0
            && stats[0].compute_time_ns[2] >= stats[0].compute_time_ns[1]
    );
    // Stamps are wall-clock time and increase.
    assert!(est.windows(2).all(|w| w[1].stamp_ns > w[0].stamp_ns));
}

#[test]
fn timeout_ramp_brings_the_velocity_to_zero_at_the_configured_deceleration() {
    let mut cfg = timer_config();
    cfg.node.timeout_behaviour = TimeoutBehaviour::RampToZero;
    cfg.node.timeout_deceleration_m_s2 = 4.0;
    let link = MemoryLink::new(100_000);
    let mut peer = link.peer();
    peer.send(&Command {
        kind: CommandKind::Velocity,
        value: 0.3,
        stamp_ns: 1,
    })
    .unwrap();
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap();
    l.run(&AtomicBool::new(false), Some(Duration::from_millis(600)));
    let est = drain(&mut peer);
    let ramp: Vec<f64> = est
        .iter()
        .filter(|e| e.status == codes::STATUS_COMMAND_TIMEOUT)
        .map(|e| e.velocity_m_s)
        .collect();
    assert!(ramp.len() > 75, "{} timed-out steps", ramp.len());
    // 4 m/s² × 1 ms per step: 0.3 → 0 in 75 steps, monotonically.
    assert!(
        ramp.windows(2)
            .all(|w| w[1] <= w[0] && w[0] - w[1] <= 0.004 + 1e-12),
        "{:?}",
        &ramp[..10]
    );
    assert_eq!(*ramp.last().unwrap(), 0.0);
}

#[test]
fn absurd_and_non_finite_commands_never_reach_the_solver() {
    let cfg = timer_config();
    let link = MemoryLink::new(100_000);
    let mut peer = link.peer();
    let send = |p: &mut dyn PeerPort, kind, value| {
        p.send(&Command {
            kind,
            value,
            stamp_ns: 1,
        })
        .unwrap()
    };
    send(&mut peer, CommandKind::Velocity, 0.2);
    send(&mut peer, CommandKind::Load, 12_000.0);
    for bad in [f64::NAN, f64::INFINITY, 11.0, -50.0] {
        send(&mut peer, CommandKind::Velocity, bad);
    }
    for bad in [f64::NAN, -1.0, 0.0, 1e9] {
        send(&mut peer, CommandKind::Load, bad);
    }
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap();
    let s = l.run(&AtomicBool::new(false), Some(Duration::from_millis(30)));
    let est = drain(&mut peer);
    assert_eq!(s.commands_rejected, 8);
    assert_eq!(s.commands_received, 10);
    // The first step flags the rejections; the good values are held.
    assert_eq!(est[0].status, codes::STATUS_COMMAND_REJECTED);
    assert!(est
        .iter()
        .all(|e| e.velocity_m_s == 0.2 && e.load_n == 12_000.0 && e.friction_force_n.is_finite()));
    assert!(est[1..]
        .iter()
        .all(|e| e.status != codes::STATUS_COMMAND_REJECTED));
}

#[cfg(feature = "mcap")]
mod recording {
    use super::*;
    use friction_node::config::CommandType;
    use friction_node::msgs;
    use friction_node::record::Recorder;
    use friction_node::transport::names::TopicNames;
    use friction_node::transport::ProfileSlot;
    use std::collections::BTreeMap;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("fn-node-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d.join(name)
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
        let path = tmp("roundtrip.mcap");
        let slot = ProfileSlot::new(cfg.solver.cells);
        let rec = Recorder::start(
            &path,
            &cfg,
            &TopicNames::from_config(&cfg),
            Some(slot.clone()),
        )
        .unwrap();
        let link = MemoryLink::new(100_000);
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
            vec![Box::new(link.node())],
            Some(rec.queue()),
            Some(slot),
            Arc::new(LiveStatus::default()),
        )
        .unwrap();
        let s = l.run(&AtomicBool::new(false), Some(Duration::from_millis(400)));
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
            .arg("solver.cells=32")
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        c
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
        let path = tmp("sigterm.mcap");
        let child = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "60",
            "--quiet",
            "--record",
            path.to_str().unwrap(),
        ])
        .spawn()
        .unwrap();
        std::thread::sleep(Duration::from_millis(1500));
        unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
        let out = child.wait_with_output().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
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
        let path = tmp("killed.mcap");
        let mut child = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "60",
            "--quiet",
            "--record",
            path.to_str().unwrap(),
        ])
        .spawn()
        .unwrap();
        std::thread::sleep(Duration::from_millis(2500));
        child.kill().unwrap();
        let _ = child.wait();
        // No footer, but every complete chunk (closed at least each second) reads.
        let (n, _) = messages_before_damage(&path);
        assert!(n >= 100, "{n} messages readable after a crash");
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn a_full_disk_stops_the_recording_not_the_loop() {
        // /dev/full accepts the file but fails every write with ENOSPC.
        let out = node_cmd(&[
            "run",
            "--transport",
            "iceoryx2",
            "--duration",
            "1",
            "--quiet",
            "--record",
            "/dev/full",
        ])
        .output()
        .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1), "{stdout}");
        assert!(stdout.contains("recording        FAILED"), "{stdout}");
        let steps: u64 = stdout
            .lines()
            .find(|l| l.trim_start().starts_with("steps"))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|s| s.parse().ok())
            .unwrap();
        assert!(steps > 100, "the loop kept stepping: {steps}");
    }

    #[cfg(feature = "iceoryx2")]
    #[test]
    fn an_unwritable_recording_path_is_reported_and_the_node_runs() {
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
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(1));
        assert!(
            stdout.contains("FAILED") && stdout.contains("/proc/nope/x.mcap"),
            "{stdout}"
        );
        assert!(stdout.contains("steps"), "{stdout}");
    }
}
