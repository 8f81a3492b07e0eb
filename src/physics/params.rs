//! Physical parameters of the model (in-memory core types); the solver's
//! numerical settings are in [`super::settings`].
//!
//! All quantities are SI. Defaults are the paper's Tables A2–A4 with the
//! decisions of `docs/model.md` (parabolic slider of depth 25.4 µm, text loads,
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
//! | p_amb | `Lubricant::ambient_pressure` | pressure at the domain's edges (absolute) | Pa |
//! | p_s, p_v | `saturation_pressure`, `vapour_pressure` | EOS anchor pressures | Pa |
//! | α_s, α_v | `vapour_fraction_*` | vapour fraction at p_s and p_v | – |
//! | σ | `Roughness::sigma` | combined RMS roughness | m |
//! | η | `asperity_density` | asperities per unit area | 1/m² |
//! | β_a | `asperity_radius` | asperity tip radius | m |
//! | E* | `effective_modulus` | effective elastic modulus | Pa |
//! | m | `Contact::mass` | equivalent slider mass | kg |
//! | h_floor | `Contact::min_film` | optional floor on h0 (0 = off) | m |
//!
//! The friction terms (μ_bl, v_reg, μ_r, v_a, σ0, σ1, κ, F_ref and the
//! drivetrain's) are [`ModelParams::terms`], each documented in its file
//! of [`super::terms`].

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

/// Lubricant and its cavitation equation of state (docs/model.md §3).
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

/// The slider's rigid-body parameters and the film's floor (its friction
/// terms are [`ModelParams::terms`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// m, slider mass, kg.
    pub mass: f64,
    /// Floor on h0; 0 disables it (the default: with GW it should not bind).
    pub min_film: f64,
}

impl Default for Contact {
    fn default() -> Self {
        Self {
            mass: 1.0,
            min_film: 0.0,
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
    /// The slider's mass and the film's floor.
    pub contact: Contact,
    /// The friction terms beside the film's shear: the boundary film and
    /// its rate, pre-sliding, the soft width, the drivetrain (all off by
    /// default but the boundary film; see [`super::terms`]).
    pub terms: super::terms::FrictionTerms,
}

pub(super) fn positive(field: &'static str, value: f64) -> Result<(), SetupError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SetupError::invalid(field, value, "must be finite and > 0"))
    }
}

pub(super) fn non_negative(field: &'static str, value: f64) -> Result<(), SetupError> {
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
        check_geometry(&self.geometry)?;
        check_lubricant(&self.lubricant)?;
        check_roughness(&self.roughness)?;
        check_contact(&self.contact)?;
        self.terms.check()?;
        Ok(())
    }
}

/// The slider's dimensions, profile and pockets.
fn check_geometry(g: &Geometry) -> Result<(), SetupError> {
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
    Ok(())
}

/// The lubricant's properties and its cavitation model.
fn check_lubricant(l: &Lubricant) -> Result<(), SetupError> {
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
    Ok(())
}

/// The asperities.
fn check_roughness(r: &Roughness) -> Result<(), SetupError> {
    positive("roughness.sigma", r.sigma)?;
    non_negative("roughness.asperity_density", r.asperity_density)?;
    positive("roughness.asperity_radius", r.asperity_radius)?;
    positive("roughness.effective_modulus", r.effective_modulus)?;
    if r.flow_factors {
        super::flow_factors::FlowFactors::new(r.lay_gamma, r.sigma)?;
    }
    Ok(())
}

/// The contact's mass and film floor (its terms check themselves).
fn check_contact(c: &Contact) -> Result<(), SetupError> {
    non_negative("contact.mass", c.mass)?;
    non_negative("contact.min_film", c.min_film)?;
    Ok(())
}
