//! `fit --fit auto --baselines` on records made by the classic models
//! themselves: ours contains them (the boundary friction with sgn v, the
//! drivetrain's viscous and Stribeck terms), so on each it reaches the
//! generating model's training error and predicts the held-out part no
//! worse than that model as the tool fits it. Before the chosen scale put
//! the film's transition three decades above the data and its sign's
//! regularisation below the first sample after a reversal, ours fitted a
//! Stribeck spike to sharpen a rounded sign and predicted 0.04–0.3 % worse.

mod common;
use common::cli::run;

use friction_node::fit::synthetic::gaussian;
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::fmt::Write as _;
use std::path::Path;

fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("contains-classics", name)
}

/// F(v) = sgn v (f_c + (f_s − f_c) e^(−(v/v_s)²)) + b v with 1 % white
/// noise, as a CSV `t_s,velocity_m_s,friction_n`.
fn stribeck_record(path: &Path, fc: f64, fs: f64, vs: f64, b: f64) {
    let m = common::motion::point_to_point(8.0, 1.0);
    let f: Vec<f64> = m
        .iter()
        .map(|(_, v)| {
            let sgn = if *v > 0.0 {
                1.0
            } else if *v < 0.0 {
                -1.0
            } else {
                0.0
            };
            sgn * (fc + (fs - fc) * (-(v / vs).powi(2)).exp()) + b * v
        })
        .collect();
    let rms = (f.iter().map(|x| x * x).sum::<f64>() / f.len() as f64).sqrt();
    let mut rng = StdRng::seed_from_u64(17);
    let mut s = String::from("t_s,velocity_m_s,friction_n\n");
    for ((t, v), f) in m.iter().zip(&f) {
        writeln!(s, "{t},{v},{}", f + gaussian(&mut rng, 0.01 * rms)).unwrap();
    }
    std::fs::write(path, s).unwrap();
}

/// A models-table row's training and held-out RMS, by the row's label.
fn row(md: &str, label: &str) -> (f64, f64) {
    let line = md
        .lines()
        .find(|l| l.starts_with(&format!("| {label} |")))
        .unwrap_or_else(|| panic!("no row {label} in\n{md}"));
    let cells: Vec<&str> = line.split('|').map(str::trim).collect();
    // | model | n | parameters | fit | training | CV | held-out | share |
    (cells[5].parse().unwrap(), cells[7].parse().unwrap())
}

/// `fit DATA EXTRA… --fit auto --baselines --out DATA.yaml`: its summary
/// (the exit status checked).
fn fit_auto_with(data: &Path, extra: &[&str]) -> String {
    let out = data.with_extension("yaml");
    let mut args = vec!["fit", data.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend([
        "--fit",
        "auto",
        "--baselines",
        "--out",
        out.to_str().unwrap(),
    ]);
    let (code, stdout, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    stdout
}

fn fit_auto(data: &Path) -> String {
    fit_auto_with(data, &["--holdout", "0.3", "--set", "solver.cells=16"])
}

fn assert_ours_contains(md: &str, classic: &str) {
    let (ours_train, _) = row(md, "friction-node");
    let (their_train, _) = row(md, classic);
    assert!(
        ours_train <= 1.001 * their_train,
        "training RMS: ours {ours_train}, {classic} {their_train}\n{md}"
    );
    // The same curve, fitted by two optimisers: equal to 1e-4 (the scale
    // of 100× and a rounded sign left ours 4e-4 to 3e-3 behind).
    assert_held_out_within(md, classic, 1.0 + 1e-4);
    assert!(!md.contains("ours is not the best"), "{md}");
}

/// Ours' held-out RMS is at most `factor` × the classic's (`label`).
/// The selection's "Chosen:" line starts with `prefix`.
fn assert_chosen(md: &str, prefix: &str) {
    let chosen = md
        .lines()
        .find(|l| l.starts_with("Chosen:"))
        .unwrap_or_else(|| panic!("no Chosen line\n{md}"));
    assert!(chosen.starts_with(prefix), "{chosen}");
}

fn assert_held_out_within(md: &str, label: &str, factor: f64) {
    let (_, ours) = row(md, "friction-node");
    let (_, classic) = row(md, label);
    assert!(
        ours <= factor * classic,
        "held-out RMS ours {ours}, {label} {classic} (at most {factor} × it)\n{md}"
    );
}

#[test]
fn on_a_coulomb_plus_viscous_record_ours_chooses_the_viscous_rise_and_predicts_as_well() {
    let d = dir("coulomb-viscous");
    let data = d.join("cv.csv");
    stribeck_record(&data, 200.0, 200.0, 0.01, 2000.0);
    let md = fit_auto(&data);
    assert_ours_contains(&md, "Coulomb + viscous");
    assert_chosen(&md, "Chosen: boundary friction, drivetrain viscous.");
}

#[test]
fn on_a_stribeck_record_that_rises_and_saturates_ours_reaches_the_classic_and_predicts_as_well() {
    let d = dir("stribeck-rise");
    let data = d.join("rise.csv");
    stribeck_record(&data, 200.0, 80.0, 0.02, 500.0);
    let md = fit_auto(&data);
    assert_ours_contains(&md, "Stribeck");
}

/// A joint's steady curve τ(ω) = sgn ω (f_c + (f_s − f_c) e^(−(ω/ω_s)²)) +
/// b ω, each speed (deg/s) taken both ways with 0.5 % noise, as a CSV
/// `velocity_rad_s,friction_nm`.
fn joint_curve(path: &Path, speeds_deg_s: &[f64], (fc, fs, ws, b): (f64, f64, f64, f64)) {
    let mut rng = StdRng::seed_from_u64(4);
    let mut s = String::from("velocity_rad_s,friction_nm\n");
    for deg in speeds_deg_s {
        for sign in [1.0, -1.0] {
            let w = sign * deg.to_radians();
            let tau = sign * (fc + (fs - fc) * (-(w / ws).powi(2)).exp()) + b * w;
            writeln!(s, "{w},{}", tau * (1.0 + gaussian(&mut rng, 0.005))).unwrap();
        }
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn a_joint_fitted_on_0_5_to_20_deg_s_predicts_25_to_90_deg_s_within_5_percent_of_the_classic() {
    // The held-back direct-drive arm's split, on Stribeck curves: one
    // whose static level is above the Coulomb level, one below it. A
    // guard of the held-back target (within 1.05 × the best classic), not
    // a reproduction of a past failure: on this noise draw the earlier
    // scale passes too (on another, the peak curve's film collapsed past
    // the data, 5.6 × Stribeck's held-out error).
    let d = dir("joint-past-the-data");
    let train = [0.5, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 13.0, 16.0, 20.0];
    let validate = [25.0, 35.0, 45.0, 60.0, 75.0, 90.0];
    for (name, curve) in [
        ("peak", (1.2, 1.8, 0.05, 2.0)),
        ("rise", (1.2, 0.6, 0.1, 1.0)),
    ] {
        let t = d.join(format!("{name}-train.csv"));
        let v = d.join(format!("{name}-validate.csv"));
        joint_curve(&t, &train, curve);
        joint_curve(&v, &validate, curve);
        let md = fit_auto_with(&t, &["--validate", v.to_str().unwrap(), "--rotary"]);
        assert_held_out_within(&md, "Stribeck", 1.05);
    }
}

/// The lead screw's steady curve (`data/lead-screw`, drive 1, forward),
/// split as docs/real-data-benchmarks.sh's (b): fitted at ≤ 100 rpm,
/// predicting 120–200 rpm. Written as `velocity_rad_s,friction_nm`.
fn lead_screw_faster_speeds(train: &Path, validate: &Path) {
    let table =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("data/lead-screw/steady_state_summary.csv");
    let mut r = csv::Reader::from_path(&table).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |name: &str| h.iter().position(|c| c == name).unwrap();
    let (drive, label, speed, torque) = (
        col("drive"),
        col("file_label"),
        col("motor_speed_rad_s"),
        col("motor_torque_mNm"),
    );
    let (mut t, mut v) = (String::new(), String::new());
    for s in [&mut t, &mut v] {
        s.push_str("velocity_rad_s,friction_nm\n");
    }
    for rec in r.records() {
        let rec = rec.unwrap();
        if &rec[drive] != "1" || rec[label].starts_with('n') {
            continue;
        }
        let rpm: u32 = rec[label].parse().unwrap();
        let nm: f64 = rec[torque].parse::<f64>().unwrap() / 1000.0;
        let out = if rpm <= 100 { &mut t } else { &mut v };
        writeln!(out, "{},{nm}", &rec[speed]).unwrap();
    }
    std::fs::write(train, t).unwrap();
    std::fs::write(validate, v).unwrap();
}

/// `--rotary --fit auto` on the joint fixture `tests/fixtures/NAME-train.csv`
/// (copied into a fresh directory), validated on `NAME-validate.csv`.
fn fit_joint_fixture(name: &str) -> String {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let d = dir(name);
    let t = d.join("train.csv");
    std::fs::copy(fixtures.join(format!("{name}-train.csv")), &t).unwrap();
    let v = fixtures.join(format!("{name}-validate.csv"));
    fit_auto_with(&t, &["--validate", v.to_str().unwrap(), "--rotary"])
}

/// The selection table's cross-validated RMS of the set `terms` (beside
/// the boundary friction).
fn selection_cv(md: &str, terms: &str) -> f64 {
    let line = md
        .lines()
        .find(|l| l.starts_with(&format!("| {terms} |")))
        .unwrap_or_else(|| panic!("no selection row {terms} in\n{md}"));
    line.split('|')
        .map(str::trim)
        .nth(2)
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn on_the_lead_screws_faster_speeds_the_film_scored_by_refitted_folds_does_not_pay_beside_the_stribeck_curve(
) {
    // Each fold of a set's trial is refitted from the set's fit on all the
    // training points, which saw the fold. With the film's keys and the
    // friction terms' searched together, the folds of the film beside the
    // Stribeck curve hardly moved from there: three of four ended with a
    // higher training error than the Stribeck curve alone on the same fold
    // (the set contains it) and predicted the points their start was
    // fitted on, CV 1.86e-5 N·m against the Stribeck curve's refitted
    // 2.73e-5: the film seemed to pay, and only the correlation rule took
    // it out again. With the friction terms profiled, the folds converge:
    // the film pays nothing, and ours is the Stribeck curve it contains,
    // as good held out as the classic, to 1e-4.
    let d = dir("lead-screw-faster");
    let (t, v) = (d.join("train.csv"), d.join("validate.csv"));
    lead_screw_faster_speeds(&t, &v);
    let md = fit_auto_with(&t, &["--validate", v.to_str().unwrap(), "--rotary"]);
    let stribeck = selection_cv(&md, "drivetrain Stribeck");
    let with_film = selection_cv(&md, "drivetrain Stribeck, film");
    assert!(
        with_film >= stribeck,
        "the film beside the Stribeck curve: CV {with_film}, the curve alone {stribeck}\n{md}"
    );
    assert_chosen(&md, "Chosen: boundary friction, drivetrain Stribeck.");
    assert_held_out_within(&md, "Stribeck", 1.0 + 1e-4);
}

#[test]
fn a_film_placed_inside_a_joints_data_by_its_trial_is_not_shipped_there() {
    // A joint's Stribeck curve (a peak: f_s above f_c) with 1 % noise, 0.5
    // to 20 deg/s both ways, predicted at 25 to 90 deg/s
    // (`tests/fixtures/joint-peak-*.csv`, one draw of the held-back arm's
    // split). The film's trial, its transition placed inside the data,
    // pays in cross-validation (0.0082 against 0.0105 N·m); shipped there,
    // the film bent the curve below the data's rise past them (2.5 % low):
    // 0.092 N·m held out, 6.5 × the Stribeck curve's 0.014. Until rule 10
    // it came in and went again by rule 4 (its viscosity correlates 0.998
    // with the Stribeck curve's viscous rise). Now it does not come in:
    // the whole curve's small-sample Akaike criterion does not support it
    // (−188.3 with it against −188.0 without), and ours is the Stribeck
    // curve.
    let md = fit_joint_fixture("joint-peak");
    assert_held_out_within(&md, "Stribeck", 1.05);
    assert_chosen(&md, "Chosen: boundary friction, drivetrain Stribeck.");
    assert!(
        md.lines().any(|l| l
            .starts_with("Not admitted: film beside drivetrain Stribeck: it pays on the folds")),
        "{md}"
    );
}

#[test]
fn a_quadratic_rise_whose_coefficient_the_data_cannot_tell_from_zero_is_not_admitted_even_where_the_folds_favour_it(
) {
    // A joint's Stribeck curve (a peak) with 1 % noise, 0.5 to 20 deg/s both
    // ways, predicted at 25 to 90 deg/s: one draw of the held-back arm's
    // split (`tests/fixtures/joint-peak-draw5-*.csv`). On it the folds favour
    // the drivetrain's quadratic loss beside the Stribeck curve (CV 0.0418
    // against 0.0472 N·m), but its fit cannot tell the quadratic's
    // coefficient from zero (95 % interval [−3.7e6, 3.0e7] N·s²/m²). Kept
    // on the folds' word, it rose without end past the data: 1.22 N·m held
    // out, 25 × the Stribeck curve's 0.049. Rule 9: not admitted. (Before
    // rule 9, rule 4 removed it as confounded with the Stribeck curve's
    // viscous key, ρ 0.987; on a fresh joint where the two correlated
    // 0.909 it stayed and predicted 35× worse.)
    let md = fit_joint_fixture("joint-peak-draw5");
    assert_chosen(&md, "Chosen: boundary friction, drivetrain Stribeck.");
    assert!(
        md.lines().any(|l| l
            .starts_with("Not admitted: drivetrain quadratic beside drivetrain Stribeck: ")
            && l.contains("that holds zero")),
        "{md}"
    );
    assert_held_out_within(&md, "Stribeck", 1.05);
}

#[test]
fn a_noise_dip_that_pays_on_the_folds_but_not_on_the_whole_curve_is_not_added() {
    // A Coulomb + viscous joint in all but a Stribeck dip below every
    // training speed (f_c 0.65, f_s 0.86 N·m, ω_s 0.0052 rad/s, b 0.025
    // N·m·s/rad; random joint 17 of seed 5, `docs/fit-auto-judged.md`),
    // 1 % noise, 0.5 to 20 deg/s both ways, predicted at 25 to 90 deg/s
    // (`tests/fixtures/joint-cv-noise-dip-*.csv`). The folds paid for a
    // Stribeck curve whose dip sat on the noise at 0.11 rad/s (CV 0.0074 →
    // 0.0065 N·m), while the whole curve's small-sample Akaike criterion
    // rose with it (−207.7 → −205.5); its steeper viscous rise beneath
    // the dip predicted 25–90 deg/s 3.0× worse than Coulomb + viscous.
    // Rule 10: a term enters a steady curve only where both support it.
    let md = fit_joint_fixture("joint-cv-noise-dip");
    assert_chosen(&md, "Chosen: boundary friction, drivetrain viscous.");
    assert!(
        md.lines().any(|l| l.starts_with(
            "Not admitted: drivetrain Stribeck beside drivetrain viscous: it pays on the folds"
        )),
        "{md}"
    );
    assert_held_out_within(&md, "Coulomb + viscous", 1.05);
}

/// The training RMS of a fit's summary (its first "training RMS" line).
fn training_rms(md: &str) -> f64 {
    let line = md
        .lines()
        .find(|l| l.starts_with("training RMS "))
        .unwrap_or_else(|| panic!("no training RMS\n{md}"));
    line["training RMS ".len()..]
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap()
}

#[test]
fn profiled_cheap_keys_reach_the_lead_screws_optimum_with_the_film_beside_the_stribeck_curve() {
    // The film beside the Stribeck curve on the lead screw's speeds up to
    // 100 rpm: the searched path reaches training RMS 1.377e-5 N·m from
    // the default start. The profiled path fitted the Stribeck speed at
    // the start's film from its start alone and settled where the curve
    // bends at 0.2 rad/s instead of 4.1: 6.86e-5 N·m, and the film's one
    // key could not lead it out. A key that bends the curve at a speed is
    // now also started at three places of its range at a run's first
    // point: the same optimum, with fewer film solves.
    let d = dir("lead-screw-profiled");
    let (t, v) = (d.join("train.csv"), d.join("validate.csv"));
    lead_screw_faster_speeds(&t, &v);
    let keys = "contact.boundary_friction,drivetrain.stribeck_n,drivetrain.stribeck_speed_m_s,\
                drivetrain.viscous_n_s_m,lubricant.viscosity_pa_s";
    let fit = |rule: &str| {
        let out = d.join(format!("{rule}.yaml"));
        let args = [
            "fit",
            t.to_str().unwrap(),
            "--rotary",
            "--fit",
            keys,
            "--cheap-keys",
            rule,
            "--out",
            out.to_str().unwrap(),
        ];
        let (code, stdout, err) = run(&args);
        assert_eq!(code, 0, "{err}");
        let films: usize = stdout
            .lines()
            .find_map(|l| l.split(" simulations (").nth(1))
            .and_then(|l| l.split_whitespace().next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no film solves\n{stdout}"));
        (training_rms(&stdout), films)
    };
    let (searched, searched_films) = fit("searched");
    let (profiled, profiled_films) = fit("profiled");
    assert!(
        profiled <= searched * (1.0 + 1e-3),
        "profiled {profiled}, searched {searched}"
    );
    assert!(
        profiled_films < searched_films,
        "film solves: profiled {profiled_films}, searched {searched_films}"
    );
}

/// The line `Chosen: …` of a report.
fn chosen(md: &str) -> &str {
    md.lines().find(|l| l.starts_with("Chosen:")).unwrap()
}

#[test]
fn a_coulomb_plus_viscous_joint_keeps_its_viscous_rise_where_a_boundary_rate_fits_the_folds_as_well(
) {
    // Random joint 9 of seed 19 (`CURVES=random SEED=19
    // docs/arm-steady-draws.sh`): f_c 2.559 N·m, b 0.7595 N·m·s/rad, 1 %
    // noise. The folds paid 5 % for a boundary rate (a logarithmic rise)
    // in place of the presumed viscous rise; past the data it fell behind,
    // 9.9× the Coulomb + viscous line's held-out error.
    let md = fit_joint_fixture("joint-cv-rate");
    let chosen = chosen(&md);
    assert!(
        chosen.starts_with("Chosen: boundary friction, drivetrain viscous"),
        "{chosen}"
    );
    assert_held_out_within(&md, "Coulomb + viscous", 1.05);
}

#[test]
fn a_stribeck_dip_the_noise_made_gives_way_to_the_viscous_rise_beneath_it() {
    // Random joint 7 of seed 5: f_c 1.459 N·m with a rise below the data
    // (ω_s 0.005 rad/s), so Coulomb + viscous over 0.5–20 deg/s. The noise
    // gave the Stribeck curve a dip (AICc 5.7 below the viscous rise, its
    // keys correlated 0.997), which predicts the folds worse than the rise
    // and 25–90 deg/s 4.5× worse than Coulomb + viscous.
    let md = fit_joint_fixture("joint-cv-dip");
    let chosen = chosen(&md);
    assert!(
        chosen.starts_with("Chosen: boundary friction, drivetrain viscous."),
        "{chosen}"
    );
    assert!(
        md.contains("drivetrain Stribeck → drivetrain viscous"),
        "the curve gives way to its rise"
    );
    assert_held_out_within(&md, "Coulomb + viscous", 1.05);
}

#[test]
fn a_path_of_removals_that_ends_on_a_set_its_start_beats_goes_back_to_the_start() {
    // Random joint 14 of seed 241 (drawn after rule 10): a Stribeck dip,
    // f_c 0.630, f_s 1.110 N·m, ω_s 0.222 rad/s, b 0.350 N·m·s/rad. The
    // curve gave way to its rise beside the film, the film went as
    // confounded with the rise, the rise ended at zero: the base alone
    // (criterion −83.3 against the curve's −174.6, CV 0.154 against
    // 0.043 N·m) predicted 25–90 deg/s 1.9× worse than Stribeck.
    let md = fit_joint_fixture("joint-dip-path");
    let chosen = chosen(&md);
    assert!(
        chosen.starts_with("Chosen: boundary friction, drivetrain Stribeck."),
        "{chosen}"
    );
    assert!(
        md.contains("the base alone → drivetrain Stribeck: the selection's path ended there"),
        "rule 11 says why"
    );
    assert_held_out_within(&md, "Stribeck", 1.05);
}
