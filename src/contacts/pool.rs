//! A fixed pool of worker threads that step their share of the contacts
//! each period, with no allocation and no lock on the step path.
//!
//! Each contact lives in a [`Cell`] that exactly one thread (its owner:
//! the caller for share 0, worker k for share k) touches while a step is in
//! flight, and only the caller touches between steps. The hand-over is two
//! atomics: the caller publishes inputs then bumps `epoch` (Release); a
//! worker that sees the new epoch (Acquire) steps its cells and stores the
//! epoch in its `done` (Release); the caller reads the outputs after it has
//! seen every `done` equal to the epoch (Acquire). Workers spin for a while
//! after each step (a period is short) and then park; the caller unparks
//! them with each new epoch.

use crate::clock::Clock;
use crate::physics::{Estimate, Solver};
use std::cell::UnsafeCell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

/// What one step of one contact needs and gives.
pub(super) struct CellData {
    pub solver: Solver,
    pub velocity: f64,
    pub load: f64,
    /// 0: a regular step of the solver's dt; else one step over this, s.
    pub jump_s: f64,
    pub estimate: Estimate,
    pub compute_ns: u64,
}

impl CellData {
    fn step(&mut self, clock: &dyn Clock) {
        let start = clock.now_ns();
        self.estimate = if self.jump_s > 0.0 {
            self.solver
                .step_lasting(self.velocity, self.load, self.jump_s)
        } else {
            self.solver.step(self.velocity, self.load)
        };
        self.compute_ns = clock.now_ns().saturating_sub(start);
    }
}

/// One contact, shared between the caller and the worker that owns it.
pub(super) struct Cell(UnsafeCell<CellData>);

// SAFETY: a Cell is only accessed by one thread at a time, as the epoch
// protocol of this module guarantees (see the module documentation).
unsafe impl Sync for Cell {}

/// State shared by the caller and the workers.
pub(super) struct Shared {
    pub cells: Box<[Cell]>,
    /// Cell indices of each share (share 0: the caller).
    pub shares: Box<[Box<[usize]>]>,
    pub epoch: AtomicU64,
    /// Per worker (share 1..): the last epoch it finished.
    pub done: Box<[AtomicU64]>,
    pub stop: AtomicBool,
    pub clock: Arc<dyn Clock>,
    /// How long a worker spins for the next epoch before parking, ns.
    pub spin_ns: u64,
}

impl Shared {
    /// # Safety
    /// The caller must own cell `i` under the epoch protocol.
    #[allow(clippy::mut_from_ref)]
    pub(super) unsafe fn cell(&self, i: usize) -> &mut CellData {
        // SAFETY: exclusive by the caller's contract.
        unsafe { &mut *self.cells[i].0.get() }
    }

    /// Step every cell of `share` (the calling thread owns them now).
    fn step_share(&self, share: usize) {
        for &i in self.shares[share].iter() {
            // SAFETY: between an epoch bump and its `done`, share k's cells
            // belong to share k's thread alone.
            unsafe { self.cell(i) }.step(self.clock.as_ref());
        }
    }
}

pub(super) fn new_cell(data: CellData) -> Cell {
    Cell(UnsafeCell::new(data))
}

/// The workers of a contact set.
pub(super) struct Pool {
    pub shared: Arc<Shared>,
    threads: Vec<JoinHandle<()>>,
}

impl Pool {
    /// Start one worker per share after the first; `setup(k)` runs first on
    /// worker k (1-based: pinning, scheduling).
    pub(super) fn start(
        shared: Arc<Shared>,
        setup: Arc<dyn Fn(usize) + Send + Sync>,
    ) -> std::io::Result<Self> {
        let mut threads = Vec::new();
        for k in 1..shared.shares.len() {
            let sh = shared.clone();
            let setup = setup.clone();
            let t = std::thread::Builder::new()
                .name(format!("contacts-{k}"))
                .spawn(move || {
                    setup(k);
                    worker(&sh, k);
                });
            match t {
                Ok(t) => threads.push(t),
                Err(e) => {
                    let pool = Self { shared, threads };
                    drop(pool); // stops the ones started
                    return Err(e);
                }
            }
        }
        Ok(Self { shared, threads })
    }

    /// One step of every contact: the caller's share here, the others on
    /// their workers; returns when all are done.
    pub(super) fn step_all(&self) {
        let sh = &self.shared;
        let epoch = sh.epoch.fetch_add(1, Ordering::Release) + 1;
        for t in &self.threads {
            t.thread().unpark();
        }
        sh.step_share(0);
        for d in sh.done.iter() {
            while d.load(Ordering::Acquire) != epoch {
                std::hint::spin_loop();
            }
        }
    }
}

impl Drop for Pool {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        for t in &self.threads {
            t.thread().unpark();
        }
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

fn worker(sh: &Shared, k: usize) {
    // The epoch the pool started at (0): a worker that starts after the
    // first step was published must still take that step.
    let mut seen = 0;
    loop {
        // Wait for the next epoch: spin, then park.
        let spin_from = sh.clock.now_ns();
        let epoch = loop {
            if sh.stop.load(Ordering::Acquire) {
                return;
            }
            let e = sh.epoch.load(Ordering::Acquire);
            if e != seen {
                break e;
            }
            if sh.clock.now_ns().saturating_sub(spin_from) < sh.spin_ns {
                std::hint::spin_loop();
            } else {
                std::thread::park();
            }
        };
        sh.step_share(k);
        seen = epoch;
        sh.done[k - 1].store(epoch, Ordering::Release);
    }
}
