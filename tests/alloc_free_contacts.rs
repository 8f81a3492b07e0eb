//! Stepping several contacts on a pool of workers allocates nothing, on
//! any thread: a counting global allocator over all threads proves it
//! (one test in this binary, so no other test allocates meanwhile).

use friction_node::clock::SystemClock;
use friction_node::config::{Config, Origin};
use friction_node::contacts::ContactSet;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

#[test]
fn stepping_eight_contacts_on_two_workers_allocates_nothing_on_any_thread() {
    let mut yaml = String::from(
        "friction_node:\n  ros__parameters:\n    solver: {cells: 64}\n    contacts:\n",
    );
    for i in 0..8 {
        yaml += &format!(
            "      c{i}: {{contact: {{load_n: {}}}}}\n",
            5000.0 + 1000.0 * i as f64
        );
    }
    let config = Config::from_yaml(&yaml, &Origin::Embedded, &[]).unwrap();
    let mut set = ContactSet::new(
        &config,
        2,
        // Workers park between steps too (spin 20 µs): parking allocates nothing either.
        20_000,
        Arc::new(SystemClock::new()),
        Arc::new(|_| {}),
    )
    .unwrap();
    let mut v = [0.0; 8];
    let loads = [10_000.0; 8];
    // Warm up (first steps may touch lazily built state).
    set.step(&v, &loads, None);
    COUNTING.store(true, Ordering::SeqCst);
    for k in 1..=2000 {
        let t = k as f64 * 1e-3;
        for (i, x) in v.iter_mut().enumerate() {
            *x = (2.0 * std::f64::consts::PI * (t + 0.1 * i as f64)).sin();
        }
        set.step(&v, &loads, if k % 500 == 0 { Some(0.02) } else { None });
    }
    COUNTING.store(false, Ordering::SeqCst);
    assert_eq!(ALLOCS.load(Ordering::SeqCst), 0);
    assert!(set.estimates().iter().all(|e| e.friction_force.is_finite()));
}
