//! The coupled solver: transient Reynolds + mixture EOS + GW + load balance.
//!
//! ## Equations (docs/model.md §2, §5)
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
//! with `d_f = Δx` (interior) or `Δx/2` (edge face, ghost at p_amb) and
//! `ρ_up` the density of the upwind cell. Only the density is upwinded: h is
//! exact at the face, so in full film (ρ ≈ ρl) the scheme is second order and
//! in cavitated zones it is monotone, but first order (`solver.flux:
//! upwind`). With `solver.flux: muscl_*` (`flux.rs`; `muscl_van_leer` is the
//! default) ρ_up gains
//! half the upwind cell's limited slope: second order in cavitated zones
//! too, still conservative and free of new extrema; the rows then reach two
//! cells upwind and the solve is `banded.rs`'s. Cell i's residual is
//!
//! ```text
//! R_i = Δx Σ_k a_k (ρ h̄)_i^(n−k) / Δt + Σ_k w_k (q_(i+1) − q_i)^(n−k) − s_i
//! G   = m Σ_k c_k h0^(n−k) / Δt² − Σ_k w_k (F_hyd + F_asp − F_ext)^(n−k)
//! ```
//!
//! (`s_i` an optional external mass source, zero unless set.)
//!
//! ## Where each part lives
//!
//! | file | content |
//! |---|---|
//! | `mod.rs` | [`Solver`]: state, discretisation data, accessors; [`PreparedModel`] |
//! | `history.rs` | time levels: starting states and the history of past levels |
//! | `step.rs` | one time step: input checks, predictor, Newton and its fallbacks |
//! | `steady.rs` | steady states (Stribeck points) and continuation |
//! | `newton.rs` | Newton iteration, line search, sub-stepping |
//! | `assembly.rs` | residual and Jacobian of one iterate |
//! | `work.rs` | the scratch memory: cell, face and row columns, factors, buffers |
//! | `cell_pass.rs` | pass 1 of the assembly: per-cell density, viscosity ratio and their derivatives |
//! | `flux.rs` | the MUSCL Couette flux: the limited slope's part of each face flux |
//! | `bordered.rs` | the tridiagonal-plus-border linear solve |
//! | `banded.rs` | the pentadiagonal-plus-border linear solve (MUSCL flux) |
//! | `border.rs` | the load-balance border and the Schur-complement close both solves share |
//! | `lanes.rs` | lane-wise sums and maxima that vectorise |
//! | `postprocess.rs` | forces, friction and diagnostics of a solved state |
//! | `predictor.rs` | the earlier levels the time step's warm start extrapolates from |
//! | `reference.rs` | the paper's Algorithm 1 (Picard + secant), the verification reference |
//! | `breakdown.rs` | the cost of each part of an iteration (a benchmark aid) |

mod assembly;
mod banded;
mod border;
mod bordered;
mod breakdown;
mod cell_pass;
mod flux;
mod history;
mod lanes;
mod newton;
mod postprocess;
mod predictor;
mod reference;
mod steady;
mod step;
mod work;

pub use breakdown::StepBreakdown;
pub(crate) use work::Work;

use super::eos::MixtureEos;
use super::error::SetupError;
use super::estimate::{Estimate, Status};
use super::flow_factors::FlowFactors;
use super::geometry::Grid;
use super::gw::{Greenwood, SummedContact};
use super::params::ModelParams;
use super::scheme::StepCoefficients;
use super::settings::{Method, SolverSettings};
use super::terms::soft_width::WidthScale;
use super::terms::{FrictionTerms, TermStates};
use newton::CONTRACTION_MAX;
use predictor::Predictor;

/// The film's model discretised on its grid, immutable between model swaps
/// (the friction terms, which act after the film, are [`Solver`]'s `terms`).
#[derive(Debug, Clone)]
pub(crate) struct Disc {
    pub grid: Grid,
    pub eos: MixtureEos,
    pub gw: Greenwood,
    /// GW contact summed over the cells, as a function of h0.
    pub contact: SummedContact,
    pub ff: Option<FlowFactors>,
    /// The Couette flux's face density.
    pub flux: super::settings::CouetteFlux,
    pub sigma: f64,
    pub p_amb: f64,
    /// ρ, ρ/μ at the domain's edges (ambient pressure).
    pub rho_edge: f64,
    pub gr_edge: f64,
    pub mass: f64,
    pub min_film: f64,
    pub guard: step::PredictionGuard,
}

/// Which instruction-set version of the step runs (detected once, in
/// [`Solver::new`]). The hot loops are written so that they vectorise; the
/// step is compiled once per version with the wider vectors enabled and the
/// CPU picks the widest it has. Rust never fuses a multiply and an add on
/// its own, so every version computes the same numbers bit for bit (a test
/// checks it); only the speed differs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Isa {
    /// The target's baseline (SSE2 on x86-64).
    Baseline,
    /// AVX2 (x86-64).
    Avx2,
    /// AVX-512 F/DQ/VL (x86-64).
    Avx512,
}

impl Isa {
    /// The widest version this CPU runs.
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            let avx2 = has!("avx2")
                && has!("fma")
                && has!("bmi1")
                && has!("bmi2")
                && has!("lzcnt")
                && has!("popcnt");
            if avx2 && has!("avx512f") && has!("avx512dq") && has!("avx512vl") {
                return Isa::Avx512;
            }
            if avx2 {
                return Isa::Avx2;
            }
        }
        Isa::Baseline
    }
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
    /// Copy another level's values into this one's buffers (no allocation).
    pub(crate) fn copy_from(&mut self, other: &Level) {
        self.rho_h.copy_from_slice(&other.rho_h);
        self.div.copy_from_slice(&other.div);
        self.f_net = other.f_net;
        self.h0 = other.h0;
    }

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
pub(crate) enum H0Mode {
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
    pub gap: H0Mode,
}

impl Ctx {
    pub(crate) fn w0(&self) -> f64 {
        self.time.map_or(1.0, |(c, _)| c.w[0])
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
    /// The friction terms beside the film's shear, composed by
    /// [`crate::physics::terms`] after the film is solved (they do not act
    /// on the film; the soft width's scale is applied to its forces).
    pub(crate) terms: FrictionTerms,
    /// The geometry the grid was built from (a swapped model must match it).
    geometry: super::params::Geometry,
    pub(crate) settings: SolverSettings,
    pub(crate) p: Vec<f64>,
    pub(crate) h0: f64,
    pub(crate) time: f64,
    /// Time is `time_base + time_steps · dt`: counted in whole steps from
    /// the last start or variable-length step, never summed step by step
    /// (a sum of 4 000 steps of 1 ms is 3.9999999999996705 s).
    time_base: f64,
    time_steps: u64,
    pub(crate) velocity: f64,
    pub(crate) hist: [Level; 2],
    /// Scratch copy of the history while a step is sub-stepped.
    hist_save: [Level; 2],
    /// Load of the last accepted step (sub-steps interpolate from it).
    last_load: Option<f64>,
    /// Number of valid history levels (0, 1 or 2).
    pub(crate) hist_len: usize,
    pub(crate) w: Work,
    /// Earlier levels kept for the time step's warm start.
    predictor: Predictor,
    /// Newton contraction constant K (see the module doc).
    contraction: f64,
    anchor: (f64, f64, f64),
    last: Option<Estimate>,
    /// The friction terms' states, owned beside the terms: the pre-sliding
    /// displacement z ([`crate::physics::terms::presliding`]) and the soft
    /// width's B(F)/B of the solve in progress
    /// ([`crate::physics::WidthLaw`]; the solver works on the load per
    /// reference width, F/that).
    pub(crate) states: TermStates,
    /// The instruction-set version of the step.
    isa: Isa,
}

/// Model parameters prepared for a running solver: every table built and
/// buffer allocated here, off the loop thread, so that
/// [`Solver::swap_model`] changes the model between two steps in O(1)
/// without allocating. The geometry and the grid must be those of the
/// solver it is swapped into (lubricant, roughness, contact and drivetrain
/// may differ).
#[derive(Debug, Clone)]
pub struct PreparedModel {
    d: Disc,
    terms: FrictionTerms,
    cells: usize,
    geometry: super::params::Geometry,
}

/// Why a prepared model cannot replace a solver's.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelMismatch;

impl std::fmt::Display for ModelMismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the prepared model has another geometry or grid than the solver's (only lubricant, roughness, contact and drivetrain may change while running)")
    }
}

impl std::error::Error for ModelMismatch {}

impl Solver {
    /// Build the discretisation data of `model` on `settings.cells` cells.
    fn disc(model: &ModelParams, settings: &SolverSettings) -> Result<Disc, SetupError> {
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
        Ok(Disc {
            grid,
            eos,
            gw,
            contact,
            ff,
            flux: settings.flux,
            sigma: model.roughness.sigma,
            p_amb,
            rho_edge: sb.rho,
            gr_edge: sb.rho / sb.mu,
            mass: model.contact.mass,
            min_film: model.contact.min_film,
            guard: step::PredictionGuard::new(&eos, model.lubricant.saturation_pressure),
        })
    }

    /// Prepare `model` for [`Solver::swap_model`] (validates it; allocates).
    pub fn prepare_model(
        model: &ModelParams,
        settings: &SolverSettings,
    ) -> Result<PreparedModel, SetupError> {
        Ok(PreparedModel {
            d: Self::disc(model, settings)?,
            terms: model.terms,
            cells: settings.cells,
            geometry: model.geometry.clone(),
        })
    }

    /// Whether `m` can replace this solver's model (same geometry and grid).
    pub fn fits(&self, m: &PreparedModel) -> bool {
        m.cells == self.d.grid.n && m.geometry == self.geometry
    }

    /// Replace the model by a prepared one between two steps, keeping the
    /// state (pressures, h0, history). No allocation: `m` receives the old
    /// model, to be dropped off the loop thread.
    pub fn swap_model(&mut self, m: &mut PreparedModel) -> Result<(), ModelMismatch> {
        if !self.fits(m) {
            return Err(ModelMismatch);
        }
        std::mem::swap(&mut self.d, &mut m.d);
        std::mem::swap(&mut self.terms, &mut m.terms);
        // Each term's state carries over, or starts as if it had always
        // been on (pre-sliding switched on: the last state's level).
        let last = self.last.map(|e| e.contact_friction_force);
        self.states = self.terms.swapped(&m.terms, self.states, last);
        Ok(())
    }

    /// Build the solver: validates the parameters and allocates every buffer.
    /// Start it with [`Solver::initialize_steady`] or [`Solver::initialize_gap`]
    /// (a first [`Solver::step`] without either starts from the steady state).
    pub fn new(model: &ModelParams, settings: &SolverSettings) -> Result<Self, SetupError> {
        let d = Self::disc(model, settings)?;
        let n = settings.cells;
        let p_amb = d.p_amb;
        let mut s = Self {
            d,
            terms: model.terms,
            geometry: model.geometry.clone(),
            settings: *settings,
            p: vec![p_amb; n],
            h0: model.roughness.sigma * 3.0,
            time: 0.0,
            time_base: 0.0,
            time_steps: 0,
            velocity: 0.0,
            hist: [Level::new(n), Level::new(n)],
            hist_save: [Level::new(n), Level::new(n)],
            last_load: None,
            hist_len: 0,
            w: Work::new(n),
            predictor: Predictor::new(n, p_amb),
            contraction: CONTRACTION_MAX,
            anchor: (0.0, 0.0, 0.0),
            last: None,
            states: TermStates::default(),
            isa: Isa::Baseline,
        };
        s.set_isa(Isa::detect());
        s.w.p_anchor.copy_from_slice(&s.p);
        Ok(s)
    }

    /// The instruction-set version of the step in use.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Run another instruction-set version of the step; one this CPU does
    /// not have falls back to [`Isa::Baseline`]. Returns the version set.
    pub fn set_isa(&mut self, isa: Isa) -> Isa {
        let best = Isa::detect();
        let ok = match isa {
            Isa::Baseline => true,
            Isa::Avx2 => best != Isa::Baseline,
            Isa::Avx512 => best == Isa::Avx512,
        };
        self.isa = if ok { isa } else { Isa::Baseline };
        self.isa
    }

    /// The numerical settings the solver was built with.
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

    /// Cells along x.
    pub fn cells(&self) -> usize {
        self.d.grid.n
    }

    /// Cell width, m.
    pub fn dx(&self) -> f64 {
        self.d.grid.dx
    }

    /// Model time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Film thickness h0 of the current state, m.
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

    /// The load per reference width of a solve at `load` (N), after
    /// setting the width scale the solve's forces are reported with.
    pub(crate) fn per_reference_width(&mut self, load: f64) -> f64 {
        let scale = self.terms.soft_width.scale(load);
        self.states.soft_width = WidthScale(scale);
        load / scale
    }

    /// Restart the time count at `t`, s.
    pub(crate) fn set_time(&mut self, t: f64) {
        self.time = t;
        self.time_base = t;
        self.time_steps = 0;
    }

    /// Advance the time by one step of the configured length.
    pub(crate) fn advance_time(&mut self) {
        self.time_steps += 1;
        self.time = self.time_base + self.time_steps as f64 * self.settings.dt;
    }

    /// Change the liquid's viscosity between two steps (it follows the
    /// temperature). No allocation; the stored time levels are kept. A value
    /// that is not finite and positive is ignored (returns false).
    pub fn set_liquid_viscosity(&mut self, mu_l: f64) -> bool {
        if !(mu_l.is_finite() && mu_l > 0.0) {
            return false;
        }
        self.d.eos.mu_l = mu_l;
        let b = self.d.eos.eval(self.d.p_amb);
        self.d.rho_edge = b.rho;
        self.d.gr_edge = b.rho / b.mu;
        true
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
}
