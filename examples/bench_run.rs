//! The Rust side of the Python `Model.run` benchmark: the same run through
//! the Rust API (steady state at the first sample, then one `step` per
//! sample, every estimate kept in columns as `Model.run` keeps them), timed
//! over repetitions. Prints one line per repetition: `rust_run_s <seconds>`.
//!
//! `cargo run --release --example bench_run -- SECONDS REPEATS [CELLS]`
//! (python/benchmarks/bench_package.py runs it beside `Model.run`).

use friction_node::config::Config;
use friction_node::physics::Solver;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seconds: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(60.0);
    let repeats: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(5);
    let mut overrides = Vec::new();
    if let Some(c) = args.get(3) {
        overrides.push(format!("solver.cells={c}"));
    }
    let config = Config::load(None, &overrides).expect("the default configuration");
    let dt = config.solver.dt_s;
    let n = (seconds / dt).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let v: Vec<f64> = t
        .iter()
        .map(|t| (2.0 * std::f64::consts::PI * t).sin())
        .collect();
    let load = config.contact.load_n;
    for _ in 0..repeats {
        let started = Instant::now();
        let mut solver = Solver::new(&config.model(), &config.solver_settings()).expect("a solver");
        let mut columns: Vec<Vec<f64>> = (0..19).map(|_| Vec::with_capacity(n)).collect();
        let e = solver.initialize_steady(v[0], load);
        columns[0].push(e.friction_force);
        for k in 1..n {
            let e = solver.step(v[k], load);
            let row = [
                t[k],
                e.velocity,
                e.load,
                e.h0,
                e.h_min,
                e.hydrodynamic_force,
                e.asperity_force,
                e.friction_force,
                e.cof,
                e.viscous_force,
                e.asperity_load_share,
                e.inertia_force,
                e.diagnostics.residual,
                e.diagnostics.load_residual,
                e.max_pressure,
                e.cavitated_fraction,
                e.contact_area_ratio,
                0.0,
                e.contact_friction_force,
            ];
            for (c, x) in columns.iter_mut().zip(row) {
                c.push(x);
            }
        }
        std::hint::black_box(&columns);
        println!("rust_run_s {}", started.elapsed().as_secs_f64());
    }
}
