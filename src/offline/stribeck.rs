//! `stribeck`: steady states over a velocity sweep (linear or logarithmic),
//! each warm-started from its neighbour, as CSV rows.

use super::{arg_err, SimulationError};
use crate::config::Config;
use crate::physics::{Estimate, Solver};
use crate::text::Num;

/// Velocities of a Stribeck sweep.
pub fn sweep(
    v_min: f64,
    v_max: f64,
    points: usize,
    log: bool,
) -> Result<Vec<f64>, SimulationError> {
    if !(v_min.is_finite() && v_max.is_finite()) || v_min >= v_max {
        return Err(arg_err(
            "--v-min/--v-max",
            format!("{v_min}/{v_max}"),
            "need finite v-min < v-max",
        ));
    }
    if points < 2 {
        return Err(arg_err("--points", points, "need at least 2 points"));
    }
    if log {
        if !(v_min > 0.0 || v_max < 0.0) {
            return Err(arg_err(
                "--log",
                format!("[{v_min}, {v_max}]"),
                "a logarithmic sweep needs a range that does not contain 0",
            ));
        }
        let (a, b) = (v_min.abs().ln(), v_max.abs().ln());
        let s = v_min.signum();
        Ok((0..points)
            .map(|k| s * (a + (b - a) * k as f64 / (points - 1) as f64).exp())
            .collect())
    } else {
        Ok((0..points)
            .map(|k| v_min + (v_max - v_min) * k as f64 / (points - 1) as f64)
            .collect())
    }
}

/// Steady states at the given velocities (any order), returned in the
/// input order. Each sign is swept outwards from zero so that every solve
/// is warm-started from its neighbour.
pub fn stribeck(
    config: &Config,
    velocities: &[f64],
    load: f64,
) -> Result<Vec<Estimate>, SimulationError> {
    let mut out: Vec<Option<Estimate>> = vec![None; velocities.len()];
    let mut order: Vec<usize> = (0..velocities.len()).collect();
    order.sort_by(|&a, &b| velocities[a].abs().total_cmp(&velocities[b].abs()));
    for positive in [true, false] {
        let mut solver = Solver::new(&config.model(), &config.solver_settings())?;
        for &i in &order {
            let v = velocities[i];
            if (v >= 0.0) == positive {
                out[i] = Some(solver.steady(v, load));
            }
        }
    }
    Ok(out
        .into_iter()
        .map(|e| e.expect("every point solved"))
        .collect())
}

/// Columns of `stribeck`.
pub const STRIBECK_COLUMNS: &str = "velocity_m_s,h0_m,h_min_m,f_hyd_n,f_asp_n,friction_n,cof,viscous_n,asperity_load_share,regime,status,iterations,contact_friction_n";

/// One `stribeck` CSV row of a steady state.
pub fn stribeck_row(e: &Estimate) -> String {
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{}",
        Num(e.velocity),
        Num(e.h0),
        Num(e.h_min),
        Num(e.hydrodynamic_force),
        Num(e.asperity_force),
        Num(e.friction_force),
        Num(e.cof),
        Num(e.viscous_force),
        Num(e.asperity_load_share),
        e.regime.as_str(),
        e.status.as_str(),
        e.diagnostics.iterations,
        Num(e.contact_friction_force)
    )
}
