//! `profile`: the steady film thickness, pressure, vapour fraction,
//! asperity pressure and shear along the contact at one velocity, with
//! h0 prescribed or from the load balance.

use super::{arg_err, SimulationError};
use crate::config::Config;
use crate::physics::{Estimate, Solver};
use crate::text::Num;

/// How h0 is fixed in a `profile` run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProfileGap {
    /// h0 prescribed, m.
    H0(f64),
    /// h0 from the load balance at this load, N.
    Load(f64),
}

/// Columns of `profile`.
pub const PROFILE_COLUMNS: &str = "x_m,h_m,p_pa,vapour_fraction,p_asp_pa,shear_pa";

/// Steady field at one velocity; returns the estimate and the field rows.
pub fn profile(
    config: &Config,
    velocity: f64,
    gap: ProfileGap,
) -> Result<(Estimate, Vec<crate::physics::FieldPoint>), SimulationError> {
    if !velocity.is_finite() {
        return Err(arg_err("--velocity", velocity, "must be finite"));
    }
    let mut solver = Solver::new(&config.model(), &config.solver_settings())?;
    let e = match gap {
        ProfileGap::H0(h) => {
            if !(h.is_finite() && h > 0.0 && h < 1e-3) {
                return Err(arg_err("--h0", h, "must be a gap in metres, in (0, 1e-3)"));
            }
            solver.steady_prescribed_gap(velocity, h, config.contact.load_n)
        }
        ProfileGap::Load(f) => {
            if !(f.is_finite() && f > 0.0) {
                return Err(arg_err("--load", f, "must be a positive force in newtons"));
            }
            solver.steady(velocity, f)
        }
    };
    Ok((e, solver.field().collect()))
}

/// One `profile` CSV row of a cell.
pub fn profile_row(p: &crate::physics::FieldPoint) -> String {
    format!(
        "{},{},{},{},{},{}",
        Num(p.x),
        Num(p.h),
        Num(p.p),
        Num(p.vapour_fraction),
        Num(p.asperity_pressure),
        Num(p.shear)
    )
}
