//! The coupled solver: transient Reynolds + mixture EOS + GW + load balance.
//!
//! ## Equations (MODEL.md §2, §5)
//!
//! ```text
//! ∂x( φx ρ h³/(12 μ) ∂x p ) = (v/2) ∂x(ρ h) + (v/2) σ ∂x(ρ φs) + ∂t(ρ h)
//! m h0'' = F_hyd + F_asp − F_ext
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | p | absolute pressure, p(0) = p(L) = p_amb | Pa |
//! | h | film thickness h0 + hg + ht | m |
//! | v | sliding velocity (one surface moves) | m/s |
//! | q | lubricant mass flux per unit width | kg/(m·s) |
//! | F_hyd, F_asp, F_ext | hydrodynamic, asperity, external load | N |
//! | m | equivalent mass | kg |
//!
//! ## Discretisation
//!
//! Finite volumes on N cells. The mass flux through face f is
//!
//! ```text
//! q_f = −φx h_f³/(12 d_f) · ½(ρ/μ|_L + ρ/μ|_R) · (p_R − p_L) + (v/2)(h_f + σ φs) ρ_up
//! ```
//!
//! with `d_f = Δx` (interior) or `Δx/2` (boundary face, ghost at p_amb) and
//! `ρ_up` the density of the upwind cell. Only the density is upwinded: h is
//! exact at the face, so in full film (ρ ≈ ρl) the scheme is second order and
//! in cavitated zones it is monotone. Cell i's residual is
//!
//! ```text
//! R_i = Δx Σ_k a_k (ρ h̄)_i^(n−k) / Δt + Σ_k w_k (q_(i+1) − q_i)^(n−k) − s_i
//! G   = m Σ_k c_k h0^(n−k) / Δt² − Σ_k w_k (F_hyd + F_asp − F_ext)^(n−k)
//! ```
//!
//! (`s_i` an optional external mass source, zero unless set.)
//!
//! ## Newton
//!
//! The Jacobian of (R, G) in (p, h0) is tridiagonal in p, bordered by the
//! dense column ∂R/∂h0 and the uniform row ∂G/∂p = −w0 B Δx. One Thomas
//! factorisation serves two right-hand sides and a scalar Schur complement
//! gives Δh0: O(N) per iteration. Globalisation is Deuflhard's natural
//! monotonicity test: a trial step λΔ is accepted when the simplified Newton
//! correction at the trial point, computed with the *old* factors, shrinks
//! (‖Δ̄‖ ≤ (1 − λ/4)‖Δ‖); the trial point's assembly is then reused by the
//! next iteration, so a full step costs nothing extra. h0 may not change by
//! more than 25 % in one update. All buffers are allocated in
//! [`Solver::new`]; a step allocates nothing.
//!
//! The iteration stops when the error left after the last update is below
//! the tolerance. Newton converges quadratically, ‖e_(k+1)‖ ≈ K‖Δ_k‖², so
//! that error is estimated as K‖Δ_k‖² with K observed from the last two
//! full updates, ‖Δ_k‖/‖Δ_(k−1)‖² (bounded to [1, 1e6]); the first update of
//! a time step, from the predictor, uses the K last observed. After a damped
//! update K is unknown and only an update at or below the tolerance ends the
//! iteration, which is also the rule of steady solves (off the real-time
//! path, they converge to the update tolerance). Norms are the scaled
//! max-norm of (Δp / max(p_amb, max|p|), Δh0 / h0).

use super::eos::MixtureEos;
use super::error::SetupError;
use super::estimate::{Diagnostics, Estimate, Regime, Status};
use super::flow_factors::FlowFactors;
use super::geometry::Grid;
use super::gw::{Greenwood, SummedContact};
use super::params::{Method, ModelParams, SolverSettings};
use super::scheme::StepCoefficients;

/// Finest sub-division of a step that failed to converge.
const MAX_SUBSTEPS: usize = 16;

/// Largest relative change of h0 in one Newton update.
const H0_TRUST: f64 = 0.25;

/// Updates below this (scaled) are taken without the monotonicity test
/// (with the h0 trust region and a consistent merit scale, measured safe on
/// every study case; it saves a solve per iteration in the slow phase of a
/// vapour-pocket collapse).
const SMALL_UPDATE: f64 = 1e-1;

/// Bounds of the Newton contraction constant K (‖e_(k+1)‖ ≈ K‖e_k‖², scaled
/// norm) used to estimate the error left after an update; K starts at the
/// upper bound and follows the observed ratios.
const CONTRACTION_MIN: f64 = 1.0;
const CONTRACTION_MAX: f64 = 1e6;

/// Immutable discretisation data.
#[derive(Debug, Clone)]
pub(crate) struct Disc {
    pub grid: Grid,
    pub eos: MixtureEos,
    pub gw: Greenwood,
    /// GW contact summed over the cells, as a function of h0.
    pub contact: SummedContact,
    pub ff: Option<FlowFactors>,
    pub sigma: f64,
    pub p_amb: f64,
    /// ρ, ρ/μ at the boundary pressure.
    pub rho_b: f64,
    pub gr_b: f64,
    pub mass: f64,
    pub mu_bl: f64,
    pub v_reg: f64,
    pub min_film: f64,
}

/// One stored time level.
#[derive(Debug, Clone)]
pub(crate) struct Level {
    pub rho_h: Vec<f64>,
    pub div: Vec<f64>,
    pub f_net: f64,
    pub h0: f64,
}

impl Level {
    fn new(n: usize) -> Self {
        Self {
            rho_h: vec![0.0; n],
            div: vec![0.0; n],
            f_net: 0.0,
            h0: 0.0,
        }
    }
}

/// How h0 is determined in a solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Gap {
    /// Load balance decides h0.
    Balance,
    /// h0 is given.
    Prescribed(f64),
}

/// Everything that is fixed during one solve.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ctx {
    pub v: f64,
    pub load: f64,
    /// None: steady (no time derivatives, no inertia).
    pub time: Option<(StepCoefficients, f64)>,
    pub gap: Gap,
}

impl Ctx {
    pub fn w0(&self) -> f64 {
        self.time.map_or(1.0, |(c, _)| c.w[0])
    }
}

/// Mixture properties of one cell at the current iterate.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct CellProps {
    pub rho: f64,
    pub drho: f64,
    /// ρ/μ and its pressure derivative.
    pub gr: f64,
    pub dgr: f64,
    pub mu: f64,
    pub dmu: f64,
}

/// Mass flux through one face and its derivatives.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct FaceFlux {
    pub q: f64,
    pub dql: f64,
    pub dqr: f64,
    pub dqh: f64,
}

/// One row of the bordered system: tridiagonal (a, b, c), border column, residual.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Row {
    pub a: f64,
    pub b: f64,
    pub c: f64,
    pub col: f64,
    pub r: f64,
}

/// Factors of one row of the twisted elimination, plus z = A⁻¹ col.
/// `fa` is the coupling to the already-eliminated neighbour (a above the
/// meeting row, c below it) and `cp` the multiplier of the other neighbour.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Factor {
    pub fa: f64,
    pub cp: f64,
    pub inv_m: f64,
    pub z: f64,
}

/// Work arrays (allocated once).
#[derive(Debug, Clone)]
pub(crate) struct Work {
    pub cells: Vec<CellProps>,
    pub faces: Vec<FaceFlux>,
    pub rows: Vec<Row>,
    pub g: f64,
    pub dgdh: f64,
    pub f_net: f64,
    pub factors: Vec<Factor>,
    pub schur: f64,
    pub c_row: f64,
    pub balance: bool,
    /// Scratch of length N (post-processing, Picard).
    pub tmp: Vec<f64>,
    pub dp: Vec<f64>,
    pub dbar: Vec<f64>,
    pub p_trial: Vec<f64>,
    pub p_backup: Vec<f64>,
    pub p_anchor: Vec<f64>,
    pub source: Vec<f64>,
    pub has_source: bool,
    /// Σ_k≥1 (history storage and flux terms) per cell, valid for the
    /// coefficients it was computed with (reset when the history changes).
    pub hist_term: Vec<f64>,
    #[allow(clippy::type_complexity)]
    pub hist_term_valid: Option<Option<([f64; 3], [f64; 3], f64)>>,
    /// Set when the state is the last assembly point plus the update
    /// (`dp`, Δh0): post-processing then linearises instead of re-evaluating.
    pub linearised: Option<f64>,
}

impl Work {
    fn new(n: usize) -> Self {
        Self {
            cells: vec![CellProps::default(); n],
            faces: vec![FaceFlux::default(); n + 1],
            rows: vec![Row::default(); n],
            g: 0.0,
            dgdh: 0.0,
            f_net: 0.0,
            factors: vec![Factor::default(); n],
            schur: 0.0,
            c_row: 0.0,
            balance: true,
            tmp: vec![0.0; n],
            dp: vec![0.0; n],
            dbar: vec![0.0; n],
            p_trial: vec![0.0; n],
            p_backup: vec![0.0; n],
            p_anchor: vec![0.0; n],
            source: vec![0.0; n],
            has_source: false,
            hist_term: vec![0.0; n],
            hist_term_valid: None,
            linearised: None,
        }
    }
}

/// Result of one nonlinear solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Outcome {
    pub status: Status,
    pub iterations: u32,
    pub inner_iterations: u32,
    pub residual: f64,
    pub backtracks: u32,
}

/// One point of a field along x (see [`Solver::field`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldPoint {
    /// Cell centre, m.
    pub x: f64,
    /// Film thickness, m.
    pub h: f64,
    /// Absolute pressure, Pa.
    pub p: f64,
    /// Vapour volume fraction.
    pub vapour_fraction: f64,
    /// Asperity contact pressure, Pa.
    pub asperity_pressure: f64,
    /// Fluid shear stress on the slider, −(h/2) ∂x p + μ v / h, Pa.
    pub shear: f64,
}

/// The friction model, advanced one fixed step at a time.
#[derive(Debug, Clone)]
pub struct Solver {
    pub(crate) d: Disc,
    pub(crate) settings: SolverSettings,
    pub(crate) p: Vec<f64>,
    pub(crate) h0: f64,
    pub(crate) time: f64,
    pub(crate) velocity: f64,
    pub(crate) hist: [Level; 2],
    /// Scratch copy of the history while a step is sub-stepped.
    hist_save: [Level; 2],
    /// Load of the last accepted step (sub-steps interpolate from it).
    last_load: Option<f64>,
    /// Number of valid history levels (0, 1 or 2).
    pub(crate) hist_len: usize,
    pub(crate) w: Work,
    /// Pressure at level n−2 (for the predictor).
    p_old: Vec<f64>,
    /// Pressure at level n−3.
    p_old2: Vec<f64>,
    /// How many of p_old, p_old2 are valid (0..=2).
    p_hist: usize,
    /// h0 at level n−3 (valid when p_hist == 2).
    h0_n3: f64,
    /// Newton contraction constant K (see the module doc).
    contraction: f64,
    anchor: (f64, f64, f64),
    last: Option<Estimate>,
}

impl Solver {
    /// Build the solver: validates the parameters and allocates every buffer.
    /// Start it with [`Solver::initialize_steady`] or [`Solver::initialize_gap`]
    /// (a first [`Solver::step`] without either starts from the steady state).
    pub fn new(model: &ModelParams, settings: &SolverSettings) -> Result<Self, SetupError> {
        model.check()?;
        settings.check()?;
        let n = settings.cells;
        let grid = Grid::new(&model.geometry, n);
        let eos = MixtureEos::new(&model.lubricant);
        let gw = Greenwood::new(&model.roughness);
        let ff = if model.roughness.flow_factors {
            Some(FlowFactors::new(
                model.roughness.lay_gamma,
                model.roughness.sigma,
            )?)
        } else {
            None
        };
        let p_amb = model.lubricant.ambient_pressure;
        let sb = eos.eval(p_amb);
        let contact = gw.summed(&grid.g_cell);
        let d = Disc {
            grid,
            eos,
            gw,
            contact,
            ff,
            sigma: model.roughness.sigma,
            p_amb,
            rho_b: sb.rho,
            gr_b: sb.rho / sb.mu,
            mass: model.contact.mass,
            mu_bl: model.contact.boundary_friction,
            v_reg: model.contact.sign_regularization,
            min_film: model.contact.min_film,
        };
        let mut s = Self {
            d,
            settings: *settings,
            p: vec![p_amb; n],
            h0: model.roughness.sigma * 3.0,
            time: 0.0,
            velocity: 0.0,
            hist: [Level::new(n), Level::new(n)],
            hist_save: [Level::new(n), Level::new(n)],
            last_load: None,
            hist_len: 0,
            w: Work::new(n),
            p_old: vec![p_amb; n],
            p_old2: vec![p_amb; n],
            p_hist: 0,
            h0_n3: 0.0,
            contraction: CONTRACTION_MAX,
            anchor: (0.0, 0.0, 0.0),
            last: None,
        };
        s.w.p_anchor.copy_from_slice(&s.p);
        Ok(s)
    }

    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    /// Switch the algorithm (and its tolerance) while keeping the state, e.g.
    /// to time the reference solver from exactly the same state.
    pub fn set_method(&mut self, method: Method, tolerance: f64) {
        self.settings.method = method;
        self.settings.tolerance = tolerance;
        self.settings.reference.fluid_tolerance = tolerance;
        self.settings.reference.motion_tolerance = tolerance;
    }

    pub fn cells(&self) -> usize {
        self.d.grid.n
    }

    pub fn dx(&self) -> f64 {
        self.d.grid.dx
    }

    pub fn time(&self) -> f64 {
        self.time
    }

    pub fn h0(&self) -> f64 {
        self.h0
    }

    /// Absolute pressure at the cell centres, Pa.
    pub fn pressure(&self) -> &[f64] {
        &self.p
    }

    /// Film thickness at cell i (cell average), m.
    pub fn film_thickness(&self, i: usize) -> f64 {
        self.h0 + self.d.grid.g_cell[i]
    }

    /// The last estimate returned, if any.
    pub fn last_estimate(&self) -> Option<&Estimate> {
        self.last.as_ref()
    }

    /// Vapour fraction α(p) of the mixture EOS.
    pub fn vapour_fraction(&self, p: f64) -> f64 {
        self.d.eos.alpha(p)
    }

    /// Fields along x at the current state (allocation-free iterator).
    pub fn field(&self) -> impl Iterator<Item = FieldPoint> + '_ {
        let n = self.d.grid.n;
        (0..n).map(move |i| {
            let h = self.film_thickness(i);
            let s = self.d.eos.eval(self.p[i]);
            let (pl, pr) = self.face_pressures(i);
            FieldPoint {
                x: self.d.grid.x_cell(i),
                h,
                p: self.p[i],
                vapour_fraction: s.alpha,
                asperity_pressure: self.d.gw.pressure(h).0,
                shear: -0.5 * h * (pr - pl) / self.d.grid.dx + s.mu * self.velocity / h,
            }
        })
    }

    /// Set an external lubricant mass source per cell (kg/(m·s) per unit
    /// width, integrated over the cell), applied at the new time level. Used by
    /// the method of manufactured solutions. `None` clears it.
    pub fn set_mass_source(&mut self, source: Option<&[f64]>) {
        match source {
            Some(s) => {
                let n = self.w.source.len().min(s.len());
                self.w.source[..n].copy_from_slice(&s[..n]);
                self.w.has_source = true;
            }
            None => {
                self.w.source.fill(0.0);
                self.w.has_source = false;
            }
        }
    }

    fn face_pressures(&self, i: usize) -> (f64, f64) {
        let n = self.d.grid.n;
        let pl = if i == 0 {
            self.d.p_amb
        } else {
            0.5 * (self.p[i - 1] + self.p[i])
        };
        let pr = if i + 1 == n {
            self.d.p_amb
        } else {
            0.5 * (self.p[i] + self.p[i + 1])
        };
        (pl, pr)
    }

    // ------------------------------------------------------------------
    // Initialisation
    // ------------------------------------------------------------------

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
        self.time = 0.0;
        Estimate { time: 0.0, ..e }
    }

    /// Place the slider at gap `h0` with p = p_amb, at rest, time 0. The
    /// first step is backward Euler (only one history level exists).
    pub fn initialize_gap(&mut self, h0: f64) {
        self.p.fill(self.d.p_amb);
        self.h0 = h0;
        self.velocity = 0.0;
        self.time = 0.0;
        self.hist_len = 0;
        // Both levels at rest (so h0'' starts at 0), but only one counts:
        // the first step is backward Euler.
        self.push_history_current(0.0);
        self.push_history_current(0.0);
        self.hist_len = 1;
        self.p_hist = 0;
        self.last = None;
    }

    /// Start from a given pressure field (Pa, one value per cell) and gap
    /// (m), time 0. The first step is backward Euler. Non-finite or
    /// wrongly-sized input is rejected.
    pub fn initialize_state(&mut self, p: &[f64], h0: f64) -> Result<(), SetupError> {
        if p.len() != self.d.grid.n {
            return Err(SetupError::invalid(
                "initial_state.pressure.len",
                p.len() as f64,
                "must equal the number of cells",
            ));
        }
        if let Some(bad) = p.iter().find(|x| !x.is_finite()) {
            return Err(SetupError::invalid(
                "initial_state.pressure",
                *bad,
                "must be finite",
            ));
        }
        if !(h0.is_finite() && h0 > 0.0) {
            return Err(SetupError::invalid(
                "initial_state.h0",
                h0,
                "must be finite and > 0",
            ));
        }
        self.initialize_gap(h0);
        self.p.copy_from_slice(p);
        self.hist_len = 0;
        self.push_history_current(0.0);
        self.push_history_current(0.0);
        self.hist_len = 1;
        Ok(())
    }

    fn fill_history_with_current(&mut self) {
        self.hist_len = 0;
        self.p_hist = 0;
        let f_net = self
            .last
            .map_or(0.0, |e| e.hydrodynamic_force + e.asperity_force - e.load);
        self.push_history_current(f_net);
        self.push_history_current(f_net);
    }

    /// Push the current state as level n−1.
    fn push_history_current(&mut self, f_net: f64) {
        self.hist.swap(0, 1);
        self.w.hist_term_valid = None;
        let lvl = &mut self.hist[0];
        for i in 0..self.d.grid.n {
            let h = self.h0 + self.d.grid.g_cell[i];
            lvl.rho_h[i] = self.d.eos.eval(self.p[i]).rho * h;
        }
        lvl.f_net = f_net;
        lvl.h0 = self.h0;
        // Flux divergence at this level (only the θ scheme reads it).
        lvl.div.fill(0.0);
        self.hist_len = (self.hist_len + 1).min(2);
    }

    // ------------------------------------------------------------------
    // Public solves
    // ------------------------------------------------------------------

    /// Advance one step of `dt` with velocity `v` (m/s) and load `load` (N).
    pub fn step(&mut self, v: f64, load: f64) -> Estimate {
        self.step_with_gap(v, load, Gap::Balance)
    }

    /// Advance one step with a prescribed gap h0 (no load balance). `load`
    /// is only used to normalise the COF.
    pub fn step_prescribed_gap(&mut self, v: f64, h0: f64, load: f64) -> Estimate {
        self.step_with_gap(v, load, Gap::Prescribed(h0))
    }

    /// Steady state at (v, load) (Stribeck point), warm-started from the
    /// current state with continuation in velocity and load from the last
    /// converged steady state when the direct solve fails.
    pub fn steady(&mut self, v: f64, load: f64) -> Estimate {
        if !(v.is_finite() && load.is_finite() && load > 0.0) {
            return self.rejected_input(v, load);
        }
        if self.anchor.2 == 0.0 {
            self.set_static_anchor(load);
        }
        let ctx = Ctx {
            v,
            load,
            time: None,
            gap: Gap::Balance,
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
            return self.rejected_input(v, load);
        }
        let ctx = Ctx {
            v,
            load,
            time: None,
            gap: Gap::Prescribed(h0),
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
                gap: Gap::Balance,
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

    fn rejected_input(&mut self, v: f64, load: f64) -> Estimate {
        let mut e = self.last.unwrap_or_else(|| self.blank_estimate());
        e.velocity = v;
        e.load = load;
        e.status = Status::NonFiniteInput;
        e.diagnostics = Diagnostics::default();
        e
    }

    fn blank_estimate(&self) -> Estimate {
        Estimate {
            time: self.time,
            velocity: self.velocity,
            load: f64::NAN,
            h0: self.h0,
            h_min: self.h0 + self.d.grid.g_min,
            hydrodynamic_force: 0.0,
            asperity_force: 0.0,
            viscous_force: 0.0,
            friction_force: 0.0,
            cof: 0.0,
            asperity_load_share: 0.0,
            inertia_force: 0.0,
            contact_area_ratio: 0.0,
            max_pressure: self.d.p_amb,
            cavitated_fraction: 0.0,
            regime: Regime::Boundary,
            status: Status::NonFiniteInput,
            diagnostics: Diagnostics::default(),
        }
    }

    fn step_with_gap(&mut self, v: f64, load: f64, gap: Gap) -> Estimate {
        let gap_ok = match gap {
            Gap::Balance => true,
            Gap::Prescribed(h) => h.is_finite() && h > 0.0,
        };
        if !(v.is_finite() && load.is_finite() && load > 0.0 && gap_ok) {
            return self.rejected_input(v, load);
        }
        if self.hist_len == 0 {
            // Never initialised: start from the steady state at this input.
            self.initialize_steady(v, load);
        }
        let coeffs = if self.hist_len >= 2 {
            StepCoefficients::for_scheme(self.settings.scheme)
        } else {
            StepCoefficients::BDF1
        };
        let ctx = Ctx {
            v,
            load,
            time: Some((coeffs, self.settings.dt)),
            gap,
        };
        self.w.p_backup.copy_from_slice(&self.p);
        let h_backup = self.h0;
        // Warm start: pressure and h0 extrapolated in time, quadratically
        // once three levels exist (error O(Δt³): within the tolerance for
        // smooth motion, so such steps take one Newton iteration).
        let quadratic = self.p_hist == 2 && self.hist_len >= 2;
        if quadratic {
            for ((p, o), o2) in self.p.iter_mut().zip(&self.p_old).zip(&self.p_old2) {
                *p = 3.0 * (*p - o) + o2;
            }
        } else if self.p_hist >= 1 && self.hist_len >= 2 {
            for (p, o) in self.p.iter_mut().zip(&self.p_old) {
                *p = 2.0 * *p - o;
            }
        }
        match gap {
            Gap::Prescribed(h) => self.h0 = h,
            Gap::Balance => {
                if self.hist_len >= 2 {
                    let (h1, h2) = (self.hist[0].h0, self.hist[1].h0);
                    let ext = if quadratic {
                        3.0 * (h1 - h2) + self.h0_n3
                    } else {
                        2.0 * h1 - h2
                    };
                    if ext > 0.5 * self.h0 && ext.is_finite() {
                        self.h0 = ext;
                    }
                }
            }
        }
        let mut out = match self.settings.method {
            Method::Newton => self.solve(&ctx),
            Method::Reference => self.reference_solve(&ctx),
        };
        let mut substeps = 0;
        if out.status != Status::Converged && self.settings.method == Method::Newton {
            // Fallbacks for the rare hard step (a fast vapour-pocket collapse):
            // Newton from the last state instead of the extrapolated one, then
            // the step split into backward-Euler sub-steps.
            let spent = out.iterations;
            self.p.copy_from_slice(&self.w.p_backup);
            self.h0 = match gap {
                Gap::Prescribed(h) => h,
                Gap::Balance => h_backup,
            };
            out = self.solve(&ctx);
            out.iterations += spent;
            let mut m = 2;
            while out.status != Status::Converged && m <= MAX_SUBSTEPS {
                let spent = out.iterations;
                out = self.solve_substepped(&ctx, m, h_backup);
                out.iterations += spent;
                substeps = m;
                m *= 2;
            }
        }
        let mut floor = false;
        if out.status != Status::NonFinite && gap == Gap::Balance && self.h0 < self.d.min_film {
            // The floor binds: hold h0 there and give up the load balance.
            floor = true;
            let inner = out.iterations;
            let c2 = Ctx {
                gap: Gap::Prescribed(self.d.min_film),
                ..ctx
            };
            self.h0 = self.d.min_film;
            out = self.solve(&c2);
            out.iterations += inner;
        }
        if out.status == Status::NonFinite {
            self.p.copy_from_slice(&self.w.p_backup);
            self.h0 = h_backup;
        }
        std::mem::swap(&mut self.p_old2, &mut self.p_old);
        std::mem::swap(&mut self.p_old, &mut self.w.p_backup);
        self.p_hist = (self.p_hist + 1).min(2);
        // Level n−2 now becomes n−3 for the next step.
        self.h0_n3 = self.hist[1].h0;
        self.velocity = v;
        self.last_load = Some(load);
        let mut e = self.finish(&ctx, out, true);
        e.diagnostics.film_floor_active = floor;
        e.diagnostics.substeps = substeps as u32;
        self.last = Some(e);
        e
    }

    // ------------------------------------------------------------------
    // Newton
    // ------------------------------------------------------------------

    /// Newton on the current state as initial guess.
    pub(crate) fn solve(&mut self, ctx: &Ctx) -> Outcome {
        let max_it = self.settings.max_iterations;
        let tol = self.settings.tolerance;
        let mut out = Outcome {
            status: Status::MaxIterations,
            iterations: 0,
            inner_iterations: 0,
            residual: f64::NAN,
            backtracks: 0,
        };
        self.w.linearised = None;
        if let Gap::Prescribed(h) = ctx.gap {
            self.h0 = h;
        }
        if !assemble(&self.d, &self.hist, &self.p, self.h0, ctx, &mut self.w) {
            out.status = Status::NonFinite;
            return out;
        }
        // Norm of the previous update when it was taken in full.
        let mut previous: Option<f64> = None;
        for k in 1..=max_it {
            out.iterations = k;
            let Some(dh) = factor_solve(&mut self.w) else {
                out.status = Status::NonFinite;
                return out;
            };
            let scale = norm_scale(&self.p, self.h0, self.d.p_amb);
            let norm = scaled_norm(&self.w.dp, dh, scale);
            out.residual = norm;
            if !norm.is_finite() {
                out.status = Status::NonFinite;
                return out;
            }
            // Error left after this update (time steps only; steady solves
            // iterate until the update itself is within the tolerance).
            let left = match previous {
                Some(prev) if prev > 0.0 => {
                    self.contraction =
                        (norm / (prev * prev)).clamp(CONTRACTION_MIN, CONTRACTION_MAX);
                    self.contraction * norm * norm
                }
                // From the predictor: K carried from earlier steps.
                None if k == 1 => self.contraction * norm * norm,
                // After a damped update (or a zero one) K is unknown.
                _ => f64::INFINITY,
            };
            if norm <= tol || (ctx.time.is_some() && left <= tol) {
                for (p, dp) in self.p.iter_mut().zip(&self.w.dp) {
                    *p += dp;
                }
                self.h0 += dh;
                self.w.linearised = Some(dh);
                out.status = Status::Converged;
                return out;
            }
            // Trust region on the gap: |Δh0| ≤ 25 % of h0 per iteration.
            let mut lambda: f64 = 1.0;
            if dh.abs() > H0_TRUST * self.h0 {
                lambda = H0_TRUST * self.h0 / dh.abs();
            }
            let mut accepted = false;
            // Deep in the quadratic region the full step is taken untested.
            let test = norm > SMALL_UPDATE;
            for _ in 0..12 {
                let h_trial = self.h0 + lambda * dh;
                for ((pt, p), dp) in self.w.p_trial.iter_mut().zip(&self.p).zip(&self.w.dp) {
                    *pt = p + lambda * dp;
                }
                let pt = std::mem::take(&mut self.w.p_trial);
                let ok = assemble(&self.d, &self.hist, &pt, h_trial, ctx, &mut self.w);
                self.w.p_trial = pt;
                if ok && !test && lambda == 1.0 && dh.abs() <= H0_TRUST * self.h0 {
                    accepted = true;
                    self.h0 = h_trial;
                    break;
                }
                if ok {
                    let dhb = direction_with_old_factors(&mut self.w);
                    let nb = scaled_norm(&self.w.dbar, dhb, scale);
                    if nb.is_finite() && nb <= (1.0 - 0.25 * lambda) * norm {
                        accepted = true;
                        self.h0 = h_trial;
                        break;
                    }
                    if lambda < 1.0 / 256.0 {
                        // Cannot find descent: take the small step and go on.
                        accepted = true;
                        self.h0 = h_trial;
                        break;
                    }
                }
                lambda *= 0.5;
                out.backtracks += 1;
            }
            if !accepted {
                out.status = Status::NonFinite;
                return out;
            }
            previous = (lambda == 1.0).then_some(norm);
            std::mem::swap(&mut self.p, &mut self.w.p_trial);
        }
        out
    }

    /// March the step in `m` backward-Euler sub-steps of Δt/m from the
    /// previous state (in `w.p_backup`, `h_start`), with velocity and load
    /// interpolated. The stored history is saved and restored around it.
    fn solve_substepped(&mut self, ctx: &Ctx, m: usize, h_start: f64) -> Outcome {
        let Some((_, dt)) = ctx.time else {
            return self.solve(ctx);
        };
        self.p.copy_from_slice(&self.w.p_backup);
        self.h0 = h_start;
        for (save, lvl) in self.hist_save.iter_mut().zip(&self.hist) {
            save.clone_from(lvl);
        }
        // The inertia term's previous slope, rescaled to the sub-step.
        self.hist[1].h0 = self.hist[0].h0 - (self.hist[0].h0 - self.hist[1].h0) / m as f64;
        let (v0, f0) = (self.velocity, self.last_load.unwrap_or(ctx.load));
        let mut total = Outcome {
            status: Status::Converged,
            iterations: 0,
            inner_iterations: 0,
            residual: 0.0,
            backtracks: 0,
        };
        for j in 1..=m {
            let w = j as f64 / m as f64;
            let sub = Ctx {
                v: v0 + w * (ctx.v - v0),
                load: f0 + w * (ctx.load - f0),
                time: Some((StepCoefficients::BDF1, dt / m as f64)),
                gap: ctx.gap,
            };
            let o = self.solve(&sub);
            total.iterations += o.iterations;
            total.backtracks += o.backtracks;
            total.residual = o.residual;
            if o.status != Status::Converged {
                total.status = o.status;
                break;
            }
            if j < m {
                let f_net = self.w.f_net;
                self.push_history_current(f_net);
                self.w.linearised = None;
            }
        }
        for (lvl, save) in self.hist.iter_mut().zip(&self.hist_save) {
            lvl.clone_from(save);
        }
        self.w.hist_term_valid = None;
        total
    }

    // ------------------------------------------------------------------
    // Post-processing
    // ------------------------------------------------------------------

    fn finish(&mut self, ctx: &Ctx, out: Outcome, advance: bool) -> Estimate {
        let d = &self.d;
        let n = d.grid.n;
        let (b, dx) = (d.grid.width, d.grid.dx);
        let v = ctx.v;
        let mut sum_p = 0.0;
        let sum_asp = d.contact.pressure_sum(self.h0).0;
        let sum_area = d.contact.area_sum(self.h0);
        let mut visc = 0.0;
        let mut p_max = f64::NEG_INFINITY;
        let mut cav = 0usize;
        // After a converged Newton update the last assembly point differs from
        // the state by the update (≤ tolerance): first-order corrections of
        // the stored properties are exact to O(tolerance²).
        let lin = self.w.linearised.take().is_some();
        // Vapour fraction α > ½ ⇔ ρ < (ρl + ρg)/2 (α = (ρl − ρ)/(ρl − ρg)).
        let rho_half = 0.5 * (d.eos.rho_l + d.eos.rho_g);
        let p = &self.p[..n];
        let gc = &d.grid.g_cell[..n];
        let tmp = &mut self.w.tmp[..n];
        let vdx = v * dx;
        for i in 0..n {
            let h = self.h0 + gc[i];
            let pi = p[i];
            let (rho, mu) = if lin {
                let c = &self.w.cells[i];
                let dp = self.w.dp[i];
                (c.rho + c.drho * dp, c.mu + c.dmu * dp)
            } else {
                let s = d.eos.eval(pi);
                (s.rho, s.mu)
            };
            sum_p += pi - d.p_amb;
            // Face pressures: the mean of the neighbours, p_amb at the edges;
            // p_r − p_l = ½ (p_(i+1) − p_(i−1)).
            let pl = if i == 0 {
                d.p_amb
            } else {
                0.5 * (p[i - 1] + pi)
            };
            let pr = if i + 1 == n {
                d.p_amb
            } else {
                0.5 * (pi + p[i + 1])
            };
            visc += -0.5 * h * (pr - pl) + mu * vdx / h;
            p_max = p_max.max(pi);
            cav += (rho < rho_half) as usize;
            tmp[i] = rho * h;
        }
        let f_hyd = b * dx * sum_p;
        let f_asp = b * dx * sum_asp;
        let f_visc = b * visc;
        let f_net = f_hyd + f_asp - ctx.load;
        let load = ctx.load;
        let (inertia, load_res) = match ctx.time {
            Some((c, dt)) if self.hist_len >= 1 => {
                let h1 = self.hist[0].h0;
                let h2 = if self.hist_len >= 2 {
                    self.hist[1].h0
                } else {
                    h1
                };
                let acc = (self.h0 - 2.0 * h1 + h2) / (dt * dt);
                let inertia = d.mass * acc;
                let weighted =
                    c.w[0] * f_net + c.w[1] * self.hist[0].f_net + c.w[2] * self.hist[1].f_net;
                (inertia, (inertia - weighted).abs() / load)
            }
            _ => (0.0, f_net.abs() / load),
        };
        let friction = f_visc + d.mu_bl * f_asp * (v / d.v_reg).tanh();
        let cof = (f_visc.abs() + d.mu_bl * f_asp) / load;
        let share = f_asp / load;
        let load_residual = match ctx.gap {
            Gap::Balance => load_res,
            Gap::Prescribed(_) => f64::NAN,
        };
        if advance {
            self.time += ctx.time.map_or(0.0, |(_, dt)| dt);
            // The θ scheme needs this level's flux divergence.
            let needs_div = ctx.time.is_some_and(|(c, _)| c.uses_force_history())
                || StepCoefficients::for_scheme(self.settings.scheme).uses_force_history();
            self.hist.swap(0, 1);
            self.w.hist_term_valid = None;
            let lvl = &mut self.hist[0];
            lvl.rho_h.copy_from_slice(&self.w.tmp);
            lvl.f_net = f_net;
            lvl.h0 = self.h0;
            self.hist_len = (self.hist_len + 1).min(2);
            if needs_div {
                let c_steady = Ctx {
                    time: None,
                    gap: Gap::Prescribed(self.h0),
                    ..*ctx
                };
                assemble(
                    &self.d,
                    &self.hist,
                    &self.p,
                    self.h0,
                    &c_steady,
                    &mut self.w,
                );
                let lvl = &mut self.hist[0];
                for i in 0..n {
                    lvl.div[i] = self.w.faces[i + 1].q - self.w.faces[i].q;
                }
            }
        }
        Estimate {
            time: self.time,
            velocity: v,
            load,
            h0: self.h0,
            h_min: self.h0 + self.d.grid.g_min,
            hydrodynamic_force: f_hyd,
            asperity_force: f_asp,
            viscous_force: f_visc,
            friction_force: friction,
            cof,
            asperity_load_share: share,
            inertia_force: inertia,
            contact_area_ratio: sum_area / n as f64,
            max_pressure: p_max,
            cavitated_fraction: cav as f64 / n as f64,
            regime: Regime::from_asperity_share(share),
            status: out.status,
            diagnostics: Diagnostics {
                iterations: out.iterations,
                inner_iterations: out.inner_iterations,
                residual: out.residual,
                load_residual,
                backtracks: out.backtracks,
                film_floor_active: false,
                substeps: 0,
            },
        }
    }
}

/// Scaled max-norm of an update: pressure relative to max(p_amb, max|p|),
/// h0 relative to itself.
pub(crate) fn scaled_norm(dp: &[f64], dh: f64, scale: (f64, f64)) -> f64 {
    let dmax = dp.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    if dmax.is_nan() {
        return f64::NAN;
    }
    (dmax / scale.0).max(dh.abs() / scale.1)
}

/// Scales of an iterate for [`scaled_norm`]: max(p_amb, max|p|) and h0. A
/// line search measures the update and the trial correction on the scales
/// of the *current* iterate, so that the merit is consistent.
pub(crate) fn norm_scale(p: &[f64], h0: f64, p_amb: f64) -> (f64, f64) {
    let pmax = p.iter().fold(p_amb, |m, x| m.max(x.abs()));
    (pmax, h0.abs().max(f64::MIN_POSITIVE))
}

/// What a face flux needs besides the two neighbouring states.
struct FluxCtx<'a> {
    d: &'a Disc,
    half_v: f64,
    upwind_left: bool,
}

impl FluxCtx<'_> {
    /// Mass flux through a face of thickness `hf` between (pl, l) and (pr, r).
    #[inline(always)]
    fn flux(
        &self,
        hf: f64,
        inv_df: f64,
        pl: f64,
        l: &CellProps,
        pr: f64,
        r: &CellProps,
    ) -> FaceFlux {
        let d = self.d;
        let (phi, dphi, phis, dphis) = match &d.ff {
            Some(ff) => {
                let (a, b) = ff.pressure(hf);
                let (c, e) = ff.shear(hf);
                (a, b, c, e)
            }
            None => (1.0, 0.0, 0.0, 0.0),
        };
        let h2 = hf * hf;
        let k = inv_df * (1.0 / 12.0);
        let cf = phi * h2 * hf * k;
        let dcf = (dphi * hf + 3.0 * phi) * h2 * k;
        let ch = hf + d.sigma * phis;
        let dch = 1.0 + d.sigma * dphis;
        let gbar = 0.5 * (l.gr + r.gr);
        let dpf = pr - pl;
        let cg = cf * gbar;
        let mut out = FaceFlux {
            q: -cg * dpf,
            dql: cg - 0.5 * cf * l.dgr * dpf,
            dqr: -cg - 0.5 * cf * r.dgr * dpf,
            dqh: -dcf * gbar * dpf,
        };
        let hv = self.half_v;
        if self.upwind_left {
            out.q += hv * ch * l.rho;
            out.dqh += hv * dch * l.rho;
            out.dql += hv * ch * l.drho;
        } else {
            out.q += hv * ch * r.rho;
            out.dqh += hv * dch * r.rho;
            out.dqr += hv * ch * r.drho;
        }
        out
    }
}

/// Assemble residual and Jacobian at (p, h0). Returns false when anything is
/// non-finite.
pub(crate) fn assemble(
    d: &Disc,
    hist: &[Level; 2],
    p: &[f64],
    h0: f64,
    ctx: &Ctx,
    w: &mut Work,
) -> bool {
    let n = d.grid.n;
    let dx = d.grid.dx;
    let inv_dx = 1.0 / dx;
    let p = &p[..n];
    // Pass 1: cell properties (independent per cell, so the exp latencies
    // overlap; fusing the passes was measured slower).
    let cells = &mut w.cells[..n];
    for (c, &pi) in cells.iter_mut().zip(p) {
        let s = d.eos.cell(pi);
        *c = CellProps {
            rho: s.rho,
            drho: s.drho,
            gr: s.gr,
            dgr: s.dgr,
            mu: s.mu,
            dmu: s.dmu,
        };
    }
    // Pass 2: face fluxes.
    let boundary = CellProps {
        rho: d.rho_b,
        drho: 0.0,
        gr: d.gr_b,
        dgr: 0.0,
        ..CellProps::default()
    };
    let fx = FluxCtx {
        d,
        half_v: 0.5 * ctx.v,
        upwind_left: ctx.v >= 0.0,
    };
    let faces = &mut w.faces[..=n];
    let gf = &d.grid.g_face[..=n];
    faces[0] = fx.flux(
        h0 + gf[0],
        2.0 * inv_dx,
        d.p_amb,
        &boundary,
        p[0],
        &cells[0],
    );
    faces[n] = fx.flux(
        h0 + gf[n],
        2.0 * inv_dx,
        p[n - 1],
        &cells[n - 1],
        d.p_amb,
        &boundary,
    );
    for (((fc, g), cw), pw) in faces[1..n]
        .iter_mut()
        .zip(&gf[1..n])
        .zip(cells.windows(2))
        .zip(p.windows(2))
    {
        *fc = fx.flux(h0 + g, inv_dx, pw[0], &cw[0], pw[1], &cw[1]);
    }
    // Pass 3: rows.
    let w0 = ctx.w0();
    let (coef, inv_dt) = match ctx.time {
        Some((c, dt)) => (c, 1.0 / dt),
        None => (
            StepCoefficients {
                a: [0.0; 3],
                w: [1.0, 0.0, 0.0],
            },
            0.0,
        ),
    };
    let st = dx * inv_dt;
    let sa0 = st * coef.a[0];
    let (h1, h2) = (&hist[0], &hist[1]);
    let key = Some(ctx.time.map(|(c, dt)| (c.a, c.w, dt)));
    if w.hist_term_valid != key {
        // The history part of the storage and flux terms is fixed in a step.
        for (i, t) in w.hist_term.iter_mut().enumerate() {
            *t = st * (coef.a[1] * h1.rho_h[i] + coef.a[2] * h2.rho_h[i])
                + coef.w[1] * h1.div[i]
                + coef.w[2] * h2.div[i];
        }
        w.hist_term_valid = key;
    }
    let rows = &mut w.rows[..n];
    let gc = &d.grid.g_cell[..n];
    let hist_term = &w.hist_term[..n];
    let source = &w.source[..n];
    let has_source = w.has_source;
    let mut sum_p = 0.0;
    let mut finite = true;
    for (i, (((row, fw), c), (&g, &pi))) in rows
        .iter_mut()
        .zip(faces.windows(2))
        .zip(cells.iter())
        .zip(gc.iter().zip(p))
        .enumerate()
    {
        let hc = h0 + g;
        let (fl, fr) = (&fw[0], &fw[1]);
        let mut r = w0 * (fr.q - fl.q) + sa0 * c.rho * hc + hist_term[i];
        if has_source {
            r -= source[i];
        }
        let col = w0 * (fr.dqh - fl.dqh) + sa0 * c.rho;
        *row = Row {
            a: -w0 * fl.dql,
            b: w0 * (fr.dql - fl.dqr) + sa0 * c.drho * hc,
            c: w0 * fr.dqr,
            col,
            r,
        };
        sum_p += pi - d.p_amb;
        finite &= (r + col).is_finite();
    }
    rows[0].a = 0.0;
    rows[n - 1].c = 0.0;
    let (sum_asp, sum_dasp) = d.contact.pressure_sum(h0);
    let bdx = d.grid.width * dx;
    let f_net = bdx * (sum_p + sum_asp) - ctx.load;
    w.f_net = f_net;
    match ctx.time {
        Some((c, dt)) => {
            let inv_dt2 = 1.0 / (dt * dt);
            w.g = d.mass * (h0 - 2.0 * h1.h0 + h2.h0) * inv_dt2
                - (c.w[0] * f_net + c.w[1] * h1.f_net + c.w[2] * h2.f_net);
            w.dgdh = d.mass * inv_dt2 - c.w[0] * bdx * sum_dasp;
            w.c_row = -c.w[0] * bdx;
        }
        None => {
            w.g = -f_net;
            w.dgdh = -bdx * sum_dasp;
            w.c_row = -bdx;
        }
    }
    w.balance = ctx.gap == Gap::Balance;
    finite && w.g.is_finite()
}

/// Factor the bordered system and solve it for the Newton direction.
///
/// The tridiagonal block is factored "twisted" (burn at both ends): rows
/// 0..k are eliminated downwards and rows N−1..k+1 upwards, meeting at
/// k = N/2. The two recurrences are independent, so their division latencies
/// overlap (the sweep is latency-bound, not flop-bound); stability is that of
/// the Thomas algorithm. Both right-hand sides (residual and border column)
/// ride along. Direction into `w.dp`; returns Δh0, or None when the system is
/// singular or non-finite.
pub(crate) fn factor_solve(w: &mut Work) -> Option<f64> {
    let n = w.rows.len();
    let k = n / 2;
    let nb = n - 1 - k;
    let rows = &w.rows[..n];
    let fs = &mut w.factors[..n];
    let y = &mut w.dp[..n];
    // Downward (top) and upward (bottom) eliminations, interleaved.
    let (mut pt, mut zt, mut yt) = (0.0, 0.0, 0.0);
    let (mut pb, mut zb, mut yb) = (0.0, 0.0, 0.0);
    for j in 0..k {
        let t = &rows[j];
        let inv = 1.0 / (t.b - t.a * pt);
        pt = t.c * inv;
        zt = (t.col - t.a * zt) * inv;
        yt = (t.r - t.a * yt) * inv;
        fs[j] = Factor {
            fa: t.a,
            cp: pt,
            inv_m: inv,
            z: zt,
        };
        y[j] = yt;
        if j < nb {
            let i = n - 1 - j;
            let u = &rows[i];
            let inv = 1.0 / (u.b - u.c * pb);
            pb = u.a * inv;
            zb = (u.col - u.c * zb) * inv;
            yb = (u.r - u.c * yb) * inv;
            fs[i] = Factor {
                fa: u.c,
                cp: pb,
                inv_m: inv,
                z: zb,
            };
            y[i] = yb;
        }
    }
    // Meeting row.
    let m = &rows[k];
    let inv = 1.0 / (m.b - m.a * pt - m.c * pb);
    let zk = (m.col - m.a * zt - m.c * zb) * inv;
    let yk = (m.r - m.a * yt - m.c * yb) * inv;
    fs[k] = Factor {
        fa: 0.0,
        cp: 0.0,
        inv_m: inv,
        z: zk,
    };
    y[k] = yk;
    // Back substitution outwards from k, both directions interleaved.
    let (mut sz, mut sy) = (zk, yk);
    let (mut zu, mut yu, mut zd, mut yd) = (zk, yk, zk, yk);
    for j in 1..=k.max(nb) {
        if j <= k {
            let i = k - j;
            let f = &mut fs[i];
            f.z -= f.cp * zu;
            y[i] -= f.cp * yu;
            zu = f.z;
            yu = y[i];
            sz += zu;
            sy += yu;
        }
        if j <= nb {
            let i = k + j;
            let f = &mut fs[i];
            f.z -= f.cp * zd;
            y[i] -= f.cp * yd;
            zd = f.z;
            yd = y[i];
            sz += zd;
            sy += yd;
        }
    }
    if !(sz.is_finite() && sy.is_finite()) {
        return None;
    }
    if !w.balance {
        for v in y.iter_mut() {
            *v = -*v;
        }
        return Some(0.0);
    }
    w.schur = w.dgdh - w.c_row * sz;
    if !(w.schur.is_finite() && w.schur != 0.0) {
        return None;
    }
    let dh = (-w.g + w.c_row * sy) / w.schur;
    for (v, f) in y.iter_mut().zip(fs.iter()) {
        *v = -*v - f.z * dh;
    }
    Some(dh)
}

/// Simplified Newton direction: the current residual (rows' r, w.g) with the
/// stored (old) factors, into `w.dbar`. Returns Δh0.
pub(crate) fn direction_with_old_factors(w: &mut Work) -> f64 {
    let n = w.rows.len();
    let k = n / 2;
    let nb = n - 1 - k;
    let rows = &w.rows[..n];
    let fs = &w.factors[..n];
    let y = &mut w.dbar[..n];
    let (mut yt, mut yb) = (0.0, 0.0);
    for j in 0..k {
        yt = (rows[j].r - fs[j].fa * yt) * fs[j].inv_m;
        y[j] = yt;
        if j < nb {
            let i = n - 1 - j;
            yb = (rows[i].r - fs[i].fa * yb) * fs[i].inv_m;
            y[i] = yb;
        }
    }
    let m = &rows[k];
    let yk = (m.r - m.a * yt - m.c * yb) * fs[k].inv_m;
    y[k] = yk;
    let mut sy = yk;
    let (mut yu, mut yd) = (yk, yk);
    for j in 1..=k.max(nb) {
        if j <= k {
            let i = k - j;
            y[i] -= fs[i].cp * yu;
            yu = y[i];
            sy += yu;
        }
        if j <= nb {
            let i = k + j;
            y[i] -= fs[i].cp * yd;
            yd = y[i];
            sy += yd;
        }
    }
    if w.balance {
        let dh = (-w.g + w.c_row * sy) / w.schur;
        for (v, f) in y.iter_mut().zip(fs) {
            *v = -*v - f.z * dh;
        }
        dh
    } else {
        for v in y.iter_mut() {
            *v = -*v;
        }
        0.0
    }
}

#[cfg(test)]
mod jacobian_tests {
    //! The analytic Jacobian equals central finite differences of the
    //! residual, for random states (property test).
    use super::*;
    use crate::physics::params::{Pocket, Profile, TimeScheme};
    use proptest::prelude::*;

    fn residual(s: &mut Solver, p: &[f64], h0: f64, ctx: &Ctx) -> (Vec<f64>, f64) {
        assemble(&s.d, &s.hist, p, h0, ctx, &mut s.w);
        (s.w.rows.iter().map(|r| r.r).collect(), s.w.g)
    }

    #[allow(clippy::too_many_arguments)]
    fn check(
        profile: Profile,
        pocket: bool,
        flow_factors: bool,
        sigma: f64,
        p: Vec<f64>,
        h0: f64,
        v: f64,
        theta: bool,
    ) {
        let mut m = ModelParams::default();
        m.geometry.profile = profile;
        if pocket {
            m.geometry.pockets.push(Pocket {
                start: 0.02,
                width: 0.011,
                depth: 4e-6,
            });
        }
        m.roughness.flow_factors = flow_factors;
        m.roughness.sigma = sigma;
        let st = SolverSettings {
            cells: p.len(),
            scheme: if theta {
                TimeScheme::PAPER
            } else {
                TimeScheme::Bdf2
            },
            ..Default::default()
        };
        let mut s = Solver::new(&m, &st).unwrap();
        s.initialize_steady(0.1, 20_000.0);
        let coef = StepCoefficients::for_scheme(st.scheme);
        let ctx = Ctx {
            v,
            load: 20_000.0,
            time: Some((coef, st.dt)),
            gap: Gap::Balance,
        };
        assemble(&s.d, &s.hist, &p, h0, &ctx, &mut s.w);
        let rows = s.w.rows.clone();
        let (c_row, dgdh) = (s.w.c_row, s.w.dgdh);
        // Magnitude of the terms of G, for its rounding error.
        let bdx = s.d.grid.width * s.d.grid.dx;
        let g_mag = bdx * p.iter().map(|x| x.abs()).sum::<f64>()
            + bdx * s.d.contact.pressure_sum(h0).0
            + ctx.load
            + s.d.mass * h0 / (st.dt * st.dt);
        let n = p.len();
        let scale: Vec<f64> = rows
            .iter()
            .map(|r| r.a.abs().max(r.b.abs()).max(r.c.abs()) + 1e-300)
            .collect();
        // Magnitude of the terms of each mass residual (storage levels and
        // face fluxes), for the rounding error of a difference quotient.
        let g_max = s.d.grid.g_cell.iter().cloned().fold(0.0, f64::max);
        let storage = s.d.grid.dx / st.dt * 4.0 * s.d.eos.rho_l * (h0 + g_max);
        let r_mag: Vec<f64> = (0..n)
            .map(|i| storage + s.w.faces[i].q.abs() + s.w.faces[i + 1].q.abs())
            .collect();
        let close = |fd: f64, an: f64, sc: f64, round: f64, what: &str| {
            assert!(
                (fd - an).abs() <= 1e-5 * (an.abs() + sc) + round,
                "{what}: finite difference {fd:e} vs analytic {an:e}"
            );
        };
        for j in 0..n {
            let h = 1e-6 * p[j].abs().max(1e5);
            let (mut pp, mut pm) = (p.clone(), p.clone());
            pp[j] += h;
            pm[j] -= h;
            let (rp, gp) = residual(&mut s, &pp, h0, &ctx);
            let (rm, gm) = residual(&mut s, &pm, h0, &ctx);
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                let an = if i == j {
                    rows[i].b
                } else if i + 1 == j {
                    rows[i].c
                } else if j + 1 == i {
                    rows[i].a
                } else {
                    0.0
                };
                let round = 8.0 * f64::EPSILON * r_mag[i] / h;
                close(fd, an, scale[i], round, &format!("dR{i}/dp{j}"));
            }
            let fd = (gp - gm) / (2.0 * h);
            assert!(
                (fd - c_row).abs() <= 1e-5 * c_row.abs() + 8.0 * f64::EPSILON * g_mag / h,
                "dG/dp{j}: finite difference {fd:e} vs analytic {c_row:e}"
            );
        }
        let hh = 1e-7 * h0;
        let (rp, gp) = residual(&mut s, &p, h0 + hh, &ctx);
        let (rm, gm) = residual(&mut s, &p, h0 - hh, &ctx);
        for i in 0..n {
            let col_scale = rows.iter().map(|r| r.col.abs()).fold(0.0, f64::max);
            let round = 8.0 * f64::EPSILON * r_mag[i] / hh;
            close(
                (rp[i] - rm[i]) / (2.0 * hh),
                rows[i].col,
                col_scale,
                round,
                &format!("dR{i}/dh0"),
            );
        }
        let fd = (gp - gm) / (2.0 * hh);
        assert!(
            (fd - dgdh).abs() <= 1e-5 * dgdh.abs() + 8.0 * f64::EPSILON * g_mag / hh,
            "dG/dh0: finite difference {fd:e} vs analytic {dgdh:e}"
        );
    }

    fn profile() -> impl Strategy<Value = Profile> {
        prop_oneof![
            (5e-6..40e-6f64).prop_map(|depth| Profile::Parabolic { depth }),
            (1e-6..20e-6f64).prop_map(|depth| Profile::Linear { depth }),
            Just(Profile::Flat),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn jacobian_matches_finite_differences(
            profile in profile(),
            pocket in any::<bool>(),
            p in prop::collection::vec(prop_oneof![2e3..1.2e5f64, 1e5..4e6f64], 6..20),
            h0 in 8e-6..30e-6f64,
            v in -3.0..3.0f64,
            theta in any::<bool>(),
        ) {
            check(profile, pocket, false, 5e-6, p, h0, v, theta);
        }

        #[test]
        fn jacobian_with_flow_factors_matches_finite_differences(
            thick in any::<bool>(),
            p in prop::collection::vec(prop_oneof![2e3..1.2e5f64, 1e5..4e6f64], 6..20),
            h0f in 0.0..1.0f64,
            v in -3.0..3.0f64,
        ) {
            // Stay inside one branch of Table A1's φs (it jumps at H = 5).
            let (sigma, h0) = if thick { (1e-6, 6e-6 + 20e-6 * h0f) } else { (5e-6, 3e-6 + 20e-6 * h0f * 0.05) };
            check(Profile::Flat, false, true, sigma, p, h0, v, false);
        }
    }
}
