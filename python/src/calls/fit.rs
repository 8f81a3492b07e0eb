//! `fit`: calibration as the command line's `fit`, returning the outcome
//! as a dict (and writing the report and fitted file when asked).

use crate::errors;
use crate::model::load_config;
use friction_node::fit::compare::OursFitted;
use friction_node::fit::inputs::{DataRequest, TopicChoice};
use friction_node::fit::options::{
    CheapKeys, JacobianRule, LabelledProgress, LaterRuns, LinearKeys, SearchSettings,
};
use friction_node::fit::request::{param_specs, Calibration, FitOutputs, FitRequest};
use friction_node::fit::{models_table, report};
use friction_node::fit::{Delimiter, FitOutcome, Mapping};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::path::PathBuf;
use std::sync::Arc;

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
    d.set_item("held_out_series", series(&o.held_out)?)?;
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
    d.set_item("error_batches", o.statistics.batches)?;
    let params = PyList::empty(py);
    for (i, p) in o.params.iter().enumerate() {
        let r = PyDict::new(py);
        r.set_item("name", &p.name)?;
        r.set_item("value", o.best[i])?;
        r.set_item("start", p.start)?;
        r.set_item("std_error", o.statistics.standard_error_of(i))?;
        let (lo95, hi95) = o.statistics.interval95_of(i);
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
    d.set_item("summary", report::summary(o, "", ""))?;
    Ok(d)
}

/// `search` with its rules named as the command line names them: the
/// Jacobian, the later runs, the linear keys and the cheap keys.
fn with_rules(search: SearchSettings, names: [&str; 4]) -> PyResult<SearchSettings> {
    let [jacobian, later_runs, linear_keys, cheap_keys] = names;
    Ok(SearchSettings {
        jacobian: JacobianRule::parse(jacobian).map_err(|e| argument("jacobian", e))?,
        later_runs: LaterRuns::parse(later_runs).map_err(|e| argument("later_runs", e))?,
        linear_keys: LinearKeys::parse(linear_keys).map_err(|e| argument("linear_keys", e))?,
        cheap_keys: CheapKeys::parse(cheap_keys).map_err(|e| argument("cheap_keys", e))?,
        ..search
    })
}

/// A map coefficient's name has no dots (dotted names are configuration
/// keys).
fn check_map_names(map: &[(String, f64)]) -> PyResult<()> {
    match map.iter().find(|(n, _)| n.contains('.')) {
        Some((n, _)) => Err(errors::value(format!(
            "map {n}: a map coefficient's name has no dots (dotted names are configuration keys)"
        ))),
        None => Ok(()),
    }
}

/// Calibrate (see the Python wrapper): the command line's `fit`.
#[pyfunction]
#[pyo3(signature = (data, keys, config_path=None, overrides=Vec::new(), bounds=Vec::new(),
    starts_at=Vec::new(), holdout=0.0, validate=Vec::new(), baselines=false, starts=3,
    global_points=16, seed=1, max_evaluations=200, columns=None, skip=0, delimiter="auto",
    time=None, velocity="velocity_m_s".to_string(), friction="friction_n".to_string(),
    load=None, temperature=None, smooth=0.05, map=Vec::new(), velocity_topic=None,
    friction_topic=None, joint=None, load_topic=None, temperature_topic=None, out=None,
    report_dir=None, progress=false, rotary=false, jacobian="secant", later_runs="full",
    linear_keys="solved", cheap_keys="profiled"))]
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
    jacobian: &str,
    later_runs: &str,
    linear_keys: &str,
    cheap_keys: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let config = match &config_path {
        Some(p) => load_config(None, Some(&p.display().to_string()), &overrides)?,
        None => load_config(None, None, &overrides)?,
    };
    let delimiter = delimiter_named(delimiter)?;
    check_map_names(&map)?;
    let req = FitRequest {
        data: DataRequest {
            files: data,
            validate,
            holdout,
            mapping: Mapping {
                time,
                velocity,
                friction,
                load,
                temperature,
                smooth_s: smooth,
                coefficients: map,
            },
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
            rotary,
            friction_offset: None,
        },
        params: param_specs(&keys, &bounds, &starts_at).map_err(errors::fit)?,
        search: with_rules(
            SearchSettings {
                starts,
                global_points,
                seed,
                max_evaluations,
                ..Default::default()
            },
            [jacobian, later_runs, linear_keys, cheap_keys],
        )?,
        baselines,
    };
    let progress = progress.then(|| {
        Arc::new(|label: &str, l: &str| eprintln!("fit [{label}]: {l}")) as LabelledProgress
    });
    let outputs = FitOutputs {
        fitted: out,
        report: report_dir,
    };
    // The command line's flow: the same steps, files and report sections.
    let c = crate::interrupts::interruptible(py, |stop| {
        req.run(&config, &outputs, progress.as_ref(), stop)
    })?
    .map_err(errors::fit)?;
    calibration_dict(py, &c, baselines)
}

/// What `fit` returns of a calibration: ours (and the classic models when
/// `baselines`), the fitted file, the notes, the summary and the
/// calibrated range.
fn calibration_dict<'py>(
    py: Python<'py>,
    c: &Calibration,
    baselines: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let d = fit_dict(py, &c.ours, baselines.then_some(&c.classic[..]), &c.yaml)?;
    let mut notes = c.prepared.notes.clone();
    notes.extend(c.skipped.iter().cloned());
    if let Some(s) = &c.selection {
        notes.push(friction_node::fit::selection_report::report(
            s,
            c.prepared.data.units,
        ));
    }
    d.set_item("notes", notes)?;
    d.set_item("summary_md", c.summary_md())?;
    let range = c.ours.config.calibrated_range.as_ref().or_else(|| {
        c.ours
            .config
            .contacts
            .0
            .first()
            .and_then(|e| e.calibrated_range.as_ref())
    });
    d.set_item(
        "calibrated_range",
        range.map(|r| range_dict(py, r)).transpose()?,
    )?;
    Ok(d)
}

/// A calibrated range as a dict of its keys (None where a range was not
/// an input).
fn range_dict<'py>(
    py: Python<'py>,
    r: &friction_node::config::CalibratedRange,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let pairs = [
        ("speed_forward_min_m_s", r.speed_forward_min_m_s),
        ("speed_forward_max_m_s", r.speed_forward_max_m_s),
        ("speed_backward_min_m_s", r.speed_backward_min_m_s),
        ("speed_backward_max_m_s", r.speed_backward_max_m_s),
        ("speed_forward_min_rad_s", r.speed_forward_min_rad_s),
        ("speed_forward_max_rad_s", r.speed_forward_max_rad_s),
        ("speed_backward_min_rad_s", r.speed_backward_min_rad_s),
        ("speed_backward_max_rad_s", r.speed_backward_max_rad_s),
        ("load_min_n", r.load_min_n),
        ("load_max_n", r.load_max_n),
        ("temperature_min_c", r.temperature_min_c),
        ("temperature_max_c", r.temperature_max_c),
        ("acceleration_max_m_s2", r.acceleration_max_m_s2),
        ("acceleration_max_rad_s2", r.acceleration_max_rad_s2),
        ("training_rms_n", r.training_rms_n),
        ("training_rms_n_m", r.training_rms_n_m),
    ];
    for (k, v) in pairs {
        d.set_item(k, v)?;
    }
    d.set_item("training_samples", r.training_samples)?;
    Ok(d)
}

/// A bad value of the argument `name`: a `ValueError` naming it.
fn argument(name: &str, why: String) -> PyErr {
    errors::value(format!("{name}: {why}"))
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
            models_table::models_table_of(&ours.outcome, classic),
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
