//! A calibration as data: what `fit`'s command line and the Python
//! `friction_node.fit()` both build, and the steps from it to the fitted
//! outcomes (data → sources → parameters → our fit → the classic models on
//! the same data). Writing the fitted file and the report stays with the
//! caller; nothing here prints.

use super::driver::{fit, FitOutcome};
use super::options::{Options, Progress};
use super::params::{map_parameter, DataScale};
use super::problem::Model;
use super::{
    Baseline, BaselineKind, Data, Delimiter, FitError, FittedParameter, LoadForm, Mapping,
    ParamSpec, PhysicsModel, Source, Table,
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

/// Fitted parameters from names, `(name, lo, hi)` bounds and `(name,
/// start)` starts; every bound and start must name a fitted parameter.
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
        let Some(s) = specs.iter_mut().find(|s| s.name == *n) else {
            return Err(FitError::Bounds {
                key: n.clone(),
                message: format!("`{n}` is not in --fit"),
            });
        };
        s.bounds = Some((*lo, *hi));
    }
    for (n, v) in starts {
        let Some(s) = specs.iter_mut().find(|s| s.name == *n) else {
            return Err(FitError::Data {
                what: format!("--start {n}"),
                message: format!("`{n}` is not in --fit"),
            });
        };
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

/// Scales of the training data at the maps' start values: the scale, the
/// mean |F| and whether the load varies.
pub fn data_scale(
    sources: &[Source],
    map: &[f64],
    load_n: f64,
) -> Result<(DataScale, f64, bool), FitError> {
    let (mut f, mut v, mut lmin, mut lmax) = (0.0f64, 0.0f64, f64::INFINITY, 0.0f64);
    let (mut sum_abs, mut n) = (0.0, 0usize);
    let mut all = Vec::with_capacity(sources.len());
    for s in sources {
        let se = s.series(map)?;
        for k in 0..se.len() {
            f = f.max(se.friction[k].abs());
            v = v.max(se.velocity[k].abs());
            let l = se.load_at(k, load_n);
            lmin = lmin.min(l);
            lmax = lmax.max(l);
            sum_abs += se.friction[k].abs();
            n += 1;
        }
        all.push(se);
    }
    if v == 0.0 {
        return Err(FitError::Data {
            what: "data".into(),
            message: "the velocity is zero in every sample: there is no sliding to fit".into(),
        });
    }
    let scale = DataScale {
        friction_n: f,
        velocity_m_s: v,
        load_min_n: lmin,
        reversal_stiffness_n_m: super::reversals::stiffness(&all).stiffness_n_m,
    };
    Ok((scale, sum_abs / n.max(1) as f64, lmax > 1.01 * lmin))
}

/// A rotary joint's model configuration and lever: the configuration's
/// one contact with its gain, or a lever arm and load chosen from the data
/// (their start values); a bound on the boundary friction that excludes the
/// value the chosen load rests on is an error naming both.
fn rotary_setup(
    config: &Config,
    train: &[Source],
    map: &[f64],
    specs: &[ParamSpec],
) -> Result<(Config, super::rotary::Lever), FitError> {
    let contacts = config.resolved_contacts();
    if config.contacts.0.len() > 1 {
        return Err(FitError::Data {
            what: "--rotary".into(),
            message: format!(
                "the configuration has {} contacts; a joint's fit needs one (or none: the top level)",
                contacts.len()
            ),
        });
    }
    let one = &contacts[0];
    if !config.contacts.is_empty() && one.gain != 1.0 {
        return Ok((
            one.config.clone(),
            super::rotary::Lever {
                lever_m: one.gain,
                load_n: one.config.contact.load_n,
                how: format!("configured: contacts.{}.gain", one.name),
            },
        ));
    }
    let (mut top, mut sum, mut n) = (0.0f64, 0.0, 0usize);
    let mut all = Vec::new();
    for s in train {
        all.push(s.series(map)?);
    }
    for se in &all {
        top = se.velocity.iter().fold(top, |m, v| m.max(v.abs()));
    }
    for se in &all {
        for k in (0..se.len()).filter(|&k| se.velocity[k].abs() > 0.1 * top) {
            sum += se.friction[k].abs();
            n += 1;
        }
    }
    let level = sum / n.max(1) as f64;
    let lever = super::rotary::choose(&one.config, top, level)?;
    let mut c = one.config.clone();
    if all.iter().all(|s| s.load.is_none()) {
        c.contact.load_n = lever.load_n;
    }
    let mu = c.contact.boundary_friction;
    for s in specs
        .iter()
        .filter(|s| s.name == "contact.boundary_friction")
    {
        if let Some((lo, hi)) = s.bounds {
            if !(lo..=hi).contains(&mu) {
                return Err(FitError::Bounds {
                    key: s.name.clone(),
                    message: format!(
                        "{lo}:{hi} excludes {mu}, the boundary friction on which the chosen scale rests (load {} N and lever arm {} m give the data's sliding level {} N·m with it): widen the bounds, or set contact.boundary_friction inside them in the configuration (the load is then chosen from that value)",
                        crate::text::Num(lever.load_n),
                        crate::text::Num(lever.lever_m),
                        crate::text::Num(level)
                    ),
                });
            }
        }
    }
    Ok((c, lever))
}

/// Data, the physics model's parameters and the fitted map coefficients.
pub struct Prepared {
    /// The sources.
    pub data: Data,
    /// Our model with its fitted keys.
    pub model: PhysicsModel,
    /// Fitted map coefficients (index, bounds).
    pub map_fit: Vec<(usize, FittedParameter)>,
    /// The data's velocity and friction scales (for the baselines' starts and bounds).
    pub scale: DataScale,
    /// Mean |friction| of the training data, N.
    pub mean_abs_n: f64,
    /// Whether the training loads differ by more than 1 %.
    pub loads_vary: bool,
    /// The validation data hold loads outside the training data's range.
    pub other_loads: bool,
    /// The training files, as given.
    pub names: Vec<String>,
    /// What was read from each bag (topics used, warnings).
    pub notes: Vec<String>,
    /// A rotary joint's lever arm and load (`--rotary`).
    pub lever: Option<super::rotary::Lever>,
    /// The joint's name in the fitted file (`--joint`, else `joint`).
    pub joint: String,
    /// The configuration our model runs on (a rotary joint's contact with
    /// its chosen load).
    pub model_config: Config,
    /// The data's scales as our model sees them (through the lever).
    pub model_scale: DataScale,
    /// The names given to `--fit` (besides `auto`).
    pub given: Vec<ParamSpec>,
    /// `--fit auto`: the data choose the terms.
    pub auto: bool,
}

/// Fitted map coefficients: index into the data's maps and bounds.
pub type MapFit = Vec<(usize, FittedParameter)>;

/// Split specs into configuration keys and map coefficients (with their
/// bounds resolved).
fn split_specs(
    specs: &[ParamSpec],
    map_names: &[String],
    map_values: &[f64],
) -> Result<(Vec<ParamSpec>, MapFit), FitError> {
    let mut key_specs = Vec::new();
    let mut map_fit = Vec::new();
    for s in specs {
        if s.name.contains('.') {
            key_specs.push(s.clone());
        } else if let Some(i) = map_names.iter().position(|n| *n == s.name) {
            map_fit.push((i, map_parameter(s, map_values[i])?));
        } else {
            return Err(FitError::Key {
                key: s.name.clone(),
                message:
                    "neither a configuration key (dotted, e.g. roughness.sigma_m) nor a --map coefficient"
                        .into(),
            });
        }
    }
    Ok((key_specs, map_fit))
}

/// Our model for `specs` on `p`'s data (a rotary joint's lever included)
/// and its fitted map coefficients, every parameter started at its value
/// in `warm` when it has one (the bounds stay those of `specs`).
pub fn model_for(
    p: &Prepared,
    specs: &[ParamSpec],
    warm: &[(String, f64)],
) -> Result<(PhysicsModel, MapFit), FitError> {
    let (key_specs, mut map_fit) = split_specs(specs, &p.data.map_names, &p.data.map_values)?;
    let lever_m = p.lever.as_ref().map_or(1.0, |l| l.lever_m);
    let mut model =
        PhysicsModel::new(&p.model_config, &key_specs, &p.model_scale)?.with_lever(lever_m);
    model.warm(warm);
    for (_, q) in &mut map_fit {
        if let Some((_, v)) = warm.iter().find(|(n, _)| *n == q.name) {
            q.warm(*v);
        }
    }
    Ok((model, map_fit))
}

fn load_range(sources: &[Source], map: &[f64], load_n: f64) -> Result<(f64, f64), FitError> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for s in sources {
        let se = s.series(map)?;
        for k in 0..se.len() {
            let l = se.load_at(k, load_n);
            lo = lo.min(l);
            hi = hi.max(l);
        }
    }
    Ok((lo, hi))
}

/// Read the data and set up the parameters (everything checked before any
/// simulation).
pub fn prepare(config: &Config, req: &FitRequest) -> Result<Prepared, FitError> {
    req.check()?;
    let mut notes = Vec::new();
    let mut source = |p: &PathBuf| -> Result<Source, FitError> {
        let (table, note) = req.table(p)?;
        notes.extend(note);
        Source::new(table, &req.mapping)
    };
    let train = req
        .data
        .iter()
        .map(&mut source)
        .collect::<Result<Vec<_>, _>>()?;
    let validate = req
        .validate
        .iter()
        .map(&mut source)
        .collect::<Result<Vec<_>, _>>()?;
    let mapping = &req.mapping;
    let map_names: Vec<String> = mapping.coefficients.iter().map(|c| c.0.clone()).collect();
    let map_values: Vec<f64> = mapping.coefficients.iter().map(|c| c.1).collect();
    let load_n = config.contact.load_n;
    let (scale, mean_abs_n, loads_vary) = data_scale(&train, &map_values, load_n)?;
    let other_loads = if validate.is_empty() {
        false
    } else {
        let (tl, th) = load_range(&train, &map_values, load_n)?;
        let (vl, vh) = load_range(&validate, &map_values, load_n)?;
        vl < 0.99 * tl || vh > 1.01 * th
    };
    let (auto, _) = super::auto::split(
        &req.params
            .iter()
            .map(|s| s.name.clone())
            .collect::<Vec<_>>(),
    );
    let given: Vec<ParamSpec> = req
        .params
        .iter()
        .filter(|s| s.name != super::auto::AUTO)
        .cloned()
        .collect();
    // With `auto` the model starts with the base key; the selection
    // chooses the rest.
    let mut specs = given.clone();
    if auto && !specs.iter().any(|s| s.name == super::auto::BASE_KEY) {
        specs.insert(
            0,
            ParamSpec {
                name: super::auto::BASE_KEY.into(),
                ..Default::default()
            },
        );
    }
    let (key_specs, map_fit) = split_specs(&specs, &map_names, &map_values)?;
    if scale.reversal_stiffness_n_m.is_none() {
        for s in key_specs.iter().filter(|s| s.name.contains("presliding_")) {
            notes.push(format!(
                "warning: {} is fitted, but the training data hold no usable velocity reversal: pre-sliding shows only through a reversal, so these data cannot identify it (its estimate will follow its start and bounds)",
                s.name
            ));
        }
    }
    let (model_config, lever) = if req.rotary {
        let (c, l) = rotary_setup(config, &train, &map_values, &key_specs)?;
        notes.push(format!(
            "rotary joint: lever arm {} m, contact load {} N ({})",
            crate::text::Num(l.lever_m),
            crate::text::Num(l.load_n),
            l.how
        ));
        (c, Some(l))
    } else {
        (config.clone(), None)
    };
    let model_scale = match &lever {
        Some(l) => {
            let load_min = load_range(&train, &map_values, model_config.contact.load_n)?.0;
            scale.through_lever(l.lever_m, load_min)
        }
        None => scale,
    };
    let lever_m = lever.as_ref().map_or(1.0, |l| l.lever_m);
    let model = PhysicsModel::new(&model_config, &key_specs, &model_scale)?.with_lever(lever_m);
    Ok(Prepared {
        model_config,
        model_scale,
        given,
        auto,
        lever,
        joint: req.topics.joint.clone().unwrap_or_else(|| "joint".into()),
        names: req.data.iter().map(|p| p.display().to_string()).collect(),
        data: Data {
            train,
            validate,
            holdout: if req.holdout > 0.0 {
                super::problem::HoldOut::Fraction(req.holdout)
            } else {
                super::problem::HoldOut::None
            },
            map_names,
            map_values,
            units: if req.rotary {
                super::Units::Rotary
            } else {
                super::Units::Linear
            },
        },
        model,
        map_fit,
        scale,
        mean_abs_n,
        loads_vary,
        other_loads,
        notes,
    })
}

/// `--fit auto`: choose the terms (see `auto.rs`) and set `p`'s model to
/// the chosen keys; `say` receives a line per set tried.
pub fn select_terms(
    p: &mut Prepared,
    req: &FitRequest,
    say: &(dyn Fn(&str) + Sync),
) -> Result<super::auto::Selection, FitError> {
    let given = p.given.clone();
    let s = super::auto::select(p, req, &given, say)?;
    let specs: Vec<ParamSpec> = s
        .keys
        .iter()
        .map(|k| {
            given
                .iter()
                .find(|g| g.name == *k)
                .cloned()
                .unwrap_or(ParamSpec {
                    name: k.clone(),
                    ..Default::default()
                })
        })
        .collect();
    let (model, map_fit) = model_for(p, &specs, &[])?;
    p.model = model;
    p.map_fit = map_fit;
    Ok(s)
}

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
/// the held-out part), N: the scale of the held-out error.
pub fn held_out_scale(o: &FitOutcome) -> f64 {
    let (mut ss, mut n) = (0.0, 0usize);
    let mut add = |f: f64| {
        ss += f * f;
        n += 1;
    };
    if o.validate.is_empty() {
        for sf in &o.train {
            for k in 0..sf.series.len() {
                if !sf.series.fit[k] {
                    add(sf.series.friction[k]);
                }
            }
        }
    } else {
        for sf in &o.validate {
            sf.series.friction.iter().for_each(|f| add(*f));
        }
    }
    (ss / n.max(1) as f64).sqrt()
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
            LoadForm::for_data(p.loads_vary, p.other_loads),
            &p.scale,
            p.mean_abs_n,
            &series,
        );
        // A classic model costs microseconds per evaluation: give it ten
        // times the budget, so that a non-converged baseline is never the
        // budget's fault.
        let mut opts = req.options(kind.label());
        opts.max_evaluations = req.max_evaluations.saturating_mul(10);
        // The secant update saves simulations; a classic model costs
        // microseconds, so it keeps the exact Jacobian (whose path the
        // classic models' optima were checked on against SciPy).
        opts.jacobian = super::local_run::JacobianRule::Differences;
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
            LoadForm::for_data(p.loads_vary, p.other_loads),
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
