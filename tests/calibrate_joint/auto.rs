//! `--fit auto` as a user runs it: the smallest set where the data show no
//! more, bounds on candidate keys, a load set in the configuration kept.

use super::*;

#[test]
fn auto_on_data_of_one_speed_without_a_reversal_keeps_the_smallest_set_and_says_why() {
    let d = dir("auto-one-speed");
    let c = simulate_record(&d, "c.csv", "const:0.05", "1", &[]);
    let mut text = String::from("t_s,velocity_m_s,friction_n\n");
    for (k, (t, v, f)) in simulated(&c).into_iter().enumerate() {
        text += &format!("{t},{v},{}\n", f + 20.0 * noise(k));
    }
    let data = d.join("d.csv");
    std::fs::write(&data, text).unwrap();
    let (code, stdout, err) = run(&[
        "fit",
        data.to_str().unwrap(),
        "--set",
        "solver.cells=32",
        "--fit",
        "auto",
        "--out",
        d.join("f.yaml").to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 4, "{err}");
    assert!(
        stdout.contains("Chosen: boundary friction. Stopped:")
            && stdout.contains("does not pay for itself"),
        "{stdout}"
    );
    assert!(
        stdout.contains("Keys fitted: contact.boundary_friction."),
        "{stdout}"
    );
}

#[test]
fn a_bound_that_excludes_the_value_the_chosen_scale_rests_on_is_an_error_naming_both() {
    let d = dir("bounds");
    let mut text = String::from("t,w,tau\n");
    for k in 0..2000 {
        let t = k as f64 * 1e-3;
        let w = 2.0 * (2.0 * std::f64::consts::PI * t).sin();
        text += &format!("{t},{w},{}\n", 5.0 * (w / 0.1).tanh());
    }
    let data = d.join("joint.csv");
    std::fs::write(&data, text).unwrap();
    let (code, _, err) = run(&[
        "fit",
        data.to_str().unwrap(),
        "--rotary",
        "--time",
        "t",
        "--velocity",
        "w",
        "--friction",
        "tau",
        "--set",
        "solver.cells=32",
        "--fit",
        "contact.boundary_friction",
        "--bounds",
        "contact.boundary_friction=0.5:1",
        "--out",
        d.join("x.yaml").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    // The bound, the configured boundary friction 0.3 and the chosen scale.
    assert!(
        err.contains("0.5:1 excludes 0.3") && err.contains("gain"),
        "{err}"
    );
    assert!(!d.join("x.yaml").exists());
}

#[test]
fn under_auto_a_bound_on_a_candidate_key_is_accepted_and_a_term_without_a_reversal_says_so() {
    let d = dir("auto-bounds");
    // One speed, no reversal: pre-sliding is no candidate, for that reason.
    let c = simulate_record(&d, "c.csv", "const:0.05", "1", &[]);
    let fit = |extra: &[&str]| {
        let mut args = vec![
            "fit",
            c.to_str().unwrap(),
            "--set",
            "solver.cells=32",
            "--fit",
            "auto",
            "--max-evaluations",
            "20",
            "--out",
        ];
        let out = d.join("f.yaml");
        args.push(out.to_str().unwrap());
        args.extend_from_slice(extra);
        run(&args)
    };
    let (code, stdout, err) = fit(&[
        "--bounds",
        "contact.boundary_friction=0.1:0.5",
        "--bounds",
        "contact.presliding_stiffness_n_m=1e5:1e9",
        "--start",
        "drivetrain.viscous_n_s_m=10",
        "--bounds",
        "drivetrain.viscous_n_s_m=0:1000",
    ]);
    assert!(code == 0 || code == 4, "{err}");
    assert!(
        stdout.contains("pre-sliding: the data hold no velocity reversal"),
        "{stdout}"
    );
    // The base key's bound is used.
    let row = stdout
        .lines()
        .find(|l| l.starts_with("| `contact.boundary_friction`"))
        .unwrap();
    assert!(row.contains("[1.0000e-1, 5.0000e-1]"), "{row}");
    // A key auto never fits is still refused, naming what it may choose.
    let (code, _, err) = fit(&["--bounds", "roughness.sigma_m=1e-6:1e-5"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("roughness.sigma_m") && err.contains("--fit auto may choose"),
        "{err}"
    );
}

#[test]
fn under_auto_a_load_set_in_the_configuration_is_kept_and_without_one_the_scale_is_chosen() {
    let d = dir("configured-load");
    let c = simulate_record(
        &d,
        "contact.csv",
        "sine:0,0.05,1",
        "1",
        &["contact.load_n=2000"],
    );
    // The data without their load column: the load is not an input.
    let mut text = String::from("t_s,velocity_m_s,friction_n\n");
    for (t, v, f) in simulated(&c) {
        text += &format!("{t},{v},{f}\n");
    }
    let data = d.join("no-load.csv");
    std::fs::write(&data, text).unwrap();
    let fit = |extra: &[&str]| {
        let out = d.join("f.yaml");
        let args = [&["--max-evaluations", "10"], extra].concat();
        let (code, _, err) = common::cli::quick_fit(&data, "auto", &out, &args);
        assert!(code == 0 || code == 4, "{err}");
        (err, Config::load(Some(&out), &[]).unwrap())
    };
    let (err, kept) = fit(&["--set", "contact.load_n=2000"]);
    assert!(!err.contains("the contact's scale: gain"), "{err}");
    assert_eq!(kept.contact.load_n, 2000.0);
    assert!(kept.contacts.is_empty());
    let (err, chosen) = fit(&[]);
    assert!(err.contains("the contact's scale: gain"), "{err}");
    // The chosen gain is written as the one listed contact's.
    assert_eq!(chosen.contacts.0.len(), 1, "{err}");
    assert!(chosen.contacts.0[0].gain != 1.0);
}
