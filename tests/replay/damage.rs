//! Bad bags and bad arguments: each named (topic, index, field), replayed up
//! to the damage where that is possible, never a panic, never a lost output.

use super::*;

#[test]
fn a_schema_that_does_not_match_its_type_names_the_topic() {
    let d = dir("schema");
    let bag = d.join("bad_schema.mcap");
    write_bag(
        &bag,
        &[(
            "/axis/velocity",
            "std_msgs/msg/Float64",
            "float32 data\nuint8 flags\n",
        )],
        &[(0, float64(0.1)), (0, float64(0.2))],
    );
    let e = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap_err();
    let m = e.to_string();
    assert!(
        matches!(e, ReplayError::Bag(BagError::SchemaMismatch { .. })),
        "{m}"
    );
    assert!(
        m.contains("`/axis/velocity`") && m.contains("float32 data"),
        "{m}"
    );
}

#[test]
fn a_message_that_does_not_decode_is_damage_named_by_topic_and_index() {
    let d = dir("decode");
    let bag = d.join("short.mcap");
    let channels = [("/axis/velocity", "std_msgs/msg/Float64", "float64 data\n")];
    let garbage = vec![0, 1, 0, 0, 1];
    let good: Vec<(usize, Vec<u8>)> = (0..20).map(|k| (0, float64(0.01 * k as f64))).collect();
    let mut msgs = good.clone();
    msgs.push((0, garbage.clone()));
    msgs.extend(good);
    write_bag(&bag, &channels, &msgs);
    let p = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap();
    assert_eq!(p.velocity_messages, 20, "the messages before the bad one");
    let damage = p.scan.damage.expect("damage");
    assert_eq!(damage.after_messages, 20);
    assert!(
        damage.error.contains("`/axis/velocity`, message 21"),
        "{}",
        damage.error
    );
    // Nothing before it: the decode error itself.
    write_bag(&bag, &channels, &[(0, garbage)]);
    let e = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::Decode { index: 1, .. })),
        "{e}"
    );
    assert!(e.to_string().contains("/axis/velocity"), "{e}");
}

#[test]
fn a_truncated_bag_replays_up_to_the_damage_and_says_where() {
    let d = dir("truncated");
    let bytes = std::fs::read(NODE_BAG).unwrap();
    let bag = d.join("truncated.mcap");
    std::fs::write(&bag, &bytes[..bytes.len() * 7 / 10]).unwrap();
    let p = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap();
    let damage = p.scan.damage.clone().expect("damage reported");
    assert!(
        damage.after_messages > 0 && damage.last_log_time_ns.is_some(),
        "{damage:?}"
    );
    let steps = p.recorded.len();
    assert!(
        steps > 500 && steps < 2000,
        "{steps} steps before the damage"
    );
    let r = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    assert_eq!(r.estimates.len(), steps);
    let out = d.join("out.csv");
    let (code, stdout, err) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("damaged") && stdout.contains("damaged bag      stopped after"),
        "{stdout}{err}"
    );
    let rows = std::fs::read_to_string(&out).unwrap().lines().count();
    assert_eq!(rows, steps + 1);
}

#[test]
fn a_corrupt_chunk_stops_the_replay_there() {
    let d = dir("corrupt");
    let mut bytes = std::fs::read(FOREIGN_BAG).unwrap();
    // Scribble over the middle of the middle chunk's compressed records.
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let chunk = &summary.chunk_indexes[summary.chunk_indexes.len() / 2];
    let mid = (chunk.chunk_start_offset + chunk.chunk_length / 2) as usize;
    for b in &mut bytes[mid..mid + 64] {
        *b ^= 0x5a;
    }
    let bag = d.join("corrupt.mcap");
    std::fs::write(&bag, &bytes).unwrap();
    let p = prepare(
        bag.to_str().unwrap(),
        &opts(Some("/joint_states"), Some("slider")),
    )
    .unwrap();
    let damage = p.scan.damage.clone().expect("damage reported");
    assert!(
        p.velocity_messages > 0 && p.velocity_messages < 1001,
        "{}",
        p.velocity_messages
    );
    assert!(!damage.error.is_empty());
}

#[test]
fn invalid_input_writes_nothing_and_an_existing_output_survives() {
    let d = dir("atomic");
    let out = d.join("run.csv");
    std::fs::write(&out, "precious\n").unwrap();
    let not_a_bag = d.join("notes.mcap");
    std::fs::write(&not_a_bag, "not an mcap file").unwrap();
    for args in [
        vec![
            "replay",
            not_a_bag.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        vec!["replay", FOREIGN_BAG, "--out", out.to_str().unwrap()],
        vec![
            "replay",
            FOREIGN_BAG,
            "--topic",
            "/joint_states",
            "--out",
            out.to_str().unwrap(),
        ],
        vec![
            "replay",
            NODE_BAG,
            "--set",
            "solver.cells=3",
            "--out",
            out.to_str().unwrap(),
        ],
        vec![
            "replay",
            "/nonexistent/bag.mcap",
            "--out",
            out.to_str().unwrap(),
        ],
    ] {
        let (code, _, err) = run(&args);
        assert_ne!(code, 0, "{args:?}");
        assert!(err.starts_with("error:"), "{args:?}: {err}");
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            "precious\n",
            "{args:?}"
        );
    }
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--out",
        d.join("run.txt").to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(err.contains(".mcap or .csv"), "{err}");
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 2, "{leftovers:?}");
}

#[test]
fn a_truncated_sqlite3_bag_is_refused_or_replayed_up_to_the_damage_never_a_panic() {
    let d = dir("db3-damaged");
    let bytes = std::fs::read(format!("{ROSBAGS_SQLITE3}/rosbags_sqlite3.db3")).unwrap();
    for keep in [
        16,
        100,
        4096,
        bytes.len() / 3,
        bytes.len() / 2,
        bytes.len() - 4096,
    ] {
        let bag = d.join(format!("cut{keep}.db3"));
        std::fs::write(&bag, &bytes[..keep]).unwrap();
        let out = d.join(format!("cut{keep}.csv"));
        let (code, stdout, stderr) = run(&[
            "replay",
            bag.to_str().unwrap(),
            "--topic",
            "/joint_states",
            "--joint",
            "slider",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            code == 0 || code == 2,
            "cut at {keep}: exit {code}\n{stdout}\n{stderr}"
        );
        if code == 2 {
            assert!(
                stderr.contains("cut"),
                "cut at {keep}: names the file: {stderr}"
            );
            assert!(!out.exists(), "cut at {keep}: nothing written");
        }
    }
}

#[test]
fn an_output_whose_extension_contradicts_the_format_is_refused() {
    let d = dir("format-contradiction");
    let out = d.join("x.mcap");
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--out",
        out.to_str().unwrap(),
        "--format",
        "csv",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(".mcap") && err.contains("--format csv"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn a_bad_override_is_the_configurations_error_not_the_bags() {
    let d = dir("bad-override");
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--set",
        "contact.load_n=-1",
        "--out",
        d.join("r.csv").to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("contact.load_n"), "{err}");
    assert!(!err.contains("bag ") && !err.contains("recorded"), "{err}");
}
