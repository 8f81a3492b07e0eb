//! The C API's cost over the Rust step: two identical models on the paper's
//! reciprocating case (the default grid and flux, 1 kHz, V1 = 1 m/s, f = 1 Hz), one stepped
//! through `Solver::step`, one through `fn_model_step`, alternately, every
//! step timed; the overhead is the median of the per-step differences (same
//! states, same work), beside both medians.
//!
//! ```sh
//! cargo run --release -p friction-node-capi --example bench_capi [CYCLES]
//! ```

use friction_node::config::Config;
use friction_node::physics::Solver;
use friction_node_c::{
    fn_model_dt, fn_model_free, fn_model_new_from_yaml, fn_model_step, FnEstimate,
};
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let cycles: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let config = Config::load(None, &[]).unwrap();
    let load = config.contact.load_n;
    let mut rust = Solver::new(&config.model(), &config.solver_settings()).unwrap();
    rust.initialize_steady(0.0, load);
    let mut c = std::ptr::null_mut();
    let empty = c"";
    assert_eq!(unsafe { fn_model_new_from_yaml(empty.as_ptr(), &mut c) }, 0);
    let dt = unsafe { fn_model_dt(c) };
    let steps = cycles * (1.0 / dt).round() as usize;
    let (mut tr, mut tc, mut diff) = (
        Vec::with_capacity(steps),
        Vec::with_capacity(steps),
        Vec::with_capacity(steps),
    );
    let mut e = FnEstimate::default();
    for k in 1..=steps {
        let v = (2.0 * std::f64::consts::PI * k as f64 * dt).sin();
        let (r_ns, c_ns);
        if k % 2 == 0 {
            let t = Instant::now();
            black_box(rust.step(black_box(v), load));
            r_ns = t.elapsed().as_nanos() as i64;
            let t = Instant::now();
            unsafe { fn_model_step(c, black_box(v), load, dt, &mut e) };
            c_ns = t.elapsed().as_nanos() as i64;
        } else {
            let t = Instant::now();
            unsafe { fn_model_step(c, black_box(v), load, dt, &mut e) };
            c_ns = t.elapsed().as_nanos() as i64;
            let t = Instant::now();
            black_box(rust.step(black_box(v), load));
            r_ns = t.elapsed().as_nanos() as i64;
        }
        black_box(&e);
        tr.push(r_ns);
        tc.push(c_ns);
        diff.push(c_ns - r_ns);
    }
    unsafe { fn_model_free(c) };
    let median = |v: &mut Vec<i64>| {
        v.sort_unstable();
        v[v.len() / 2]
    };
    let (mr, mc, md) = (median(&mut tr), median(&mut tc), median(&mut diff));
    println!(
        "{steps} steps at N = {}: Rust step median {:.2} µs, C API step median {:.2} µs, \
         C API overhead (median of paired differences) {md} ns",
        config.solver.cells,
        mr as f64 / 1e3,
        mc as f64 / 1e3
    );
}
