//! The model's sections of the configuration: `contact`, `texture`,
//! `lubricant`, `roughness`, `solver`. Every default comes from the physics
//! core's `Default` impls (one source of truth); units are in the key names.

use crate::physics::{
    Contact, FrictionTerms, Geometry, Lubricant, Profile, ReferenceSettings, Roughness,
    SolverSettings, TimeScheme,
};
use serde::{Deserialize, Serialize};

/// `contact.*`: slider geometry, mass, load and boundary friction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactConfig {
    /// `contact.length_m`: L, slider length along the sliding direction — range (0.1 mm, 10 m]
    pub length_m: f64,
    /// `contact.width_m`: B, slider width — range (0.1 mm, 10 m]
    pub width_m: f64,
    /// `contact.mass_kg`: m, equivalent mass of slider and load — range [0, 1e6]
    pub mass_kg: f64,
    /// `contact.load_n`: F_ext, normal load (the paper's text value) — range (0, 1e9]
    pub load_n: f64,
    /// `contact.profile`: parabolic | linear (inclined slider) | flat.
    pub profile: ProfileKind,
    /// `contact.profile_depth_m`: d: parabola rise at the edges / taper rise — range [0, 1 mm]
    pub profile_depth_m: f64,
    /// `contact.boundary_friction`: mu_bl, boundary friction coefficient — range [0, 2]
    pub boundary_friction: f64,
    /// `contact.boundary_friction_rate`: mu_r, the boundary friction's increase per e-fold of
    /// sliding speed above `boundary_activation_speed_m_s` (thermally activated shear of the
    /// boundary film, Eyring); 0 = a constant mu_bl — range [0, 1]
    pub boundary_friction_rate: f64,
    /// `contact.boundary_activation_speed_m_s`: v_a, below it the rate term grows linearly with
    /// speed, above it logarithmically — range (1e-12, 100]
    pub boundary_activation_speed_m_s: f64,
    /// `contact.sign_regularization_m_s`: v_reg in tanh(v/v_reg) for the rigid contact's and the
    /// drivetrain's friction sign; with pre-sliding on, the bristle (exact sign) shapes the
    /// contact's reversal instead, so a stiff bristle reaches the rigid result as v_reg → 0 —
    /// range (1e-9, 1]
    pub sign_regularization_m_s: f64,
    /// `contact.min_film_m`: optional floor on h0; 0 = off (the paper uses sigma) — range [0, 1 mm]
    pub min_film_m: f64,
    /// Pre-sliding (tangential) stiffness σ0 of the contact, N/m; 0: rigid.
    pub presliding_stiffness_n_m: f64,
    /// Damping σ1 of the pre-sliding displacement's rate, N·s/m (LuGre's): while the bristle
    /// moves it adds at most 2 σ1 |v| to the sliding level, nothing in steady sliding.
    pub presliding_damping_n_s_m: f64,
    /// Soft contact: the width follows (F/F_ref)^κ; 0 = rigid.
    pub width_load_exponent: f64,
    /// F_ref, the load at which the width is `width_m`, N.
    pub width_reference_load_n: f64,
}

/// Shape of the global profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProfileKind {
    /// `parabolic`: hg = 4 d (x/L − ½)².
    Parabolic,
    /// `linear`: an inclined slider, hg = d (1 − x/L).
    Linear,
    /// `flat`: a parallel pad.
    Flat,
}

/// The paper's load for the reciprocating studies (Table A4 says 5 kN, the
/// figures use the text's 20 762 N; docs/model.md §9 decides for the text).
pub const DEFAULT_LOAD_N: f64 = 20_762.0;

impl Default for ContactConfig {
    fn default() -> Self {
        Self::of_core(
            &Geometry::default(),
            &Contact::default(),
            &FrictionTerms::default(),
            DEFAULT_LOAD_N,
        )
    }
}

impl ContactConfig {
    /// The section as it writes a core geometry, contact and the contact's
    /// friction terms at load `load_n` (its defaults are the core's: one
    /// source of truth). The other way is `Config::model`; the pair is
    /// tested (a round trip of distinct values returns every key to its
    /// place).
    pub fn of_core(g: &Geometry, c: &Contact, t: &FrictionTerms, load_n: f64) -> Self {
        let (profile, depth) = match g.profile {
            Profile::Parabolic { depth } => (ProfileKind::Parabolic, depth),
            Profile::Linear { depth } => (ProfileKind::Linear, depth),
            Profile::Flat => (ProfileKind::Flat, 0.0),
        };
        Self {
            length_m: g.length,
            width_m: g.width,
            mass_kg: c.mass,
            load_n,
            profile,
            profile_depth_m: depth,
            boundary_friction: t.boundary_film.friction,
            boundary_friction_rate: t.boundary_rate.sensitivity,
            boundary_activation_speed_m_s: t.boundary_rate.activation_speed,
            sign_regularization_m_s: t.boundary_film.sign_regularization,
            min_film_m: c.min_film,
            presliding_stiffness_n_m: t.presliding.stiffness,
            presliding_damping_n_s_m: t.presliding.damping,
            width_load_exponent: t.soft_width.exponent,
            width_reference_load_n: t.soft_width.reference_load,
        }
    }
}

/// `texture.*`: rectangular pockets as parallel arrays (ROS 2 parameters
/// cannot hold lists of structs).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureConfig {
    /// `texture.pocket_start_m`: x of each pocket's leading edge — range [0, L)
    pub pocket_start_m: Vec<f64>,
    /// `texture.pocket_width_m`: pocket widths — range (0, L - start]
    pub pocket_width_m: Vec<f64>,
    /// `texture.pocket_depth_m`: pocket depths — range [0, 1 mm]
    pub pocket_depth_m: Vec<f64>,
}

/// `lubricant.*`: liquid, gas and the cavitation equation of state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LubricantConfig {
    /// `lubricant.viscosity_pa_s`: mu_l, liquid dynamic viscosity — range (1e-5, 100]
    pub viscosity_pa_s: f64,
    /// The temperature at which `viscosity_pa_s` holds, °C (with a constant
    /// viscosity it only labels the estimates).
    pub reference_temperature_c: f64,
    /// How the viscosity follows the temperature input.
    pub viscosity_model: ViscosityModelKind,
    /// Vogel's B, °C (K): μ = A exp(B / (T − C)).
    pub vogel_b_c: f64,
    /// Vogel's C, °C.
    pub vogel_c_c: f64,
    /// `lubricant.density_kg_m3`: rho_l, liquid density — range [100, 3e4]
    pub density_kg_m3: f64,
    /// `lubricant.gas_viscosity_pa_s`: mu_g — range (1e-7, 1e-2]
    pub gas_viscosity_pa_s: f64,
    /// `lubricant.gas_density_kg_m3`: rho_g — range (1e-4, rho_l)
    pub gas_density_kg_m3: f64,
    /// `lubricant.ambient_pressure_pa`: p at both slider edges (absolute) — range (0, 1e9]
    pub ambient_pressure_pa: f64,
    /// `lubricant.saturation_pressure_pa`: p_s — range (0, 1e9]
    pub saturation_pressure_pa: f64,
    /// `lubricant.vapour_pressure_pa`: p_v — range [0, p_s)
    pub vapour_pressure_pa: f64,
    /// `lubricant.vapour_fraction_at_saturation`: alpha_s = alpha(p_s) — range (0, 1)
    pub vapour_fraction_at_saturation: f64,
    /// `lubricant.vapour_fraction_at_vapour_pressure`: alpha_v = alpha(p_v) — range (alpha_s, 1)
    pub vapour_fraction_at_vapour_pressure: f64,
}

impl Default for LubricantConfig {
    fn default() -> Self {
        let l = Lubricant::default();
        Self {
            viscosity_pa_s: l.viscosity,
            reference_temperature_c: 40.0,
            viscosity_model: ViscosityModelKind::Constant,
            // SAE 30 (see physics::viscosity::VogelModel::SAE).
            vogel_b_c: 970.6,
            vogel_c_c: -96.0,
            density_kg_m3: l.density,
            gas_viscosity_pa_s: l.gas_viscosity,
            gas_density_kg_m3: l.gas_density,
            ambient_pressure_pa: l.ambient_pressure,
            saturation_pressure_pa: l.saturation_pressure,
            vapour_pressure_pa: l.vapour_pressure,
            vapour_fraction_at_saturation: l.vapour_fraction_saturation,
            vapour_fraction_at_vapour_pressure: l.vapour_fraction_vapour,
        }
    }
}

/// `lubricant.viscosity_model`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ViscosityModelKind {
    /// `viscosity_pa_s` at every temperature.
    Constant,
    /// Vogel's equation through `viscosity_pa_s` at `reference_temperature_c`.
    Vogel,
}

/// `drivetrain.*`: losses beside the contact, added to its friction (all
/// zero by default).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DrivetrainConfig {
    /// Constant friction, signed with the velocity, N.
    pub coulomb_n: f64,
    /// Friction proportional to the velocity, N·s/m (bent: its force at
    /// `viscous_reference_speed_m_s` over that speed).
    pub viscous_n_s_m: f64,
    /// The viscous rise's exponent δ: 1 a straight rise, below 1 a rise
    /// b v_b sgn v |v/v_b|^δ that bends below the line as speed grows.
    pub viscous_exponent: f64,
    /// v_b, the speed at which the bent viscous rise equals b v_b, m/s.
    pub viscous_reference_speed_m_s: f64,
    /// Friction proportional to the normal load (rolling elements).
    pub load_coefficient: f64,
    /// Loss growing with the square of the speed, N·s²/m².
    pub quadratic_n_s2_m2: f64,
    /// Half the difference between the forward and backward constant
    /// levels, N (forward F_c + this, backward F_c − this).
    pub coulomb_asymmetry_n: f64,
    /// The static level's excess over the Coulomb level (Stribeck), N;
    /// negative: a friction that rises with speed to the Coulomb level.
    pub stribeck_n: f64,
    /// The Stribeck speed, m/s: the excess decays as e^(−|v/v_s|^α_s).
    pub stribeck_speed_m_s: f64,
    /// The Stribeck fall's exponent α_s: 2 the Gaussian fall of the
    /// classic curve and LuGre; below 2 a fall with a longer tail.
    pub stribeck_exponent: f64,
}

impl Default for DrivetrainConfig {
    /// Every term off.
    fn default() -> Self {
        let d = crate::physics::Drivetrain::default();
        Self {
            coulomb_n: d.coulomb,
            viscous_n_s_m: d.viscous,
            viscous_exponent: d.viscous_exponent,
            viscous_reference_speed_m_s: d.viscous_reference_speed,
            load_coefficient: d.load_coefficient,
            quadratic_n_s2_m2: d.quadratic,
            coulomb_asymmetry_n: d.coulomb_asymmetry,
            stribeck_n: d.stribeck,
            stribeck_speed_m_s: d.stribeck_speed,
            stribeck_exponent: d.stribeck_exponent,
        }
    }
}

/// `roughness.*`: GW contact and flow factors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoughnessConfig {
    /// `roughness.sigma_m`: combined RMS roughness sqrt(Rq1^2 + Rq2^2) — range (1e-10, 1e-4]
    pub sigma_m: f64,
    /// `roughness.asperity_density_per_m2`: eta — range [0, 1e16]
    pub asperity_density_per_m2: f64,
    /// `roughness.asperity_radius_m`: beta_a, asperity tip radius — range (1e-9, 1e-2]
    pub asperity_radius_m: f64,
    /// `roughness.effective_modulus_pa`: E* — range (1e5, 1e13]
    pub effective_modulus_pa: f64,
    /// `roughness.flow_factors`: Patir–Cheng flow factors (the paper's runs: off)
    pub flow_factors: bool,
    /// `roughness.lay_gamma`: surface lay, one of 1/9 1/6 1/3 1 3 6 9 (used with flow_factors)
    pub lay_gamma: f64,
}

impl Default for RoughnessConfig {
    fn default() -> Self {
        let r = Roughness::default();
        Self {
            sigma_m: r.sigma,
            asperity_density_per_m2: r.asperity_density,
            asperity_radius_m: r.asperity_radius,
            effective_modulus_pa: r.effective_modulus,
            flow_factors: r.flow_factors,
            lay_gamma: r.lay_gamma,
        }
    }
}

/// `solver.method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MethodKind {
    /// `newton`: the production solver.
    Newton,
    /// `reference`: the paper's Algorithm 1.
    Reference,
}

/// `solver.scheme`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SchemeKind {
    /// `bdf2`.
    Bdf2,
    /// `theta`: with `theta1`, `theta2`.
    Theta,
}

/// `solver.flux`: the Couette flux's face density (`upwind`, first order;
/// `muscl_minmod`, `muscl_van_leer`, `muscl_van_albada`: second order where
/// the density is smooth, see `physics/solver/flux.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FluxKind {
    /// `upwind`: first order.
    Upwind,
    /// `muscl_minmod`: second order, minmod limiter.
    MusclMinmod,
    /// `muscl_van_leer`: second order, van Leer limiter (the default).
    MusclVanLeer,
    /// `muscl_van_albada`: second order, van Albada limiter.
    MusclVanAlbada,
}

impl FluxKind {
    /// Every value, as written in a configuration.
    pub const NAMES: &'static str = "upwind, muscl_minmod, muscl_van_leer, muscl_van_albada";

    /// The value as written in a configuration.
    pub fn name(self) -> &'static str {
        match self {
            FluxKind::Upwind => "upwind",
            FluxKind::MusclMinmod => "muscl_minmod",
            FluxKind::MusclVanLeer => "muscl_van_leer",
            FluxKind::MusclVanAlbada => "muscl_van_albada",
        }
    }

    /// The configuration value of the solver's flux.
    pub fn of(flux: crate::physics::CouetteFlux) -> Self {
        use crate::physics::{CouetteFlux, Limiter};
        match flux {
            CouetteFlux::Upwind => FluxKind::Upwind,
            CouetteFlux::Muscl(Limiter::Minmod) => FluxKind::MusclMinmod,
            CouetteFlux::Muscl(Limiter::VanLeer) => FluxKind::MusclVanLeer,
            CouetteFlux::Muscl(Limiter::VanAlbada) => FluxKind::MusclVanAlbada,
        }
    }

    /// The solver's flux.
    pub fn couette_flux(self) -> crate::physics::CouetteFlux {
        use crate::physics::{CouetteFlux, Limiter};
        match self {
            FluxKind::Upwind => CouetteFlux::Upwind,
            FluxKind::MusclMinmod => CouetteFlux::Muscl(Limiter::Minmod),
            FluxKind::MusclVanLeer => CouetteFlux::Muscl(Limiter::VanLeer),
            FluxKind::MusclVanAlbada => CouetteFlux::Muscl(Limiter::VanAlbada),
        }
    }
}

/// `solver.*`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverConfig {
    /// `solver.cells`: finite-volume cells along x (64 with muscl_van_leer: loop area within 1 %) —
    /// range [8, 65536]
    pub cells: usize,
    /// `solver.dt_s`: fixed time step — range (1e-7, 1]
    pub dt_s: f64,
    /// `solver.method`: newton (production) | reference (the paper's Algorithm 1)
    pub method: MethodKind,
    /// `solver.scheme`: bdf2 | theta (three-level scheme with theta1, theta2)
    pub scheme: SchemeKind,
    /// `solver.theta1`: used with scheme: theta (the paper's value) — range [0.5, 10]
    pub theta1: f64,
    /// `solver.theta2`: used with scheme: theta (the paper's value) — range (0, 10]
    pub theta2: f64,
    /// `solver.tolerance`: Newton: scaled max-norm of the update — range (1e-14, 0.1]
    pub tolerance: f64,
    /// `solver.max_iterations`: Newton iterations per attempt (then fallbacks) — range [1, 10000]
    pub max_iterations: u32,
    /// Default `muscl_van_leer` (bags recorded before the key existed
    /// replay with `upwind`, see [`crate::config::Config::from_recorded_yaml`]).
    pub flux: FluxKind,
    /// `solver.reference`: the paper's Algorithm 1 (Table A2)
    pub reference: ReferenceConfig,
}

impl Default for SolverConfig {
    fn default() -> Self {
        let s = SolverSettings::default();
        let TimeScheme::Theta { theta1, theta2 } = TimeScheme::PAPER else {
            unreachable!()
        };
        Self {
            cells: s.cells,
            dt_s: s.dt,
            method: MethodKind::Newton,
            scheme: SchemeKind::Bdf2,
            theta1,
            theta2,
            tolerance: s.tolerance,
            max_iterations: s.max_iterations,
            flux: FluxKind::of(s.flux),
            reference: ReferenceConfig::default(),
        }
    }
}

/// `solver.reference.*`: the paper's Algorithm 1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReferenceConfig {
    /// `solver.reference.fluid_relaxation`: largest Picard relaxation omega_fluid — range (0, 1]
    pub fluid_relaxation: f64,
    /// `solver.reference.fluid_relaxation_min`: smallest omega_fluid (halved when the update grows)
    pub fluid_relaxation_min: f64,
    /// `solver.reference.max_fluid_iterations`: Picard iterations per secant step, at most.
    pub max_fluid_iterations: u32,
    /// `solver.reference.fluid_tolerance`: Picard: max |dp| / max |p|.
    pub fluid_tolerance: f64,
    /// `solver.reference.motion_relaxation`: omega_motion of the secant update on h0 — range (0, 1]
    pub motion_relaxation: f64,
    /// `solver.reference.max_motion_iterations`: secant iterations per step, at most.
    pub max_motion_iterations: u32,
    /// `solver.reference.motion_tolerance`: secant: |dh0| / h0.
    pub motion_tolerance: f64,
}

impl Default for ReferenceConfig {
    fn default() -> Self {
        ReferenceSettings::default().into()
    }
}

/// The core's settings as the configuration writes them (its defaults).
impl From<ReferenceSettings> for ReferenceConfig {
    fn from(r: ReferenceSettings) -> Self {
        Self {
            fluid_relaxation: r.fluid_relaxation,
            fluid_relaxation_min: r.fluid_relaxation_min,
            max_fluid_iterations: r.max_fluid_iterations,
            fluid_tolerance: r.fluid_tolerance,
            motion_relaxation: r.motion_relaxation,
            max_motion_iterations: r.max_motion_iterations,
            motion_tolerance: r.motion_tolerance,
        }
    }
}

/// The configuration's section as the core's settings (the pair is
/// tested: a round trip of distinct values returns every field to its
/// place).
impl From<&ReferenceConfig> for ReferenceSettings {
    fn from(r: &ReferenceConfig) -> Self {
        Self {
            fluid_relaxation: r.fluid_relaxation,
            fluid_relaxation_min: r.fluid_relaxation_min,
            max_fluid_iterations: r.max_fluid_iterations,
            fluid_tolerance: r.fluid_tolerance,
            motion_relaxation: r.motion_relaxation,
            max_motion_iterations: r.max_motion_iterations,
            motion_tolerance: r.motion_tolerance,
        }
    }
}

#[cfg(test)]
mod mirror_tests {
    use super::*;

    #[test]
    fn the_reference_section_and_the_cores_reference_settings_map_field_to_field() {
        let c = ReferenceConfig {
            fluid_relaxation: 0.1,
            fluid_relaxation_min: 0.2,
            max_fluid_iterations: 3,
            fluid_tolerance: 0.4,
            motion_relaxation: 0.5,
            max_motion_iterations: 6,
            motion_tolerance: 0.7,
        };
        let core = ReferenceSettings::from(&c);
        assert_eq!(ReferenceConfig::from(core), c);
        assert_eq!(
            ReferenceSettings::from(&ReferenceConfig::default()),
            ReferenceSettings::default()
        );
    }

    #[test]
    fn the_contact_section_and_the_cores_geometry_and_contact_map_key_to_key() {
        let c = ContactConfig {
            length_m: 0.011,
            width_m: 0.012,
            mass_kg: 0.013,
            load_n: 14.0,
            profile: ProfileKind::Linear,
            profile_depth_m: 1.5e-5,
            boundary_friction: 0.16,
            boundary_friction_rate: 0.017,
            boundary_activation_speed_m_s: 0.018,
            sign_regularization_m_s: 1.9e-4,
            min_film_m: 2.0e-9,
            presliding_stiffness_n_m: 2.1e6,
            presliding_damping_n_s_m: 22.0,
            width_load_exponent: 0.23,
            width_reference_load_n: 24.0,
        };
        let config = crate::config::Config {
            contact: c.clone(),
            ..Default::default()
        };
        let m = config.model();
        assert_eq!(
            ContactConfig::of_core(&m.geometry, &m.contact, &m.terms, c.load_n),
            c
        );
    }
}
