//! Configuration files and `--set`: refused with what is wrong, or read
//! where only the encoding differs (a byte order mark, CRLF lines).

use super::*;

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
