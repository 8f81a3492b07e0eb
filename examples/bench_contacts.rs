//! Several contacts stepped together at a fixed rate: the compute time per
//! period (all contacts) and the deadline misses, with 0..=W workers side
//! by side in one run.
//!
//! ```sh
//! cargo run --release --example bench_contacts -- [CONTACTS [CELLS [SECONDS [MAX_WORKERS [CPU...]]]]]
//! ```
//! Defaults: 8 contacts, 256 cells, 10 s per worker count, workers 0 and 1.
//! CPU...: the loop's CPU then each worker's (pinned when given).
//! `SPIN_US=N` in the environment busy-waits the last N µs before each
//! deadline, as the node's `node.timer_spin_us` does (≥ 1000: never sleep).
//! Every
//! contact follows v = sin 2π(t + i/8) m/s under its own load. Run the
//! empty 1 kHz loop, `cargo run --release --example timer_baseline --
//! SECONDS`, in the same minute to read the misses.

use friction_node::clock::{Clock, SystemClock};
use friction_node::config::{Config, Origin, RealtimeConfig};
use friction_node::contacts::ContactSet;
use std::sync::Arc;

/// Pin the calling thread with the node's own real-time helper.
fn pin(cpu: Option<usize>) {
    if let Some(cpu) = cpu {
        let rt = RealtimeConfig {
            cpu: cpu as i32,
            ..RealtimeConfig::default()
        };
        let (_, warnings) = friction_node::node::rt::apply(&rt);
        for w in warnings {
            eprintln!("warning: {w}");
        }
    }
}

fn pct(sorted: &[u64], p: f64) -> f64 {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i] as f64 / 1e3
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: f64| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (n, cells, seconds, max_workers) = (
        arg(0, 8.0) as usize,
        arg(1, 256.0) as usize,
        arg(2, 10.0),
        arg(3, 1.0) as usize,
    );
    let cpus: Vec<usize> = a.iter().skip(4).filter_map(|s| s.parse().ok()).collect();
    let spin_ns: u64 = std::env::var("SPIN_US")
        .ok()
        .and_then(|s| s.parse::<u64>().ok())
        .unwrap_or(0)
        .saturating_mul(1000);
    let mut yaml =
        format!("/**:\n  ros__parameters:\n    solver: {{cells: {cells}}}\n    contacts:\n");
    for i in 0..n {
        yaml += &format!(
            "      c{i}: {{contact: {{load_n: {}}}}}\n",
            10_000.0 + 1_000.0 * i as f64
        );
    }
    let config = Config::from_yaml(&yaml, &Origin::Embedded, &[]).expect("config");
    let clock: Arc<dyn Clock> = Arc::new(SystemClock::new());
    pin(cpus.first().copied());
    println!(
        "{n} contacts, N = {cells}, 1 kHz, {seconds} s per run, spin {} µs",
        spin_ns / 1000
    );
    for workers in 0..=max_workers.min(n.saturating_sub(1)) {
        let worker_cpus = cpus.clone();
        let mut set = ContactSet::new(
            &config,
            workers,
            200_000,
            clock.clone(),
            Arc::new(move |k| pin(worker_cpus.get(k).copied())),
        )
        .expect("contact set");
        let periods = (seconds * 1000.0) as u64;
        let (mut compute, mut slowest) = (Vec::with_capacity(periods as usize), Vec::new());
        slowest.reserve(periods as usize);
        let mut v = vec![0.0; n];
        let loads = vec![10_000.0; n];
        let (t0, mut misses) = (clock.now_ns() + 1_000_000, 0u64);
        for k in 0..periods {
            let deadline = t0 + k * 1_000_000;
            clock.sleep_until_ns(deadline.saturating_sub(spin_ns));
            clock.spin_until_ns(deadline);
            let t = k as f64 * 1e-3;
            for (i, x) in v.iter_mut().enumerate() {
                *x = (2.0 * std::f64::consts::PI * (t + i as f64 / 8.0)).sin();
            }
            let start = clock.now_ns();
            let timing = set.step(&v, &loads, None);
            let end = clock.now_ns();
            compute.push(end - start);
            slowest.push(timing.slowest_ns);
            if end > deadline + 1_000_000 {
                misses += 1;
            }
        }
        compute.sort_unstable();
        slowest.sort_unstable();
        println!(
            "workers {workers}: period compute p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs, max {:.1} µs; \
             slowest contact p50 {:.1} µs; misses {misses} of {periods}",
            pct(&compute, 0.5),
            pct(&compute, 0.99),
            pct(&compute, 0.999),
            pct(&compute, 1.0),
            pct(&slowest, 0.5),
        );
    }
}
