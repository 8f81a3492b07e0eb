//! A fit whose optimum lies on a bound ends there converged. The joint of
//! `tests/fixtures/joint-speed-at-bound-*.csv` (a random steady joint of
//! `docs/arm-steady-draws.sh`, seed 107 joint 16: a Stribeck peak of
//! f_s 3.22 against f_c 2.15 N·m at ω_s 0.373 rad/s, above the data's top
//! speed 0.349) puts the Stribeck curve's speed on rule 9's bound, the
//! data's top speed. Under the sine transform Levenberg–Marquardt crawled
//! toward it until its budget ended: "NOT converged", exit 4, on 16 of 768
//! random joints. `fit/bound_polish.rs` holds the speed on its bound, fits
//! the rest and checks that the bound is active.

mod common;
use common::cli::run;

use std::path::Path;

#[test]
fn a_stribeck_speed_on_its_bound_ends_the_fit_converged_there() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let d = common::cli::fresh_dir("at-a-bound", "speed");
    let train = d.join("train.csv");
    std::fs::copy(fixtures.join("joint-speed-at-bound-train.csv"), &train).unwrap();
    let validate = fixtures.join("joint-speed-at-bound-validate.csv");
    let (code, stdout, err) = run(&[
        "fit",
        train.to_str().unwrap(),
        "--validate",
        validate.to_str().unwrap(),
        "--rotary",
        "--fit",
        "auto",
        "--out",
        d.join("f.yaml").to_str().unwrap(),
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
