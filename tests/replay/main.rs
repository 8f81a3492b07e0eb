//! Replay over the fixture bags in bags/ (regenerated only by
//! bags/regenerate.sh): one recorded by friction-node, one written by the
//! Python mcap-ros2-support writer. Bad bags are made here from them.
//! This file holds the shared helpers, the report and the input maps:
//!
//! | file | job |
//! |---|---|
//! | `topics.rs` | which topic and joint a replay reads |
//! | `fidelity.rs` | a replay reproduces its recording |
//! | `damage.rs` | bad bags and arguments, named, never a panic |
//! | `rosbag2.rs` | rosbag2 directories from an independent writer, replayed and fitted |
#![cfg(feature = "mcap")]

#[path = "../common/mod.rs"]
mod common;
mod damage;
mod fidelity;
mod rosbag2;
mod topics;
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

// rosbag2 directories written by the Python `rosbags` writer, both storages.

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
