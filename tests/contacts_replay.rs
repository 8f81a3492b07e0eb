//! Recording and replay of several contacts: the node records each
//! contact's estimate on its own topic (`~/contacts/NAME/friction`) and the
//! joint commands as JointState; replay re-simulates every contact together
//! and checks each against its recording (the oracle per contact), through
//! CSV and MCAP outputs, and a changed contact is the only one that differs.

#![cfg(all(feature = "mcap", feature = "iceoryx2"))]

mod common;
use common::cli::fresh_dir;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const CONFIG: &str = "\
friction_node:
  ros__parameters:
    node:
      transport: iceoryx2
    solver:
      cells: 48
    contacts:
      left:  {joint: x_left,  contact: {load_n: 5000.0}}
      right: {joint: x_right, contact: {load_n: 4000.0}}
      wrist: {joint: wrist, gain: 0.03, contact: {load_n: 800.0}, solver: {cells: 32}}
";

fn node(d: &Path, args: &[&str]) -> Output {
    let svc = format!(
        "fn_{}",
        d.file_name().unwrap().to_string_lossy().replace('-', "_")
    );
    let mut c = Command::new(env!("CARGO_BIN_EXE_friction-node"));
    c.arg("--config").arg(d.join("three.yaml"));
    for (key, suffix) in [
        ("cmd_velocity_service", "v"),
        ("normal_load_service", "l"),
        ("temperature_service", "t"),
        ("friction_service", "f"),
        ("loop_statistics_service", "s"),
        ("cmd_event_service", "e"),
        ("joint_state_service", "j"),
        ("efforts_service", "x"),
        ("contact_friction_service", "c"),
    ] {
        c.arg("--set").arg(format!("iceoryx2.{key}={svc}/{suffix}"));
    }
    c.args(args).output().unwrap()
}

fn ok(o: &Output) -> String {
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "exit {:?}\n{out}\n{}",
        o.status,
        String::from_utf8_lossy(&o.stderr)
    );
    out
}

/// A recorded run of three contacts driven by the demo's JointStates.
fn recording(d: &Path) -> PathBuf {
    std::fs::write(d.join("three.yaml"), CONFIG).unwrap();
    let bag = d.join("three.mcap");
    ok(&node(
        d,
        &[
            "run",
            "--demo",
            "1",
            "--record",
            bag.to_str().unwrap(),
            "--quiet",
        ],
    ));
    bag
}

/// A joint's replay row holds the joint's velocity and effort beside the
/// contact's: ω = v / gain, τ = gain · F (the wrist's gain is 0.03).
fn assert_the_joint_columns_are_the_contacts_through_their_gains(
    rows: &[Vec<&str>],
    col: &dyn Fn(&str) -> usize,
) {
    let num = |r: &Vec<&str>, c: &str| -> f64 { r[col(c)].parse().unwrap() };
    let mut moving = 0;
    for r in rows {
        let (joint, gain) = match r[col("contact")] {
            "left" => ("x_left", 1.0),
            "right" => ("x_right", 1.0),
            _ => ("wrist", 0.03),
        };
        assert_eq!(r[col("joint")], joint);
        approx::assert_relative_eq!(
            num(r, "joint_velocity"),
            num(r, "velocity_m_s") / gain,
            max_relative = 1e-12
        );
        approx::assert_relative_eq!(
            num(r, "joint_effort"),
            gain * num(r, "friction_n"),
            max_relative = 1e-12
        );
        moving += usize::from(num(r, "joint_effort") != 0.0);
    }
    assert!(moving > rows.len() / 2);
}

#[test]
fn a_recording_of_three_contacts_replays_bit_identical_for_each_contact() {
    let d = fresh_dir("contacts-replay", "identical");
    let bag = recording(&d);
    // The bag: each contact's estimates and the joint commands, readable alone.
    let reader = friction_node::bag::Bag::open(&bag).unwrap();
    let scan = reader.scan().unwrap();
    let count = |t: &str| scan.channel(t).map_or(0, |c| c.messages);
    for name in ["left", "right", "wrist"] {
        assert!(
            count(&format!("/friction_node/contacts/{name}/friction")) > 500,
            "{}",
            friction_node::bag::listing(&scan.listing())
        );
    }
    assert!(count("/friction_node/joint_commands") > 1500);
    let csv = d.join("replay.csv");
    let out = ok(&node(
        &d,
        &[
            "replay",
            bag.to_str().unwrap(),
            "--out",
            csv.to_str().unwrap(),
            "--expect-identical",
        ],
    ));
    for name in ["left", "right", "wrist"] {
        assert!(
            out.lines()
                .any(|l| l.trim_start().starts_with(name) && l.contains("bit-identical")),
            "{out}"
        );
    }
    // Every contact's rows, named in the contact column.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert!(head.ends_with(&["contact", "joint", "joint_velocity", "joint_effort"]));
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let per = |n: &str| rows.iter().filter(|r| r[col("contact")] == n).count();
    assert!(per("left") > 500);
    assert_eq!(per("left"), per("right"));
    assert_eq!(per("left"), per("wrist"));
    assert_eq!(rows.len(), 3 * per("left"));
    assert_the_joint_columns_are_the_contacts_through_their_gains(&rows, &col);
    // Replayed to MCAP, and that replayed again: still identical.
    let again = d.join("replay.mcap");
    ok(&node(
        &d,
        &[
            "replay",
            bag.to_str().unwrap(),
            "--out",
            again.to_str().unwrap(),
            "--expect-identical",
        ],
    ));
    ok(&node(
        &d,
        &[
            "replay",
            again.to_str().unwrap(),
            "--out",
            d.join("twice.csv").to_str().unwrap(),
            "--expect-identical",
        ],
    ));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_changed_contact_is_the_only_one_the_oracle_flags() {
    let d = fresh_dir("contacts-replay", "changed");
    let bag = recording(&d);
    let o = node(
        &d,
        &[
            "replay",
            bag.to_str().unwrap(),
            "--set",
            "contacts.wrist.lubricant.viscosity_pa_s=0.2",
            "--out",
            d.join("x.csv").to_str().unwrap(),
            "--expect-identical",
        ],
    );
    assert_eq!(o.status.code(), Some(3));
    let out = String::from_utf8_lossy(&o.stdout);
    let line = |n: &str| {
        out.lines()
            .find(|l| l.trim_start().starts_with(n))
            .unwrap_or_else(|| panic!("no line for {n}:\n{out}"))
            .to_string()
    };
    assert!(line("left").contains("bit-identical"), "{out}");
    assert!(line("right").contains("bit-identical"), "{out}");
    assert!(line("wrist").contains("DIFFERS"), "{out}");
    // Driven by its recorded joint commands instead (a JointState topic):
    // every contact re-simulated, with nothing to compare to.
    let out = ok(&node(
        &d,
        &[
            "replay",
            bag.to_str().unwrap(),
            "--topic",
            "/friction_node/joint_commands",
            "--out",
            d.join("y.csv").to_str().unwrap(),
        ],
    ));
    assert!(out.contains("3 replayed together"), "{out}");
    // A Float64 topic cannot drive several contacts: a clear refusal.
    let o = node(
        &d,
        &[
            "replay",
            bag.to_str().unwrap(),
            "--topic",
            "/friction_node/cmd_velocity",
            "--out",
            d.join("z.csv").to_str().unwrap(),
        ],
    );
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("3 contacts") && err.contains("JointState"),
        "{err}"
    );
    assert!(!d.join("z.csv").exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_joint_state_bag_drives_every_configured_joint_each_as_its_one_joint_replay() {
    let d = fresh_dir("contacts-replay", "joints");
    std::fs::write(
        d.join("two.yaml"),
        "friction_node:\n  ros__parameters:\n    contacts:\n      slide: {joint: slider}\n      \
         yaw: {joint: base_yaw, gain: 0.05, contact: {load_n: 3000.0}}\n",
    )
    .unwrap();
    let bag = Path::new(env!("CARGO_MANIFEST_DIR")).join("bags/foreign_joint_states.mcap");
    let bin = env!("CARGO_BIN_EXE_friction-node");
    let two = d.join("two.csv");
    let o = Command::new(bin)
        .arg("--config")
        .arg(d.join("two.yaml"))
        .args([
            "replay",
            bag.to_str().unwrap(),
            "--out",
            two.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let out = ok(&o);
    assert!(out.contains("2 replayed together"), "{out}");
    let one = d.join("one.csv");
    ok(&Command::new(bin)
        .args([
            "replay",
            bag.to_str().unwrap(),
            "--topic",
            "/joint_states",
            "--joint",
            "slider",
            "--out",
            one.to_str().unwrap(),
        ])
        .output()
        .unwrap());
    // The slider's rows are the one-joint replay's, bit for bit (load topic
    // and resampling included); the yaw joint has as many of its own.
    let two = std::fs::read_to_string(&two).unwrap();
    let one = std::fs::read_to_string(&one).unwrap();
    // A row of several contacts: the one-contact columns, then contact,
    // joint, joint velocity and joint effort.
    fn split(l: &str) -> (&str, &str) {
        let mut back = l.rsplitn(5, ',');
        let _effort_velocity_joint = (back.next(), back.next(), back.next());
        let contact = back.next().unwrap();
        (back.next().unwrap(), contact)
    }
    let slide: Vec<&str> = two
        .lines()
        .skip(1)
        .map(split)
        .filter(|(_, c)| *c == "slide")
        .map(|(row, _)| row)
        .collect();
    let single: Vec<&str> = one.lines().skip(1).collect();
    assert!(single.len() > 1900);
    assert_eq!(slide, single);
    let yaw = two.lines().skip(1).filter(|l| split(l).1 == "yaw").count();
    assert_eq!(yaw, single.len());
    // A configured joint the bag does not have is named.
    std::fs::write(
        d.join("bad.yaml"),
        "friction_node:\n  ros__parameters:\n    contacts:\n      slide: {joint: slider}\n      \
         knee: {joint: knee}\n",
    )
    .unwrap();
    let o = Command::new(bin)
        .arg("--config")
        .arg(d.join("bad.yaml"))
        .args([
            "replay",
            bag.to_str().unwrap(),
            "--out",
            d.join("x.csv").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("knee"), "{err}");
    assert!(!d.join("x.csv").exists());
    let _ = std::fs::remove_dir_all(&d);
}
