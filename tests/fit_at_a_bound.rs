//! A fit whose optimum lies on a bound ends there converged. The joint of
//! `tests/fixtures/joint-speed-at-bound-*.csv` (a random steady joint of
//! `docs/arm-steady-draws.sh`, seed 107 joint 16: a Stribeck peak of
//! f_s 3.22 against f_c 2.15 N·m at ω_s 0.373 rad/s, above the data's top
//! speed 0.349) puts the Stribeck curve's speed on rule 8's bound, the
//! data's top speed. Under the sine transform Levenberg–Marquardt crawled
//! toward it until its budget ended: "NOT converged", exit 4, on 16 of 768
//! random joints. `fit/bound_polish.rs` holds the speed on its bound, fits
//! the rest and checks that the bound is active. The Stribeck curve is
//! fitted by name, started near the bound (`--fit auto` now starts this
//! concave curve from the viscous rise bent, rule 7c, and never fits the
//! curve there).

mod common;

use std::path::Path;

#[test]
fn a_stribeck_speed_on_its_bound_ends_the_fit_converged_there() {
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/joint-speed-at-bound-train.csv");
    let d = common::cli::fresh_dir("at-a-bound", "joint-speed-at-bound");
    let out = d.join("f.yaml");
    let (code, stdout, err) = common::cli::run(&[
        "fit",
        fixture.to_str().unwrap(),
        "--rotary",
        "--fit",
        "contact.boundary_friction,drivetrain.stribeck_n,drivetrain.stribeck_speed_m_s,drivetrain.viscous_n_s_m",
        "--start",
        "drivetrain.stribeck_speed_m_s=0.002",
        "--start",
        "drivetrain.stribeck_n=200",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        stdout.starts_with("# Fit of friction-node: converged"),
        "{stdout}"
    );
    assert!(
        err.contains("with drivetrain.stribeck_speed_m_s held on its bound (the cost rises inward"),
        "{err}"
    );
    // On the bound, the data's top speed 0.349 rad/s, flagged there.
    let row = stdout
        .lines()
        .find(|l| l.starts_with("| `drivetrain.stribeck_speed_m_s` |"))
        .unwrap();
    assert!(
        row.contains("at a bound") && row.contains("0.34907 rad/s"),
        "{row}"
    );
}
