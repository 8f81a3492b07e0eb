//! Command-line arguments, signal specs and CSV tables: the argument, the
//! spec, the file and the line named.

use super::*;

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
