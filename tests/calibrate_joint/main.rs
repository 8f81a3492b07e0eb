//! Calibration without an expert: a rotary joint's recording in its own
//! units (`fit --rotary`) and the terms chosen by the data (`--fit auto`),
//! through the command line as a user runs them. This file holds the
//! shared helpers:
//!
//! | file | job |
//! |---|---|
//! | `rotary.rs` | a joint in its own units |
//! | `sign.rs` | friction in the wrong sign convention, refused |
//! | `auto.rs` | `--fit auto` as a user runs it |
//! | `past_the_data.rs` | a joint predicted past its data |

mod auto;
#[path = "../common/mod.rs"]
mod common;
mod past_the_data;
mod rotary;
mod sign;
use common::cli::run;

use friction_node::config::Config;
use std::path::Path;

/// A fresh directory for test `name`.
fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("joint", name)
}

/// `simulate`'s columns t_s, velocity_m_s, friction_n of `csv`.
fn simulated(csv: &Path) -> Vec<(f64, f64, f64)> {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (t, v, f) = (col("t_s"), col("velocity_m_s"), col("friction_n"));
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (
                c[t].parse().unwrap(),
                c[v].parse().unwrap(),
                c[f].parse().unwrap(),
            )
        })
        .collect()
}

/// Deterministic noise in [-1, 1].
fn noise(k: usize) -> f64 {
    ((k as f64 * 12.9898).sin() * 43758.5453).fract() * 2.0 - 1.0
}

/// `simulate` on 32 cells with `velocity` for `seconds` and the extra
/// `--set`s `sets`, written to `d/name`, whose path is returned.
fn simulate_record(
    d: &Path,
    name: &str,
    velocity: &str,
    seconds: &str,
    sets: &[&str],
) -> std::path::PathBuf {
    let out = d.join(name);
    let mut args = vec!["simulate", "--velocity", velocity, "--duration", seconds];
    args.extend(["--set", "solver.cells=32"]);
    for s in sets {
        args.extend(["--set", s]);
    }
    args.extend(["--out", out.to_str().unwrap()]);
    let (code, _, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    out
}

/// A joint's record through a 20 mm lever, written with the joint's
/// column names (`velocity_rad_s`, `torque_nm`): `seconds` of a 0.5 Hz
/// sine of `amplitude_rad_s`.
fn joint_record(d: &Path, amplitude_rad_s: f64, seconds: f64) -> std::path::PathBuf {
    let velocity = format!("sine:0,{},0.5", 0.02 * amplitude_rad_s);
    let c = simulate_record(d, "contact.csv", &velocity, &seconds.to_string(), &[]);
    let mut text = String::from("t_s,velocity_rad_s,torque_nm\n");
    for (t, v, f) in simulated(&c).into_iter().step_by(10) {
        text += &format!("{t},{},{}\n", v / 0.02, f * 0.02);
    }
    let joint = d.join("joint.csv");
    std::fs::write(&joint, text).unwrap();
    joint
}
