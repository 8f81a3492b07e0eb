//! The bad-input suite: every kind of mistake or damage a user's input can
//! carry, through the real binary. Each case asserts the exit code, that the
//! message names what is wrong, and that nothing half-written is left (no
//! output file, no temporary sibling). No input may panic (exit 101).

mod common;

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

// ---------------------------------------------------------------------------
// Configuration files and --set
// ---------------------------------------------------------------------------

#[test]
fn bad_configuration_files_are_refused_with_what_is_wrong() {
    let d = dir("config");
    let out = d.join("out.csv");
    let out = out.to_str().unwrap();
    let deep = format!("{}1{}", "[".repeat(20_000), "]".repeat(20_000));
    let bomb = "a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\nc: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\ne: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]\nf: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]\ng: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f]\nh: &h [*g, *g, *g, *g, *g, *g, *g, *g, *g]\ni: &i [*h, *h, *h, *h, *h, *h, *h, *h, *h]\n";
    let node = |body: &str| format!("friction_node:\n  ros__parameters:\n{body}");
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        ("empty", String::new(), vec!["expected"]),
        (
            "binary",
            "friction_node:\u{0}\u{1}\u{2}".into(),
            vec!["not valid YAML"],
        ),
        ("list_top", "- 1\n- 2\n".into(), vec!["top level"]),
        (
            "wrong_node",
            "other_node:\n  ros__parameters: {}\n".into(),
            vec!["other_node", "friction_node"],
        ),
        (
            "two_nodes",
            "friction_node:\n  ros__parameters: {}\nx:\n  ros__parameters: {}\n".into(),
            vec!["exactly one"],
        ),
        (
            "duplicate",
            node("    contact:\n      load_n: 1.0\n      load_n: 2.0\n"),
            vec!["duplicate"],
        ),
        ("alias_bomb", bomb.into(), vec!["repetition limit"]),
        ("deep", deep, vec!["recursion limit"]),
        (
            "wrong_type",
            node("    contact:\n      load_n: heavy\n"),
            vec!["contact.load_n"],
        ),
        (
            "nan",
            node("    lubricant:\n      viscosity_pa_s: .nan\n"),
            vec!["lubricant.viscosity_pa_s", "NaN"],
        ),
        (
            "inf",
            node("    contact:\n      load_n: .inf\n"),
            vec!["contact.load_n", "inf"],
        ),
        (
            "negative",
            node("    lubricant:\n      viscosity_pa_s: -1\n"),
            vec!["lubricant.viscosity_pa_s", "-1", "(1e-5, 100]"],
        ),
        (
            "unknown_key",
            node("    contact:\n      lenght_m: 0.1\n"),
            vec!["contact.lenght_m"],
        ),
        (
            "unknown_section",
            node("    contacts_x: {}\n"),
            vec!["contacts_x"],
        ),
        (
            "huge_int",
            node("    solver:\n      cells: 100000000000000000000000\n"),
            vec!["solver.cells"],
        ),
        (
            "negative_usize",
            node("    solver:\n      cells: -5\n"),
            vec!["solver.cells"],
        ),
        ("section_scalar", node("    contact: 5\n"), vec!["contact"]),
        (
            "params_list",
            "friction_node:\n  ros__parameters: [1, 2]\n".into(),
            vec!["ros__parameters"],
        ),
        (
            "bad_name",
            node("    ros:\n      node_name: \"my node\"\n"),
            vec!["ros.node_name"],
        ),
        (
            "bad_topic",
            node("    ros:\n      topics:\n        friction: \"a//b\"\n"),
            vec!["ros.topics.friction", "//"],
        ),
    ];
    for (name, text, needles) in &cases {
        let f = write(&d, &format!("{name}.yaml"), text);
        refused(
            &[
                "simulate",
                "--config",
                &f,
                "--velocity",
                "const:0.1",
                "--duration",
                "0.01",
                "--out",
                out,
            ],
            needles,
            &d,
            &[&format!("{name}.yaml")],
        );
        let _ = std::fs::remove_file(&f);
    }
    // Not UTF-8 at all.
    let f = write(&d, "binary.yaml", [0u8, 159, 146, 150, 255, 0, 1]);
    refused(
        &[
            "simulate",
            "--config",
            &f,
            "--velocity",
            "const:0.1",
            "--duration",
            "0.01",
            "--out",
            out,
        ],
        &["binary.yaml", "UTF-8"],
        &d,
        &["binary.yaml"],
    );
    std::fs::remove_file(&f).unwrap();
    // A file that is not there, and a directory.
    refused(
        &[
            "simulate",
            "--config",
            "/nonexistent/x.yaml",
            "--velocity",
            "const:0.1",
            "--duration",
            "0.01",
            "--out",
            out,
        ],
        &["/nonexistent/x.yaml"],
        &d,
        &[],
    );
    refused(
        &[
            "simulate",
            "--config",
            d.to_str().unwrap(),
            "--velocity",
            "const:0.1",
            "--duration",
            "0.01",
            "--out",
            out,
        ],
        &["cannot read config file"],
        &d,
        &[],
    );
}

#[test]
fn a_configuration_file_with_a_byte_order_mark_or_crlf_lines_is_read() {
    let d = dir("bom");
    let f = write(
        &d,
        "bom.yaml",
        "\u{feff}friction_node:\r\n  ros__parameters:\r\n    solver:\r\n      cells: 16\r\n",
    );
    let out = d.join("out.csv");
    let o = run(&[
        "simulate",
        "--config",
        &f,
        "--velocity",
        "const:0.1",
        "--duration",
        "0.01",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(o.stderr.contains("N = 16"), "{}", o.stderr);
}

#[test]
fn bad_overrides_are_refused_with_the_override_named() {
    let d = dir("set");
    let out = d.join("out.csv");
    let out = out.to_str().unwrap();
    for (set, needles) in [
        ("nokey", vec!["nokey", "dotted.key=value"]),
        ("=5", vec!["dotted path"]),
        ("contact..load_n=5", vec!["dotted path"]),
        ("contact.load_n=[1,", vec!["contact.load_n", "YAML"]),
        ("contact.load_n.x=1", vec!["contact.load_n", "section"]),
        ("contact.lode_n=5", vec!["contact.lode_n"]),
        ("contact.load_n=.nan", vec!["contact.load_n"]),
        ("solver.cells=3", vec!["solver.cells", "[8, 65536]"]),
        ("solver.method=magic", vec!["solver.method", "newton"]),
        (
            "node.max_abs_velocity_m_s=0",
            vec!["node.max_abs_velocity_m_s"],
        ),
    ] {
        refused(
            &[
                "simulate",
                "--set",
                set,
                "--velocity",
                "const:0.1",
                "--duration",
                "0.01",
                "--out",
                out,
            ],
            &needles,
            &d,
            &[],
        );
    }
}

// ---------------------------------------------------------------------------
// Command-line arguments
// ---------------------------------------------------------------------------

#[test]
fn out_of_range_arguments_name_the_argument_and_the_allowed_values() {
    let d = dir("args");
    let out = d.join("o.csv");
    let out = out.to_str().unwrap();
    let sim = |dur: &str| {
        vec![
            "simulate",
            "--velocity",
            "const:0.1",
            "--duration",
            dur,
            "--out",
            out,
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>()
    };
    for dur in ["-1", "0", "1e300", "nan", "inf", "abc"] {
        let a = sim(dur);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        refused(&a, &["--duration", "(0, 1e7]"], &d, &[]);
    }
    for (args, needles) in [
        (
            vec!["study", "nosuch", "--out", out],
            vec!["nosuch", "stribeck", "hersey"],
        ),
        (
            vec!["profile", "--velocity", "1", "--h0", "-1e-6", "--out", out],
            vec!["--h0", "(0, 0.001]"],
        ),
        (
            vec!["profile", "--velocity", "1e9", "--h0", "1e-5", "--out", out],
            vec!["--velocity", "[-100, 100]"],
        ),
        (
            vec![
                "stribeck", "--v-min", "0.1", "--v-max", "1", "--points", "1", "--out", out,
            ],
            vec!["--points", "[2, 1000000]"],
        ),
        (
            vec!["stribeck", "--v-min", "1", "--v-max", "0.1", "--out", out],
            vec!["--v-min", "v-min < v-max"],
        ),
        (
            vec![
                "stribeck", "--v-min", "-1", "--v-max", "1", "--log", "--out", out,
            ],
            vec!["--log", "0"],
        ),
        (
            vec![
                "stribeck", "--v-min", "0.1", "--v-max", "1", "--load", "-3", "--out", out,
            ],
            vec!["--load", "(0, 1e9]"],
        ),
        (vec!["bench", "--cells", "3"], vec!["--cells", "[8, 65536]"]),
        (
            vec!["study", "load", "--cycles", "0", "--out", out],
            vec!["--cycles"],
        ),
        (vec!["run", "--demo", "0"], vec!["--demo", "(0, 1e9]"]),
        (vec!["run", "--duration", "-5"], vec!["--duration"]),
        (vec!["bench-latency", "--samples", "0"], vec!["--samples"]),
        (
            vec!["simulate", "--velocity", "const:1"],
            vec!["--duration", "--out"],
        ),
        (vec!["nosuchcommand"], vec!["nosuchcommand"]),
    ] {
        refused(&args, &needles, &d, &[]);
    }
    #[cfg(feature = "mcap")]
    refused(
        &["replay", "bags/node_lockstep.mcap", "--out", "x.txt"],
        &["--out", ".mcap or .csv", "--format"],
        &d,
        &[],
    );
}

// ---------------------------------------------------------------------------
// Signal specs and CSV tables
// ---------------------------------------------------------------------------

#[test]
fn bad_signal_specs_and_tables_name_the_spec_the_file_and_the_line() {
    let d = dir("signal");
    let out = d.join("o.csv");
    let out = out.to_str().unwrap();
    let csv = |name: &str, text: &[u8]| write(&d, name, text);
    let cases: Vec<(String, Vec<String>)> = vec![
        ("fast".into(), vec!["missing `kind:`".into()]),
        ("ramp:1".into(), vec!["unknown kind `ramp`".into()]),
        ("const:nan".into(), vec!["not finite".into()]),
        ("const:".into(), vec!["not a number".into()]),
        ("sine:1,2".into(), vec!["sine takes 3 or 4".into()]),
        ("sine:0,1,-1".into(), vec!["negative".into()]),
        (
            "const:1e300".into(),
            vec!["node.max_abs_velocity_m_s".into()],
        ),
        (
            "csv:/nonexistent/v.csv".into(),
            vec!["/nonexistent/v.csv".into()],
        ),
        (
            format!("csv:{}", csv("empty.csv", b"")),
            vec!["no data rows".into()],
        ),
        (
            format!("csv:{}", csv("nan.csv", b"t,v\n0,1\n1,nan\n")),
            vec!["nan.csv:3".into(), "finite".into()],
        ),
        (
            format!("csv:{}", csv("order.csv", b"0,0\n1,1\n0.5,2\n")),
            vec!["order.csv:3".into(), "does not increase".into()],
        ),
        (
            format!("csv:{}", csv("dup.csv", b"0,0\n1,1\n1,2\n")),
            vec!["dup.csv:3".into()],
        ),
        (
            format!("csv:{}", csv("short.csv", b"0,0\n1\n")),
            vec!["short.csv:2".into(), "columns".into()],
        ),
        (
            format!("csv:{}@load", csv("nocol.csv", b"t,v\n0,1\n")),
            vec!["no column named `load`".into()],
        ),
        (
            format!("csv:{}@v", csv("nohead.csv", b"0,1\n1,2\n")),
            vec!["needs a header".into()],
        ),
        (
            format!("csv:{}", csv("huge.csv", b"0,0\n1,1e300\n")),
            vec!["node.max_abs_velocity_m_s".into()],
        ),
        (
            format!("csv:{}", csv("binary.csv", &[0, 255, 254, 10, 1, 2])),
            vec!["binary.csv".into()],
        ),
        (
            format!("csv:{}", csv("text.csv", b"t,v\n0,fast\n")),
            vec!["text.csv:2".into(), "`fast`".into()],
        ),
        (
            format!("csv:{}", d.display()),
            vec!["cannot read velocity table".into()],
        ),
    ];
    let inputs: Vec<String> = files(&d);
    let inputs: Vec<&str> = inputs.iter().map(String::as_str).collect();
    for (spec, needles) in &cases {
        let n: Vec<&str> = needles.iter().map(String::as_str).collect();
        refused(
            &[
                "simulate",
                "--velocity",
                spec,
                "--duration",
                "0.01",
                "--set",
                "solver.cells=16",
                "--out",
                out,
            ],
            &n,
            &d,
            &inputs,
        );
    }
    // Loads: non-positive or absurd ones are user errors.
    for (spec, needles) in [
        ("const:-5", vec!["--load", "node.min_load_n"]),
        ("const:0", vec!["--load", "node.min_load_n"]),
        ("sine:100,200,1", vec!["--load", "[-100, 300]"]),
        ("const:1e12", vec!["--load", "node.max_load_n"]),
    ] {
        refused(
            &[
                "simulate",
                "--velocity",
                "const:0.1",
                "--load",
                spec,
                "--duration",
                "0.01",
                "--out",
                out,
            ],
            &needles,
            &d,
            &inputs,
        );
    }
}

#[test]
fn tables_with_a_byte_order_mark_crlf_lines_or_one_row_are_read() {
    let d = dir("table-ok");
    for (name, text) in [
        ("bom.csv", "\u{feff}t_s,v\r\n0,0.1\r\n1,0.2\r\n"),
        ("bom_nohead.csv", "\u{feff}0,0.1\n1,0.2\n"),
        ("one.csv", "0,0.15\n"),
    ] {
        let f = write(&d, name, text);
        let out = d.join(format!("{name}.out.csv"));
        let o = run(&[
            "simulate",
            "--velocity",
            &format!("csv:{f}"),
            "--duration",
            "0.01",
            "--set",
            "solver.cells=16",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.code, 0, "{name}: {}", o.stderr);
        let rows = std::fs::read_to_string(&out).unwrap();
        assert_eq!(rows.lines().count(), 11, "{name}");
        // The first data row counts (a BOM does not turn it into a header).
        let first: Vec<&str> = rows.lines().nth(1).unwrap().split(',').collect();
        let v: f64 = first[1].parse().unwrap();
        assert!(v > 0.1 - 1e-12 && v < 0.2, "{name}: v = {v}");
    }
}

// ---------------------------------------------------------------------------
// Output failures
// ---------------------------------------------------------------------------

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

// ---------------------------------------------------------------------------
// Recording settings: refused at start, before the loop runs
// ---------------------------------------------------------------------------

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
