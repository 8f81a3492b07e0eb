//! Calibration on synthetic data: the fit recovers the parameters the data
//! were made with (ours, with drivetrain terms, and the classic models
//! their own), its standard errors cover the truth, the global phase is
//! reproducible; steady curves and mapped inputs (the O-ring seal's real
//! data, `data/oring-seal/`) fit too; bad input gets a clear message.
//! This file holds the shared helpers and the fits through the library:
//!
//! | file | job |
//! |---|---|
//! | `command_line.rs` | `fit` on the command line: outputs, errors, warnings |
//! | `oring_seal.rs` | the O-ring seal's real data, calibrated and predicted |

mod command_line;
#[path = "../common/mod.rs"]
mod common;
mod oring_seal;
use common::cli::run;

use friction_node::config::Config;
use friction_node::fit::driver::{fit, FitOutcome};
use friction_node::fit::options::Options;
use friction_node::fit::problem::Model;
use friction_node::fit::synthetic::{
    gaussian, model_friction, noisy_csv, two_amplitudes_two_loads,
};
use friction_node::fit::unknowns::DataScale;
use friction_node::fit::{
    Baseline, BaselineKind, Data, Delimiter, LoadForm, Mapping, ParamSpec, PhysicsModel, Source,
    Table,
};
use friction_node::physics::Solver;
use rand::rngs::StdRng;
use rand::SeedableRng;
use std::path::Path;

/// A reciprocating motion: two amplitudes and two loads, one quarter each.
fn motion(duration: f64, dt: f64) -> Vec<(f64, f64, f64)> {
    two_amplitudes_two_loads(duration, dt)
}

/// Friction of the transient model along `motion`, with white noise of
/// `rel` times its RMS, as CSV text `t_s,velocity_m_s,friction_n,load_n`.
fn synthetic_csv(config: &Config, motion: &[(f64, f64, f64)], rel: f64, seed: u64) -> String {
    noisy_csv(motion, &model_friction(config, motion).unwrap(), rel, seed)
}

fn data(csv: &str) -> Data {
    let table = Table::parse(csv, Path::new("synthetic.csv"), Delimiter::Auto, None, 0).unwrap();
    Data {
        train: vec![Source::new(table, &Mapping::default()).unwrap()],
        held_out: vec![],
        validate: vec![],
        holdout: Default::default(),
        units: Default::default(),
        map_names: vec![],
        map_values: vec![],
    }
}

fn scale(d: &Data) -> DataScale {
    let s = d.train[0].series(&[]).unwrap();
    DataScale {
        friction_n: s.friction.iter().fold(0.0, |m: f64, f| m.max(f.abs())),
        velocity_m_s: s.velocity.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
        load_min_n: s.load.unwrap().iter().fold(f64::INFINITY, |m, l| m.min(*l)),
        reversal_stiffness_n_m: None,
    }
}

fn coarse() -> Config {
    let mut c = Config::default();
    c.solver.cells = 32;
    c
}

fn specs(keys: &[&str]) -> Vec<ParamSpec> {
    keys.iter()
        .map(|k| ParamSpec {
            name: (*k).into(),
            ..Default::default()
        })
        .collect()
}

fn options(seed: u64) -> Options {
    Options {
        seed,
        ..Default::default()
    }
}

/// Every parameter within `tol` of the truth and inside its 95 % interval.
fn assert_recovered(o: &FitOutcome, truth: &[f64], tol: f64) {
    assert!(o.converged, "{:?}", o.optima[0].termination);
    for (j, p) in o.params.iter().enumerate() {
        let (est, t) = (o.best[j], truth[j]);
        assert!(
            ((est - t) / t).abs() < tol,
            "{}: {est} vs truth {t}",
            p.name
        );
        let (lo, hi) = o.statistics.interval95[j];
        assert!(
            (lo..=hi).contains(&t),
            "{}: the 95 % interval [{lo}, {hi}] (SE {}) misses the truth {t}",
            p.name,
            o.statistics.standard_error[j]
        );
    }
}

#[test]
fn the_fit_recovers_roughness_boundary_friction_and_viscosity_from_noisy_data_within_5_percent() {
    let mut truth = coarse();
    truth.roughness.sigma_m = 3.5e-6;
    truth.contact.boundary_friction = 0.22;
    truth.lubricant.viscosity_pa_s = 0.08;
    let d = data(&synthetic_csv(&truth, &motion(4.0, 1e-3), 0.02, 1));
    let keys = [
        "roughness.sigma_m",
        "contact.boundary_friction",
        "lubricant.viscosity_pa_s",
    ];
    // Start: the defaults (5 µm, 0.3, 0.0564 Pa·s).
    let model = PhysicsModel::new(&coarse(), &specs(&keys), &scale(&d)).unwrap();
    let o = fit(&model, &d, vec![], &options(1)).unwrap();
    assert_recovered(&o, &[3.5e-6, 0.22, 0.08], 0.05);
    // The residual is the noise: 2 % of the friction's RMS.
    assert!(
        o.statistics.sigma < 1.1 * 0.02 * 2100.0,
        "σ = {}",
        o.statistics.sigma
    );
}

#[test]
fn drivetrain_terms_and_the_contact_are_recovered_together_and_three_seeds_find_the_same_optimum() {
    let mut truth = coarse();
    truth.roughness.sigma_m = 3.5e-6;
    truth.contact.boundary_friction = 0.22;
    truth.drivetrain.coulomb_n = 300.0;
    truth.drivetrain.viscous_n_s_m = 800.0;
    let d = data(&synthetic_csv(&truth, &motion(4.0, 1e-3), 0.02, 2));
    let keys = [
        "roughness.sigma_m",
        "contact.boundary_friction",
        "drivetrain.coulomb_n",
        "drivetrain.viscous_n_s_m",
    ];
    let model = PhysicsModel::new(&coarse(), &specs(&keys), &scale(&d)).unwrap();
    let truth_x = [3.5e-6, 0.22, 300.0, 800.0];
    let mut bests = Vec::new();
    for seed in [1, 2, 3] {
        let o = fit(&model, &d, vec![], &options(seed)).unwrap();
        assert_recovered(&o, &truth_x, 0.05);
        bests.push(o.best);
    }
    for b in &bests[1..] {
        for (x, y) in b.iter().zip(&bests[0]) {
            assert!(((x - y) / y).abs() < 1e-3, "{b:?} vs {:?}", bests[0]);
        }
    }
}

/// Data of a classic model with `x`, 1 % noise.
fn classic_csv(model: &Baseline, x: &[f64]) -> String {
    let m = motion(4.0, 1e-3);
    let mut csv = String::from("t_s,velocity_m_s,friction_n,load_n\n");
    for &(t, v, l) in &m {
        csv += &format!("{t},{v},0,{l}\n");
    }
    let d = data(&csv);
    let s = d.train[0].series(&[]).unwrap();
    let f = model.predict(x, &s).unwrap();
    let rms = (f.iter().map(|x| x * x).sum::<f64>() / f.len() as f64).sqrt();
    let mut rng = StdRng::seed_from_u64(5);
    let mut out = String::from("t_s,velocity_m_s,friction_n,load_n\n");
    for (k, &(t, v, l)) in m.iter().enumerate() {
        out += &format!("{t},{v},{},{l}\n", f[k] + gaussian(&mut rng, 0.01 * rms));
    }
    out
}

#[test]
fn each_classic_model_recovers_its_own_parameters() {
    let sc = DataScale {
        friction_n: 3000.0,
        velocity_m_s: 1.0,
        load_min_n: 10_000.0,
        reversal_stiffness_n_m: None,
    };
    let cases: [(BaselineKind, Vec<f64>); 3] = [
        (BaselineKind::CoulombViscous, vec![100.0, 0.05, 400.0]),
        (
            BaselineKind::Stribeck,
            vec![100.0, 0.05, 200.0, 0.07, 0.05, 400.0],
        ),
        (
            BaselineKind::LuGre,
            vec![100.0, 0.05, 200.0, 0.07, 0.05, 400.0, 1e7, 2000.0],
        ),
    ];
    for (kind, truth) in cases {
        // Loads vary: the load-linear forms.
        let m = Baseline::new(kind, LoadForm::Linear, &sc, 1000.0);
        let d = data(&classic_csv(&m, &truth));
        // The command gives the classic models ten times the budget too.
        let opts = Options {
            max_evaluations: 2000,
            ..options(1)
        };
        let o = fit(&m, &d, vec![], &opts).unwrap();
        assert!(o.converged, "{kind:?}: {}", o.optima[0].termination);
        for (j, p) in o.params.iter().enumerate() {
            // σ₁ is seen only in the few milliseconds after reversals.
            let tol = if p.name.starts_with("sigma1") {
                0.25
            } else {
                0.05
            };
            assert!(
                ((o.best[j] - truth[j]) / truth[j]).abs() < tol,
                "{kind:?} {}: {} vs {}",
                p.name,
                o.best[j],
                truth[j]
            );
        }
    }
}

/// A fresh directory for test `name`.
fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("fit", name)
}

#[test]
fn a_steady_stribeck_curve_recovers_roughness_and_boundary_friction_and_viscosity() {
    // A tribometer's Stribeck curve: steady points, no time column, two
    // loads, 1 % noise.
    let mut truth = coarse();
    truth.roughness.sigma_m = 3.5e-6;
    truth.contact.boundary_friction = 0.22;
    truth.lubricant.viscosity_pa_s = 0.08;
    let mut solver = Solver::new(&truth.model(), &truth.solver_settings()).unwrap();
    let mut rng = StdRng::seed_from_u64(7);
    let mut csv = String::from("velocity_m_s,friction_n,load_n\n");
    for load in [10_000.0, 20_000.0] {
        for k in 0..24 {
            let v = 0.01 * 10f64.powf(k as f64 / 8.0); // 0.01 … 9 m/s
            let e = solver.steady(v, load);
            assert!(e.status.is_converged());
            let f = e.friction_force * (1.0 + gaussian(&mut rng, 0.01));
            csv += &format!("{v},{f},{load}\n");
        }
    }
    let d = data(&csv);
    assert!(d.train[0].is_steady(), "no time column: a steady curve");
    let keys = [
        "roughness.sigma_m",
        "contact.boundary_friction",
        "lubricant.viscosity_pa_s",
    ];
    let model = PhysicsModel::new(&coarse(), &specs(&keys), &scale(&d)).unwrap();
    let o = fit(&model, &d, vec![], &options(1)).unwrap();
    assert_recovered(&o, &[3.5e-6, 0.22, 0.08], 0.05);
}

#[test]
fn secant_jacobians_reach_the_optimum_of_finite_differences() {
    // How many simulations each takes is a benchmark's question
    // (docs/bench-fit-speed.sh, docs/bench-emps-fit-speed.sh): on this
    // 4 s record the secant run takes about as many as differences.
    use friction_node::fit::options::JacobianRule;
    let mut truth = coarse();
    truth.roughness.sigma_m = 3.5e-6;
    truth.contact.boundary_friction = 0.22;
    truth.drivetrain.coulomb_n = 300.0;
    truth.drivetrain.viscous_n_s_m = 800.0;
    let d = data(&synthetic_csv(&truth, &motion(4.0, 1e-3), 0.02, 2));
    let keys = [
        "roughness.sigma_m",
        "contact.boundary_friction",
        "drivetrain.coulomb_n",
        "drivetrain.viscous_n_s_m",
    ];
    let model = PhysicsModel::new(&coarse(), &specs(&keys), &scale(&d)).unwrap();
    let with = |jacobian| {
        let o = Options {
            jacobian,
            starts: 1,
            ..options(1)
        };
        fit(&model, &d, vec![], &o).unwrap()
    };
    let (exact, secant) = (with(JacobianRule::Differences), with(JacobianRule::Secant));
    assert!(exact.converged && secant.converged);
    approx::assert_relative_eq!(secant.train_rms, exact.train_rms, max_relative = 1e-6);
    for (s, e) in secant.best.iter().zip(&exact.best) {
        approx::assert_relative_eq!(*s, *e, max_relative = 1e-3);
    }
}
