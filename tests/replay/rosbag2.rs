//! rosbag2 directories (SQLite3 and MCAP) from an independent writer: replayed
//! identically, and fitted as a calibration's input.

use super::*;

#[test]
fn sqlite3_and_mcap_rosbag2_directories_from_an_independent_writer_replay_identically() {
    let d = dir("rosbags");
    let mut outputs = Vec::new();
    for (bag, name) in [
        (ROSBAGS_SQLITE3.to_string(), "sqlite3.csv"),
        (ROSBAGS_MCAP.to_string(), "mcap.csv"),
        // A .db3 file on its own is a bag too.
        (
            format!("{ROSBAGS_SQLITE3}/rosbags_sqlite3.db3"),
            "db3-file.csv",
        ),
    ] {
        let out = d.join(name);
        let mut args = vec![
            "replay",
            bag.as_str(),
            "--topic",
            "/joint_states",
            "--joint",
            "slider",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(ROSBAGS_SETS);
        let (code, stdout, stderr) = run(&args);
        assert_eq!(code, 0, "{bag}: {stdout}\n{stderr}");
        assert!(
            stderr.contains("load `/slider/normal_load`")
                && stderr.contains("temperature `/oil_temperature`"),
            "{bag}: the load and temperature topics are found: {stderr}"
        );
        assert!(stdout.contains("steps            500"), "{bag}: {stdout}");
        outputs.push(std::fs::read_to_string(&out).unwrap());
    }
    assert_eq!(
        outputs[0], outputs[1],
        "sqlite3 and mcap storage replay alike"
    );
    assert_eq!(
        outputs[0], outputs[2],
        "a .db3 file alone replays like its directory"
    );
    // The temperature ramp (20 → 60 °C over the run) reached the model.
    let rows: Vec<Vec<String>> = outputs[0]
        .lines()
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let col = rows[0].iter().position(|c| c == "temperature_c").unwrap();
    let first: f64 = rows[1][col].parse().unwrap();
    let last: f64 = rows[rows.len() - 1][col].parse().unwrap();
    assert!((20.0..21.0).contains(&first), "first temperature {first}");
    assert!((58.0..60.0).contains(&last), "last temperature {last}");
}

#[test]
fn a_fit_on_an_sqlite3_bag_recovers_boundary_friction_and_viscosity() {
    let d = dir("rosbags-fit");
    let out = d.join("fitted.yaml");
    let mut args = vec![
        "fit",
        ROSBAGS_SQLITE3,
        "--velocity-topic",
        "/joint_states",
        "--joint",
        "slider",
        "--friction-topic",
        "/slider/friction",
        "--fit",
        "contact.boundary_friction,lubricant.viscosity_pa_s",
        "--start",
        "contact.boundary_friction=0.1",
        "--start",
        "lubricant.viscosity_pa_s=0.2",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(ROSBAGS_SETS);
    let (code, stdout, stderr) = run(&args);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    let fitted = friction_node::config::Config::load(Some(&out), &[]).unwrap();
    // The bag's truth: the shipped defaults (mu_bl 0.3, mu_l 0.0564 Pa s at
    // 40 degC). The temperature topic is sampled at 50 Hz and held, so the
    // model sees up to 0.8 degC less than the simulation did: within 5 %.
    approx::assert_relative_eq!(fitted.contact.boundary_friction, 0.3, max_relative = 0.05);
    approx::assert_relative_eq!(fitted.lubricant.viscosity_pa_s, 0.0564, max_relative = 0.05);
}

#[test]
fn a_fit_on_the_nodes_own_lockstep_recording_recovers_its_boundary_friction_though_its_load_topic_is_empty(
) {
    // The node ran without a load input: its bag has the topic
    // `/friction_node/normal_load` with no message. The load is then the
    // configuration's, as it was in the node (before: the empty topic was
    // taken by default and the fit refused it, "no message could be read").
    let d = dir("own-bag-fit");
    let out = d.join("fitted.yaml");
    let (code, stdout, stderr) = run(&[
        "fit",
        NODE_BAG,
        "--velocity-topic",
        "/friction_node/cmd_velocity",
        "--friction-topic",
        "/friction_node/friction_force",
        "--fit",
        "contact.boundary_friction",
        "--start",
        "contact.boundary_friction=0.2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}\n{stderr}");
    assert!(
        stderr.contains("load from the configuration (contact.load_n), temperature none"),
        "{stderr}"
    );
    let fitted = friction_node::config::Config::load(Some(&out), &[]).unwrap();
    approx::assert_relative_eq!(fitted.contact.boundary_friction, 0.3, max_relative = 1e-4);
}

#[test]
fn a_fit_on_a_bag_without_its_topics_named_lists_the_bags_topics() {
    let d = dir("rosbags-fit-untold");
    let out = d.join("fitted.yaml");
    let (code, _, stderr) = run(&[
        "fit",
        ROSBAGS_MCAP,
        "--fit",
        "contact.boundary_friction",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("needs --velocity-topic and --friction-topic; the bag has:")
            && stderr.contains("/joint_states  [sensor_msgs/msg/JointState]")
            && stderr.contains("/slider/friction"),
        "{stderr}"
    );
    assert!(!out.exists(), "nothing written");
}
