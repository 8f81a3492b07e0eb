//! Several lubricated contacts stepped together against one deadline.
//!
//! A [`ContactSet`] holds one solver per configured contact
//! ([`crate::config::Config::resolved_contacts`]), each with its own grid,
//! load, lubricant and roughness. One call steps them all with one
//! velocity and load each; with `workers > 0` the contacts are shared out
//! (balanced by grid size) between the calling thread and a fixed pool of
//! worker threads (`pool.rs`), so that more contacts fit in one period than
//! one core can step. Nothing is allocated and no lock is taken per step.
//!
//! Each contact's effort on its joint is `gain · F_f` (`gain` = 1 for a
//! linear joint, N; the lever arm in m for a rotary joint, N·m). Each
//! step reports every contact's estimate and compute time and which
//! contact was the slowest.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_f,i | friction force of contact i ([`Estimate::friction_force`]) | N |
//! | g_i | gain of contact i | 1 or m |
//! | τ_i = g_i F_f,i | effort of contact i on its joint | N or N·m |
//!
//! | file | job |
//! |---|---|
//! | `mod.rs` | [`ContactSet`]: the contacts, their joints and gains, one step of all |
//! | `pool.rs` | a fixed pool of worker threads stepping their share of the contacts |
//! | `tests.rs` | unit tests: one contact equals the single solver, the pool equals serial |

mod pool;

use crate::clock::Clock;
use crate::config::{Config, ResolvedContact};
use crate::physics::{Estimate, SetupError, Solver};
use pool::{new_cell, CellData, Pool, Shared};
use std::sync::atomic::{AtomicBool, AtomicU64};
use std::sync::Arc;

/// Errors building a contact set.
#[derive(Debug, thiserror::Error)]
pub enum ContactSetError {
    #[error("contact `{name}`: {cause}")]
    /// A contact's solver could not be built.
    Setup {
        /// The contact.
        name: String,
        /// Why.
        cause: SetupError,
    },
    #[error("node.contact_workers = {workers}: at most one worker per contact beyond the first ({contacts} contacts)")]
    /// More worker threads than contacts to step.
    TooManyWorkers {
        /// `node.contact_workers`.
        workers: usize,
        /// Contacts configured.
        contacts: usize,
    },
    #[error("cannot start contact worker threads: {0}")]
    /// A worker thread could not be started.
    Spawn(std::io::Error),
}

/// The outcome of one step of every contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SetTiming {
    /// Index of the contact whose step took longest.
    pub slowest: usize,
    /// Its compute time, ns.
    pub slowest_ns: u64,
}

/// Every contact's solver, stepped together.
pub struct ContactSet {
    names: Vec<String>,
    joints: Vec<String>,
    gains: Vec<f64>,
    pool: Pool,
    estimates: Vec<Estimate>,
    compute_ns: Vec<u64>,
}

impl ContactSet {
    /// One solver per contact of `config`, each at its steady state at
    /// `node.initial_velocity_m_s` under its own load; `workers` threads
    /// beside the caller (0: the caller steps all), each first running
    /// `setup(k)` for k = 1..=workers (pinning, scheduling).
    pub fn new(
        config: &Config,
        workers: usize,
        spin_ns: u64,
        clock: Arc<dyn Clock>,
        setup: Arc<dyn Fn(usize) + Send + Sync>,
    ) -> Result<Self, ContactSetError> {
        let contacts = config.resolved_contacts();
        if workers >= contacts.len().max(1) && workers > 0 {
            return Err(ContactSetError::TooManyWorkers {
                workers,
                contacts: contacts.len(),
            });
        }
        let v0 = config.node.initial_velocity_m_s;
        let mut cells = Vec::with_capacity(contacts.len());
        for c in &contacts {
            let mut solver = build(c)?;
            let estimate = solver.initialize_steady(v0, c.config.contact.load_n);
            cells.push(new_cell(CellData {
                solver,
                velocity: v0,
                load: c.config.contact.load_n,
                jump_s: 0.0,
                estimate,
                compute_ns: 0,
            }));
        }
        let shares = balance(&contacts, workers + 1);
        let shared = Arc::new(Shared {
            cells: cells.into_boxed_slice(),
            shares,
            epoch: AtomicU64::new(0),
            done: (0..workers).map(|_| AtomicU64::new(0)).collect(),
            stop: AtomicBool::new(false),
            clock,
            spin_ns,
        });
        let pool = Pool::start(shared, setup).map_err(ContactSetError::Spawn)?;
        let n = contacts.len();
        let estimates = (0..n)
            // SAFETY: no step is in flight; the caller owns every cell.
            .map(|i| unsafe { pool.shared.cell(i) }.estimate)
            .collect();
        Ok(Self {
            names: contacts.iter().map(|c| c.name.clone()).collect(),
            joints: contacts.iter().map(|c| c.joint.clone()).collect(),
            gains: contacts.iter().map(|c| c.gain).collect(),
            pool,
            estimates,
            compute_ns: vec![0; n],
        })
    }

    /// The number of contacts.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether the set has no contact.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The contacts' names, in configured order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The contacts' joint names, in configured order.
    pub fn joints(&self) -> &[String] {
        &self.joints
    }

    /// Each contact's friction-to-effort factor (1 for a linear joint, the
    /// lever arm in m for a rotary one), in configured order.
    pub fn gains(&self) -> &[f64] {
        &self.gains
    }

    /// Worker threads beside the caller.
    pub fn workers(&self) -> usize {
        self.pool.shared.shares.len() - 1
    }

    /// One step of every contact with `velocities[i]` (m/s) and `loads[i]`
    /// (N); `jump_s` = None for a regular step of `solver.dt_s`, or
    /// Some(dt) for one backward-Euler step over dt (a loop that fell far
    /// behind). Slices shorter than the set leave the missing contacts'
    /// inputs as they were.
    pub fn step(&mut self, velocities: &[f64], loads: &[f64], jump_s: Option<f64>) -> SetTiming {
        let sh = &self.pool.shared;
        for i in 0..self.names.len() {
            // SAFETY: no step is in flight; the caller owns every cell.
            let c = unsafe { sh.cell(i) };
            if let Some(v) = velocities.get(i) {
                c.velocity = *v;
            }
            if let Some(l) = loads.get(i) {
                c.load = *l;
            }
            c.jump_s = jump_s.unwrap_or(0.0);
        }
        self.pool.step_all();
        let mut timing = SetTiming::default();
        for i in 0..self.names.len() {
            // SAFETY: step_all returned: every worker is done with its cells.
            let c = unsafe { sh.cell(i) };
            self.estimates[i] = c.estimate;
            self.compute_ns[i] = c.compute_ns;
            if c.compute_ns > timing.slowest_ns || i == 0 {
                timing = SetTiming {
                    slowest: i,
                    slowest_ns: c.compute_ns,
                };
            }
        }
        timing
    }

    /// The last estimate of every contact.
    pub fn estimates(&self) -> &[Estimate] {
        &self.estimates
    }

    /// The compute time of every contact's last step, ns.
    pub fn compute_ns(&self) -> &[u64] {
        &self.compute_ns
    }

    /// Contact i's effort on its joint, `gain · F_f` (N or N·m).
    pub fn effort(&self, i: usize) -> f64 {
        self.gains[i] * self.estimates[i].friction_force
    }

    /// Run `f` on contact i's solver between steps (a parameter change,
    /// a reset).
    pub fn with_solver<R>(&mut self, i: usize, f: impl FnOnce(&mut Solver) -> R) -> R {
        // SAFETY: &mut self: no step is in flight; the caller owns every cell.
        f(&mut unsafe { self.pool.shared.cell(i) }.solver)
    }
}

fn build(c: &ResolvedContact) -> Result<Solver, ContactSetError> {
    Solver::new(&c.config.model(), &c.config.solver_settings()).map_err(|cause| {
        ContactSetError::Setup {
            name: c.name.clone(),
            cause,
        }
    })
}

/// Share the contacts out between `n` threads, largest grid first onto
/// the least loaded thread (the step cost grows with the cells).
fn balance(contacts: &[ResolvedContact], n: usize) -> Box<[Box<[usize]>]> {
    let mut order: Vec<usize> = (0..contacts.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(contacts[i].config.solver.cells));
    let mut shares: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut cost = vec![0usize; n];
    for i in order {
        let k = (0..n).min_by_key(|&k| (cost[k], k)).unwrap_or(0);
        cost[k] += contacts[i].config.solver.cells;
        shares[k].push(i);
    }
    for s in &mut shares {
        s.sort_unstable();
    }
    shares.into_iter().map(Vec::into_boxed_slice).collect()
}

#[cfg(test)]
mod tests;
