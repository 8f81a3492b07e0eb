//! What one step returns: the estimate, its numerical status and diagnostics.
//!
//! | field | meaning | unit |
//! |---|---|---|
//! | `time` | solver time at the end of the step | s |
//! | `velocity` | sliding velocity v | m/s |
//! | `load` | external normal load F_ext | N |
//! | `h0`, `h_min` | minimum nominal separation, minimum film thickness | m |
//! | `hydrodynamic_force` | F_hyd = B ∫ (p − p_amb) dx | N |
//! | `asperity_force` | F_asp = B ∫ p_asp dx | N |
//! | `viscous_force` | F_visc = B ∫ (−(h/2) ∂x p + μ v / h) dx | N |
//! | `friction_force` | F_f = F_c + F_dt: the contact plus the drivetrain terms | N |
//! | `contact_friction_force` | F_c = F_visc + μ(v) F_asp tanh(v/v_reg), through the pre-sliding bristle when on | N |
//! | `cof` | contact friction per unit load: rigid (\|F_visc\| + (mu_bl + mu_r asinh(\|v\|/v_a)) F_asp) / F_ext; with pre-sliding \|F_c\| / F_ext; drivetrain terms excluded | – |
//! | `asperity_load_share` | F_asp / F_ext | – |
//! | `inertia_force` | m h0'' | N |
//! | `contact_area_ratio` | mean A_r/A_0 over the slider | – |
//! | `max_pressure` | max absolute fluid pressure | Pa |
//! | `cavitated_fraction` | share of the length with vapour fraction > ½ | – |
//!
//! `friction_force` carries the sign of the velocity: it is the force the
//! contact exerts *against* the motion, i.e. what a feed-forward controller
//! adds to its command.

/// Numerical outcome of a step. Not an error: the estimate is always returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Status {
    /// The update fell below the tolerance.
    Converged,
    /// The iteration bound was hit; the last finite iterate was kept.
    MaxIterations,
    /// The iteration produced a non-finite value or a singular system; the
    /// previous state was kept.
    NonFinite,
    /// The velocity or load handed to the step was not finite; nothing was
    /// computed, the previous state was kept, the last good estimate is
    /// reported.
    NonFiniteInput,
    /// The velocity or load (or a step length) was outside the physical
    /// envelope (|v| ≤ 100 m/s, 0 < load ≤ 1e9 N); handled as
    /// [`Status::NonFiniteInput`].
    InputOutOfRange,
}

impl Status {
    /// Stable lower-case name (CSV, logs).
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Converged => "converged",
            Status::MaxIterations => "max_iterations",
            Status::NonFinite => "non_finite",
            Status::NonFiniteInput => "non_finite_input",
            Status::InputOutOfRange => "input_out_of_range",
        }
    }

    /// Whether the step converged.
    pub fn is_converged(self) -> bool {
        self == Status::Converged
    }
}

/// Lubrication regime from the asperity load share.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Regime {
    /// Asperities carry at least 95 % of the load.
    Boundary,
    /// Between the two: film and asperities share the load.
    Mixed,
    /// Asperities carry at most 5 % of the load.
    Hydrodynamic,
}

impl Regime {
    /// Asperity load share at or above which the regime is boundary.
    pub const BOUNDARY_SHARE: f64 = 0.95;
    /// Asperity load share at or below which the regime is hydrodynamic.
    pub const HYDRODYNAMIC_SHARE: f64 = 0.05;

    /// The regime of an asperity load share (F_asp / F_ext).
    pub fn from_asperity_share(share: f64) -> Self {
        if share >= Self::BOUNDARY_SHARE {
            Regime::Boundary
        } else if share <= Self::HYDRODYNAMIC_SHARE {
            Regime::Hydrodynamic
        } else {
            Regime::Mixed
        }
    }

    /// The name on the wire and in CSV (`boundary`, `mixed`, `hydrodynamic`).
    pub fn as_str(self) -> &'static str {
        match self {
            Regime::Boundary => "boundary",
            Regime::Mixed => "mixed",
            Regime::Hydrodynamic => "hydrodynamic",
        }
    }
}

/// How the step went numerically.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Diagnostics {
    /// Newton iterations (reference solver: secant iterations on h0).
    pub iterations: u32,
    /// Reference solver only: total Picard iterations in the step.
    pub inner_iterations: u32,
    /// Scaled max-norm of the last update (relative to max|p| and h0).
    pub residual: f64,
    /// |load-balance residual| / F_ext at the returned state.
    pub load_residual: f64,
    /// Line-search step halvings in the step.
    pub backtracks: u32,
    /// The h0 floor (`contact.min_film`) was active.
    pub film_floor_active: bool,
    /// 0, or the number of backward-Euler sub-steps the step needed after
    /// Newton failed on the full step (a rare fallback at hard steps).
    pub substeps: u32,
}

/// The model's output for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// Model time at the end of the step, s.
    pub time: f64,
    /// Slider velocity of the step, m/s.
    pub velocity: f64,
    /// Normal load F_ext, N.
    pub load: f64,
    /// Film thickness h0 (the gap at the profile's minimum), m.
    pub h0: f64,
    /// Smallest gap over the slider, h0 + min(hg + ht), m.
    pub h_min: f64,
    /// Load carried by the film's pressure, N.
    pub hydrodynamic_force: f64,
    /// Load carried by the asperities (Greenwood–Williamson), N.
    pub asperity_force: f64,
    /// Shear force of the film (Couette and Poiseuille), N.
    pub viscous_force: f64,
    /// Friction force: the contact's plus the drivetrain's terms, N.
    pub friction_force: f64,
    /// The contact's friction alone (viscous + boundary, through the pre-sliding compliance when on), N.
    pub contact_friction_force: f64,
    /// Coefficient of friction: the magnitude of the friction the contact
    /// transmits per unit load. Rigid contact (the paper's):
    /// (|F_visc| + μ F_asp) / F_ext, μ = μ_bl + μ_r asinh(|v|/v_a); with
    /// pre-sliding: |F_contact| / F_ext, the bristle's force (the drivetrain's
    /// terms are not the contact's and are not in it). In one line:
    /// contact friction per unit load: rigid (|F_visc| + (mu_bl + mu_r asinh(|v|/v_a)) F_asp) / F_ext; with pre-sliding |F_c| / F_ext; drivetrain terms excluded
    pub cof: f64,
    /// The boundary rate's part of `cof`, μ_r asinh(|v|/v_a) F_asp / F_ext
    /// (0 when the rate term is off, and with pre-sliding); zero at v = 0.
    pub boundary_rate_cof: f64,
    /// F_asp / F_ext.
    pub asperity_load_share: f64,
    /// Inertia force m ḧ0 of the slider, N.
    pub inertia_force: f64,
    /// Real contact area over nominal area (mean over the cells).
    pub contact_area_ratio: f64,
    /// Largest film pressure, Pa (absolute).
    pub max_pressure: f64,
    /// Share of cells whose vapour fraction exceeds ½.
    pub cavitated_fraction: f64,
    /// The lubrication regime from the asperity share.
    pub regime: Regime,
    /// How the step ended.
    pub status: Status,
    /// Iterations, residuals and fallbacks of the step.
    pub diagnostics: Diagnostics,
}
