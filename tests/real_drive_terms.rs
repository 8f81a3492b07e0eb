//! The terms real drives show, through every path: pre-sliding compliance
//! (a bristle on the model's own friction), a soft contact whose width
//! follows the load, a boundary film whose friction rises with the
//! logarithm of speed, and the drivetrain's quadratic loss and direction
//! asymmetry. Off by default (every other test checks that the estimates
//! are then unchanged); here they are on.

mod common;
use common::cli::{bin, fresh_dir};

use approx::assert_relative_eq;
use friction_node::config::Config;
use friction_node::physics::{Solver, Status};

fn config(sets: &[&str]) -> Config {
    let mut all = vec!["solver.cells=32".to_string()];
    all.extend(sets.iter().map(|s| s.to_string()));
    Config::load(None, &all).unwrap()
}

/// Friction along v = A sin 2πt from the steady state at rest.
fn run(c: &Config, amplitude: f64, steps: usize) -> Vec<(f64, f64)> {
    let mut s = Solver::new(&c.model(), &c.solver_settings()).unwrap();
    s.initialize_steady(0.0, c.contact.load_n);
    (1..=steps)
        .map(|k| {
            let t = k as f64 * c.solver.dt_s;
            let v = amplitude * (std::f64::consts::TAU * t).sin();
            let e = s.step(v, c.contact.load_n);
            assert_eq!(e.status, Status::Converged, "step {k}");
            (v, e.friction_force)
        })
        .collect()
}

#[test]
fn with_presliding_the_friction_passes_zero_gradually_where_the_rigid_contact_switches() {
    // A slow reversal (1 cm/s, 1 Hz) through t = 0.5 s.
    let rigid = run(&config(&[]), 0.01, 700);
    let soft = run(
        &config(&["contact.presliding_stiffness_n_m=2e8"]),
        0.01,
        700,
    );
    // The displacement over which the level L ≈ 6.2 kN is reached is about
    // L/σ0 = 31 µm: at 1 cm/s near the reversal, many steps.
    let rise = |r: &[(f64, f64)]| {
        r[480..600]
            .iter()
            .filter(|(_, f)| f.abs() < 0.8 * 6000.0)
            .count()
    };
    assert!(
        rise(&rigid) <= 4,
        "the rigid contact switches within ±v_reg: {}",
        rise(&rigid)
    );
    assert!(
        rise(&soft) >= 4 * rise(&rigid).max(3),
        "the compliant contact passes zero gradually: {} steps against {}",
        rise(&soft),
        rise(&rigid)
    );
    // Mid-stroke both are the same sliding friction (the bristle follows
    // the level with a lag of L/(σ0 |v|) = 3 ms, as the level drifts).
    let k = 250;
    assert_relative_eq!(rigid[k].1, soft[k].1, max_relative = 1e-3);
}

#[test]
fn any_presliding_stiffness_is_stable_and_a_very_stiff_one_is_the_rigid_sliding_friction() {
    let rigid = run(&config(&[]), 0.5, 1000);
    for stiffness in ["1e4", "1e9", "1e15"] {
        let soft = run(
            &config(&[&format!("contact.presliding_stiffness_n_m={stiffness}")]),
            0.5,
            1000,
        );
        assert!(
            soft.iter().all(|(_, f)| f.is_finite() && f.abs() < 7000.0),
            "σ0 {stiffness}"
        );
    }
    let stiff = run(
        &config(&["contact.presliding_stiffness_n_m=1e15"]),
        0.5,
        1000,
    );
    // Away from the reversals (|v| ≫ v_reg) the rigid contact's tanh is 1.
    for k in (100..400).chain(600..900) {
        assert_relative_eq!(stiff[k].1, rigid[k].1, max_relative = 1e-9);
    }
}

#[test]
fn a_soft_contact_whose_area_follows_the_load_has_a_load_independent_friction_coefficient() {
    // κ = 1: the film is the reference load's at every load; every force
    // scales with the load.
    let c = config(&[
        "contact.width_load_exponent=1",
        "contact.width_reference_load_n=20762",
    ]);
    let mut s = Solver::new(&c.model(), &c.solver_settings()).unwrap();
    let a = s.steady(0.3, 20_762.0);
    let b = s.steady(0.3, 2.0 * 20_762.0);
    assert_relative_eq!(b.h0, a.h0, max_relative = 1e-9);
    assert_relative_eq!(b.cof, a.cof, max_relative = 1e-9);
    assert_relative_eq!(
        b.friction_force,
        2.0 * a.friction_force,
        max_relative = 1e-9
    );
    assert_relative_eq!(b.load, 2.0 * a.load, max_relative = 1e-15);
    // κ = 0 (rigid): twice the load thins the film and changes the COF.
    let r = config(&[]);
    let mut s = Solver::new(&r.model(), &r.solver_settings()).unwrap();
    let (a, b) = (s.steady(0.3, 20_762.0), s.steady(0.3, 2.0 * 20_762.0));
    assert!(b.h0 < 0.99 * a.h0, "{} {}", a.h0, b.h0);
}

#[test]
fn a_rate_sensitive_boundary_film_adds_mu_r_asinh_v_over_v_a_times_the_asperity_load() {
    let (mu_r, v_a) = (0.02, 1e-4);
    let on = config(&[
        "contact.boundary_friction_rate=0.02",
        "contact.boundary_activation_speed_m_s=1e-4",
    ]);
    let off = config(&[]);
    let mut a = Solver::new(&on.model(), &on.solver_settings()).unwrap();
    let mut b = Solver::new(&off.model(), &off.solver_settings()).unwrap();
    for v in [-0.05, -1e-3, 1e-5, 1e-3, 0.01, 0.05] {
        let (x, y) = (a.steady(v, 20_762.0), b.steady(v, 20_762.0));
        assert_eq!(x.status, Status::Converged);
        // The film does not depend on the friction: the same state.
        assert_eq!(x.h0, y.h0);
        assert_eq!(x.asperity_force, y.asperity_force);
        let term = x.asperity_force * mu_r * (v / v_a).asinh();
        assert_relative_eq!(
            x.friction_force - y.friction_force,
            term,
            max_relative = 1e-9
        );
        // The coefficient of friction counts it by magnitude.
        assert_relative_eq!(x.cof - y.cof, term.abs() / 20_762.0, max_relative = 1e-9);
    }
    // Well above v_a: a rise of μ_r times the asperity load per e-fold of speed.
    let (v1, v2) = (2e-3, 2e-3 * std::f64::consts::E);
    let (x1, x2) = (a.steady(v1, 20_762.0), a.steady(v2, 20_762.0));
    let (y1, y2) = (b.steady(v1, 20_762.0), b.steady(v2, 20_762.0));
    let rise = (x2.friction_force - y2.friction_force) - (x1.friction_force - y1.friction_force);
    let asp = 0.5 * (x1.asperity_force + x2.asperity_force);
    assert_relative_eq!(rise, mu_r * asp, max_relative = 2e-3);
}

#[test]
fn simulate_the_python_columns_and_a_recorded_node_carry_the_new_terms_bit_for_bit() {
    // simulate equals the solver stepped directly, with every term on.
    let sets = [
        "contact.presliding_stiffness_n_m=1e8",
        "contact.presliding_damping_n_s_m=50",
        "contact.width_load_exponent=0.5",
        "drivetrain.quadratic_n_s2_m2=300",
        "drivetrain.coulomb_asymmetry_n=40",
        "contact.boundary_friction_rate=0.01",
        "contact.boundary_activation_speed_m_s=1e-3",
    ];
    let c = config(&sets);
    let d = fresh_dir("drive", "simulate");
    let out = d.join("run.csv");
    let mut args = vec![
        "simulate",
        "--velocity",
        "sine:0,0.3,2",
        "--load",
        "sine:20000,5000,1",
        "--duration",
        "1",
    ];
    let owned: Vec<String> = std::iter::once("solver.cells=32".to_string())
        .chain(sets.iter().map(|s| s.to_string()))
        .collect();
    for s in &owned {
        args.extend(["--set", s.as_str()]);
    }
    args.extend(["--out", out.to_str().unwrap()]);
    let o = bin().args(&args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let mut s = Solver::new(&c.model(), &c.solver_settings()).unwrap();
    s.initialize_steady(0.0, 20_000.0);
    for (k, line) in text.lines().skip(1).enumerate() {
        let t = (k + 1) as f64 * c.solver.dt_s;
        let v = 0.3 * (std::f64::consts::TAU * 2.0 * t).sin();
        let f = 20_000.0 + 5000.0 * (std::f64::consts::TAU * t).sin();
        let e = s.step(v, f);
        let col: f64 = line.split(',').nth(7).unwrap().parse().unwrap();
        assert_eq!(col, e.friction_force, "row {k}");
    }
}

#[test]
#[cfg(all(feature = "mcap", feature = "iceoryx2"))]
fn a_node_recording_with_the_new_terms_replays_bit_identically() {
    let d = fresh_dir("drive", "node");
    let bag = d.join("lockstep.mcap");
    let base = format!("fn_drive_{}", std::process::id());
    let mut args: Vec<String> = vec![
        "run".into(),
        "--demo".into(),
        "0.5".into(),
        "--config".into(),
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/launch-config/lockstep-iceoryx2.yaml"
        )
        .into(),
    ];
    for s in [
        "solver.cells=64".to_string(),
        "contact.presliding_stiffness_n_m=1e8".into(),
        "contact.width_load_exponent=0.5".into(),
        "drivetrain.quadratic_n_s2_m2=300".into(),
        "drivetrain.coulomb_asymmetry_n=40".into(),
        "contact.boundary_friction_rate=0.01".into(),
        "contact.boundary_activation_speed_m_s=1e-3".into(),
        format!("iceoryx2.cmd_velocity_service={base}/cmd"),
        format!("iceoryx2.normal_load_service={base}/load"),
        format!("iceoryx2.friction_service={base}/friction"),
        format!("iceoryx2.cmd_event_service={base}/event"),
    ] {
        args.extend(["--set".into(), s]);
    }
    args.extend([
        "--record".into(),
        bag.display().to_string(),
        "--quiet".into(),
    ]);
    let o = bin().args(&args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = d.join("replayed.csv");
    let o = bin()
        .args([
            "replay",
            bag.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--expect-identical",
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(stdout.contains("bit-identical"), "{stdout}");
}

#[test]
fn negative_or_non_finite_terms_are_refused_naming_the_key() {
    for (set, key) in [
        (
            "contact.presliding_stiffness_n_m=-1",
            "contact.presliding_stiffness_n_m",
        ),
        (
            "contact.presliding_damping_n_s_m=.nan",
            "contact.presliding_damping_n_s_m",
        ),
        (
            "contact.width_load_exponent=1.5",
            "contact.width_load_exponent",
        ),
        (
            "contact.width_reference_load_n=0",
            "contact.width_reference_load_n",
        ),
        (
            "drivetrain.quadratic_n_s2_m2=-3",
            "drivetrain.quadratic_n_s2_m2",
        ),
        (
            "drivetrain.coulomb_asymmetry_n=.inf",
            "drivetrain.coulomb_asymmetry_n",
        ),
        (
            "contact.boundary_friction_rate=-0.01",
            "contact.boundary_friction_rate",
        ),
        (
            "contact.boundary_friction_rate=.nan",
            "contact.boundary_friction_rate",
        ),
        (
            "contact.boundary_activation_speed_m_s=0",
            "contact.boundary_activation_speed_m_s",
        ),
    ] {
        let e = Config::load(None, &[set.to_string()])
            .unwrap_err()
            .to_string();
        assert!(e.contains(key), "{set}: {e}");
        let o = bin()
            .args([
                "simulate",
                "--velocity",
                "const:0.1",
                "--duration",
                "0.01",
                "--set",
                set,
                "--out",
                "/dev/null",
            ])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{set}");
        assert!(String::from_utf8_lossy(&o.stderr).contains(key), "{set}");
    }
}

#[test]
fn fitting_a_presliding_key_on_data_without_a_reversal_warns_that_it_cannot_be_identified() {
    let d = fresh_dir("drive", "no-reversal");
    let data = d.join("oneway.csv");
    let mut csv = String::from("t_s,velocity_m_s,friction_n\n");
    for k in 0..400 {
        csv += &format!(
            "{},{},{}\n",
            k as f64 * 1e-3,
            0.1 + 0.05 * (k as f64 * 0.01).sin(),
            6200.0
        );
    }
    std::fs::write(&data, csv).unwrap();
    let o = bin()
        .args([
            "fit",
            data.to_str().unwrap(),
            "--fit",
            "contact.boundary_friction,contact.presliding_stiffness_n_m",
            "--bounds",
            "contact.presliding_stiffness_n_m=1e6:1e9",
            "--start",
            "contact.presliding_stiffness_n_m=1e7",
            "--starts",
            "1",
            "--global-points",
            "0",
            "--set",
            "solver.cells=16",
            "--out",
            d.join("f.yaml").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("contact.presliding_stiffness_n_m is fitted, but the training data hold no usable velocity reversal"),
        "{err}"
    );
}

#[test]
fn a_stiff_bristle_is_the_rigid_contact_without_sign_regularisation() {
    // The documented relation of `contact.sign_regularization_m_s` and the
    // bristle: the bristle's level takes the exact sign, so a stiff one
    // meets the rigid contact as v_reg → 0, not at the default v_reg.
    // σ0 = 1e15 N/m: the reversal takes 2L/σ0 ≈ 1e-11 m, far within the
    // first step's travel after it (≈ 6e-9 m at 1 mm/s, 1 kHz).
    let stiff = run(
        &config(&["contact.presliding_stiffness_n_m=1e15"]),
        1e-3,
        1000,
    );
    let sharp = run(
        &config(&["contact.sign_regularization_m_s=1e-8"]),
        1e-3,
        1000,
    );
    let smooth = run(
        &config(&["contact.sign_regularization_m_s=3e-4"]),
        1e-3,
        1000,
    );
    let mut worst_smooth: f64 = 0.0;
    for ((a, b), c) in stiff.iter().zip(&sharp).zip(&smooth) {
        if a.0.abs() < 1e-6 {
            continue; // at rest the bristle holds its force; the rigid contact has none
        }
        assert_relative_eq!(a.1, b.1, max_relative = 1e-6);
        worst_smooth = worst_smooth.max(((a.1 - c.1) / a.1).abs());
    }
    assert!(
        worst_smooth > 0.1,
        "v_reg = 3e-4 smooths a 1 mm/s motion visibly: {worst_smooth}"
    );
}

#[test]
fn with_presliding_what_acts_at_zero_speed_rides_on_the_bristle_the_drivetrains_coulomb_level_too()
{
    // The level mostly in the drivetrain (μ_bl = 0.01, F_c = 5 kN): before,
    // the bristle carried the contact's 200 N alone and F_c switched within
    // ±v_reg, so pre-sliding had almost nothing to act on.
    let base = [
        "contact.boundary_friction=0.01",
        "drivetrain.coulomb_n=5000",
    ];
    let rigid = run(&config(&base), 0.01, 700);
    let mut with = base.to_vec();
    with.push("contact.presliding_stiffness_n_m=2e8");
    let c = config(&with);
    let soft = run(&c, 0.01, 700);
    let rise = |r: &[(f64, f64)]| {
        r[480..600]
            .iter()
            .filter(|(_, f)| f.abs() < 0.8 * 5000.0)
            .count()
    };
    assert!(rise(&rigid) <= 4, "rigid: {}", rise(&rigid));
    assert!(
        rise(&soft) >= 4 * rise(&rigid).max(3),
        "the whole friction passes zero gradually: {} steps against {}",
        rise(&soft),
        rise(&rigid)
    );
    // Mid-stroke: the same sliding friction, and the contact's share is the
    // contact's own friction.
    assert_relative_eq!(rigid[250].1, soft[250].1, max_relative = 1e-3);
    let mut s = Solver::new(&c.model(), &c.solver_settings()).unwrap();
    s.initialize_steady(0.0, c.contact.load_n);
    let mut e = s.step(0.01, c.contact.load_n);
    for _ in 0..300 {
        e = s.step(0.01, c.contact.load_n);
    }
    assert_relative_eq!(
        e.friction_force,
        e.contact_friction_force + 5000.0,
        max_relative = 1e-6 // the bristle lags the drifting level by L/(σ0 v) = 2.6 ms
    );
    assert!(e.contact_friction_force > 0.0 && e.contact_friction_force < 0.1 * 5000.0);
}
