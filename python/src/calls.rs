//! `stribeck`, `replay` and `fit`: the command line's offline jobs, returning
//! Python data instead of files (and writing the same files when asked).

use crate::columns::Columns;
use crate::errors;
use crate::model::load_config;
use friction_node::analysis::metrics::LOOP_METRIC_COLUMNS;
use friction_node::fit::report;
use friction_node::fit::request::{
    fit_baselines, fit_ours, param_specs, prepare, select_terms, FitRequest, LabelledProgress,
    OursFitted, Prepared, TopicChoice,
};
use friction_node::fit::{Delimiter, FitOutcome, Mapping};
use friction_node::msgs;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The built-in default parameter file.
#[pyfunction]
pub fn default_config_yaml() -> &'static str {
    friction_node::config::DEFAULT_YAML
}

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
            c.push_stamp(rec.stamp_ns, msgs::command_status_name(rec.command_status));
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

fn outcome_dict<'py>(py: Python<'py>, o: &FitOutcome) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("label", &o.label)?;
    d.set_item("converged", o.converged)?;
    let best = o.optima.first();
    d.set_item("termination", best.map(|r| r.termination.clone()))?;
    d.set_item("cost_n2", best.map_or(f64::NAN, |r| r.cost))?;
    // The data as the model saw them at the optimum (maps applied), with
    // its prediction: for plots, and for checking the fit independently.
    let series = |fits: &[friction_node::fit::problem::SeriesFit]| -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        for f in fits {
            let s = &f.series;
            let e = PyDict::new(py);
            e.set_item("name", &s.name)?;
            e.set_item("steady", s.steady)?;
            e.set_item("t_s", PyArray1::from_slice(py, &s.t))?;
            e.set_item("velocity_m_s", PyArray1::from_slice(py, &s.velocity))?;
            e.set_item("friction_n", PyArray1::from_slice(py, &s.friction))?;
            let load: Vec<f64> = (0..s.len()).map(|k| s.load_at(k, f64::NAN)).collect();
            e.set_item("load_n", PyArray1::from_vec(py, load))?;
            e.set_item("fit", PyArray1::from_vec(py, s.fit.clone()))?;
            e.set_item("predicted_n", PyArray1::from_slice(py, &f.predicted))?;
            out.append(e)?;
        }
        Ok(out)
    };
    d.set_item("series", series(&o.train)?)?;
    d.set_item("validate_series", series(&o.validate)?)?;
    d.set_item("train_rms_n", o.train_rms)?;
    d.set_item("train_max_n", o.train_max)?;
    d.set_item("holdout_rms_n", o.holdout_rms)?;
    d.set_item("validate_rms_n", o.validate_rms)?;
    d.set_item("held_out_rms_n", o.held_out_rms())?;
    d.set_item("validate_failure", &o.validate_failure)?;
    d.set_item("simulations", o.simulations)?;
    d.set_item("wall_s", o.wall_s)?;
    d.set_item("sigma_n", o.statistics.sigma)?;
    d.set_item("rank_deficient", o.statistics.rank_deficient)?;
    let params = PyList::empty(py);
    for (i, p) in o.params.iter().enumerate() {
        let r = PyDict::new(py);
        r.set_item("name", &p.name)?;
        r.set_item("value", o.best[i])?;
        r.set_item("start", p.start)?;
        r.set_item(
            "std_error",
            o.statistics
                .standard_error
                .get(i)
                .copied()
                .unwrap_or(f64::NAN),
        )?;
        let (lo95, hi95) = o
            .statistics
            .interval95
            .get(i)
            .copied()
            .unwrap_or((f64::NAN, f64::NAN));
        r.set_item("ci95_low", lo95)?;
        r.set_item("ci95_high", hi95)?;
        r.set_item("lower_bound", p.lo)?;
        r.set_item("upper_bound", p.hi)?;
        r.set_item(
            "at_bound",
            o.statistics.at_bound.get(i).copied().unwrap_or(false),
        )?;
        params.append(r)?;
    }
    d.set_item("parameters", params)?;
    d.set_item("correlation", o.statistics.correlation.clone())?;
    d.set_item("summary", report::summary(o, ""))?;
    Ok(d)
}

/// Calibrate (see the Python wrapper): the command line's `fit`.
#[pyfunction]
#[pyo3(signature = (data, keys, config_path=None, overrides=Vec::new(), bounds=Vec::new(),
    starts_at=Vec::new(), holdout=0.0, validate=Vec::new(), baselines=false, starts=3,
    global_points=16, seed=1, max_evaluations=200, columns=None, skip=0, delimiter="auto",
    time=None, velocity="velocity_m_s".to_string(), friction="friction_n".to_string(),
    load=None, temperature=None, smooth=0.05, map=Vec::new(), velocity_topic=None,
    friction_topic=None, joint=None, load_topic=None, temperature_topic=None, out=None,
    report_dir=None, progress=false, rotary=false))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    data: Vec<PathBuf>,
    keys: Vec<String>,
    config_path: Option<PathBuf>,
    overrides: Vec<String>,
    bounds: Vec<(String, f64, f64)>,
    starts_at: Vec<(String, f64)>,
    holdout: f64,
    validate: Vec<PathBuf>,
    baselines: bool,
    starts: usize,
    global_points: usize,
    seed: u64,
    max_evaluations: usize,
    columns: Option<Vec<String>>,
    skip: usize,
    delimiter: &str,
    time: Option<String>,
    velocity: String,
    friction: String,
    load: Option<String>,
    temperature: Option<String>,
    smooth: f64,
    map: Vec<(String, f64)>,
    velocity_topic: Option<String>,
    friction_topic: Option<String>,
    joint: Option<String>,
    load_topic: Option<String>,
    temperature_topic: Option<String>,
    out: Option<PathBuf>,
    report_dir: Option<PathBuf>,
    progress: bool,
    rotary: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let config = match &config_path {
        Some(p) => load_config(None, Some(&p.display().to_string()), &overrides)?,
        None => load_config(None, None, &overrides)?,
    };
    let delimiter = delimiter_named(delimiter)?;
    if let Some((n, _)) = map.iter().find(|(n, _)| n.contains('.')) {
        return Err(errors::value(format!(
            "map {n}: a map coefficient's name has no dots (dotted names are configuration keys)"
        )));
    }
    let req = FitRequest {
        data,
        validate,
        params: param_specs(&keys, &bounds, &starts_at).map_err(errors::fit)?,
        mapping: Mapping {
            time,
            velocity,
            friction,
            load,
            temperature,
            smooth_s: smooth,
            coefficients: map,
        },
        holdout,
        columns,
        skip,
        delimiter,
        topics: TopicChoice {
            velocity: velocity_topic,
            friction: friction_topic,
            joint,
            load: load_topic,
            temperature: temperature_topic,
        },
        starts,
        global_points,
        seed,
        max_evaluations,
        baselines,
        rotary,
        jacobian: Default::default(),
        later_runs: Default::default(),
        progress: progress.then(|| {
            Arc::new(|label: &str, l: &str| eprintln!("fit [{label}]: {l}")) as LabelledProgress
        }),
        stop: friction_node::interrupt::Stop::new(),
    };
    let (p, ours, classic, skipped) = calibrate(py, &config, &req, &out, &report_dir)?;
    let yaml = report::fitted_yaml(&ours.config, &ours.outcome, &p.names, &ours.map);
    let d = fit_dict(py, &ours, baselines.then_some(&classic[..]), &yaml)?;
    let mut notes = p.notes.clone();
    notes.extend(skipped);
    d.set_item("notes", notes)?;
    if let Some(o) = &out {
        friction_node::output::write_file(o, yaml.as_bytes())
            .map_err(|e| errors::os(e.to_string()))?;
    }
    if let Some(r) = &report_dir {
        let extra = if baselines {
            report::models_section(&ours.outcome, &classic)
        } else {
            String::new()
        };
        write_fit_report(r, &ours.outcome, &classic, &extra)?;
    }
    Ok(d)
}

/// `delimiter` by its Python name.
fn delimiter_named(name: &str) -> PyResult<Delimiter> {
    Ok(match name {
        "auto" => Delimiter::Auto,
        "comma" | "," => Delimiter::Comma,
        "semicolon" | ";" => Delimiter::Semicolon,
        "tab" | "\t" => Delimiter::Tab,
        "whitespace" => Delimiter::Whitespace,
        other => {
            return Err(errors::value(format!(
                "delimiter = {other:?}: one of auto, comma, semicolon, tab, whitespace"
            )))
        }
    })
}

/// What a calibration fitted: the prepared problem, ours, the classic
/// models (with `req.baselines`) and the notes on those skipped. Outputs
/// are checked before any computation; Ctrl-C stops the fit.
fn calibrate(
    py: Python<'_>,
    config: &friction_node::config::Config,
    req: &FitRequest,
    out: &Option<PathBuf>,
    report_dir: &Option<PathBuf>,
) -> PyResult<(Prepared, OursFitted, Vec<FitOutcome>, Vec<String>)> {
    crate::interrupts::interruptible(py, |stop| -> PyResult<_> {
        let req = FitRequest {
            stop: stop.clone(),
            ..req.clone()
        };
        let mut p = prepare(config, &req).map_err(errors::fit)?;
        if let Some(o) = out {
            drop(
                friction_node::output::AtomicFile::create(o)
                    .map_err(|e| errors::os(e.to_string()))?,
            );
        }
        // A report folder made here is removed again if the fit fails or
        // is stopped (the report itself is written by the caller).
        let dir = report_dir
            .as_deref()
            .map(friction_node::output::prepare_output_dir)
            .transpose()
            .map_err(|e| errors::os(e.to_string()))?;
        if p.auto {
            let progress = req.progress.clone();
            let say = move |l: &str| {
                if let Some(f) = &progress {
                    f("auto", l)
                }
            };
            let s = select_terms(&mut p, &req, &say).map_err(errors::fit)?;
            p.notes
                .push(friction_node::fit::auto::report(&s, p.data.units));
        }
        let ours = fit_ours(&p, &req).map_err(errors::fit)?;
        let (classic, skipped) = if req.baselines {
            fit_baselines(&p, &req).map_err(errors::fit)?
        } else {
            (Vec::new(), Vec::new())
        };
        if let Some(d) = dir {
            d.keep();
        }
        Ok((p, ours, classic, skipped))
    })?
}

/// The result dict of a fit: ours at the top level, every model in
/// `models`, with baselines asked for (`classic` is then Some) the models
/// and direction tables, the map and the fitted YAML.
fn fit_dict<'py>(
    py: Python<'py>,
    ours: &OursFitted,
    classic: Option<&[FitOutcome]>,
    yaml: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let d = outcome_dict(py, &ours.outcome)?;
    if let Some(classic) = classic {
        d.set_item(
            "models_table",
            report::models_table_of(&ours.outcome, classic),
        )?;
        let all: Vec<&FitOutcome> = std::iter::once(&ours.outcome).chain(classic).collect();
        d.set_item(
            "direction_table",
            friction_node::fit::by_direction::models_direction_table(&all),
        )?;
    }
    let models = PyList::empty(py);
    models.append(outcome_dict(py, &ours.outcome)?)?;
    for b in classic.unwrap_or_default() {
        models.append(outcome_dict(py, b)?)?;
    }
    d.set_item("models", models)?;
    d.set_item("map", ours.map.clone())?;
    d.set_item("fitted_yaml", yaml)?;
    Ok(d)
}

fn write_fit_report(
    r: &Path,
    ours: &FitOutcome,
    classic: &[FitOutcome],
    extra: &str,
) -> PyResult<()> {
    report::write_models_report(r, ours, classic, extra).map_err(|e| errors::os(e.to_string()))?;
    Ok(())
}
