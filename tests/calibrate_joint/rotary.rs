//! A joint in its own units (`fit --rotary`): rad/s and N·m through a chosen
//! lever, a report in the joint's units, column names read alike in every
//! part, a degrees-per-second question, a joint state topic's velocity and
//! effort.

use super::*;

#[test]
fn a_rotary_joint_is_fitted_in_rad_s_and_newton_metres_and_its_file_drives_the_contact_through_the_chosen_lever(
) {
    let d = dir("rotary");
    let c = simulate_record(&d, "contact.csv", "sine:0,0.05,1", "2", &[]);
    // The same motion seen at a joint through a 20 mm lever: rad/s, N·m.
    let r = 0.02;
    let rows = simulated(&c);
    let mut text = String::from("t,omega_rad_s,torque_n_m\n");
    for (t, v, f) in &rows {
        text += &format!("{t},{},{}\n", v / r, f * r);
    }
    let joint = d.join("joint.csv");
    std::fs::write(&joint, text).unwrap();
    let out = d.join("fitted.yaml");
    let (code, stdout, err) = run(&[
        "fit",
        joint.to_str().unwrap(),
        "--rotary",
        "--joint",
        "elbow",
        "--time",
        "t",
        "--velocity",
        "omega_rad_s",
        "--friction",
        "torque_n_m",
        "--set",
        "solver.cells=32",
        "--fit",
        "contact.boundary_friction,lubricant.viscosity_pa_s",
        "--starts",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("the contact's scale: gain"), "{err}");
    assert!(err.contains(" m, contact load"), "{err}");
    assert!(
        stdout.contains("training RMS") && stdout.contains(" N·m"),
        "{stdout}"
    );
    // The fitted file: one contact on joint `elbow` with the lever as gain.
    let fitted = Config::load(Some(&out), &[]).unwrap();
    let contacts = fitted.resolved_contacts();
    assert_eq!(contacts.len(), 1);
    assert_eq!(contacts[0].joint, "elbow");
    let gain = contacts[0].gain;
    assert!(gain > 0.0 && gain < 1.0, "lever arm {gain} m");
    // Its calibrated range is the joint's, in rad/s and N·m: the sine of
    // 0.05 m/s at 20 mm reaches 2.5 rad/s. The contact's own configuration
    // holds it in m/s through the gain.
    let range = contacts[0].joint_range.clone().expect("a joint's range");
    let top = range.speed_forward_max_rad_s.unwrap();
    assert!(top > 2.45 && top <= 2.5 + 1e-9, "{range:?}");
    assert!(range.training_rms_n_m.is_some() && range.training_rms_n.is_none());
    let own = contacts[0].config.calibrated_range.clone().unwrap();
    approx::assert_relative_eq!(own.speed_forward_max_m_s.unwrap(), gain * top);
    // Driven by the joint's velocity through that gain, the contact gives
    // the joint's torque: simulate the contact at gain × ω, effort = gain × F.
    let mut v = String::from("t_s,v\n");
    for (t, w, _) in rows.iter().map(|(t, vv, f)| (t, vv / r, f)) {
        v += &format!("{t},{}\n", gain * w);
    }
    let vcsv = d.join("v.csv");
    std::fs::write(&vcsv, v).unwrap();
    let contact_yaml = d.join("contact.yaml");
    std::fs::write(&contact_yaml, contacts[0].config.to_yaml()).unwrap();
    let back = d.join("back.csv");
    let (code, _, err) = run(&[
        "simulate",
        "--config",
        contact_yaml.to_str().unwrap(),
        "--velocity",
        &format!("csv:{}@v", vcsv.display()),
        "--duration",
        "2",
        "--out",
        back.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let again = simulated(&back);
    let (mut ss, mut scale) = (0.0, 0.0f64);
    for ((_, _, f_joint), (_, _, f)) in rows.iter().zip(&again) {
        let torque = f_joint * r;
        ss += (gain * f - torque).powi(2);
        scale = scale.max(torque.abs());
    }
    let rms = (ss / again.len() as f64).sqrt();
    assert!(rms < 0.02 * scale, "torque RMS {rms} N·m of {scale}");
}

#[cfg(feature = "mcap")]
#[test]
fn rotary_refuses_a_twist_stamped_velocity_naming_its_unit() {
    let bag = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/bags/foreign_joint_states.mcap"
    );
    let d = dir("twist");
    let (code, _, err) = run(&[
        "fit",
        bag,
        "--rotary",
        "--velocity-topic",
        "/cmd_vel",
        "--friction-topic",
        "/joint_states",
        "--joint",
        "slider",
        "--fit",
        "contact.boundary_friction",
        "--out",
        d.join("x.yaml").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("TwistStamped") && err.contains("m/s") && err.contains("rad/s"),
        "{err}"
    );
    assert!(!d.join("x.yaml").exists());
}

#[test]
fn a_rotary_report_speaks_in_the_joints_units_and_names_its_lever() {
    let d = dir("units");
    // The joint's own column names, read without --velocity / --friction.
    let joint = joint_record(&d, 0.5, 4.0);
    let report = d.join("report");
    let (code, stdout, err) = run(&[
        "fit",
        joint.to_str().unwrap(),
        "--rotary",
        "--set",
        "solver.cells=32",
        "--fit",
        "contact.boundary_friction,drivetrain.coulomb_n",
        "--starts",
        "1",
        "--global-points",
        "0",
        "--max-evaluations",
        "30",
        "--baselines",
        "--out",
        d.join("f.yaml").to_str().unwrap(),
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 4, "{err}");
    let summary = std::fs::read_to_string(report.join("summary.md")).unwrap();
    // The joint: lever arm and load in the summary, not only on stderr.
    assert!(
        summary.contains("## The joint") && summary.contains("lever arm r = "),
        "{summary}"
    );
    // Residual by direction in rad/s and N·m; nothing in mm/s or N.
    assert!(
        summary.contains("mean speed (rad/s) | measured mean (N·m)"),
        "{summary}"
    );
    assert!(
        !summary.contains("(mm/s)") && !summary.contains("(N) |"),
        "{summary}"
    );
    // Our drivetrain Coulomb level as it acts on the joint; the classic
    // models' levels named in N·m.
    assert!(
        summary.contains("`drivetrain.coulomb_n`") && summary.contains(" N·m |"),
        "{summary}"
    );
    assert!(stdout.contains("N·m on the joint"), "{stdout}");
    assert!(
        stdout.contains("fc_n_m=") && stdout.contains("b_n_m_s_rad=") && !stdout.contains("fc_n="),
        "{stdout}"
    );
    assert!(
        stdout.contains("held-out / friction scale: the held-out RMS divided by"),
        "{stdout}"
    );
}

#[test]
fn a_joints_column_names_are_read_in_its_held_out_part_as_in_its_training_part() {
    let d = dir("holdout-columns");
    // `velocity_rad_s` and `torque_nm`, no --velocity / --friction: the
    // held-out cut reads the file through the same joint's names (it read
    // `velocity_m_s` and failed before).
    let joint = joint_record(&d, 0.5, 4.0);
    let (code, stdout, err) = run(&[
        "fit",
        joint.to_str().unwrap(),
        "--rotary",
        "--holdout",
        "0.25",
        "--set",
        "solver.cells=32",
        "--fit",
        "contact.boundary_friction",
        "--starts",
        "1",
        "--global-points",
        "0",
        "--max-evaluations",
        "20",
        "--out",
        d.join("f.yaml").to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 4, "{err}");
    assert!(stdout.contains("held-out RMS "), "{stdout}");
    assert!(d.join("f.yaml").exists());
}

#[test]
fn a_fast_joint_is_asked_whether_its_velocity_is_in_degrees_per_second() {
    let d = dir("deg-s");
    // 0.5 rad/s written as deg/s: 28.6 "rad/s".
    let joint = joint_record(&d, 0.5f64.to_degrees(), 2.0);
    let (code, _, err) = run(&[
        "fit",
        joint.to_str().unwrap(),
        "--rotary",
        "--set",
        "solver.cells=32",
        "--fit",
        "contact.boundary_friction",
        "--starts",
        "1",
        "--global-points",
        "0",
        "--max-evaluations",
        "10",
        "--out",
        d.join("f.yaml").to_str().unwrap(),
    ]);
    assert!(code == 0 || code == 4, "{err}");
    assert!(
        err.contains("warning: --rotary: the top speed is") && err.contains("deg/s"),
        "{err}"
    );
}

#[cfg(feature = "mcap")]
#[test]
fn one_joint_state_topic_gives_both_the_velocity_and_the_effort_of_a_bag() {
    let root = env!("CARGO_MANIFEST_DIR");
    for bag in ["bags/rosbags_mcap", "bags/rosbags_sqlite3"] {
        let d = dir(&format!("one-topic-{}", bag.replace('/', "-")));
        let fit = |friction_topic: &str| {
            let (code, stdout, err) = run(&[
                "fit",
                &format!("{root}/{bag}"),
                "--velocity-topic",
                "/joint_states",
                "--friction-topic",
                friction_topic,
                "--joint",
                "slider",
                "--set",
                "solver.cells=32",
                "--fit",
                "contact.boundary_friction",
                "--starts",
                "1",
                "--global-points",
                "0",
                "--max-evaluations",
                "10",
                "--out",
                d.join("f.yaml").to_str().unwrap(),
            ]);
            assert!(code == 0 || code == 4, "{bag} {friction_topic}: {err}");
            stdout
                .lines()
                .find(|l| l.starts_with("| `contact.boundary_friction`"))
                .unwrap()
                .to_string()
        };
        // The JointState's effort is the same friction as the Float64 topic.
        assert_eq!(fit("/joint_states"), fit("/slider/friction"), "{bag}");
    }
}
