//! Estimates → named numpy columns (the `simulate` CSV columns).

use friction_node::physics::Estimate;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The columns of `simulate`, filled row by row (allocation happens here,
/// outside the model's step).
#[derive(Default)]
pub struct Columns {
    f: [Vec<f64>; 19],
    iterations: Vec<u32>,
    substeps: Vec<u32>,
    status: Vec<&'static str>,
    regime: Vec<&'static str>,
    stamp_ns: Vec<u64>,
    command_status: Vec<&'static str>,
    calibrated_range: Vec<&'static str>,
}

/// Names of the float columns, in `Columns::f` order.
const FLOAT_NAMES: [&str; 19] = [
    "t_s",
    "velocity_m_s",
    "load_n",
    "h0_m",
    "h_min_m",
    "f_hyd_n",
    "f_asp_n",
    "friction_n",
    "cof",
    "viscous_n",
    "asperity_load_share",
    "inertia_n",
    "residual",
    "load_residual",
    "max_pressure_pa",
    "cavitated_fraction",
    "contact_area_ratio",
    "temperature_c",
    "contact_friction_n",
];

impl Columns {
    pub fn with_capacity(n: usize) -> Self {
        let mut c = Self::default();
        for v in &mut c.f {
            v.reserve(n);
        }
        c
    }

    /// One row: the estimate at time `t_s`, with its status name and the
    /// lubricant temperature.
    pub fn push(&mut self, e: &Estimate, t_s: f64, status: &'static str, temperature_c: f64) {
        let row = [
            t_s,
            e.velocity,
            e.load,
            e.h0,
            e.h_min,
            e.hydrodynamic_force,
            e.asperity_force,
            e.friction_force,
            e.cof,
            e.viscous_force,
            e.asperity_load_share,
            e.inertia_force,
            e.diagnostics.residual,
            e.diagnostics.load_residual,
            e.max_pressure,
            e.cavitated_fraction,
            e.contact_area_ratio,
            temperature_c,
            e.contact_friction_force,
        ];
        for (c, x) in self.f.iter_mut().zip(row) {
            c.push(x);
        }
        self.iterations.push(e.diagnostics.iterations);
        self.substeps.push(e.diagnostics.substeps);
        self.status.push(status);
        self.regime.push(e.regime.as_str());
    }

    /// Replay's extra columns (the stamp, the command's state and where
    /// the input lay against the calibrated range).
    pub fn push_stamp(
        &mut self,
        stamp_ns: u64,
        command_status: &'static str,
        calibrated_range: &'static str,
    ) {
        self.stamp_ns.push(stamp_ns);
        self.command_status.push(command_status);
        self.calibrated_range.push(calibrated_range);
    }

    /// A dict of numpy arrays (strings as lists).
    pub fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        for (name, v) in FLOAT_NAMES.iter().zip(self.f) {
            d.set_item(name, PyArray1::from_vec(py, v))?;
        }
        d.set_item("iterations", PyArray1::from_vec(py, self.iterations))?;
        d.set_item("substeps", PyArray1::from_vec(py, self.substeps))?;
        d.set_item("status", self.status)?;
        d.set_item("regime", self.regime)?;
        if !self.stamp_ns.is_empty() {
            d.set_item("stamp_ns", PyArray1::from_vec(py, self.stamp_ns))?;
            d.set_item("command_status", self.command_status)?;
            d.set_item("calibrated_range", self.calibrated_range)?;
        }
        Ok(d)
    }
}
