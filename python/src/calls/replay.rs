//! `replay`: the model over a bag, as the command line's `replay`; the
//! estimates, every velocity cycle's loop metrics and the summary as
//! Python data (and the same files when asked).

use crate::columns::Columns;
use crate::errors;
use friction_node::analysis::metrics::LOOP_METRIC_COLUMNS;
use friction_node::msgs;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::{Path, PathBuf};

fn text_or_none(s: Option<String>) -> Option<String> {
    s.filter(|s| !s.is_empty())
}

/// Re-run the model over a bag (see the Python wrapper).
#[pyfunction]
#[pyo3(signature = (bag, config_path=None, overrides=Vec::new(), topic=None, joint=None,
    load_topic=None, temperature_topic=None, velocity_map=None, load_map=None, out=None,
    report_dir=None))]
#[allow(clippy::too_many_arguments)]
pub fn replay<'py>(
    py: Python<'py>,
    bag: PathBuf,
    config_path: Option<PathBuf>,
    overrides: Vec<String>,
    topic: Option<String>,
    joint: Option<String>,
    load_topic: Option<String>,
    temperature_topic: Option<String>,
    velocity_map: Option<String>,
    load_map: Option<String>,
    out: Option<PathBuf>,
    report_dir: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    use friction_node::replay::{OutputFormat, ReplayOptions, ReplayRequest};
    let out = match out {
        Some(o) => {
            let format = OutputFormat::from_path(&o).ok_or_else(|| {
                errors::value(format!(
                    "out = {}: the output must end in .mcap or .csv",
                    o.display()
                ))
            })?;
            Some((o, format))
        }
        None => None,
    };
    let request = ReplayRequest {
        bag,
        options: ReplayOptions {
            topic: text_or_none(topic),
            joint: text_or_none(joint),
            load_topic: text_or_none(load_topic),
            temperature_topic: text_or_none(temperature_topic),
            config: config_path,
            overrides,
            velocity_map,
            load_map,
        },
        out,
        report: report_dir,
    };
    // A configuration error is the configuration's, not the bag's: only
    // the bag's own errors are prefixed with it.
    let in_bag = |(e, config): (PyErr, bool)| -> PyErr {
        if config || e.is_instance_of::<pyo3::exceptions::PyOSError>(py) {
            e
        } else {
            errors::value(format!("bag {}: {}", request.bag.display(), e.value(py)))
        }
    };
    let to_py = |e: friction_node::replay::ReplayError| {
        let config = e.is_configuration();
        (errors::replay(e), config)
    };
    let outcome = crate::interrupts::interruptible(py, |stop| {
        let ready = request.prepare().map_err(to_py)?;
        ready.run(&mut |_, _| stop.check()).map_err(to_py)
    })?
    .map_err(in_bag)?;
    let d = PyDict::new(py);
    d.set_item("estimates", estimate_columns(py, &outcome.result)?)?;
    d.set_item("cycles", cycle_columns(py, &outcome)?)?;
    d.set_item("summary", replay_summary(py, &request.bag, &outcome)?)?;
    Ok(d)
}

/// The replayed estimates as the CSV output has them: t_s from the first
/// stamp; with several contacts every contact's rows, named in a `contact`
/// column.
fn estimate_columns<'py>(
    py: Python<'py>,
    result: &friction_node::replay::ReplayResult,
) -> PyResult<Bound<'py, PyDict>> {
    let t0 = result.estimates.first().map_or(0, |(_, r)| r.stamp_ns);
    let parts: Vec<(&str, &Vec<_>)> = if result.contacts.is_empty() {
        vec![("", &result.estimates)]
    } else {
        result
            .contacts
            .iter()
            .map(|c| (c.name.as_str(), &c.estimates))
            .collect()
    };
    let rows: usize = parts.iter().map(|(_, e)| e.len()).sum();
    let mut c = Columns::with_capacity(rows);
    let mut names = Vec::with_capacity(if result.contacts.is_empty() { 0 } else { rows });
    for (name, estimates) in &parts {
        for (e, rec) in estimates.iter() {
            let t = rec.stamp_ns.saturating_sub(t0) as f64 / 1e9;
            c.push(e, t, msgs::status_name(rec.status), rec.temperature_c);
            c.push_stamp(
                rec.stamp_ns,
                msgs::command_status_name(rec.command_status),
                msgs::range_name(rec.calibrated_range),
            );
            if !result.contacts.is_empty() {
                names.push(name.to_string());
            }
        }
    }
    let est = c.into_dict(py)?;
    if !names.is_empty() {
        est.set_item("contact", names)?;
    }
    Ok(est)
}

/// The loop metrics of every velocity cycle (the report's `cycles.csv`).
fn cycle_columns<'py>(
    py: Python<'py>,
    o: &friction_node::replay::ReplayOutcome,
) -> PyResult<Bound<'py, PyDict>> {
    let cycles = friction_node::replay::cycles(&o.result, o.prepared.config.contact.mass_kg);
    let cd = PyDict::new(py);
    cd.set_item(
        "cycle",
        PyArray1::from_vec(py, cycles.iter().map(|m| m.cycle as u64).collect()),
    )?;
    cd.set_item(
        "t_start_s",
        PyArray1::from_vec(py, cycles.iter().map(|m| m.t_start).collect()),
    )?;
    cd.set_item(
        "t_end_s",
        PyArray1::from_vec(py, cycles.iter().map(|m| m.t_end).collect()),
    )?;
    for (j, name) in LOOP_METRIC_COLUMNS.split(',').enumerate() {
        let col: Vec<f64> = cycles
            .iter()
            .map(|m| m.values().get(j).copied().flatten().unwrap_or(f64::NAN))
            .collect();
        cd.set_item(name, PyArray1::from_vec(py, col))?;
    }
    Ok(cd)
}

/// Each contact's share of steps whose input lay outside its calibrated
/// range (NaN for a contact with none), by contact name.
fn outside_shares<'py>(
    py: Python<'py>,
    r: &friction_node::replay::ReplayResult,
) -> PyResult<Bound<'py, PyDict>> {
    use friction_node::msgs::estimate_constants::{RANGE_NOT_WATCHED, RANGE_OUTSIDE};
    let share = |est: &[(
        friction_node::physics::Estimate,
        friction_node::msgs::EstimateRecord,
    )]| {
        let watched = est
            .iter()
            .filter(|(_, rec)| rec.calibrated_range != RANGE_NOT_WATCHED)
            .count();
        let outside = est
            .iter()
            .filter(|(_, rec)| rec.calibrated_range == RANGE_OUTSIDE)
            .count();
        if watched == 0 {
            f64::NAN
        } else {
            outside as f64 / est.len() as f64
        }
    };
    let d = PyDict::new(py);
    if r.contacts.is_empty() {
        d.set_item(
            friction_node::config::SINGLE_CONTACT_NAME,
            share(&r.estimates),
        )?;
    }
    for c in &r.contacts {
        d.set_item(&c.name, share(&c.estimates))?;
    }
    Ok(d)
}

/// The command line's summary lines as a dict.
fn replay_summary<'py>(
    py: Python<'py>,
    bag: &Path,
    o: &friction_node::replay::ReplayOutcome,
) -> PyResult<Bound<'py, PyDict>> {
    let (prepared, result) = (&o.prepared, &o.result);
    let s = PyDict::new(py);
    s.set_item("bag", bag.display().to_string())?;
    s.set_item("input", prepared.mode.describe())?;
    s.set_item("configuration", &prepared.config_source)?;
    s.set_item("velocity_messages", prepared.velocity_messages)?;
    s.set_item("steps", result.estimates.len())?;
    s.set_item("span_s", o.span_s())?;
    s.set_item("wall_s", o.wall_s)?;
    s.set_item("model_wall_s", o.model_wall_s)?;
    s.set_item("commands_rejected", result.commands_rejected)?;
    s.set_item(
        "steps_outside_calibrated_range",
        result.steps_outside_calibrated_range,
    )?;
    s.set_item("outside_share", outside_shares(py, result)?)?;
    s.set_item("gaps", prepared.gaps.len())?;
    s.set_item("files", prepared.scan.files.len())?;
    s.set_item(
        "damage",
        prepared.scan.damage.as_ref().map(|d| d.to_string()),
    )?;
    s.set_item("parameter_changes", prepared.parameter_changes.len())?;
    let oracle = result.oracle.as_ref();
    s.set_item("identical", oracle.map(|o| o.identical))?;
    s.set_item("compared", oracle.map_or(0, |o| o.compared))?;
    let devs = PyList::empty(py);
    for (f, dmax, k) in oracle.map_or(&[][..], |o| &o.deviations[..]) {
        devs.append((*f, *dmax, *k))?;
    }
    s.set_item("deviations", devs)?;
    let contacts = PyList::empty(py);
    for c in &result.contacts {
        let o = c.oracle.as_ref();
        contacts.append((
            c.name.clone(),
            o.map(|o| o.identical),
            o.map_or(0, |o| o.compared),
        ))?;
    }
    s.set_item("contacts", contacts)?;
    s.set_item("out", o.written.as_ref().map(|p| p.display().to_string()))?;
    Ok(s)
}
