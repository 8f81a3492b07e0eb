//! The coefficient of friction is the friction the contact transmits per
//! unit load: the paper's sliding COF for the rigid contact, the bristle's
//! force with pre-sliding; its one-sided limits at v = 0 are not biased by
//! the boundary rate's steep asinh.

use approx::assert_relative_eq;
use friction_node::analysis::{cycle_metrics, LoopSample};
use friction_node::config::Config;
use friction_node::physics::{Estimate, Solver, Status};

fn config(sets: &[&str]) -> Config {
    let mut all = vec!["solver.cells=32".to_string()];
    all.extend(sets.iter().map(|s| s.to_string()));
    Config::load(None, &all).unwrap()
}

/// Estimates along v = A sin 2πft from the steady state at rest, for `s` seconds.
fn run(c: &Config, amplitude: f64, f: f64, seconds: f64) -> Vec<Estimate> {
    let mut s = Solver::new(&c.model(), &c.solver_settings()).unwrap();
    s.initialize_steady(0.0, c.contact.load_n);
    let steps = (seconds / c.solver.dt_s).round() as usize;
    (1..=steps)
        .map(|k| {
            let t = k as f64 * c.solver.dt_s;
            let e = s.step(
                amplitude * (std::f64::consts::TAU * f * t).sin(),
                c.contact.load_n,
            );
            assert_eq!(e.status, Status::Converged, "step {k}");
            e
        })
        .collect()
}

fn last_cycle(es: &[Estimate], f: f64) -> friction_node::analysis::LoopMetrics {
    let samples: Vec<LoopSample> = es.iter().map(LoopSample::from).collect();
    let m = cycle_metrics(&samples, 0.0, 1.0 / f, 1.0, 4);
    m.last().cloned().expect("a complete cycle")
}

#[test]
fn with_presliding_the_cof_is_the_transmitted_force_per_unit_load() {
    // The case: 1 cm/s, 1 Hz, σ0 = 2e7 N/m.
    let soft = run(
        &config(&["contact.presliding_stiffness_n_m=2e7"]),
        0.01,
        1.0,
        3.0,
    );
    for e in &soft {
        assert_relative_eq!(
            e.cof,
            e.contact_friction_force.abs() / e.load,
            max_relative = 1e-12
        );
    }
    // Just after the reversal at t = 2.5 s (t = 2.501 s, v < 0) the bristle
    // still transmits the old direction's force (the issue's +6 223 N);
    // over the next ~0.1 s (a displacement of about ln 2 · L/σ0) it passes
    // zero, and so does the COF, where the rigid contact's stays near μ_bl.
    let k = 2500;
    assert!(soft[k].velocity < 0.0 && soft[k].contact_friction_force > 0.0);
    let min_in = |es: &[Estimate]| {
        es[2500..2700]
            .iter()
            .map(|e| e.cof)
            .fold(f64::INFINITY, f64::min)
    };
    let rigid = run(&config(&[]), 0.01, 1.0, 3.0);
    assert!(min_in(&soft) < 0.01, "{}", min_in(&soft));
    assert!(min_in(&rigid) > 0.25, "{}", min_in(&rigid));
    // The COF loop now has the area the friction loop has.
    let (ms, mr) = (last_cycle(&soft, 1.0), last_cycle(&rigid, 1.0));
    assert!(
        ms.cof_loop_area > 100.0 * mr.cof_loop_area,
        "COF loop area {} (pre-sliding) vs {} (rigid)",
        ms.cof_loop_area,
        mr.cof_loop_area
    );
    // |F| folds each lobe's sign change: the COF loop encloses part of the
    // friction loop's area per unit load (measured 0.38 of it), not none.
    let ratio = ms.cof_loop_area / (ms.friction_loop_area / soft[0].load);
    assert!((0.2..=1.0).contains(&ratio), "{ratio}");
}

#[test]
fn the_rigid_cof_is_the_papers_sliding_cof() {
    let c = config(&[]);
    for e in run(&c, 0.5, 1.0, 1.0) {
        let expect =
            (e.viscous_force.abs() + c.contact.boundary_friction * e.asperity_force) / e.load;
        assert_eq!(e.cof.to_bits(), expect.to_bits(), "t = {}", e.time);
        assert_eq!(e.boundary_rate_cof, 0.0);
    }
}

#[test]
fn in_steady_sliding_a_stiff_bristles_cof_is_the_rigid_cof() {
    let rigid = config(&[]);
    let soft = config(&["contact.presliding_stiffness_n_m=1e12"]);
    for v in [-0.3, 0.01, 0.2] {
        let a = Solver::new(&rigid.model(), &rigid.solver_settings())
            .unwrap()
            .steady(v, rigid.contact.load_n);
        let b = Solver::new(&soft.model(), &soft.solver_settings())
            .unwrap()
            .steady(v, soft.contact.load_n);
        assert_relative_eq!(a.cof, b.cof, max_relative = 1e-9);
    }
}

#[test]
fn with_the_boundary_rate_on_a_symmetric_sine_shows_no_cof_hysteresis_at_rest() {
    // The rate's part of the COF is 0 at v = 0 and steep near it: it must
    // not decide the one-sided limits (before: 0.3053 vs 0.2986).
    let c = config(&[
        "contact.boundary_friction_rate=0.01",
        "contact.boundary_activation_speed_m_s=1e-4",
    ]);
    let es = run(&c, 0.05, 1.0, 3.0);
    for e in &es {
        let expect = 0.01 * (e.velocity.abs() / 1e-4).asinh() * e.asperity_force / e.load;
        assert_relative_eq!(e.boundary_rate_cof, expect, max_relative = 1e-12);
    }
    let m = last_cycle(&es, 1.0);
    let (acc, dec) = (
        m.cof_v0_accelerating.unwrap(),
        m.cof_v0_decelerating.unwrap(),
    );
    // The rigid contact's limits without the rate term, for scale.
    let plain = last_cycle(&run(&config(&[]), 0.05, 1.0, 3.0), 1.0);
    let plain_gap = (plain.cof_v0_accelerating.unwrap() - plain.cof_v0_decelerating.unwrap()).abs();
    assert!(
        (acc - dec).abs() <= plain_gap + 2e-4,
        "accelerating {acc} vs decelerating {dec} (without the rate: gap {plain_gap})"
    );
    assert_relative_eq!(acc, plain.cof_v0_accelerating.unwrap(), max_relative = 0.01);
}

/// Every shape of the estimate that users read states the COF with the one
/// definition (`physics::terms::COF_DEFINITION`), and no file of the
/// project states the stale rigid-only formula (the layouts of bags
/// recorded before, in `src/msgs/legacy/`, keep the text they were recorded
/// with).
#[test]
fn the_cof_definition_is_written_once_and_every_shape_of_the_estimate_carries_it() {
    use friction_node::physics::terms::COF_DEFINITION;
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for file in [
        "msg/msg/FrictionEstimate.msg",
        "capi/include/friction_node.h",
        "capi/src/codes.rs",
        "src/msgs/wire.rs",
        "src/msgs/records.rs",
        "src/transport/iceoryx/payloads.rs",
        "src/physics/estimate.rs",
        "python/src/model.rs",
        "python/friction_node/_core.pyi",
    ] {
        let text = std::fs::read_to_string(root.join(file)).unwrap();
        let text = text.replace("\\|", "|");
        assert!(
            text.contains(COF_DEFINITION),
            "{file} does not state the COF as physics::terms::COF_DEFINITION"
        );
    }
    // Spelt in two halves, so that this file does not hold them whole.
    let stale = [
        concat!("mu_bl F_asp)", " / F_ext"),
        concat!("μ_bl F_asp)", " / F_ext"),
    ];
    let mut found = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap().map(Result::unwrap) {
            let p = e.path();
            let rel = p.strip_prefix(root).unwrap().to_string_lossy().into_owned();
            if [
                ".git",
                "target",
                "out",
                "fuzz",
                "data",
                "src/msgs/legacy",
                "bags",
            ]
            .iter()
            .any(|s| rel == *s)
            {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
            } else if let Ok(text) = std::fs::read_to_string(&p) {
                if stale.iter().any(|s| text.contains(s)) {
                    found.push(rel);
                }
            }
        }
    }
    assert!(found.is_empty(), "the stale COF formula in {found:?}");
}
