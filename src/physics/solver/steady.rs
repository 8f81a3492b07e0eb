//! Steady states (Stribeck points): the time derivatives dropped, warm
//! starts from the current state and continuation in velocity and load from
//! the last converged steady state when a direct solve fails.
//!
//! `Solver`'s fields this file uses: `d`, `p`, `h0`, `velocity`, `w`, `anchor`, `last`.

use super::{Ctx, H0Mode, Outcome, Solver};
use crate::physics::estimate::{Estimate, Status};

impl Solver {
    /// Static GW equilibrium h0 at v = 0: F_asp(h0) = load, p = p_amb.
    pub fn static_equilibrium_gap(&self, load: f64) -> f64 {
        let (b, dx) = (self.d.grid.width, self.d.grid.dx);
        let f_asp = |h0: f64| -> f64 {
            self.d
                .grid
                .g_cell
                .iter()
                .map(|g| self.d.gw.pressure(h0 + g).0)
                .sum::<f64>()
                * b
                * dx
        };
        // Bisection in log h0; F_asp is strictly decreasing while in contact.
        let (mut lo, mut hi) = (1e-4 * self.d.sigma, 12.0 * self.d.sigma);
        if f_asp(lo) < load {
            return lo;
        }
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if f_asp(mid) > load {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi / lo - 1.0 < 1e-15 {
                break;
            }
        }
        (lo * hi).sqrt()
    }

    /// Solve the steady state at (v, load) and make it the history: the
    /// contact is taken to have been sliding steadily before t = 0. Time is
    /// reset to 0.
    pub fn initialize_steady(&mut self, v: f64, load: f64) -> Estimate {
        let e = self.steady(v, load);
        self.fill_history_with_current();
        self.set_time(0.0);
        Estimate { time: 0.0, ..e }
    }

    /// Steady state at (v, load) (Stribeck point), warm-started from the
    /// current state with continuation in velocity and load from the last
    /// converged steady state when the direct solve fails.
    pub fn steady(&mut self, v: f64, load: f64) -> Estimate {
        if let Some(status) = Self::input_status(v, load) {
            return self.rejected_input(v, load, status, false);
        }
        // A soft contact: the film per reference width (1 when rigid).
        let load = self.per_reference_width(load);
        if self.anchor.2 == 0.0 {
            self.set_static_anchor(load);
        }
        let ctx = Ctx {
            v,
            load,
            time: None,
            gap: H0Mode::Balance,
        };
        self.w.p_backup.copy_from_slice(&self.p);
        let h_backup = self.h0;
        let mut out = self.solve(&ctx);
        if out.status != Status::Converged {
            self.p.copy_from_slice(&self.w.p_backup);
            self.h0 = h_backup;
            out = self.continuation(v, load);
        }
        if out.status == Status::Converged {
            self.w.p_anchor.copy_from_slice(&self.p);
            self.anchor = (v, load, self.h0);
        }
        self.velocity = v;
        let e = self.finish(&ctx, out, false);
        self.last = Some(e);
        e
    }

    /// Steady pressure field at a prescribed gap (the `profile --h0` case).
    pub fn steady_prescribed_gap(&mut self, v: f64, h0: f64, load: f64) -> Estimate {
        if !(v.is_finite() && h0.is_finite() && h0 > 0.0) {
            return self.rejected_input(v, load, Status::NonFiniteInput, false);
        }
        if v.abs() > crate::physics::params::MAX_ABS_VELOCITY {
            return self.rejected_input(v, load, Status::InputOutOfRange, false);
        }
        let load = self.per_reference_width(load);
        let ctx = Ctx {
            v,
            load,
            time: None,
            gap: H0Mode::Prescribed(h0),
        };
        self.h0 = h0;
        let mut out = self.solve(&ctx);
        if out.status != Status::Converged {
            // Continuation in velocity from a quiescent film.
            self.p.fill(self.d.p_amb);
            let mut total = 0;
            let mut s: f64 = 0.0;
            let mut ds: f64 = 0.25;
            while s < 1.0 && total < 200 {
                total += 1;
                let st = (s + ds).min(1.0);
                self.w.p_backup.copy_from_slice(&self.p);
                let o = self.solve(&Ctx { v: v * st, ..ctx });
                if o.status == Status::Converged {
                    s = st;
                    ds = (ds * 2.0).min(1.0);
                    out = o;
                } else {
                    self.p.copy_from_slice(&self.w.p_backup);
                    ds *= 0.5;
                    out = o;
                    if ds < 1e-6 {
                        break;
                    }
                }
            }
        }
        self.velocity = v;
        self.finish(&ctx, out, false)
    }

    fn set_static_anchor(&mut self, load: f64) {
        let h = self.static_equilibrium_gap(load);
        self.w.p_anchor.fill(self.d.p_amb);
        self.anchor = (0.0, load, h);
    }

    /// March from the anchor steady state to (v, load).
    fn continuation(&mut self, v: f64, load: f64) -> Outcome {
        let (v_a, load_a, h_a) = self.anchor;
        self.p.copy_from_slice(&self.w.p_anchor);
        self.h0 = h_a;
        let mut s: f64 = 0.0;
        let mut ds: f64 = 0.5;
        let mut attempts = 0;
        let mut last = Outcome {
            status: Status::MaxIterations,
            iterations: 0,
            inner_iterations: 0,
            residual: f64::NAN,
            backtracks: 0,
        };
        while s < 1.0 {
            attempts += 1;
            if attempts > 400 || ds < 1e-7 {
                return last;
            }
            let st = (s + ds).min(1.0);
            let ctx = Ctx {
                v: v_a + st * (v - v_a),
                load: load_a * (load / load_a).powf(st),
                time: None,
                gap: H0Mode::Balance,
            };
            self.w.p_backup.copy_from_slice(&self.p);
            let h_b = self.h0;
            let o = self.solve(&ctx);
            last = o;
            if o.status == Status::Converged {
                s = st;
                ds = (ds * 2.0).min(1.0);
            } else {
                self.p.copy_from_slice(&self.w.p_backup);
                self.h0 = h_b;
                ds *= 0.5;
            }
        }
        last
    }
}
