//! The command line, end to end (the real binary).

mod common;

/// A fresh directory for test `name`.
fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("cli", name)
}

/// Runs the binary: (success, stdout, stderr).
fn run(args: &[&str]) -> (bool, String, String) {
    let (code, stdout, stderr) = common::cli::run(args);
    (code == 0, stdout, stderr)
}

#[test]
fn simulate_writes_the_documented_columns_and_summarises_the_last_cycle() {
    let d = dir("sim");
    let out = d.join("run.csv");
    let (ok, stdout, stderr) = run(&[
        "simulate",
        "--velocity",
        "sine:0,1,4",
        "--duration",
        "1",
        "--set",
        "solver.cells=64",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    assert!(header.starts_with(
        "t_s,velocity_m_s,load_n,h0_m,h_min_m,f_hyd_n,f_asp_n,friction_n,cof,iterations,status"
    ));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 1000);
    assert_eq!(rows[0][0], "0.001");
    assert!(rows.iter().all(|r| r[10] == "converged"));
    // Four cycles of 0.25 s: the summary reports the last one.
    assert!(stdout.contains("last cycle       #4 of 4"), "{stdout}");
    assert!(stdout.contains("friction loop area"), "{stdout}");
    assert!(stdout.contains("COF at v = 0"), "{stdout}");
}

#[test]
fn load_from_a_csv_column_and_overrides_after_the_subcommand_accumulate() {
    let d = dir("load");
    let table = d.join("in.csv");
    std::fs::write(&table, "t_s,velocity_m_s,load_n\n0,0.2,5762\n1,0.2,10762\n").unwrap();
    let out = d.join("run.csv");
    let (ok, _, stderr) = run(&[
        "--set",
        "solver.cells=32",
        "simulate",
        "--velocity",
        &format!("csv:{}", table.display()),
        "--load",
        &format!("csv:{}@load_n", table.display()),
        "--duration",
        "0.5",
        "--set",
        "solver.dt_s=0.01",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap();
    let last: Vec<&str> = text.lines().last().unwrap().split(',').collect();
    assert_eq!(text.lines().count(), 51);
    assert_eq!(last[2], "8262");
}

#[test]
fn a_malformed_velocity_line_is_reported_with_its_number_and_nothing_is_written() {
    let d = dir("bad");
    let v = d.join("v.csv");
    std::fs::write(&v, "t_s,v\n0,0\n0.5,0.1\n1.0,fast\n").unwrap();
    let out = d.join("run.csv");
    std::fs::write(&out, "precious").unwrap();
    let (ok, _, stderr) = run(&[
        "simulate",
        "--velocity",
        &format!("csv:{}", v.display()),
        "--duration",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("v.csv:4") && stderr.contains("`fast`"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "precious");
    assert_eq!(
        std::fs::read_dir(&d).unwrap().count(),
        2,
        "no temporary file left"
    );
}

#[test]
fn config_errors_name_the_key() {
    let (ok, _, stderr) = run(&[
        "--set",
        "contact.lenght_m=0.1",
        "simulate",
        "--velocity",
        "const:1",
        "--duration",
        "1",
        "--out",
        "/tmp/never.csv",
    ]);
    assert!(!ok);
    assert!(stderr.contains("contact.lenght_m"), "{stderr}");
    let d = dir("cfg");
    let f = d.join("p.yaml");
    std::fs::write(
        &f,
        "friction_node:\n  ros__parameters:\n    roughness:\n      sigma_m: 0.5\n",
    )
    .unwrap();
    let (ok, _, stderr) = run(&[
        "--config",
        f.to_str().unwrap(),
        "profile",
        "--velocity",
        "1",
        "--h0",
        "1e-5",
        "--out",
        "/tmp/never.csv",
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("roughness.sigma_m") && stderr.contains("0.5"),
        "{stderr}"
    );
}

#[test]
fn an_unwritable_output_is_reported() {
    let (ok, _, stderr) = run(&[
        "simulate",
        "--velocity",
        "const:0.1",
        "--duration",
        "100",
        "--out",
        "/nonexistent-dir/run.csv",
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("cannot write /nonexistent-dir/run.csv"),
        "{stderr}"
    );
}

#[test]
fn stribeck_and_profile_write_their_columns() {
    let d = dir("sp");
    let s = d.join("s.csv");
    let (ok, stdout, stderr) = run(&[
        "stribeck",
        "--v-min",
        "0.01",
        "--v-max",
        "3",
        "--points",
        "8",
        "--log",
        "--set",
        "solver.cells=64",
        "--out",
        s.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("8 points"));
    let text = std::fs::read_to_string(&s).unwrap();
    assert!(text.starts_with("velocity_m_s,h0_m,h_min_m,f_hyd_n,f_asp_n,friction_n,cof"));
    assert_eq!(text.lines().count(), 9);
    let p = d.join("p.csv");
    let (ok, stdout, stderr) = run(&[
        "profile",
        "--velocity",
        "1",
        "--load",
        "20762",
        "--out",
        p.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("p_max")
            && stdout.contains("hydrodynamic load")
            && stdout.contains("asperity load")
    );
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.starts_with("x_m,h_m,p_pa,vapour_fraction,p_asp_pa,shear_pa"));
    // A header and one row per cell (the default N = 64).
    assert_eq!(text.lines().count(), 65);
    let (ok, _, stderr) = run(&[
        "stribeck",
        "--v-min",
        "-1",
        "--v-max",
        "1",
        "--log",
        "--out",
        s.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("does not contain 0"), "{stderr}");
}

#[test]
fn a_missing_required_argument_is_named_on_the_errors_one_line() {
    let (ok, _, stderr) = run(&["fit", "data.csv", "--fit", "auto"]);
    assert!(!ok);
    assert!(
        stderr.contains("the following required arguments were not provided: --out <FILE>"),
        "{stderr}"
    );
    assert!(!stderr.contains(":;"), "{stderr}");
}

#[test]
fn an_unknown_study_lists_the_valid_ones() {
    let (ok, _, stderr) = run(&["study", "frequency", "--out", "/tmp/never"]);
    assert!(!ok);
    for name in [
        "stribeck",
        "amplitude-frequency",
        "load",
        "viscosity",
        "inertia",
        "unidirectional",
        "roughness",
        "hersey",
        "all",
    ] {
        assert!(stderr.contains(name), "{name} missing from: {stderr}");
    }
}

#[test]
fn an_unusable_study_directory_is_reported_before_computing() {
    let d = dir("studyfile");
    let file = d.join("not-a-dir");
    std::fs::write(&file, "x").unwrap();
    let out = file.join("study");
    let (ok, stdout, stderr) = run(&["study", "all", "--out", out.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        stderr.contains("cannot write") && stderr.contains("not-a-dir"),
        "{stderr}"
    );
    assert!(
        !stderr.contains("cases on"),
        "no computation started: {stderr}"
    );
    assert!(stdout.is_empty());
}

#[test]
fn a_study_writes_case_csvs_a_summary_plots_and_the_claims() {
    let d = dir("study");
    let (ok, stdout, stderr) = run(&[
        "study",
        "hersey",
        "--out",
        d.to_str().unwrap(),
        "--set",
        "solver.cells=32",
        "--cycles",
        "2",
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("hersey")
            && stdout.contains("8 cases")
            && stdout.contains("6 steady curves"),
        "{stdout}"
    );
    // A study of steady curves alone counts its curves, not "0 cases".
    let (ok, stdout, stderr) = run(&[
        "study",
        "stribeck",
        "--out",
        d.to_str().unwrap(),
        "--set",
        "solver.cells=32",
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("6 steady curves") && !stdout.contains("0 cases"),
        "{stdout}"
    );
    let s = d.join("hersey");
    let summary = std::fs::read_to_string(s.join("summary.csv")).unwrap();
    assert_eq!(summary.lines().count(), 9);
    assert!(
        summary.lines().skip(1).all(|l| l.contains(",\"ok\",")),
        "{summary}"
    );
    assert_eq!(std::fs::read_dir(s.join("cases")).unwrap().count(), 8);
    let claims = std::fs::read_to_string(d.join("claims.md")).unwrap();
    assert!(claims.contains("## Claim 9"), "{claims}");
    if cfg!(feature = "plots") {
        let svg = std::fs::read_to_string(s.join("hersey.svg")).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("Hersey"));
    }
}

#[test]
#[cfg(feature = "iceoryx2")]
fn log_lines_on_a_redirected_stderr_carry_no_colour_codes() {
    let svc = format!("fn-cli-colour-{}", std::process::id());
    let mut c = common::cli::bin();
    c.args(["run", "--demo", "0.2", "--transport", "iceoryx2", "--quiet"]);
    for (key, suffix) in [
        ("cmd_velocity_service", "v"),
        ("normal_load_service", "l"),
        ("temperature_service", "t"),
        ("friction_service", "f"),
        ("loop_statistics_service", "s"),
        ("cmd_event_service", "e"),
    ] {
        c.arg("--set").arg(format!("iceoryx2.{key}={svc}/{suffix}"));
    }
    let o = c.output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("INFO"), "a tracing line was logged: {err}");
    assert!(!err.contains('\u{1b}'), "no escape codes: {err:?}");
}

#[test]
fn simulate_times_are_whole_steps_without_accumulated_rounding() {
    let d = dir("times");
    let out = d.join("run.csv");
    let (ok, _, stderr) = run(&[
        "simulate",
        "--velocity",
        "sine:0,1,1",
        "--duration",
        "4",
        "--set",
        "solver.cells=32",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let text = std::fs::read_to_string(&out).unwrap();
    for (k, line) in text.lines().skip(1).enumerate() {
        let t = line.split(',').next().unwrap();
        // Row k is step k + 1, at (k + 1) dt exactly.
        assert_eq!(
            t,
            friction_node::text::Num((k + 1) as f64 * 1e-3).to_string(),
            "row {k}"
        );
    }
}

#[test]
fn a_sine_at_or_above_the_steps_nyquist_frequency_is_refused() {
    let d = dir("nyquist");
    let out = d.join("run.csv");
    // dt = 1 ms: Nyquist at 500 Hz (before: simulated as v ≈ 0, silently).
    for f in ["500", "990"] {
        let (ok, _, err) = run(&[
            "simulate",
            "--velocity",
            &format!("sine:0,0.1,{f}"),
            "--duration",
            "0.1",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok, "{f} Hz");
        assert!(
            err.contains("Nyquist") && err.contains("--velocity"),
            "{err}"
        );
        assert!(!out.exists());
    }
    let (ok, _, err) = run(&[
        "simulate",
        "--velocity",
        "sine:0,0.1,400",
        "--duration",
        "0.01",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
}

#[test]
fn an_accuracy_reference_no_finer_than_the_tested_setting_is_refused() {
    let (ok, _, err) = run(&[
        "bench-accuracy",
        "--grids",
        "64,128",
        "--steps",
        "0.001",
        "--reference-cells",
        "128",
    ]);
    assert!(!ok);
    assert!(err.contains("--reference-cells 128"), "{err}");
    let (ok, _, err) = run(&[
        "bench-cases",
        "--grids",
        "64",
        "--fluxes",
        "upwind,upwind",
        "--reference-dt",
        "0.002",
    ]);
    assert!(!ok);
    assert!(err.contains("--reference-dt 0.002"), "{err}");
}

#[test]
fn run_check_on_a_joint_configuration_lists_the_joint_topics_with_their_remaps() {
    let config = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/launch-config/gantry-8-contacts.yaml"
    );
    let (ok, stdout, stderr) = run(&[
        "run",
        "--check",
        "--config",
        config,
        "--ros-args",
        "-r",
        "~/joint_commands:=/robot/joint_cmds",
    ]);
    assert!(ok, "{stderr}");
    for line in [
        "  joint_commands: /robot/joint_cmds",
        "  joint_efforts: /friction_node/joint_efforts",
        "  joint_friction: /friction_node/joint_friction",
        "  contacts/shoulder/friction: /friction_node/contacts/shoulder/friction",
        "  contacts/wrist_roll/friction: /friction_node/contacts/wrist_roll/friction",
    ] {
        assert!(stdout.lines().any(|l| l == line), "`{line}` in {stdout}");
    }
    // One contact: no joint topics.
    let (ok, stdout, stderr) = run(&["run", "--check"]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("  cmd_velocity: /friction_node/cmd_velocity"));
    assert!(!stdout.contains("joint_commands"), "{stdout}");
}

#[cfg(feature = "mcap")]
#[test]
fn a_recording_named_neither_mcap_nor_a_split_directory_is_refused_and_overwrites_nothing() {
    let d = dir("record-name");
    let csv = d.join("sim.csv");
    std::fs::write(&csv, "t_s,velocity_m_s\n0,1\n").unwrap();
    for name in [csv.clone(), d.join("out.txt")] {
        let (ok, _, stderr) = run(&[
            "run",
            "--duration",
            "0.2",
            "--quiet",
            "--record",
            name.to_str().unwrap(),
        ]);
        assert!(!ok, "{stderr}");
        assert!(
            stderr.contains(name.to_str().unwrap()) && stderr.contains(".mcap"),
            "{stderr}"
        );
        assert!(!stderr.contains("loop running"), "{stderr}");
    }
    assert_eq!(
        std::fs::read_to_string(&csv).unwrap(),
        "t_s,velocity_m_s\n0,1\n"
    );
    assert!(!d.join("out.txt").exists());
}

#[test]
fn a_negative_number_gets_the_options_range_message_not_an_unknown_argument() {
    for (args, option) in [
        (vec!["bench-accuracy", "--grids", "-64"], "--grids"),
        (
            vec![
                "fit",
                "x.csv",
                "--fit",
                "auto",
                "--holdout",
                "-0.5",
                "--out",
                "o.yaml",
            ],
            "--holdout",
        ),
        (
            vec![
                "fit", "x.csv", "--fit", "auto", "--smooth", "-1", "--out", "o.yaml",
            ],
            "--smooth",
        ),
        (vec!["bench-cases", "--count", "-3"], "--count"),
        (vec!["bench-latency", "--samples", "-5"], "--samples"),
        (
            vec!["bench-accuracy", "--reference-dt", "-1"],
            "--reference-dt",
        ),
    ] {
        let (code, _, stderr) = common::cli::run(&args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        let value = args[args.iter().position(|a| *a == option).unwrap() + 1];
        assert!(
            stderr.contains(&format!("invalid value '{value}' for '{option}")),
            "{args:?}: {stderr}"
        );
        assert!(!stderr.contains("unexpected argument"), "{stderr}");
    }
}

/// A steady curve `stribeck` wrote into `d`.
fn steady_curve(d: &std::path::Path) -> std::path::PathBuf {
    let curve = d.join("curve.csv");
    let (ok, _, stderr) = run(&[
        "stribeck",
        "--v-min",
        "0.01",
        "--v-max",
        "1",
        "--points",
        "8",
        "--set",
        "solver.cells=32",
        "--out",
        curve.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    curve
}

#[test]
fn a_validation_file_without_the_named_columns_is_named_in_the_error() {
    let d = dir("validate-columns");
    let curve = steady_curve(&d);
    let other = d.join("other_columns.csv");
    std::fs::write(&other, "speed,torque\n0.1,2\n0.2,3\n").unwrap();
    let (code, _, stderr) = common::cli::run(&[
        "fit",
        curve.to_str().unwrap(),
        "--validate",
        other.to_str().unwrap(),
        "--fit",
        "contact.boundary_friction",
        "--out",
        d.join("f.yaml").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("other_columns.csv"), "{stderr}");
}

#[test]
fn expressions_call_functions_by_their_usual_names_and_an_unknown_one_lists_them() {
    let d = dir("functions");
    let curve = steady_curve(&d);
    let out = d.join("f.yaml");
    let fit = |friction: &str| {
        let keys = "contact.boundary_friction";
        common::cli::quick_fit(&curve, keys, &out, &["--friction", friction])
    };
    // sqrt(x²) = |x|, cos(0) = 1, abs and tanh: the friction itself.
    let (code, stdout, stderr) =
        fit("sqrt(friction_n * friction_n) * cos(0) * abs(tanh(velocity_m_s * 1e9))");
    assert!(code == 0 || code == 4, "{stderr}");
    assert!(stdout.contains("training RMS"), "{stdout}");
    let (code, _, stderr) = fit("sine(friction_n)");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("`sine(…)`") && stderr.contains("sin, cos, tan"),
        "{stderr}"
    );
}
