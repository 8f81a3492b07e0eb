//! A step allocates nothing: a counting global allocator proves it.

use friction_node::physics::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCS.load(Ordering::SeqCst);
    f();
    ALLOCS.load(Ordering::SeqCst) - before
}

#[test]
fn the_counter_sees_allocations() {
    assert!(allocations(|| drop(std::hint::black_box(vec![1u8; 10]))) >= 1);
}

#[test]
fn newton_steps_allocate_nothing_through_reversals_and_vapour_collapse() {
    // The paper's reciprocating case (V1 1 m/s, f 1 Hz, 20 762 N), two cycles.
    let mut s = Solver::new(&ModelParams::default(), &SolverSettings::default()).unwrap();
    s.initialize_steady(0.0, 20_762.0);
    let mut worst = 0;
    let mut iterations = 0;
    for k in 1..=2000 {
        let v = (2.0 * std::f64::consts::PI * k as f64 * 1e-3).sin();
        let n = allocations(|| {
            let e = s.step(v, 20_762.0);
            iterations += e.diagnostics.iterations;
        });
        worst = worst.max(n);
    }
    assert_eq!(worst, 0, "a step allocated");
    assert!(iterations > 2000 * 2, "the steps did real work");
    // Rejected input and the theta scheme's history bookkeeping too.
    assert_eq!(allocations(|| drop(s.step(f64::NAN, 20_762.0))), 0);
}

#[test]
fn theta_scheme_steady_solves_and_reference_steps_allocate_nothing() {
    let st = SolverSettings {
        cells: 64,
        scheme: TimeScheme::PAPER,
        ..Default::default()
    };
    let mut s = Solver::new(&ModelParams::default(), &st).unwrap();
    s.initialize_steady(0.2, 20_762.0);
    assert_eq!(
        allocations(|| for k in 0..200 {
            drop(s.step(0.2 + 1e-3 * k as f64, 20_762.0))
        }),
        0
    );
    // Steady solves, including a cold continuation to high speed.
    let mut s = Solver::new(
        &ModelParams::default(),
        &SolverSettings {
            cells: 64,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(
        allocations(|| {
            s.steady(4.5, 20_762.0);
        }),
        0
    );
    let st = SolverSettings {
        cells: 16,
        method: Method::Reference,
        ..Default::default()
    };
    let mut r = Solver::new(&ModelParams::default(), &st).unwrap();
    r.initialize_steady(0.0, 20_762.0);
    assert_eq!(
        allocations(|| for _ in 0..3 {
            drop(r.step(0.05, 20_762.0))
        }),
        0
    );
}
