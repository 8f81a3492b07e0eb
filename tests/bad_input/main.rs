//! The bad-input suite: every kind of mistake or damage a user's input can
//! carry, through the real binary. Each case asserts the exit code, that the
//! message names what is wrong, and that nothing half-written is left (no
//! output file, no temporary sibling). No input may panic (exit 101).
//! This file holds the shared helpers:
//!
//! | file | job |
//! |---|---|
//! | `configuration.rs` | configuration files and `--set` |
//! | `arguments.rs` | command-line arguments, signal specs and CSV tables |
//! | `outputs.rs` | output failures and recording settings that cannot work |

mod arguments;
#[path = "../common/mod.rs"]
mod common;
mod configuration;
mod outputs;

use std::path::Path;

struct Outcome {
    code: i32,
    stdout: String,
    stderr: String,
}

/// A fresh directory for test `name`.
fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("bad", name)
}

fn run(args: &[&str]) -> Outcome {
    let (code, stdout, stderr) = common::cli::run(args);
    Outcome {
        code,
        stdout,
        stderr,
    }
}

/// Files in `d` (names).
fn files(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The command fails with exit code 2, its last stderr line names every
/// needle, and `d` holds only `inputs` afterwards.
#[track_caller]
fn refused(args: &[&str], needles: &[&str], d: &Path, inputs: &[&str]) {
    let before: Vec<String> = inputs.iter().map(|s| s.to_string()).collect();
    let o = run(args);
    assert_eq!(
        o.code, 2,
        "{args:?}\nstdout: {}\nstderr: {}",
        o.stdout, o.stderr
    );
    assert!(
        o.stderr.lines().any(|l| l.starts_with("error: ")),
        "{args:?}: no error line in {:?}",
        o.stderr
    );
    for n in needles {
        assert!(
            o.stderr.contains(n),
            "{args:?}: the message does not name `{n}`:\n{}",
            o.stderr
        );
    }
    let mut left = files(d);
    left.retain(|f| !before.contains(f));
    assert!(left.is_empty(), "{args:?} left {left:?}");
}

fn write(d: &Path, name: &str, data: impl AsRef<[u8]>) -> String {
    let p = d.join(name);
    std::fs::write(&p, data).unwrap();
    p.to_str().unwrap().to_string()
}
