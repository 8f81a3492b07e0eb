//! The codes a C caller sees: `FN_*` return codes, the estimate's status
//! and regime codes, and `FnEstimate`, one step's estimate.

use friction_node::msgs::{regime_code, status_code};
use friction_node::physics::Estimate;
use friction_node::range_watch::{RangeWatch, Watched};

impl FnEstimate {
    /// The estimate of a step whose input the watch judged: its flag, and
    /// the friction as `node.outside_envelope` says.
    pub(crate) fn watched(e: &Estimate, watch: &RangeWatch, w: &Watched) -> Self {
        Self {
            friction_force_n: watch.published(w.flag, e.friction_force),
            contact_friction_force_n: watch.published(w.flag, e.contact_friction_force),
            calibrated_range: w.flag.code(),
            ..Self::from(e)
        }
    }
}

/// Success.
pub const FN_OK: i32 = 0;
/// A required pointer argument was null.
pub const FN_ERROR_NULL_ARGUMENT: i32 = 1;
/// The handle is null or not a live model.
pub const FN_ERROR_INVALID_HANDLE: i32 = 2;
/// The configuration was refused (syntax, unknown key, type, range); the
/// message names the key and value.
pub const FN_ERROR_CONFIG: i32 = 3;
/// A file could not be read.
pub const FN_ERROR_IO: i32 = 4;
/// The solver could not be built from a valid configuration.
pub const FN_ERROR_SETUP: i32 = 5;
/// A parameter set was refused (unknown, read-only, wrong type, out of
/// range); the model is unchanged.
pub const FN_ERROR_PARAMETER: i32 = 6;
/// An argument was out of its range (a step length, a temperature).
pub const FN_ERROR_ARGUMENT: i32 = 7;
/// A string argument was not UTF-8.
pub const FN_ERROR_UTF8: i32 = 8;
/// A panic inside the library was caught; the model should be freed.
pub const FN_ERROR_PANIC: i32 = 9;

/// `FnEstimate.status`: the solver converged.
pub const FN_STATUS_CONVERGED: u8 = 0;
/// The iteration bound was hit; the last finite iterate was kept.
pub const FN_STATUS_MAX_ITERATIONS: u8 = 1;
/// A non-finite value appeared; the previous state was kept.
pub const FN_STATUS_NON_FINITE: u8 = 2;
/// A non-finite velocity or load was given; the last good estimate is
/// reported, the state kept.
pub const FN_STATUS_NON_FINITE_INPUT: u8 = 3;
/// |v| > 100 m/s, a load not in (0, 1e9] N, or a step length not in
/// (0, 3600] s;
/// handled as `FN_STATUS_NON_FINITE_INPUT`.
pub const FN_STATUS_INPUT_OUT_OF_RANGE: u8 = 6;

/// `FnEstimate.calibrated_range`: the contact's configuration has no
/// `calibrated_range` (hand-written parameters): nothing is judged.
pub const FN_RANGE_NOT_WATCHED: u8 = 0;
/// The step's speed, load and temperature lie inside the range the contact
/// was calibrated on.
pub const FN_RANGE_INSIDE: u8 = 1;
/// An input lies outside it: the friction is as `node.outside_envelope`
/// says (warn: the model's; hold: the model's at the nearest edge; zero: 0).
pub const FN_RANGE_OUTSIDE: u8 = 2;

/// `FnEstimate.regime`: asperities carry at least 95 % of the load.
pub const FN_REGIME_BOUNDARY: u8 = 0;
/// Between the two.
pub const FN_REGIME_MIXED: u8 = 1;
/// Asperities carry at most 5 % of the load.
pub const FN_REGIME_HYDRODYNAMIC: u8 = 2;

/// One step's estimate (the fields of `friction_msgs/FrictionEstimate`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FnEstimate {
    /// Model time at the end of the step, s.
    pub time_s: f64,
    /// sliding velocity of the step
    pub velocity_m_s: f64,
    /// normal load of the step
    pub load_n: f64,
    /// total friction: the contact plus the drivetrain terms, signed like the velocity
    pub friction_force_n: f64,
    /// the lubricated contact alone, signed like the velocity
    pub contact_friction_force_n: f64,
    /// contact friction per unit load: rigid (|F_visc| + (mu_bl + mu_r asinh(|v|/v_a)) F_asp) / F_ext; with pre-sliding |F_c| / F_ext; drivetrain terms excluded
    pub cof: f64,
    /// minimum nominal separation
    pub h0_m: f64,
    /// minimum film thickness
    pub h_min_m: f64,
    /// B * integral of (p - p_amb)
    pub hydrodynamic_force_n: f64,
    /// Greenwood-Williamson contact force
    pub asperity_force_n: f64,
    /// asperity_force_n / load_n
    pub asperity_load_share: f64,
    /// Newton's last residual (scaled).
    pub residual: f64,
    /// Newton iterations of the step.
    pub iterations: u32,
    /// Backward-Euler sub-steps taken as a fallback (0 normally).
    pub substeps: u32,
    /// `FN_STATUS_*`.
    pub status: u8,
    /// `FN_REGIME_*`.
    pub regime: u8,
    /// `FN_RANGE_*`: where the step's input lay against the contact's
    /// calibrated range.
    pub calibrated_range: u8,
}

impl From<&Estimate> for FnEstimate {
    fn from(e: &Estimate) -> Self {
        Self {
            time_s: e.time,
            velocity_m_s: e.velocity,
            load_n: e.load,
            friction_force_n: e.friction_force,
            contact_friction_force_n: e.contact_friction_force,
            cof: e.cof,
            h0_m: e.h0,
            h_min_m: e.h_min,
            hydrodynamic_force_n: e.hydrodynamic_force,
            asperity_force_n: e.asperity_force,
            asperity_load_share: e.asperity_load_share,
            residual: e.diagnostics.residual,
            iterations: e.diagnostics.iterations,
            substeps: e.diagnostics.substeps,
            status: status_code(e.status),
            regime: regime_code(e.regime),
            calibrated_range: FN_RANGE_NOT_WATCHED,
        }
    }
}
