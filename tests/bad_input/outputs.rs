//! Output failures (a full disk, an unwritable place) and recording
//! settings that cannot work: an error before anything is half-written, and
//! before the loop runs.

use super::*;

#[test]
fn a_full_disk_or_an_unwritable_place_is_an_error_and_leaves_nothing() {
    let d = dir("out");
    let sim = |out: &str| -> Vec<String> {
        [
            "simulate",
            "--velocity",
            "const:0.1",
            "--duration",
            "0.5",
            "--set",
            "solver.cells=16",
            "--out",
            out,
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    for (out, needles) in [
        ("/dev/full", vec!["/dev/full", "No space left"]),
        ("/proc/friction/out.csv", vec!["/proc/friction/out.csv"]),
        (d.to_str().unwrap(), vec!["is a directory"]),
    ] {
        let a = sim(out);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        refused(&a, &needles, &d, &[]);
    }
    assert!(Path::new("/dev/full").exists(), "the device is still there");
    let stub = d.join("stub");
    std::fs::write(&stub, "not a directory").unwrap();
    for (args, needles) in [
        (
            vec![
                "stribeck",
                "--v-min",
                "0.1",
                "--v-max",
                "1",
                "--points",
                "3",
                "--set",
                "solver.cells=16",
                "--out",
                "/dev/full",
            ],
            vec!["/dev/full"],
        ),
        (
            vec![
                "profile",
                "--velocity",
                "1",
                "--h0",
                "1e-5",
                "--set",
                "solver.cells=16",
                "--out",
                "/dev/full",
            ],
            vec!["/dev/full"],
        ),
        (
            vec!["study", "stribeck", "--out", stub.to_str().unwrap()],
            vec!["stub", "not a directory"],
        ),
        (
            vec![
                "bench",
                "--cells",
                "16",
                "--cycles",
                "1",
                "--reference-steps",
                "1",
                "--out",
                "/proc/nope/b.csv",
            ],
            vec!["/proc/nope/b.csv"],
        ),
    ] {
        refused(&args, &needles, &d, &["stub"]);
    }
    #[cfg(feature = "mcap")]
    for (args, needles) in [
        (
            vec![
                "replay",
                "bags/node_lockstep.mcap",
                "--out",
                "/dev/full",
                "--format",
                "csv",
            ],
            vec!["/dev/full"],
        ),
        (
            vec![
                "replay",
                "bags/node_lockstep.mcap",
                "--out",
                "/dev/full",
                "--format",
                "mcap",
            ],
            vec!["/dev/full"],
        ),
        (
            vec![
                "replay",
                "bags/node_lockstep.mcap",
                "--out",
                "/proc/nope/r.mcap",
            ],
            vec!["/proc/nope/r.mcap"],
        ),
    ] {
        refused(&args, &needles, &d, &["stub"]);
    }
}

#[cfg(feature = "mcap")]
#[test]
fn a_replay_report_into_an_unwritable_directory_fails_before_any_output() {
    let d = dir("report");
    let out = d.join("r.csv");
    refused(
        &[
            "replay",
            "bags/node_lockstep.mcap",
            "--out",
            out.to_str().unwrap(),
            "--report",
            "/proc/nope/report",
        ],
        &["/proc/nope/report"],
        &d,
        &[],
    );
}

/// Needs the default `run` transport (ROS 2) and the recorder (MCAP).
#[cfg(all(feature = "mcap", feature = "ros2"))]
#[test]
fn recording_settings_that_cannot_work_are_refused_before_the_loop_runs() {
    let d = dir("recording");
    std::fs::write(d.join("occupied"), "x").unwrap();
    let rec = d.join("rec");
    let rec = rec.to_str().unwrap();
    for (sets, record, needles) in [
        (
            vec![
                "recording.split.max_bytes=2000",
                "recording.chunk_size_bytes=4096",
            ],
            rec,
            vec!["recording.split.max_bytes", "smaller than one chunk"],
        ),
        (
            vec![
                "recording.split.max_bytes=1000000",
                "recording.budget_bytes=1500000",
            ],
            rec,
            vec!["recording.budget_bytes", "two split files"],
        ),
        (
            vec!["recording.budget_bytes=1000000"],
            rec,
            vec!["recording.budget_bytes", "needs split files"],
        ),
        (
            vec!["recording.snapshot_s=86400"],
            rec,
            vec!["recording.snapshot_s", "MB", "recording.snapshot_max_bytes"],
        ),
        (
            vec!["recording.split.max_duration_s=5"],
            d.to_str().unwrap(),
            vec!["not empty", d.to_str().unwrap()],
        ),
        (
            vec!["recording.split.max_duration_s=5"],
            "/proc/sys/friction_rec",
            vec!["/proc/sys/friction_rec"],
        ),
    ] {
        let mut args = vec!["run", "--duration", "1", "--quiet", "--record", record];
        for s in &sets {
            args.push("--set");
            args.push(s);
        }
        let o = run(&args);
        assert_eq!(o.code, 2, "{sets:?}: {}", o.stderr);
        assert!(!o.stderr.contains("loop running"), "{sets:?}: the loop ran");
        for n in &needles {
            assert!(o.stderr.contains(n), "{sets:?}: `{n}` not in {}", o.stderr);
        }
    }
    assert!(!Path::new(rec).exists(), "nothing created");
}
