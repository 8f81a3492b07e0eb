//! Physical and numerical parameters of the model (in-memory core types).
//!
//! All quantities are SI. Defaults are the paper's Tables A2–A4 with the
//! decisions of `MODEL.md` (parabolic slider of depth 25.4 µm, text loads,
//! BDF2). The configuration layer (`crate::config`) maps its unit-suffixed
//! keys onto these structs and takes its defaults from here.
//!
//! | symbol | field | meaning | unit |
//! |---|---|---|---|
//! | L | `Geometry::length` | slider length (sliding direction x) | m |
//! | B | `Geometry::width` | slider width | m |
//! | d | `Profile::*::depth` | profile depth (parabola rise, taper rise) | m |
//! | μl, μg | `Lubricant::viscosity`, `gas_viscosity` | liquid / gas dynamic viscosity | Pa·s |
//! | ρl, ρg | `Lubricant::density`, `gas_density` | liquid / gas density | kg/m³ |
//! | p_amb | `Lubricant::ambient_pressure` | boundary pressure (absolute) | Pa |
//! | p_s, p_v | `saturation_pressure`, `vapour_pressure` | EOS anchor pressures | Pa |
//! | α_s, α_v | `vapour_fraction_*` | vapour fraction at p_s and p_v | – |
//! | σ | `Roughness::sigma` | combined RMS roughness | m |
//! | η | `asperity_density` | asperities per unit area | 1/m² |
//! | β_a | `asperity_radius` | asperity tip radius | m |
//! | E* | `effective_modulus` | effective elastic modulus | Pa |
//! | m | `Contact::mass` | equivalent slider mass | kg |
//! | μ_bl | `boundary_friction` | boundary friction coefficient | – |
//! | μ_r, v_a | `boundary_rate` | the boundary friction's rate sensitivity and activation speed (0 = constant μ_bl; see [`super::boundary`]) | –, m/s |
//! | v_reg | `sign_regularization` | velocity scale of tanh(v/v_reg) | m/s |
//! | h_floor | `min_film` | optional floor on h0 (0 = off) | m |
//! | σ0, σ1 | `presliding` | pre-sliding stiffness and damping (0 = rigid; see [`super::presliding`]) | N/m, N·s/m |
//! | κ, F_ref | `width_law` | soft contact: width B(F) = B (F/F_ref)^κ (κ = 0: rigid) | –, N |

use super::error::SetupError;

/// The physical envelope of a step's inputs: |v| above this is rejected, m/s.
pub const MAX_ABS_VELOCITY: f64 = 100.0;
/// The physical envelope of a step's inputs: a load above this (or ≤ 0) is
/// rejected, N.
pub const MAX_LOAD: f64 = 1e9;
/// The longest single variable-length step ([`super::Solver::step_lasting`]), s.
pub const MAX_VARIABLE_STEP_S: f64 = 3600.0;

/// Global profile `hg(x)` of the slider.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Profile {
    /// `hg = 4 d (x/L − ½)²` (the cavitation-literature benchmark slider).
    Parabolic {
        /// d, the depth at the edges, m.
        depth: f64,
    },
    /// Inclined slider: `hg = d (1 − x/L)`; the gap converges for v > 0.
    Linear {
        /// d, the depth at the leading edge, m.
        depth: f64,
    },
    /// Parallel (flat) pad, `hg = 0`.
    Flat,
}

/// A rectangular texture pocket: `ht(x) = depth` for `start ≤ x < start + width`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pocket {
    /// Where the pocket starts, from the leading edge, m.
    pub start: f64,
    /// Pocket width along x, m.
    pub width: f64,
    /// Pocket depth, m.
    pub depth: f64,
}

/// Slider geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct Geometry {
    /// Slider length L, m.
    pub length: f64,
    /// Slider width B (across the motion), m.
    pub width: f64,
    /// The global profile hg(x).
    pub profile: Profile,
    /// Texture pockets ht(x).
    pub pockets: Vec<Pocket>,
}

impl Default for Geometry {
    fn default() -> Self {
        Self {
            length: 0.0762,
            width: 0.1,
            profile: Profile::Parabolic { depth: 25.4e-6 },
            pockets: Vec::new(),
        }
    }
}

/// Lubricant and its cavitation equation of state (MODEL.md §3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lubricant {
    /// μl, liquid viscosity, Pa·s.
    pub viscosity: f64,
    /// ρl, liquid density, kg/m³.
    pub density: f64,
    /// μg, gas viscosity, Pa·s.
    pub gas_viscosity: f64,
    /// ρg, gas density, kg/m³.
    pub gas_density: f64,
    /// Ambient pressure at the slider's edges, Pa.
    pub ambient_pressure: f64,
    /// p_s, the saturation pressure, Pa.
    pub saturation_pressure: f64,
    /// p_v, the vapour pressure, Pa.
    pub vapour_pressure: f64,
    /// α_s, the vapour fraction at p_s.
    pub vapour_fraction_saturation: f64,
    /// α_v, the vapour fraction at p_v.
    pub vapour_fraction_vapour: f64,
}

impl Default for Lubricant {
    fn default() -> Self {
        Self {
            viscosity: 0.0564,
            density: 850.0,
            gas_viscosity: 1.85e-5,
            gas_density: 0.1161,
            ambient_pressure: 1e5,
            saturation_pressure: 1e5,
            vapour_pressure: 1e3,
            vapour_fraction_saturation: 0.01,
            vapour_fraction_vapour: 0.99,
        }
    }
}

/// Surface roughness: Greenwood–Williamson contact and Patir–Cheng flow factors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roughness {
    /// σ, combined RMS roughness, m.
    pub sigma: f64,
    /// η, asperity density, 1/m².
    pub asperity_density: f64,
    /// β_a, asperity tip radius, m.
    pub asperity_radius: f64,
    /// E', effective elastic modulus, Pa.
    pub effective_modulus: f64,
    /// Patir–Cheng flow factors; off by default as in the paper's simulations.
    pub flow_factors: bool,
    /// Surface lay parameter γ (one of the Table A1 values).
    pub lay_gamma: f64,
}

impl Default for Roughness {
    fn default() -> Self {
        Self {
            sigma: 5e-6,
            asperity_density: 97e9,
            asperity_radius: 1.5e-6,
            effective_modulus: 115e9,
            flow_factors: false,
            lay_gamma: 1.0,
        }
    }
}

/// Rigid-body and boundary-friction parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// m, slider mass, kg.
    pub mass: f64,
    /// μ_bl, the boundary (asperity) friction coefficient.
    pub boundary_friction: f64,
    /// The boundary friction's dependence on speed (off by default).
    pub boundary_rate: super::terms::boundary::BoundaryRate,
    /// v_reg of the sign's tanh regularisation, m/s.
    pub sign_regularization: f64,
    /// Floor on h0; 0 disables it (the default: with GW it should not bind).
    pub min_film: f64,
    /// Pre-sliding compliance (off by default).
    pub presliding: super::terms::presliding::Presliding,
    /// How the contact's width follows the load (constant by default).
    pub width_law: super::terms::soft_width::WidthLaw,
}

impl Default for Contact {
    fn default() -> Self {
        Self {
            mass: 1.0,
            boundary_friction: 0.3,
            boundary_rate: super::terms::boundary::BoundaryRate::default(),
            sign_regularization: 1e-4,
            min_film: 0.0,
            presliding: super::terms::presliding::Presliding::default(),
            width_law: super::terms::soft_width::WidthLaw::default(),
        }
    }
}

/// Everything physical about the contact.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ModelParams {
    /// The slider's shape.
    pub geometry: Geometry,
    /// The lubricant and its cavitation EOS.
    pub lubricant: Lubricant,
    /// The surfaces' roughness.
    pub roughness: Roughness,
    /// Mass, boundary friction and the contact's other terms.
    pub contact: Contact,
    /// Losses beside the contact (zero by default).
    pub drivetrain: super::terms::drivetrain::Drivetrain,
}

/// Which algorithm advances the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// Coupled Newton on (p, h0) with a bordered tridiagonal solve (MODEL.md §7).
    #[default]
    Newton,
    /// The paper's Algorithm 1: under-relaxed Picard inside a secant loop on h0.
    Reference,
}

/// Time discretisation: the three-level θ family (MODEL.md §6).
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

fn positive(field: &'static str, value: f64) -> Result<(), SetupError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SetupError::invalid(field, value, "must be finite and > 0"))
    }
}

fn non_negative(field: &'static str, value: f64) -> Result<(), SetupError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(SetupError::invalid(field, value, "must be finite and >= 0"))
    }
}

impl ModelParams {
    /// Mathematical invariants the solver relies on. Physical plausibility
    /// ranges are checked by the configuration layer.
    pub fn check(&self) -> Result<(), SetupError> {
        let g = &self.geometry;
        positive("geometry.length", g.length)?;
        positive("geometry.width", g.width)?;
        match g.profile {
            Profile::Parabolic { depth } | Profile::Linear { depth } => {
                non_negative("geometry.profile.depth", depth)?
            }
            Profile::Flat => {}
        }
        for pk in &g.pockets {
            non_negative("geometry.pocket.start", pk.start)?;
            positive("geometry.pocket.width", pk.width)?;
            non_negative("geometry.pocket.depth", pk.depth)?;
            if pk.start + pk.width > g.length * (1.0 + 1e-12) {
                return Err(SetupError::invalid(
                    "geometry.pocket.end",
                    pk.start + pk.width,
                    "pocket must end inside the slider (start + width <= length)",
                ));
            }
        }
        let l = &self.lubricant;
        positive("lubricant.viscosity", l.viscosity)?;
        positive("lubricant.density", l.density)?;
        positive("lubricant.gas_viscosity", l.gas_viscosity)?;
        positive("lubricant.gas_density", l.gas_density)?;
        positive("lubricant.ambient_pressure", l.ambient_pressure)?;
        positive("lubricant.saturation_pressure", l.saturation_pressure)?;
        non_negative("lubricant.vapour_pressure", l.vapour_pressure)?;
        if l.vapour_pressure >= l.saturation_pressure {
            return Err(SetupError::invalid(
                "lubricant.vapour_pressure",
                l.vapour_pressure,
                "must be below the saturation pressure",
            ));
        }
        let (a_s, a_v) = (l.vapour_fraction_saturation, l.vapour_fraction_vapour);
        if !(a_s > 0.0 && a_s < 1.0) {
            return Err(SetupError::invalid(
                "lubricant.vapour_fraction_saturation",
                a_s,
                "must lie in (0, 1)",
            ));
        }
        if !(a_v > a_s && a_v < 1.0) {
            return Err(SetupError::invalid(
                "lubricant.vapour_fraction_vapour",
                a_v,
                "must lie in (vapour_fraction_saturation, 1)",
            ));
        }
        let r = &self.roughness;
        positive("roughness.sigma", r.sigma)?;
        non_negative("roughness.asperity_density", r.asperity_density)?;
        positive("roughness.asperity_radius", r.asperity_radius)?;
        positive("roughness.effective_modulus", r.effective_modulus)?;
        if r.flow_factors {
            super::flow_factors::FlowFactors::new(r.lay_gamma, r.sigma)?;
        }
        let c = &self.contact;
        non_negative("contact.mass", c.mass)?;
        non_negative("contact.boundary_friction", c.boundary_friction)?;
        non_negative(
            "contact.boundary_rate.sensitivity",
            c.boundary_rate.sensitivity,
        )?;
        positive(
            "contact.boundary_rate.activation_speed",
            c.boundary_rate.activation_speed,
        )?;
        positive("contact.sign_regularization", c.sign_regularization)?;
        non_negative("contact.min_film", c.min_film)?;
        non_negative("contact.presliding.stiffness", c.presliding.stiffness)?;
        non_negative("contact.presliding.damping", c.presliding.damping)?;
        non_negative("contact.width_law.exponent", c.width_law.exponent)?;
        positive(
            "contact.width_law.reference_load",
            c.width_law.reference_load,
        )?;
        let d = &self.drivetrain;
        non_negative("drivetrain.coulomb", d.coulomb)?;
        non_negative("drivetrain.viscous", d.viscous)?;
        non_negative("drivetrain.load_coefficient", d.load_coefficient)?;
        non_negative("drivetrain.quadratic", d.quadratic)?;
        if !d.coulomb_asymmetry.is_finite() {
            return Err(SetupError::invalid(
                "drivetrain.coulomb_asymmetry",
                d.coulomb_asymmetry,
                "must be finite",
            ));
        }
        Ok(())
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
