//! The fitted file carries where it was calibrated (`calibrated_range`),
//! the report says where the validation data lie against it, and a
//! hand-edited range that is empty, inverted or non-finite is an error
//! naming its key.

mod common;
use common::cli::{quick_fit, run};

use friction_node::config::Config;
use std::path::Path;

fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("calibrated-range", name)
}

/// `simulate` a sine of amplitude `amplitude_m_s` into `out`.
fn simulate(out: &Path, amplitude_m_s: f64) {
    let (code, _, err) = run(&[
        "simulate",
        "--velocity",
        &format!("sine:0,{amplitude_m_s},1"),
        "--duration",
        "2",
        "--set",
        "solver.cells=32",
        "--set",
        "contact.load_n=500",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn the_fitted_file_carries_the_training_range_and_the_report_splits_the_validation_error_at_it() {
    let d = dir("round-trip");
    let (slow, fast) = (d.join("slow.csv"), d.join("fast.csv"));
    simulate(&slow, 0.02);
    simulate(&fast, 0.08);
    let out = d.join("fitted.yaml");
    let extra = [
        "--validate",
        fast.to_str().unwrap(),
        "--set",
        "contact.load_n=500",
    ];
    let (code, stdout, err) = quick_fit(&slow, "contact.boundary_friction", &out, &extra);
    assert!(code == 0 || code == 4, "{err}");
    // The range is the training data's: up to 0.02 m/s each way.
    let fitted = Config::load(Some(&out), &[]).unwrap();
    let r = fitted.calibrated_range.clone().expect("a calibrated range");
    let top = r.speed_forward_max_m_s.unwrap();
    assert!(top > 0.019 && top <= 0.02 + 1e-12, "{r:?}");
    assert!(r.speed_backward_max_m_s.unwrap() > 0.019, "{r:?}");
    // `simulate` writes its load and temperature: inputs, so in the range.
    assert_eq!((r.load_min_n, r.load_max_n), (Some(500.0), Some(500.0)));
    assert!(r.temperature_min_c.is_some(), "{r:?}");
    assert!(r.acceleration_max_m_s2.unwrap() > 0.1, "{r:?}");
    assert!(r.training_samples > 1000, "{r:?}");
    // It round-trips: the file written again from what was read is the same.
    let rewritten = d.join("rewritten.yaml");
    std::fs::write(&rewritten, fitted.to_yaml()).unwrap();
    let again = Config::load(Some(&rewritten), &[]).unwrap();
    assert_eq!(again.calibrated_range, fitted.calibrated_range);
    // The report: the validation record at 4× the speed lies mostly
    // outside, and its error is given inside and outside separately.
    assert!(
        stdout.contains("## Where the calibration holds"),
        "{stdout}"
    );
    let row = stdout
        .lines()
        .find(|l| l.contains("fast.csv") && l.contains("| validation |"))
        .unwrap_or_else(|| panic!("{stdout}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    let share: f64 = cells[4]
        .split('(')
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    assert!(share > 50.0 && share < 100.0, "{row}");
    assert!(
        cells[5].contains("speed") && cells[5].contains("× its top"),
        "{row}"
    );
    assert!(cells[6] != "—" && cells[7] != "—", "{row}");
}

#[test]
fn a_hand_edited_range_that_is_inverted_non_finite_or_half_given_is_an_error_naming_its_key() {
    let d = dir("bad");
    let cases = [
        (
            "speed_forward_min_m_s: 0.5\n  speed_forward_max_m_s: 0.1",
            "calibrated_range.speed_forward_min_m_s",
        ),
        (
            "speed_forward_min_m_s: 0.0\n  speed_forward_max_m_s: .nan",
            "calibrated_range.speed_forward_max_m_s",
        ),
        (
            "speed_forward_min_m_s: 0.0\n  speed_forward_max_m_s: 0.1\n  load_min_n: 10.0",
            "calibrated_range.load_max_n",
        ),
        (
            "load_min_n: 1.0\n  load_max_n: 2.0",
            "calibrated_range.speed_forward_max_m_s",
        ),
    ];
    for (k, (body, key)) in cases.iter().enumerate() {
        let f = d.join(format!("bad{k}.yaml"));
        let body = body.replace("\n  ", "\n      ");
        let text = format!(
            "friction_node:\n  ros__parameters:\n    calibrated_range:\n      {body}\n      training_rms_n: 1.0\n      training_samples: 10\n"
        );
        std::fs::write(&f, text).unwrap();
        let e = Config::load(Some(&f), &[]).unwrap_err().to_string();
        assert!(e.contains(key), "{key}: {e}");
    }
    // A configuration without one is not watched, and valid.
    let plain = d.join("plain.yaml");
    std::fs::write(
        &plain,
        "friction_node:\n  ros__parameters:\n    contact:\n      load_n: 100.0\n",
    )
    .unwrap();
    assert_eq!(
        Config::load(Some(&plain), &[]).unwrap().calibrated_range,
        None
    );
}

/// The number of contact steps outside on a summary line
/// (`calibrated range N contact steps outside`).
#[cfg(all(feature = "mcap", feature = "iceoryx2"))]
fn outside_count(text: &str) -> u64 {
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("calibrated range"))
        .unwrap_or_else(|| panic!("no calibrated range line in {text}"));
    line.split_whitespace()
        .nth(2)
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count in {line}"))
}

#[cfg(all(feature = "mcap", feature = "iceoryx2"))]
#[test]
fn replay_counts_the_steps_outside_the_calibrated_range_as_the_node_did_on_the_same_bag() {
    let d = dir("replay-count");
    let cfg = d.join("fitted.yaml");
    std::fs::write(
        &cfg,
        "/**:\n  ros__parameters:\n    calibrated_range:\n      speed_forward_min_m_s: 0.0\n      \
         speed_forward_max_m_s: 0.5\n      speed_backward_min_m_s: 0.0\n      \
         speed_backward_max_m_s: 0.7\n      training_rms_n: 1.0\n      training_samples: 100\n",
    )
    .unwrap();
    let bag = d.join("run.mcap");
    let (code, out, err) = run(&[
        "run",
        "--config",
        cfg.to_str().unwrap(),
        "--demo",
        "2",
        "--transport",
        "iceoryx2",
        "--set",
        "solver.cells=32",
        "--set",
        &format!(
            "iceoryx2.cmd_velocity_service=fn_cr_{}/cmd_velocity",
            std::process::id()
        ),
        "--set",
        &format!(
            "iceoryx2.friction_service=fn_cr_{}/friction",
            std::process::id()
        ),
        "--set",
        &format!(
            "iceoryx2.normal_load_service=fn_cr_{}/load",
            std::process::id()
        ),
        "--set",
        &format!(
            "iceoryx2.cmd_event_service=fn_cr_{}/event",
            std::process::id()
        ),
        "--set",
        &format!(
            "iceoryx2.loop_statistics_service=fn_cr_{}/stats",
            std::process::id()
        ),
        "--record",
        bag.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let node = outside_count(&out);
    // The demo's 1 m/s sine spends about half of its time above 0.5 m/s
    // forward and 0.7 m/s backward.
    assert!(node > 200, "{out}");
    let replay_out = d.join("replay.csv");
    let (code, replayed, err) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--out",
        replay_out.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(outside_count(&replayed), node, "{replayed}");
}
