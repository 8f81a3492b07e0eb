use super::*;
use crate::clock::SystemClock;
use crate::config::Origin;
use approx::assert_relative_eq;

const THREE: &str = "friction_node:\n  ros__parameters:\n    solver: {cells: 64}\n    contacts:\n      a: {contact: {load_n: 20000.0}}\n      b: {contact: {load_n: 5000.0}, gain: 0.05, solver: {cells: 32}}\n      c: {lubricant: {viscosity_pa_s: 0.1}, solver: {cells: 128}}\n";

fn config() -> Config {
    Config::from_yaml(THREE, &Origin::Embedded, &[]).unwrap()
}

fn set(workers: usize) -> ContactSet {
    ContactSet::new(
        &config(),
        workers,
        50_000,
        Arc::new(SystemClock::new()),
        Arc::new(|_| {}),
    )
    .unwrap()
}

fn inputs(k: usize) -> ([f64; 3], [f64; 3]) {
    let t = k as f64 * 1e-3;
    let v = (2.0 * std::f64::consts::PI * t).sin();
    ([v, 0.5 * v, -v], [20_000.0, 5_000.0 + 1e3 * t, 20_762.0])
}

#[test]
fn each_contact_of_a_set_is_its_own_solver_stepped_alone() {
    let c = config();
    let mut alone: Vec<Solver> = c
        .resolved_contacts()
        .iter()
        .map(|r| {
            let mut s = Solver::new(&r.config.model(), &r.config.solver_settings()).unwrap();
            s.initialize_steady(0.0, r.config.contact.load_n);
            s
        })
        .collect();
    let mut set = set(0);
    for k in 1..=300 {
        let (v, l) = inputs(k);
        set.step(&v, &l, None);
        for (i, s) in alone.iter_mut().enumerate() {
            let e = s.step(v[i], l[i]);
            assert_eq!(set.estimates()[i], e, "contact {i} step {k}");
        }
    }
    // The contacts differ (their own load, grid and lubricant).
    let f: Vec<f64> = set.estimates().iter().map(|e| e.friction_force).collect();
    assert!(f[0] != f[1] && f[1] != f[2], "{f:?}");
}

#[test]
fn workers_give_bit_identical_estimates_to_one_thread() {
    let mut one = set(0);
    let mut pooled = set(2);
    assert_eq!(pooled.workers(), 2);
    for k in 1..=300 {
        let (v, l) = inputs(k);
        one.step(&v, &l, None);
        pooled.step(&v, &l, None);
        assert_eq!(one.estimates(), pooled.estimates(), "step {k}");
    }
    // A time jump (catch-up beyond its bound) too.
    one.step(&[0.3; 3], &[], Some(0.05));
    pooled.step(&[0.3; 3], &[], Some(0.05));
    assert_eq!(one.estimates(), pooled.estimates());
    assert_relative_eq!(one.estimates()[0].time, 0.35, max_relative = 1e-12);
}

#[test]
fn the_effort_is_the_gain_times_the_friction_force() {
    let mut s = set(1);
    s.step(&[0.2, 0.2, 0.2], &[], None);
    assert_eq!(s.gains(), &[1.0, 0.05, 1.0]);
    for i in 0..3 {
        assert_relative_eq!(
            s.effort(i),
            s.gains()[i] * s.estimates()[i].friction_force,
            max_relative = 1e-15
        );
    }
    assert_eq!(s.joints(), &["a", "b", "c"]);
}

#[test]
fn the_slowest_contact_is_the_one_with_the_largest_compute_time() {
    let mut s = set(2);
    for k in 1..=20 {
        let (v, l) = inputs(k);
        let t = s.step(&v, &l, None);
        let max = *s.compute_ns().iter().max().unwrap();
        assert_eq!(t.slowest_ns, max);
        assert_eq!(s.compute_ns()[t.slowest], max);
        assert!(max > 0);
    }
}

#[test]
fn contacts_are_shared_out_by_grid_size() {
    let c = config().resolved_contacts();
    // cells 64, 32, 128 over 2 threads: 128 alone, 64 + 32 together.
    let shares = balance(&c, 2);
    assert_eq!(&*shares[0], &[2]);
    assert_eq!(&*shares[1], &[0, 1]);
    let all: usize = balance(&c, 3).iter().map(|s| s.len()).sum();
    assert_eq!(all, 3);
}

#[test]
fn more_workers_than_contacts_is_refused() {
    let e = ContactSet::new(
        &config(),
        3,
        0,
        Arc::new(SystemClock::new()),
        Arc::new(|_| {}),
    )
    .err()
    .unwrap();
    assert!(e.to_string().contains("contact_workers = 3"), "{e}");
}

#[test]
fn workers_run_their_setup_once_each_and_stop_with_the_set() {
    let calls = Arc::new(AtomicU64::new(0));
    let seen = calls.clone();
    let s = ContactSet::new(
        &config(),
        2,
        0,
        Arc::new(SystemClock::new()),
        Arc::new(move |k| {
            assert!((1..=2).contains(&k));
            seen.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        }),
    )
    .unwrap();
    drop(s); // joins the workers
    assert_eq!(calls.load(std::sync::atomic::Ordering::SeqCst), 2);
}
