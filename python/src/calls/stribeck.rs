//! `stribeck`: steady states at given velocities, the command line's
//! `stribeck` columns as numpy arrays.

use crate::columns::Columns;
use crate::errors;
use crate::model::load_config;
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Steady states at `velocities` (any order; returned in that order) under
/// `load` (default `contact.load_n`): the `stribeck` columns.
#[pyfunction]
#[pyo3(signature = (velocities, load=None, yaml=None, path=None, overrides=Vec::new()))]
pub fn stribeck<'py>(
    py: Python<'py>,
    velocities: PyReadonlyArray1<'py, f64>,
    load: Option<f64>,
    yaml: Option<&str>,
    path: Option<&str>,
    overrides: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let config = load_config(yaml, path, &overrides)?;
    let vs = velocities
        .as_slice()
        .map_err(|_| errors::value("velocities: the array is not contiguous"))?;
    if vs.is_empty() {
        return Err(errors::value("velocities is empty"));
    }
    let vmax = config.node.max_abs_velocity_m_s;
    if let Some(k) = vs.iter().position(|v| !(v.is_finite() && v.abs() <= vmax)) {
        return Err(errors::value(format!(
            "velocities[{k}] = {}: a velocity must be finite with |v| ≤ node.max_abs_velocity_m_s = {vmax} m/s",
            vs[k]
        )));
    }
    let load = load.unwrap_or(config.contact.load_n);
    let (lo, hi) = (config.node.min_load_n, config.node.max_load_n);
    if !(load.is_finite() && load >= lo && load <= hi) {
        return Err(errors::value(format!(
            "load = {load}: a load must lie in [node.min_load_n, node.max_load_n] = [{lo}, {hi}] N"
        )));
    }
    let rows = py
        .detach(|| friction_node::offline::stribeck(&config, vs, load))
        .map_err(|e| errors::value(e.to_string()))?;
    let mut c = Columns::with_capacity(rows.len());
    let t_ref = config.lubricant.reference_temperature_c;
    for e in &rows {
        c.push(e, 0.0, e.status.as_str(), t_ref);
    }
    let d = c.into_dict(py)?;
    d.del_item("t_s")?;
    Ok(d)
}
