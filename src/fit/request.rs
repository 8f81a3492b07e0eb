//! A calibration as data: what `fit`'s command line and the Python
//! `friction_node.fit()` both build, and the steps from it to the fitted
//! outcomes (data → sources → parameters → our fit → the classic models on
//! the same data). Writing the fitted file and the report stays with the
//! caller; nothing here prints.

use super::driver::{fit, FitOutcome};
use super::options::{Options, Progress};
use super::problem::Model;
use super::{
    Baseline, BaselineKind, Delimiter, FitError, FittedParameter, LoadForm, Mapping, ParamSpec,
    Source, Table,
};
use crate::config::Config;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Progress lines with the label of the model being fitted.
pub type LabelledProgress = Arc<dyn Fn(&str, &str) + Send + Sync>;

/// Topics of bag data (velocity and friction are needed when a data path is
/// a bag).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TopicChoice {
    /// The velocity topic.
    pub velocity: Option<String>,
    /// The friction topic.
    pub friction: Option<String>,
    /// JointState topics: which joint.
    pub joint: Option<String>,
    /// The load topic.
    pub load: Option<String>,
    /// The temperature topic.
    pub temperature: Option<String>,
}

/// Everything a calibration needs besides the base configuration.
#[derive(Clone)]
pub struct FitRequest {
    /// Training data: CSV files, MCAP files, rosbag2 directories.
    pub data: Vec<PathBuf>,
    /// Validation data (not fitted; the error is reported on it).
    pub validate: Vec<PathBuf>,
    /// Fitted parameters with their optional bounds and starts.
    pub params: Vec<ParamSpec>,
    /// Column expressions and map coefficients.
    pub mapping: Mapping,
    /// Fraction of each training file held out, in [0, 0.9].
    pub holdout: f64,
    /// CSV reading: column names of headerless data, rows skipped, separator.
    pub columns: Option<Vec<String>>,
    /// Rows skipped at the top of each table.
    pub skip: usize,
    /// The column separator.
    pub delimiter: Delimiter,
    /// Bag reading.
    pub topics: TopicChoice,
    /// Optimiser settings (as `fit`'s options).
    pub starts: usize,
    /// Points of the global phase (0: none).
    pub global_points: usize,
    /// Seed of the global phase.
    pub seed: u64,
    /// Residual evaluations per local run.
    pub max_evaluations: usize,
    /// How the local runs get their Jacobians.
    pub jacobian: super::local_run::JacobianRule,
    /// How the runs after the first end.
    pub later_runs: super::local_run::LaterRuns,
    /// Also fit Coulomb + viscous, Stribeck and LuGre.
    pub baselines: bool,
    /// The data are a rotary joint's: velocity in rad/s, friction in N·m
    /// (the lever arm and the contact's load are chosen from the data, see
    /// `rotary.rs`, unless the configuration's one contact has a gain).
    pub rotary: bool,
    /// Progress lines, with the model's label.
    pub progress: Option<LabelledProgress>,
    /// Requested from outside (SIGINT, Ctrl-C): the fit ends with
    /// [`FitError::Interrupted`].
    pub stop: crate::interrupt::Stop,
}

impl Default for FitRequest {
    /// The command line's defaults.
    fn default() -> Self {
        Self {
            data: Vec::new(),
            validate: Vec::new(),
            params: Vec::new(),
            mapping: Mapping::default(),
            holdout: 0.0,
            columns: None,
            skip: 0,
            delimiter: Delimiter::Auto,
            topics: TopicChoice::default(),
            starts: 3,
            global_points: 16,
            seed: 1,
            max_evaluations: 200,
            jacobian: Default::default(),
            later_runs: Default::default(),
            baselines: false,
            rotary: false,
            progress: None,
            stop: crate::interrupt::Stop::new(),
        }
    }
}

fn range_error(what: &str, value: String, range: &str) -> FitError {
    FitError::Data {
        what: what.to_string(),
        message: format!("{value} is out of range: must be {range}"),
    }
}

impl FitRequest {
    /// The ranges the command line enforces.
    pub fn check(&self) -> Result<(), FitError> {
        if self.data.is_empty() {
            return Err(FitError::Data {
                what: "data".into(),
                message: "no data files given".into(),
            });
        }
        if self.params.is_empty() {
            return Err(FitError::Data {
                what: "--fit".into(),
                message: "no parameter to fit".into(),
            });
        }
        if !(self.holdout.is_finite() && (0.0..=0.9).contains(&self.holdout)) {
            return Err(range_error(
                "--holdout",
                self.holdout.to_string(),
                "a fraction in [0, 0.9]",
            ));
        }
        if !(1..=100).contains(&self.starts) {
            return Err(range_error(
                "--starts",
                self.starts.to_string(),
                "in [1, 100]",
            ));
        }
        if self.global_points > 10_000 {
            return Err(range_error(
                "--global-points",
                self.global_points.to_string(),
                "in [0, 10000]",
            ));
        }
        if !(10..=100_000).contains(&self.max_evaluations) {
            return Err(range_error(
                "--max-evaluations",
                self.max_evaluations.to_string(),
                "in [10, 100000]",
            ));
        }
        let s = self.mapping.smooth_s;
        if !(s.is_finite() && (1e-9..=1e3).contains(&s)) {
            return Err(range_error(
                "--smooth",
                s.to_string(),
                "a number of seconds in (0, 1e3]",
            ));
        }
        Ok(())
    }

    fn options(&self, label: &str) -> Options {
        let progress: Option<Progress> = self.progress.clone().map(|p| {
            let label = label.to_string();
            Box::new(move |l: &str| p(&label, l)) as Progress
        });
        Options {
            starts: self.starts,
            global_points: self.global_points,
            seed: self.seed,
            max_evaluations: self.max_evaluations,
            progress,
            stop: self.stop.clone(),
            extra_starts: Vec::new(),
            jacobian: self.jacobian,
            later_runs: self.later_runs,
            ..Default::default()
        }
    }

    /// One data file as a table; a bag also returns which topics were used.
    pub fn table(&self, path: &Path) -> Result<(Table, Option<String>), FitError> {
        if is_bag(path) {
            #[cfg(feature = "mcap")]
            {
                let (Some(velocity), Some(friction)) =
                    (&self.topics.velocity, &self.topics.friction)
                else {
                    return Err(FitError::Data {
                        what: path.display().to_string(),
                        message: "bag data needs --velocity-topic and --friction-topic".into(),
                    });
                };
                let topics = super::bag_input::BagTopics {
                    velocity: velocity.clone(),
                    friction: friction.clone(),
                    joint: self.topics.joint.clone(),
                    load: self.topics.load.clone(),
                    temperature: self.topics.temperature.clone(),
                    rotary: self.rotary,
                };
                let (table, note, used) = super::bag_input::read(path, &topics)?;
                let mut line = format!(
                    "{}: velocity `{}`, friction `{}`, load {}, temperature {}",
                    path.display(),
                    used.velocity,
                    used.friction,
                    used.load.as_deref().map_or(
                        "from the configuration (contact.load_n)".into(),
                        |t| format!("`{t}`")
                    ),
                    used.temperature
                        .as_deref()
                        .map_or("none".into(), |t| format!("`{t}`")),
                );
                if let Some(n) = note {
                    line.push_str(&format!("\nwarning: {n}"));
                }
                return Ok((table, Some(line)));
            }
            #[cfg(not(feature = "mcap"))]
            return Err(FitError::Data {
                what: path.display().to_string(),
                message: "reading bags needs the `mcap` feature".into(),
            });
        }
        Ok((
            Table::read(path, self.delimiter, self.columns.as_deref(), self.skip)?,
            None,
        ))
    }
}

/// A data path that is read as a bag.
pub fn is_bag(p: &Path) -> bool {
    p.is_dir() || matches!(p.extension().and_then(|e| e.to_str()), Some("mcap" | "db3"))
}

/// The spec a bound or start of `name` applies to: a fitted parameter's,
/// or under `--fit auto` one of a key the selection may choose (made on
/// first use, marked [`ParamSpec::if_chosen`]).
fn spec_for<'a>(
    specs: &'a mut Vec<ParamSpec>,
    name: &str,
    flag: &str,
) -> Result<&'a mut ParamSpec, FitError> {
    if let Some(i) = specs.iter().position(|s| s.name == name) {
        return Ok(&mut specs[i]);
    }
    let auto = specs.iter().any(|s| s.name == super::auto::AUTO);
    if auto && super::auto::may_choose(name) {
        specs.push(ParamSpec {
            name: name.to_string(),
            if_chosen: true,
            ..Default::default()
        });
        return Ok(specs.last_mut().expect("just pushed"));
    }
    let message = if auto {
        format!(
            "`{name}` is neither in --fit nor a key --fit auto may choose ({})",
            super::auto::choosable_keys().join(", ")
        )
    } else {
        format!("`{name}` is not in --fit")
    };
    Err(if flag == "--bounds" {
        FitError::Bounds {
            key: name.to_string(),
            message,
        }
    } else {
        FitError::Data {
            what: format!("{flag} {name}"),
            message,
        }
    })
}

/// Fitted parameters from names, `(name, lo, hi)` bounds and `(name,
/// start)` starts; every bound and start must name a fitted parameter or,
/// under `--fit auto`, a key the selection may choose (used if chosen).
pub fn param_specs(
    keys: &[String],
    bounds: &[(String, f64, f64)],
    starts: &[(String, f64)],
) -> Result<Vec<ParamSpec>, FitError> {
    let mut specs: Vec<ParamSpec> = Vec::new();
    for k in keys {
        let k = k.trim();
        if k.is_empty() {
            return Err(FitError::Key {
                key: String::new(),
                message: "an empty name in the list".into(),
            });
        }
        if specs.iter().any(|s| s.name == k) {
            return Err(FitError::Key {
                key: k.into(),
                message: "named twice".into(),
            });
        }
        specs.push(ParamSpec {
            name: k.to_string(),
            ..Default::default()
        });
    }
    for (n, lo, hi) in bounds {
        spec_for(&mut specs, n, "--bounds")?.bounds = Some((*lo, *hi));
    }
    for (n, v) in starts {
        let s = spec_for(&mut specs, n, "--start")?;
        if !v.is_finite() {
            return Err(FitError::Data {
                what: format!("--start {n}"),
                message: format!("`{v}` is not a finite number"),
            });
        }
        s.start = Some(*v);
    }
    Ok(specs)
}

pub use super::prepare::{data_scale, model_for, prepare, select_terms, MapFit, Prepared};

/// Our model's fit: the outcome, the fitted configuration and the map
/// coefficients (fitted or fixed) by name.
pub struct OursFitted {
    /// The fit.
    pub outcome: FitOutcome,
    /// The configuration with the fitted values.
    pub config: Config,
    /// Map coefficients by name.
    pub map: Vec<(String, f64)>,
}

/// Fit our model.
pub fn fit_ours(p: &Prepared, req: &FitRequest) -> Result<OursFitted, FitError> {
    let outcome = fit(
        &p.model,
        &p.data,
        p.map_fit.clone(),
        &req.options("friction-node"),
    )?;
    let mut outcome = outcome;
    outcome.joint = p.lever.clone();
    let n_model = p.model.parameters_len();
    let mut config = p.model.config(&outcome.best[..n_model])?;
    if let Some(l) = &p.lever {
        config = super::rotary::on_joint(config, &p.joint, l.lever_m);
    }
    let mut map = p
        .data
        .map_names
        .iter()
        .cloned()
        .zip(p.data.map_values.iter().copied())
        .collect::<Vec<_>>();
    for (j, (i, _)) in p.map_fit.iter().enumerate() {
        map[*i].1 = outcome.best[n_model + j];
    }
    Ok(OursFitted {
        outcome,
        config,
        map,
    })
}

/// RMS of the measured friction on held-out samples (validation data, else
/// the held-out parts), N: the scale of the held-out error.
pub fn held_out_scale(o: &FitOutcome) -> f64 {
    let fits = if o.validate.is_empty() {
        &o.held_out
    } else {
        &o.validate
    };
    let (ss, n) = fits
        .iter()
        .flat_map(|sf| sf.series.friction.iter())
        .fold((0.0, 0usize), |(ss, n), f| (ss + f * f, n + 1));
    (ss / n.max(1) as f64).sqrt()
}

/// The optimiser's options for classic model `kind`.
fn baseline_options(req: &FitRequest, kind: BaselineKind) -> Options {
    let mut opts = req.options(kind.label());
    // A classic model costs microseconds per evaluation: give it ten times
    // the budget, so that a non-converged baseline is never the budget's
    // fault.
    opts.max_evaluations = req.max_evaluations.saturating_mul(10);
    // The secant update saves simulations; a classic model costs
    // microseconds, so it keeps the exact Jacobian (whose path the classic
    // models' optima were checked on against SciPy).
    opts.jacobian = super::local_run::JacobianRule::Differences;
    // For the same reason every later run walks to its end: the valley test
    // saves simulations at the risk of missing a better optimum, a risk the
    // baselines need not take.
    opts.later_runs = super::local_run::LaterRuns::Full;
    opts
}

/// Fit the classic models with the same optimiser; load-only map
/// coefficients stay at their starts (the load-linear levels absorb them).
/// Returns the outcomes and a note for each model skipped.
pub fn fit_baselines(
    p: &Prepared,
    req: &FitRequest,
) -> Result<(Vec<FitOutcome>, Vec<String>), FitError> {
    let load_only: Vec<String> = p
        .data
        .train
        .iter()
        .flat_map(|s| s.load_only_coefficients())
        .collect();
    let map_fit: Vec<(usize, FittedParameter)> = p
        .map_fit
        .iter()
        .filter(|(i, _)| !load_only.contains(&p.data.map_names[*i]))
        .cloned()
        .collect();
    let all_steady = p.data.train.iter().all(Source::is_steady);
    // The training data at the maps' starts: the classic models' starts.
    let series = p
        .data
        .train
        .iter()
        .map(|s| {
            let mut se = s.series(&p.data.map_values)?;
            p.data.holdout.apply(&mut se);
            Ok(se)
        })
        .collect::<Result<Vec<_>, FitError>>()?;
    let (mut out, mut skipped) = (Vec::new(), Vec::new());
    let mut previous: Option<(Baseline, FitOutcome)> = None;
    for kind in BaselineKind::ALL {
        if kind == BaselineKind::LuGre && all_steady {
            skipped.push("LuGre skipped: on steady curves it is Stribeck".to_string());
            continue;
        }
        let model = Baseline::from_data(
            kind,
            LoadForm::for_data(p.loads_vary, p.load_given),
            &p.scale,
            p.mean_abs_n,
            &series,
        );
        let mut opts = baseline_options(req, kind);
        // Each model contains the one before it: it also starts from that
        // one's optimum, so it never ends worse than the simpler model; and
        // from generic starts that ignore the data (mean level, static
        // level half as high again), in case the data's starts sit in
        // another basin.
        if let Some((inner, o)) = &previous {
            opts.extra_starts = model.nested_starts(inner, &o.best, map_fit.len());
        }
        let generic = Baseline::from_data(
            kind,
            LoadForm::for_data(p.loads_vary, p.load_given),
            &p.scale,
            p.mean_abs_n,
            &[],
        );
        opts.extra_starts.push(
            generic
                .parameters()
                .iter()
                .map(|q| q.start)
                .chain(map_fit.iter().map(|(i, _)| p.data.map_values[*i]))
                .collect(),
        );
        let o = fit(&model, &p.data, map_fit.clone(), &opts)?;
        out.push(o.clone());
        previous = Some((model, o));
    }
    Ok((out, skipped))
}
