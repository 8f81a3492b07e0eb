//! SIGINT and SIGTERM during long offline work (`simulate`, `study`,
//! `replay`, `fit`): the command stops, exits 128 + the signal and leaves no
//! temporary (half-written) file. Each test signals the process once it
//! has printed the line it prints just before the long part (an event, not
//! a delay), with work sized to take far longer than that.

mod common;
use common::cli::{bin, fresh_dir};

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::Stdio;

/// Every file under `d`, recursively.
fn files(d: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(d).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(files(&p));
        } else {
            out.push(p);
        }
    }
    out
}

/// Start `args`, send `signal` once a stderr line contains `ready`, and
/// return the exit code and the whole stderr.
fn interrupt(args: &[&str], ready: &str, signal: i32) -> (Option<i32>, String) {
    let mut child = bin()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = String::new();
    loop {
        let line = lines
            .next()
            .unwrap_or_else(|| panic!("{args:?} ended before printing `{ready}`:\n{seen}"))
            .unwrap();
        seen.push_str(&line);
        seen.push('\n');
        if line.contains(ready) {
            break;
        }
    }
    // SAFETY: signalling our own child process.
    assert_eq!(unsafe { libc::kill(child.id() as i32, signal) }, 0);
    for l in lines {
        seen.push_str(&l.unwrap());
        seen.push('\n');
    }
    (child.wait().unwrap().code(), seen)
}

/// A simulated record of `sine:0,0.5,1` for `duration_s` on `cells` cells,
/// written to `d/data.csv`: the data the fit tests interrupt.
fn sine_record(d: &Path, duration_s: &str, cells: &str) -> PathBuf {
    let data = d.join("data.csv");
    let sim = bin()
        .args([
            "simulate",
            "--velocity",
            "sine:0,0.5,1",
            "--duration",
            duration_s,
        ])
        .args(["--set", &format!("solver.cells={cells}"), "--out"])
        .arg(&data)
        .output()
        .unwrap();
    assert!(
        sim.status.success(),
        "{}",
        String::from_utf8_lossy(&sim.stderr)
    );
    data
}

#[test]
fn sigint_and_sigterm_stop_simulate_and_remove_its_temporary_file() {
    for (signal, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        let d = fresh_dir("interrupt", &format!("simulate-{signal}"));
        let out = d.join("run.csv");
        let (rc, err) = interrupt(
            &[
                "simulate",
                "--velocity",
                "const:0.1",
                "--duration",
                "300",
                "--set",
                "solver.cells=8192",
                "--out",
                out.to_str().unwrap(),
            ],
            "simulate: velocity",
            signal,
        );
        assert_eq!(rc, Some(code), "{err}");
        assert!(err.contains("interrupted by SIG"), "{err}");
        assert_eq!(files(&d), Vec::<PathBuf>::new(), "nothing left behind");
    }
}

#[cfg(feature = "iceoryx2")]
#[test]
fn sigint_and_sigterm_end_the_node_with_their_exit_codes_after_its_summary() {
    // One after the other: the two runs use the same iceoryx2 services.
    for (signal, code) in [(libc::SIGINT, 130), (libc::SIGTERM, 143)] {
        let (rc, err) = interrupt(
            &[
                "run",
                "--transport",
                "iceoryx2",
                "--duration",
                "600",
                "--quiet",
            ],
            "loop running",
            signal,
        );
        assert_eq!(rc, Some(code), "{err}");
    }
}

#[test]
fn sigint_stops_a_study_before_anything_is_written() {
    let d = fresh_dir("interrupt", "study");
    let (rc, err) = interrupt(
        &[
            "study",
            "all",
            "--out",
            d.to_str().unwrap(),
            "--set",
            "solver.cells=4096",
        ],
        "cases and",
        libc::SIGINT,
    );
    assert_eq!(rc, Some(130), "{err}");
    assert_eq!(files(&d), Vec::<PathBuf>::new(), "nothing written");
}

#[test]
#[cfg(feature = "mcap")]
fn sigterm_stops_a_replay_and_removes_its_temporary_output() {
    let d = fresh_dir("interrupt", "replay");
    let bag = concat!(env!("CARGO_MANIFEST_DIR"), "/bags/node_lockstep.mcap");
    let out = d.join("replay.csv");
    // 2 s of bag at 10 µs steps on 8192 cells: far longer than the signal.
    let (rc, err) = interrupt(
        &[
            "replay",
            bag,
            "--out",
            out.to_str().unwrap(),
            "--set",
            "solver.cells=8192",
            "--set",
            "solver.dt_s=1e-5",
        ],
        "replay ",
        libc::SIGTERM,
    );
    assert_eq!(rc, Some(143), "{err}");
    assert_eq!(files(&d), Vec::<PathBuf>::new(), "nothing left behind");
}

#[test]
fn sigint_stops_a_fit_before_it_writes_anything() {
    let d = fresh_dir("interrupt", "fit");
    let data = sine_record(&d, "4", "64");
    let out = d.join("fitted.yaml");
    let (rc, err) = interrupt(
        &[
            "fit",
            data.to_str().unwrap(),
            "--fit",
            "contact.boundary_friction,roughness.sigma_m,lubricant.viscosity_pa_s",
            "--global-points",
            "10000",
            "--out",
            out.to_str().unwrap(),
            "--set",
            "solver.cells=2048",
        ],
        "parameter(s) on",
        libc::SIGINT,
    );
    assert_eq!(rc, Some(130), "{err}");
    assert_eq!(files(&d), vec![data], "only the data is there");
}

#[test]
fn an_interrupted_fit_says_so_in_words_and_leaves_no_empty_report_folder() {
    let d = fresh_dir("interrupt", "fit-report");
    let data = sine_record(&d, "4", "64");
    let report = d.join("report");
    let (rc, err) = interrupt(
        &[
            "fit",
            data.to_str().unwrap(),
            "--fit",
            "contact.boundary_friction,roughness.sigma_m",
            "--global-points",
            "0",
            "--starts",
            "2",
            "--out",
            d.join("fitted.yaml").to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "--set",
            "solver.cells=2048",
        ],
        "parameter(s) on",
        libc::SIGINT,
    );
    assert_eq!(rc, Some(130), "{err}");
    assert!(!err.contains("User("), "no internal names: {err}");
    assert!(!report.exists(), "the report folder it made is gone");
    assert_eq!(files(&d), vec![data], "only the data is there");
}

#[test]
fn a_second_signal_ends_at_once_and_still_removes_the_temporary_file() {
    // Both signals arrive together (held while the process is stopped):
    // the second ends the process at once, as a second Ctrl-C or
    // `timeout -s INT` (which signals the whole group) does.
    let d = fresh_dir("interrupt", "double");
    let out = d.join("run.csv");
    let mut child = bin()
        .args(["simulate", "--velocity", "const:0.1", "--duration", "300"])
        .args(["--set", "solver.cells=8192", "--out"])
        .arg(&out)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    for l in lines.by_ref() {
        if l.unwrap().contains("simulate: velocity") {
            break;
        }
    }
    let pid = child.id() as i32;
    // SAFETY: signalling our own child process.
    unsafe {
        assert_eq!(libc::kill(pid, libc::SIGSTOP), 0);
        assert_eq!(libc::kill(pid, libc::SIGINT), 0);
        assert_eq!(libc::kill(pid, libc::SIGTERM), 0);
        assert_eq!(libc::kill(pid, libc::SIGCONT), 0);
    }
    let rest: Vec<String> = lines.map(|l| l.unwrap()).collect();
    let rc = child.wait().unwrap().code();
    assert!(matches!(rc, Some(130) | Some(143)), "{rc:?}: {rest:?}");
    assert_eq!(files(&d), Vec::<PathBuf>::new(), "no temporary left behind");
}

#[test]
fn an_interrupted_term_selection_writes_nothing_and_exits_130() {
    let d = fresh_dir("interrupt", "auto");
    let data = sine_record(&d, "2", "32");
    let report = d.join("report");
    // Stopped while the candidates of the first step are fitted.
    let (rc, err) = interrupt(
        &[
            "fit",
            data.to_str().unwrap(),
            "--fit",
            "auto",
            "--out",
            d.join("fitted.yaml").to_str().unwrap(),
            "--report",
            report.to_str().unwrap(),
            "--set",
            "solver.cells=32",
        ],
        "auto: base",
        libc::SIGINT,
    );
    assert_eq!(rc, Some(130), "{err}");
    assert!(!report.exists(), "the report folder it made is gone");
    assert_eq!(files(&d), vec![data], "only the data is there");
}

#[test]
fn a_stop_during_the_classic_models_keeps_the_fitted_file_and_says_so() {
    let d = fresh_dir("interrupt", "baselines");
    // A long record: the classic models take seconds on it.
    let data = sine_record(&d, "200", "8");
    let out = d.join("fitted.yaml");
    let (rc, err) = interrupt(
        &[
            "fit",
            data.to_str().unwrap(),
            "--fit",
            "contact.boundary_friction",
            "--starts",
            "1",
            "--global-points",
            "0",
            "--max-evaluations",
            "10",
            "--baselines",
            "--out",
            out.to_str().unwrap(),
            "--set",
            "solver.cells=8",
        ],
        "fit: wrote",
        libc::SIGINT,
    );
    assert_eq!(rc, Some(130), "{err}");
    assert!(
        err.contains(&format!("fit: wrote {} (complete)", out.display())),
        "{err}"
    );
    let kept = std::fs::read_to_string(&out).unwrap();
    assert!(kept.contains("contact:"), "a whole parameter file: {kept}");
}
