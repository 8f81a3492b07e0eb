//! One rule for the inputs the model accepts, checked by every entry point:
//! the same bad values (`tests/fixtures/envelope_cases.csv`, also read by
//! the C API's and Python's tests) are refused by `simulate` and by the
//! node's commands with the envelope's message.

mod common;

use common::cli::fresh_dir;
use friction_node::clock::SimClock;
use friction_node::config::{Config, Envelope, StepMode};
use friction_node::link::LiveStatus;
use friction_node::msgs::{estimate_constants as codes, Command, CommandKind};
use friction_node::node::Loop;
use friction_node::transport::memory::MemoryQueues;
use friction_node::transport::PeerPort;
use std::process::Command as Process;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Duration;

struct Case {
    quantity: String,
    value: f64,
    overrides: Vec<String>,
    expect: String,
}

fn cases() -> Vec<Case> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/envelope_cases.csv"
    );
    let mut r = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(path)
        .expect("the cases file");
    let cases: Vec<Case> = r
        .records()
        .map(|rec| {
            let rec = rec.expect("a row");
            Case {
                quantity: rec[0].to_string(),
                value: rec[1].parse().expect("a number"),
                overrides: rec[2]
                    .split(';')
                    .filter(|s| !s.is_empty())
                    .map(str::to_string)
                    .collect(),
                expect: rec[3].to_string(),
            }
        })
        .collect();
    assert!(cases.len() >= 10, "{} cases", cases.len());
    cases
}

fn config(c: &Case) -> Config {
    Config::load(None, &c.overrides).expect("the case's overrides are valid")
}

#[test]
fn the_envelope_refuses_every_case_with_the_expected_message() {
    for c in cases() {
        let e = Envelope::of(&config(&c));
        let r = match c.quantity.as_str() {
            "temperature" => e.viscosity.viscosity_at(c.value).map(|_| ()),
            "velocity" => e.limits.check_velocity(c.value),
            "load" => e.limits.check_load(c.value),
            q => panic!("unknown quantity {q}"),
        };
        let m = r
            .expect_err(&format!("{} {}", c.quantity, c.value))
            .to_string();
        assert!(m.contains(&c.expect), "{} {}: {m}", c.quantity, c.value);
    }
}

#[test]
fn simulate_refuses_every_case_before_writing_anything() {
    let dir = fresh_dir("envelope", "refused");
    let out = dir.join("run.csv");
    for c in cases() {
        let v = format!("const:{}", c.value);
        let mut args: Vec<String> = vec!["simulate".into(), "--duration".into(), "0.01".into()];
        match c.quantity.as_str() {
            "temperature" => args.extend([
                "--velocity".into(),
                "const:0.1".into(),
                "--temperature".into(),
                v,
            ]),
            "velocity" => args.extend(["--velocity".into(), v]),
            "load" => args.extend(["--velocity".into(), "const:0.1".into(), "--load".into(), v]),
            q => panic!("unknown quantity {q}"),
        }
        for o in &c.overrides {
            args.extend(["--set".into(), o.clone()]);
        }
        args.extend(["--out".into(), out.display().to_string()]);
        let r = Process::new(env!("CARGO_BIN_EXE_friction-node"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        // A signal spec cannot even hold a non-finite number.
        let expect = if c.value.is_finite() {
            c.expect.as_str()
        } else {
            "is not finite"
        };
        assert!(err.contains(expect), "{args:?}: {err}");
        assert!(!out.exists());
    }
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "nothing left behind"
    );
}

#[test]
fn the_node_rejects_every_case_as_a_command() {
    for c in cases() {
        let mut cfg = config(&c);
        cfg.solver.cells = 32;
        cfg.node.step_mode = StepMode::Timer;
        let link = MemoryQueues::new(100);
        let mut peer = link.peer();
        let kind = match c.quantity.as_str() {
            "temperature" => CommandKind::Temperature,
            "velocity" => CommandKind::Velocity,
            "load" => CommandKind::Load,
            q => panic!("unknown quantity {q}"),
        };
        peer.send(&Command {
            kind,
            value: c.value,
            stamp_ns: 1,
        })
        .unwrap();
        let clock = Arc::new(SimClock::starting_at(0, 1_763_900_000_000_000_000));
        let mut l = Loop::new(
            &cfg,
            vec![Box::new(link.node())],
            None,
            None,
            Arc::new(LiveStatus::default()),
        )
        .unwrap()
        .with_clock(clock);
        let s = l.run(&AtomicBool::new(false), Some(Duration::from_millis(3)));
        assert_eq!(
            (s.commands_received, s.commands_rejected),
            (1, 1),
            "{} {}",
            c.quantity,
            c.value
        );
        let first = link.peer().try_recv().unwrap().expect("an estimate");
        assert_eq!(first.command_status, codes::COMMAND_REJECTED);
    }
}
