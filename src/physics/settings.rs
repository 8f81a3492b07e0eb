//! Numerical settings of the solver (in-memory core types): the method,
//! the time scheme, the grid, tolerances, the Couette flux and its
//! limiter, and the reference (Picard) solver's relaxation. The physical
//! parameters are in [`super::params`]. Defaults follow `docs/model.md` (coupled
//! Newton, BDF2).

use super::error::SetupError;
use super::params::positive;

/// Which algorithm advances the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Coupled Newton on (p, h0) with a bordered tridiagonal solve (docs/model.md §7).
    #[default]
    Newton,
    /// The paper's Algorithm 1: under-relaxed Picard inside a secant loop on h0.
    Reference,
}

/// Time discretisation: the three-level θ family (docs/model.md §6).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TimeScheme {
    /// (θ1, θ2) = (1, 1).
    #[default]
    Bdf2,
    /// General three-level scheme with force weighting.
    Theta {
        /// θ1: the time derivative [(θ1+½) uⁿ − 2θ1 uⁿ⁻¹ + (θ1−½) uⁿ⁻²] / Δt.
        theta1: f64,
        /// θ2: the forces weighted ((θ1+θ2)/2, 1−θ2, (θ2−θ1)/2) over levels n, n−1, n−2.
        theta2: f64,
    },
}

impl TimeScheme {
    /// The paper's choice, taken from Profito et al. 2015.
    pub const PAPER: TimeScheme = TimeScheme::Theta {
        theta1: 2.0,
        theta2: 0.8,
    };
}

/// Settings of the paper's reference algorithm (Table A2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceSettings {
    /// Largest (initial) Picard under-relaxation ω_fluid.
    pub fluid_relaxation: f64,
    /// Smallest ω_fluid: ω is halved whenever the Picard update grows, and
    /// never below this (the paper's range is 5e-4 … 5e-2).
    pub fluid_relaxation_min: f64,
    /// Picard iterations per motion iteration, at most.
    pub max_fluid_iterations: u32,
    /// Picard: converged when the relative pressure update is below this.
    pub fluid_tolerance: f64,
    /// Under-relaxation of the load balance's secant h0 update.
    pub motion_relaxation: f64,
    /// Load-balance iterations per step, at most.
    pub max_motion_iterations: u32,
    /// Load balance: converged when the relative h0 update |Δh0| / h0 is below this.
    pub motion_tolerance: f64,
}

impl Default for ReferenceSettings {
    fn default() -> Self {
        Self {
            fluid_relaxation: 0.05,
            fluid_relaxation_min: 5e-4,
            max_fluid_iterations: 10_000,
            fluid_tolerance: 1e-4,
            motion_relaxation: 0.5,
            max_motion_iterations: 100,
            motion_tolerance: 1e-4,
        }
    }
}

/// The density at a face in the Couette (sliding) part of the mass flux
/// (`solver.flux`, see `solver/flux.rs`).
/// The default is MUSCL with the van Leer limiter: at N = 64 it gives the
/// loop area of the upwind flux at N = 256 (README accuracy guide).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CouetteFlux {
    /// The upwind cell's density: first order, monotone.
    Upwind,
    /// The upwind cell's density plus half a limited slope (MUSCL): second
    /// order where the density is smooth, the limiter's monotone first
    /// order at extrema and at the cavitation boundary.
    Muscl(Limiter),
}

impl Default for CouetteFlux {
    fn default() -> Self {
        CouetteFlux::Muscl(Limiter::VanLeer)
    }
}

/// Slope limiter of [`CouetteFlux::Muscl`]: the slope s(Δ−, Δ+) of the upwind
/// cell from its backward and forward differences, 0 when they differ in
/// sign (every one is TVD).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Limiter {
    /// The smaller difference: the most diffusive.
    Minmod,
    /// Their harmonic mean, 2Δ−Δ+/(Δ− + Δ+).
    VanLeer,
    /// Δ−Δ+(Δ− + Δ+)/(Δ−² + Δ+²).
    VanAlbada,
}

/// Numerical settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Finite-volume cells along x.
    pub cells: usize,
    /// Fixed time step, s.
    pub dt: f64,
    /// Newton (default) or the paper's reference algorithm.
    pub method: Method,
    /// The time discretisation (BDF2 or the paper's θ scheme).
    pub scheme: TimeScheme,
    /// Newton: converged when the scaled max-norm of the update is below this.
    pub tolerance: f64,
    /// Newton: bound on iterations per step.
    pub max_iterations: u32,
    /// The Couette flux's face density.
    pub flux: CouetteFlux,
    /// The reference algorithm's settings (`method: Reference`).
    pub reference: ReferenceSettings,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            cells: 64,
            dt: 1e-3,
            method: Method::Newton,
            scheme: TimeScheme::Bdf2,
            tolerance: 1e-6,
            max_iterations: 20,
            flux: CouetteFlux::default(),
            reference: ReferenceSettings::default(),
        }
    }
}

impl SolverSettings {
    /// Invariants the solver relies on.
    pub fn check(&self) -> Result<(), SetupError> {
        if self.cells < 4 {
            return Err(SetupError::invalid(
                "solver.cells",
                self.cells as f64,
                "need at least 4 cells",
            ));
        }
        positive("solver.dt", self.dt)?;
        positive("solver.tolerance", self.tolerance)?;
        if self.max_iterations == 0 {
            return Err(SetupError::invalid(
                "solver.max_iterations",
                0.0,
                "must be at least 1",
            ));
        }
        if let TimeScheme::Theta { theta1, theta2 } = self.scheme {
            if !(theta1.is_finite() && theta1 >= 0.5) {
                return Err(SetupError::invalid(
                    "solver.theta1",
                    theta1,
                    "must be >= 0.5 (theta1 = 0.5 is backward Euler, 1 is BDF2)",
                ));
            }
            if !(theta2.is_finite() && theta2 > 0.0) {
                return Err(SetupError::invalid("solver.theta2", theta2, "must be > 0"));
            }
        }
        if self.method == Method::Reference && self.flux != CouetteFlux::Upwind {
            return Err(SetupError::Unsupported {
                field: "solver.flux",
                reason: "the reference (Picard) solver has the upwind flux only; use solver.flux: upwind with solver.method: reference",
            });
        }
        let r = &self.reference;
        if !(r.fluid_relaxation > 0.0 && r.fluid_relaxation <= 1.0) {
            return Err(SetupError::invalid(
                "solver.reference.fluid_relaxation",
                r.fluid_relaxation,
                "must lie in (0, 1]",
            ));
        }
        if !(r.fluid_relaxation_min > 0.0 && r.fluid_relaxation_min <= r.fluid_relaxation) {
            return Err(SetupError::invalid(
                "solver.reference.fluid_relaxation_min",
                r.fluid_relaxation_min,
                "must lie in (0, fluid_relaxation]",
            ));
        }
        if !(r.motion_relaxation > 0.0 && r.motion_relaxation <= 1.0) {
            return Err(SetupError::invalid(
                "solver.reference.motion_relaxation",
                r.motion_relaxation,
                "must lie in (0, 1]",
            ));
        }
        positive("solver.reference.fluid_tolerance", r.fluid_tolerance)?;
        positive("solver.reference.motion_tolerance", r.motion_tolerance)?;
        if r.max_fluid_iterations == 0 || r.max_motion_iterations == 0 {
            return Err(SetupError::invalid(
                "solver.reference.max_iterations",
                0.0,
                "must be at least 1",
            ));
        }
        Ok(())
    }
}
