//! Cross-checks between solvers and the inertia claims of docs/model.md §9.

use approx::assert_relative_eq;
use friction_node::analysis::{cycle_metrics, LoopSample};
use friction_node::physics::*;
use std::f64::consts::PI;

const LOAD: f64 = 20_762.0;

fn run(
    model: &ModelParams,
    st: &SolverSettings,
    v: impl Fn(f64) -> f64,
    steps: usize,
) -> Vec<Estimate> {
    let mut s = Solver::new(model, st).unwrap();
    s.initialize_steady(v(0.0), LOAD);
    (1..=steps)
        .map(|k| s.step(v(k as f64 * st.dt), LOAD))
        .collect()
}

#[test]
fn newton_and_reference_solvers_agree_on_a_small_case() {
    let model = ModelParams::default();
    // The reference solver has the upwind flux only: compare like with like.
    let newton = SolverSettings {
        cells: 32,
        flux: CouetteFlux::Upwind,
        ..Default::default()
    };
    // The reference's own tolerances (paper: 1e-4) would dominate the
    // comparison; tighten them so that discretisation differences show.
    let reference = SolverSettings {
        method: Method::Reference,
        reference: ReferenceSettings {
            fluid_tolerance: 1e-7,
            motion_tolerance: 1e-7,
            max_fluid_iterations: 50_000,
            ..Default::default()
        },
        ..newton
    };
    let v = |t: f64| 0.1 * (2.0 * PI * 2.0 * t).sin();
    let a = run(&model, &newton, v, 100);
    let b = run(&model, &reference, v, 100);
    let (mut dh, mut df, mut dfh) = (0.0f64, 0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.status, Status::Converged);
        assert_eq!(y.status, Status::Converged, "reference at t = {}", y.time);
        dh = dh.max((x.h0 - y.h0).abs() / x.h0);
        df = df.max((x.friction_force - y.friction_force).abs() / (0.3 * LOAD));
        dfh = dfh.max((x.hydrodynamic_force - y.hydrodynamic_force).abs() / LOAD);
    }
    eprintln!("newton vs reference: max rel. h0 {dh:.2e}, friction {df:.2e} of mu_bl F, F_hyd {dfh:.2e} of F_ext");
    // What remains is the paper's central Couette differencing against our
    // upwinded density (N = 32).
    assert!(dh < 5e-5, "h0 differs by {dh:e}");
    assert!(df < 1e-3, "friction differs by {df:e}");
    assert!(dfh < 1e-3, "F_hyd differs by {dfh:e}");
    // The reference algorithm is far more work per step.
    let inner: u32 = b.iter().map(|e| e.diagnostics.inner_iterations).sum();
    assert!(inner > 100 * 100);
}

fn reciprocating(mass: f64, f: f64, cells: usize, cycles: usize) -> (f64, f64) {
    let mut model = ModelParams::default();
    model.contact.mass = mass;
    model.lubricant.viscosity = 0.0564;
    let st = SolverSettings {
        cells,
        ..Default::default()
    };
    let steps = (cycles as f64 / f / st.dt).round() as usize;
    let est = run(&model, &st, |t| 1.0 * (2.0 * PI * f * t).sin(), steps);
    let samples: Vec<LoopSample> = est.iter().map(LoopSample::from).collect();
    let m = cycle_metrics(&samples, 0.0, 1.0 / f, mass, 6);
    let last = m.last().unwrap();
    (last.inertia_share, last.inertia_share_smooth)
}

#[test]
fn inertia_share_is_proportional_to_mass() {
    let (raw1, smooth1) = reciprocating(1.0, 1.0, 64, 3);
    let (raw10, smooth10) = reciprocating(10.0, 1.0, 64, 3);
    eprintln!(
        "M(m=1) = {raw1:.3e} (smooth {smooth1:.3e}); M(m=10) = {raw10:.3e} (smooth {smooth10:.3e})"
    );
    assert_relative_eq!(raw10 / raw1, 10.0, max_relative = 1e-3);
    assert_relative_eq!(smooth10 / smooth1, 10.0, max_relative = 1e-3);
    // The paper's range: 1e-6 % … 1e-3 %.
    assert!(raw1 > 1e-8 && raw1 < 1e-5, "M = {raw1:e}");
}

#[test]
fn smooth_inertia_share_scales_with_frequency_squared() {
    // The smooth part (6 harmonics of h0 over the cycle) scales as f²; the raw
    // maximum sits on the vapour-pocket collapse spike and does not (docs/model.md §9).
    let f = [0.5, 1.0, 2.0];
    let m: Vec<(f64, f64)> = f.iter().map(|&f| reciprocating(1.0, f, 64, 3)).collect();
    let slope = |a: f64, b: f64, fa: f64, fb: f64| (b / a).ln() / (fb / fa).ln();
    let s_smooth: Vec<f64> = (0..2)
        .map(|i| slope(m[i].1, m[i + 1].1, f[i], f[i + 1]))
        .collect();
    let s_raw: Vec<f64> = (0..2)
        .map(|i| slope(m[i].0, m[i + 1].0, f[i], f[i + 1]))
        .collect();
    eprintln!("log-log slope of M against f: smooth {s_smooth:?}, raw {s_raw:?}");
    for s in &s_smooth {
        assert!((1.7..2.3).contains(s), "smooth slopes {s_smooth:?}");
    }
}

#[test]
fn a_time_step_stops_when_the_estimated_error_left_is_within_the_tolerance() {
    // Newton ends a step on K‖Δ‖² ≤ tol (module doc of the solver): the
    // state it returns must be that close to a tightly converged one, and
    // most steps of smooth motion must take one iteration. (Measured at
    // N = 128: h0 6.1e-9, p 6.7e-6 · max p, friction 2.7e-8 · load; 92 %
    // of steps in one iteration.)
    let tol = 1e-6;
    let mk = |tolerance| {
        let st = SolverSettings {
            cells: 128,
            tolerance,
            ..Default::default()
        };
        let mut s = Solver::new(&ModelParams::default(), &st).unwrap();
        s.initialize_steady(0.0, 5762.0);
        s
    };
    let (mut loose, mut tight) = (mk(tol), mk(1e-12));
    let (mut worst_h0, mut worst_p, mut worst_f, mut one_iteration) = (0.0f64, 0.0f64, 0.0f64, 0);
    let steps = 1500;
    for k in 1..=steps {
        let v = (2.0 * PI * k as f64 * 1e-3).sin();
        let a = loose.step(v, 5762.0);
        let b = tight.step(v, 5762.0);
        assert_eq!(a.status, Status::Converged);
        assert_eq!(b.status, Status::Converged);
        worst_h0 = worst_h0.max((a.h0 - b.h0).abs() / b.h0);
        let pmax = tight.pressure().iter().fold(1e5f64, |m, p| m.max(p.abs()));
        for (pa, pb) in loose.pressure().iter().zip(tight.pressure()) {
            worst_p = worst_p.max((pa - pb).abs() / pmax);
        }
        worst_f = worst_f.max((a.friction_force - b.friction_force).abs() / 5762.0);
        one_iteration += (a.diagnostics.iterations == 1) as usize;
    }
    assert!(worst_h0 <= tol, "h0: {worst_h0:e}");
    assert!(worst_p <= 10.0 * tol, "p: {worst_p:e}");
    assert!(worst_f <= tol, "friction / load: {worst_f:e}");
    assert!(
        one_iteration * 10 >= steps * 7,
        "{one_iteration} of {steps} steps took one iteration"
    );
}

/// The iterations of every step of one reciprocating cycle (v = sin 2πt,
/// the second cycle) under `load` on `cells` cells with `flux`, with each
/// step's friction.
fn cycle_iterations(load: f64, tolerance: f64, cells: usize, flux: CouetteFlux) -> Vec<(u32, f64)> {
    let st = SolverSettings {
        tolerance,
        cells,
        flux,
        ..Default::default()
    };
    let mut s = Solver::new(&ModelParams::default(), &st).unwrap();
    s.initialize_steady(0.0, load);
    (1..=2000)
        .map(|k| {
            let e = s.step((2.0 * PI * k as f64 * st.dt).sin(), load);
            assert_eq!(e.status, Status::Converged, "step {k}");
            assert_eq!(e.diagnostics.substeps, 0, "step {k}");
            (e.diagnostics.iterations, e.friction_force)
        })
        .skip(1000)
        .collect()
}

#[test]
fn a_vapour_pocket_collapse_takes_at_most_five_newton_iterations_and_one_more_with_the_muscl_flux()
{
    // Once per half cycle, at |v| ≈ 0.4 m/s, the pocket of vapour in the
    // converging part of the film collapses and the pressure there jumps
    // (0.47 → 0.91 MPa at 20.8 kN). Newton crawled across the EOS's steep
    // transition (9 iterations at 20.8 kN, 10 at 10 kN) and, from the
    // predictor's extrapolation of the jump (absolute pressures below
    // zero), took 12 at 5 kN. The vapour-fraction map of large updates and
    // the restart from the previous state brought that to 7, 8 and 5; the
    // predictor's guard, which keeps a falling liquid cell from being
    // extrapolated into the vapour, to 5, 5 and 5.
    // Upwind at N = 256: at most 5, at least 900 of the cycle's 1000 steps
    // in one iteration. Measured (worst / one-iteration steps at 20.8, 10,
    // 5 kN): upwind N = 256 5 5 5 / 900 906 922, upwind N = 64 6 5 5 /
    // 896 908 914, MUSCL N = 256 5 6 6 / 890 904 918, MUSCL N = 64 (the
    // default) 6 5 5 / 864 900 914: at most one more, on either flux.
    for (cells, flux, worst_bound, one_bound) in [
        (256, CouetteFlux::Upwind, 5, 900),
        (64, CouetteFlux::Upwind, 6, 850),
        (256, CouetteFlux::default(), 6, 850),
        (64, CouetteFlux::default(), 6, 850),
    ] {
        for load in [20_762.0, 10_000.0, 5_000.0] {
            let its = cycle_iterations(load, 1e-6, cells, flux);
            let worst = its.iter().map(|x| x.0).max().unwrap();
            let one = its.iter().filter(|x| x.0 == 1).count();
            let case = format!("N = {cells}, {flux:?}, {load} N");
            assert!(worst <= worst_bound, "{case}: {worst} iterations");
            assert!(
                one >= one_bound,
                "{case}: {one} of 1000 steps in one iteration"
            );
        }
    }
}

#[test]
fn the_map_and_the_restart_leave_the_converged_friction_within_the_tolerance() {
    // Tightly converged (tolerance 1e-12) against the default tolerance,
    // through the collapses: the default-tolerance answer stays within
    // 1e-6 of the load (measured: 2e-8 · load).
    for load in [10_000.0, 5_000.0] {
        let loose = cycle_iterations(load, 1e-6, 256, CouetteFlux::Upwind);
        let tight = cycle_iterations(load, 1e-12, 256, CouetteFlux::Upwind);
        let worst = loose
            .iter()
            .zip(&tight)
            .map(|(a, b)| (a.1 - b.1).abs() / load)
            .fold(0.0, f64::max);
        assert!(worst <= 1e-6, "{load} N: |ΔF|/load {worst:e}");
    }
}

#[test]
fn no_step_of_the_most_viscous_4_hz_study_case_takes_more_than_eleven_iterations() {
    // μ = 0.143 Pa·s, 4 Hz, 1 m/s, 20 762 N (the viscosity study's hardest
    // case), three cycles: at |v| ≈ 0.85 m/s a cell at the cavitation edge
    // made Newton cycle (update sizes 0.08 → 0.35 → 0.17 → 0.08, three
    // times, 18 iterations) while an update after a damped one was taken
    // untested; tested, the step takes 11.
    let mut m = ModelParams::default();
    m.lubricant.viscosity = 0.143;
    let st = SolverSettings::default();
    let mut s = Solver::new(&m, &st).unwrap();
    s.initialize_steady(0.0, 20_762.0);
    let mut worst = 0;
    for k in 0..750 {
        let e = s.step((2.0 * PI * 4.0 * k as f64 * st.dt).sin(), 20_762.0);
        assert_eq!(e.status, Status::Converged, "step {k}");
        worst = worst.max(e.diagnostics.iterations);
    }
    assert!(worst <= 11, "{worst} iterations");
}
