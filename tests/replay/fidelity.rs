//! A replay reproduces the recording it reads: within a part per million of
//! the fixture, bit-identically for a fresh recording, with the flux it was
//! recorded with; and `--expect-identical` says when there is nothing to compare.

use super::*;

/// Replay `bag` on its recorded configuration and check every estimate
/// within one part per million of the recording; returns the configuration.
fn assert_replays_within_one_ppm(bag: &str) -> friction_node::config::Config {
    let p = prepare(bag, &ReplayOptions::default()).unwrap();
    assert_eq!(p.config_source, "recorded in the bag");
    assert!(
        matches!(&p.mode, InputMode::RecordedEstimates { .. }),
        "{:?}",
        p.mode
    );
    assert_eq!(p.recorded.len(), 2000);
    let r = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    let o = r.oracle.expect("a friction-node bag is compared");
    assert_eq!(o.compared, 2000);
    assert_eq!(o.count_mismatch, None);
    let load = p.recorded[0].load_n;
    for (field, dev, at) in &o.deviations {
        let bound = match *field {
            "friction_force_n" | "hydrodynamic_force_n" | "asperity_force_n" => 1e-6 * load,
            "cof" | "asperity_load_share" => 1e-6,
            "h0_m" | "h_min_m" => 1e-6 * p.recorded[*at].h0_m,
            "iterations" => continue,
            other => panic!("{other} differs by {dev} at step {at}"),
        };
        assert!(*dev <= bound, "{bag}: {field} differs by {dev:e} at step {at} (bound {bound:e}); bags/regenerate.sh after a deliberate change");
    }
    p.config
}

#[test]
fn the_node_fixture_replays_within_one_part_per_million_of_its_recording() {
    // Bit-identity holds for the binary that recorded it (tested below on a
    // fresh recording); across solver versions and CPUs the fixture must
    // still agree to the solver's tolerance.
    let c = assert_replays_within_one_ppm(NODE_BAG);
    assert_eq!(c.solver.flux, friction_node::config::FluxKind::MusclVanLeer);
}

#[test]
fn a_bag_recorded_before_solver_flux_existed_replays_with_the_upwind_flux_it_was_recorded_with() {
    // tests/fixtures/node_lockstep_before_flux.mcap: bags/node_lockstep.mcap
    // as recorded before `solver.flux` existed (upwind was the only flux);
    // kept as it was recorded, never regenerated.
    let old = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/node_lockstep_before_flux.mcap"
    );
    let c = assert_replays_within_one_ppm(old);
    assert_eq!(c.solver.flux, friction_node::config::FluxKind::Upwind);
}

#[test]
fn a_fresh_recording_replays_bit_identically_and_so_does_the_replay_output() {
    let d = dir("fresh");
    let bag = d.join("lockstep.mcap");
    let base = format!("fn_replay_{}", std::process::id());
    let (code, _, err) = run(&[
        "run",
        "--demo",
        "0.5",
        "--config",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/launch-config/lockstep-iceoryx2.yaml"
        ),
        "--set",
        "solver.cells=64",
        "--set",
        &format!("iceoryx2.cmd_velocity_service={base}/cmd"),
        "--set",
        &format!("iceoryx2.normal_load_service={base}/load"),
        "--set",
        &format!("iceoryx2.friction_service={base}/friction"),
        "--set",
        &format!("iceoryx2.cmd_event_service={base}/event"),
        "--record",
        bag.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(code, 0, "{err}");
    let out = d.join("replayed.mcap");
    let (code, stdout, err) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 0, "{stdout}{err}");
    // Every recorded step is reproduced; how many the node took depends on
    // how many of the demo's 500 commands it received before the demo
    // ended, which a loaded machine changes (lockstep takes only what arrives).
    let steps: u64 = stdout
        .split("bit-identical to the recorded estimates (")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no oracle verdict: {stdout}"));
    assert!((20..=500).contains(&steps), "{stdout}");
    // The output is a friction-node bag in its own right.
    let again = d.join("again.csv");
    let (code, stdout, err) = run(&[
        "replay",
        out.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 0, "{stdout}{err}");
    assert!(stdout.contains("bit-identical"), "{stdout}");
    // A different configuration is not: the oracle says by how much.
    let (code, stdout, _) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--set",
        "contact.boundary_friction=0.2",
        "--out",
        again.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 3, "{stdout}");
    assert!(
        stdout.contains("DIFFERS") && stdout.contains("friction_force_n"),
        "{stdout}"
    );
}

#[test]
fn expect_identical_on_a_bag_without_recorded_estimates_exits_5_before_writing() {
    let d = dir("nothing-to-compare");
    let out = d.join("r.csv");
    let (code, _, err) = run(&[
        "replay",
        FOREIGN_BAG,
        "--topic",
        "/joint_states",
        "--joint",
        "slider",
        "--out",
        out.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 5, "{err}");
    assert!(err.contains("nothing to compare"), "{err}");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "nothing written");
    // A recorded bag still compares (and exits 0 when identical).
    let (code, _, err) = run(&[
        "replay",
        NODE_BAG,
        "--out",
        out.to_str().unwrap(),
        "--expect-identical",
    ]);
    assert_eq!(code, 0, "{err}");
}
