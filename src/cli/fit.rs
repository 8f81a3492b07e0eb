//! `fit`: calibrate configuration keys (and input-map coefficients) to
//! recorded friction; optionally fit the classic models on the same data.

use anyhow::{bail, Context, Result};
use friction_node::config::Config;
use friction_node::fit::params::{map_parameter, DataScale};
use friction_node::fit::problem::{fit, FitOutcome, Options};
use friction_node::fit::report::{self, ModelRow};
use friction_node::fit::{
    Baseline, BaselineKind, Data, Delimiter, LoadForm, Mapping, ParamSpec, Parameter, PhysicsModel,
    Source, Table,
};
use std::path::{Path, PathBuf};

/// Column separator of CSV data.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DelimiterArg {
    Auto,
    Comma,
    Semicolon,
    Tab,
    Whitespace,
}

/// `fit`'s arguments.
#[derive(clap::Args, Clone)]
pub struct FitArgs {
    /// Data: CSV files (`t_s,velocity_m_s,friction_n[,load_n][,temperature_c]`,
    /// or a steady curve without `t_s`), MCAP files, rosbag2 directories.
    #[arg(value_name = "DATA", required = true)]
    pub data: Vec<PathBuf>,
    /// Parameters to fit: configuration keys (e.g. roughness.sigma_m) and
    /// --map coefficients, comma-separated.
    #[arg(
        long = "fit",
        value_name = "KEY[,KEY...]",
        value_delimiter = ',',
        required = true
    )]
    pub keys: Vec<String>,
    /// The fitted parameter file (complete; written atomically).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// Also write summary.md, fit.csv and plots into DIR.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Bounds of a fitted parameter (repeatable; default: a decade either
    /// side of the start, within the key's valid range).
    #[arg(long, value_name = "KEY=LO:HI", allow_hyphen_values = true)]
    pub bounds: Vec<String>,
    /// Start of a fitted parameter (repeatable; default: its configured value).
    #[arg(long, value_name = "KEY=VALUE", allow_hyphen_values = true)]
    pub start: Vec<String>,
    /// Hold out this fraction of each data file (the end of a time series,
    /// every k-th point of a steady curve), in [0, 0.9].
    #[arg(long, value_name = "FRACTION", default_value = "0", value_parser = holdout)]
    pub holdout: f64,
    /// Data not used for the fit, to report the error on (repeatable).
    #[arg(long, value_name = "DATA")]
    pub validate: Vec<PathBuf>,
    /// Also fit Coulomb + viscous, Stribeck and LuGre and print one table.
    #[arg(long)]
    pub baselines: bool,
    /// Local runs: the start and the best distinct global points, in [1, 100].
    #[arg(long, default_value = "3", value_parser = starts)]
    pub starts: usize,
    /// Points of the global phase, in [0, 10000].
    #[arg(long, default_value = "16", value_parser = global_points)]
    pub global_points: usize,
    /// Seed of the global phase.
    #[arg(long, default_value = "1")]
    pub seed: u64,
    /// Residual evaluations per local run, in [10, 100000].
    #[arg(long, default_value = "200", value_parser = evaluations)]
    pub max_evaluations: usize,
    /// Column names of headerless CSV data (comma-separated).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Data rows to skip at the start of every CSV file.
    #[arg(long, default_value = "0")]
    pub skip: usize,
    #[arg(long, value_enum, default_value = "auto")]
    pub delimiter: DelimiterArg,
    /// Time, s, as an expression of the columns (default: `t_s`; none: a steady curve).
    #[arg(long, value_name = "EXPR", allow_hyphen_values = true)]
    pub time: Option<String>,
    /// Velocity, m/s: an expression of the columns; `ddt(COL)` differentiates.
    #[arg(
        long,
        value_name = "EXPR",
        default_value = "velocity_m_s",
        allow_hyphen_values = true
    )]
    pub velocity: String,
    /// Friction, N: an expression of the columns and map coefficients.
    #[arg(
        long,
        value_name = "EXPR",
        default_value = "friction_n",
        allow_hyphen_values = true
    )]
    pub friction: String,
    /// Normal load, N (default: `load_n` if present, else contact.load_n).
    #[arg(long, value_name = "EXPR", allow_hyphen_values = true)]
    pub load: Option<String>,
    /// Temperature, °C (default: `temperature_c` if present).
    #[arg(long, value_name = "EXPR", allow_hyphen_values = true)]
    pub temperature: Option<String>,
    /// Half-width of the smoothing window of ddt(), s, in (0, 1e3].
    #[arg(long, value_name = "S", default_value = "0.05", value_parser = smooth)]
    pub smooth: f64,
    /// A map coefficient and its value (repeatable): fixed, or the start
    /// when it is also in --fit.
    #[arg(long, value_name = "NAME=VALUE", allow_hyphen_values = true)]
    pub map: Vec<String>,
    /// Bag data: the velocity topic.
    #[arg(long, value_name = "TOPIC")]
    pub velocity_topic: Option<String>,
    /// Bag data: the friction topic (Float64, or JointState effort with --joint).
    #[arg(long, value_name = "TOPIC")]
    pub friction_topic: Option<String>,
    /// Bag data: the joint of JointState topics.
    #[arg(long, value_name = "NAME")]
    pub joint: Option<String>,
    /// Bag data: the load topic (Float64, N).
    #[arg(long, value_name = "TOPIC")]
    pub load_topic: Option<String>,
    /// Bag data: the temperature topic (sensor_msgs/Temperature).
    #[arg(long, value_name = "TOPIC")]
    pub temperature_topic: Option<String>,
}

fn ranged(s: &str, lo: f64, hi: f64, what: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number: {what} in [{lo}, {hi}]"))?;
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be {what} in [{lo}, {hi}]"))
    }
}

fn holdout(s: &str) -> Result<f64, String> {
    ranged(s, 0.0, 0.9, "a fraction")
}

fn smooth(s: &str) -> Result<f64, String> {
    ranged(s, 1e-9, 1e3, "a number of seconds")
}

fn whole(s: &str, lo: usize, hi: usize) -> Result<usize, String> {
    let v: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number in [{lo}, {hi}]"))?;
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be a whole number in [{lo}, {hi}]"))
    }
}

fn starts(s: &str) -> Result<usize, String> {
    whole(s, 1, 100)
}

fn global_points(s: &str) -> Result<usize, String> {
    whole(s, 0, 10_000)
}

fn evaluations(s: &str) -> Result<usize, String> {
    whole(s, 10, 100_000)
}

/// `NAME=VALUE` → (name, value).
fn name_value(arg: &str, flag: &str) -> Result<(String, String)> {
    match arg.split_once('=') {
        Some((n, v)) if !n.trim().is_empty() => Ok((n.trim().to_string(), v.trim().to_string())),
        _ => bail!("{flag} {arg}: expected NAME=VALUE"),
    }
}

fn number(text: &str, what: &str) -> Result<f64> {
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => bail!("{what}: `{text}` is not a finite number"),
    }
}

fn is_bag(p: &Path) -> bool {
    p.is_dir() || matches!(p.extension().and_then(|e| e.to_str()), Some("mcap" | "db3"))
}

impl FitArgs {
    fn mapping(&self) -> Result<Mapping> {
        let coefficients = self
            .map
            .iter()
            .map(|m| {
                let (n, v) = name_value(m, "--map")?;
                if n.contains('.') {
                    bail!("--map {m}: a map coefficient's name has no dots (dotted names are configuration keys)");
                }
                Ok((n.clone(), number(&v, &format!("--map {n}"))?))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Mapping {
            time: self.time.clone(),
            velocity: self.velocity.clone(),
            friction: self.friction.clone(),
            load: self.load.clone(),
            temperature: self.temperature.clone(),
            smooth_s: self.smooth,
            coefficients,
        })
    }

    fn table(&self, path: &Path) -> Result<Table> {
        if is_bag(path) {
            #[cfg(feature = "mcap")]
            {
                let (Some(velocity), Some(friction)) = (&self.velocity_topic, &self.friction_topic)
                else {
                    bail!(
                        "{}: bag data needs --velocity-topic and --friction-topic",
                        path.display()
                    );
                };
                let topics = friction_node::fit::bag_input::BagTopics {
                    velocity: velocity.clone(),
                    friction: friction.clone(),
                    joint: self.joint.clone(),
                    load: self.load_topic.clone(),
                    temperature: self.temperature_topic.clone(),
                };
                let (table, note, used) = friction_node::fit::bag_input::read(path, &topics)?;
                eprintln!(
                    "fit: {}: velocity `{}`, friction `{}`, load {}, temperature {}",
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
                    eprintln!("warning: {n}");
                }
                return Ok(table);
            }
            #[cfg(not(feature = "mcap"))]
            bail!("{}: reading bags needs the `mcap` feature", path.display());
        }
        let delimiter = match self.delimiter {
            DelimiterArg::Auto => Delimiter::Auto,
            DelimiterArg::Comma => Delimiter::Comma,
            DelimiterArg::Semicolon => Delimiter::Semicolon,
            DelimiterArg::Tab => Delimiter::Tab,
            DelimiterArg::Whitespace => Delimiter::Whitespace,
        };
        Ok(Table::read(
            path,
            delimiter,
            self.columns.as_deref(),
            self.skip,
        )?)
    }

    /// `--bounds` and `--start` per name; each must name a fitted parameter.
    fn specs(&self) -> Result<Vec<ParamSpec>> {
        let mut specs: Vec<ParamSpec> = Vec::new();
        for k in &self.keys {
            let k = k.trim();
            if k.is_empty() {
                bail!("--fit: an empty name in the list");
            }
            if specs.iter().any(|s| s.name == k) {
                bail!("--fit {k}: named twice");
            }
            specs.push(ParamSpec {
                name: k.to_string(),
                ..Default::default()
            });
        }
        for b in &self.bounds {
            let (n, v) = name_value(b, "--bounds")?;
            let Some((lo, hi)) = v.split_once(':') else {
                bail!("--bounds {b}: expected KEY=LO:HI");
            };
            let (lo, hi) = (
                number(lo.trim(), &format!("--bounds {n}"))?,
                number(hi.trim(), &format!("--bounds {n}"))?,
            );
            let Some(s) = specs.iter_mut().find(|s| s.name == n) else {
                bail!("--bounds {n}: `{n}` is not in --fit");
            };
            s.bounds = Some((lo, hi));
        }
        for st in &self.start {
            let (n, v) = name_value(st, "--start")?;
            let v = number(&v, &format!("--start {n}"))?;
            let Some(s) = specs.iter_mut().find(|s| s.name == n) else {
                bail!("--start {n}: `{n}` is not in --fit");
            };
            s.start = Some(v);
        }
        Ok(specs)
    }
}

/// Scales of the training data at the maps' start values.
pub(crate) fn data_scale(
    sources: &[Source],
    map: &[f64],
    load_n: f64,
) -> Result<(DataScale, f64, bool)> {
    let (mut f, mut v, mut lmin, mut lmax) = (0.0f64, 0.0f64, f64::INFINITY, 0.0f64);
    let (mut sum_abs, mut n) = (0.0, 0usize);
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
    }
    if v == 0.0 {
        bail!("the velocity is zero in every sample: there is no sliding to fit");
    }
    let scale = DataScale {
        friction_n: f,
        velocity_m_s: v,
        load_min_n: lmin,
    };
    Ok((scale, sum_abs / n.max(1) as f64, lmax > 1.01 * lmin))
}

/// Data, the physics model's parameters and the fitted map coefficients.
pub struct Prepared {
    pub data: Data,
    pub model: PhysicsModel,
    pub map_fit: Vec<(usize, Parameter)>,
    pub scale: DataScale,
    pub mean_abs_n: f64,
    pub loads_vary: bool,
    /// The validation data hold loads outside the training data's range.
    pub other_loads: bool,
    pub names: Vec<String>,
}

pub fn prepare(config: &Config, args: &FitArgs) -> Result<Prepared> {
    let mapping = args.mapping()?;
    let source = |p: &PathBuf| -> Result<Source> {
        let table = args.table(p)?;
        Ok(Source::new(table, &mapping)?)
    };
    let train = args.data.iter().map(source).collect::<Result<Vec<_>>>()?;
    let validate = args
        .validate
        .iter()
        .map(source)
        .collect::<Result<Vec<_>>>()?;
    let map_names: Vec<String> = mapping.coefficients.iter().map(|c| c.0.clone()).collect();
    let map_values: Vec<f64> = mapping.coefficients.iter().map(|c| c.1).collect();
    let (scale, mean_abs_n, loads_vary) = data_scale(&train, &map_values, config.contact.load_n)?;
    let other_loads = if validate.is_empty() {
        false
    } else {
        let range = |sources: &[Source]| -> Result<(f64, f64)> {
            let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
            for s in sources {
                let se = s.series(&map_values)?;
                for k in 0..se.len() {
                    let l = se.load_at(k, config.contact.load_n);
                    lo = lo.min(l);
                    hi = hi.max(l);
                }
            }
            Ok((lo, hi))
        };
        let (tl, th) = range(&train)?;
        let (vl, vh) = range(&validate)?;
        vl < 0.99 * tl || vh > 1.01 * th
    };
    let specs = args.specs()?;
    let mut key_specs = Vec::new();
    let mut map_fit = Vec::new();
    for s in specs {
        if s.name.contains('.') {
            key_specs.push(s);
        } else if let Some(i) = map_names.iter().position(|n| *n == s.name) {
            map_fit.push((i, map_parameter(&s, map_values[i])?));
        } else {
            bail!(
                "--fit {}: neither a configuration key (dotted, e.g. roughness.sigma_m) nor a --map coefficient",
                s.name
            );
        }
    }
    let model = PhysicsModel::new(config, &key_specs, &scale)?;
    Ok(Prepared {
        names: args.data.iter().map(|p| p.display().to_string()).collect(),
        data: Data {
            train,
            validate,
            holdout: args.holdout,
            map_names,
            map_values,
        },
        model,
        map_fit,
        scale,
        mean_abs_n,
        loads_vary,
        other_loads,
    })
}

fn options(args: &FitArgs, label: &str) -> Options {
    let label = label.to_string();
    Options {
        starts: args.starts,
        global_points: args.global_points,
        seed: args.seed,
        max_evaluations: args.max_evaluations,
        progress: Some(Box::new(move |l| eprintln!("fit [{label}]: {l}"))),
    }
}

/// RMS of the measured friction on held-out samples (validation data, else
/// the held-out part), N: the scale of the held-out error.
fn held_out_scale(o: &FitOutcome) -> f64 {
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
pub fn fit_baselines(p: &Prepared, args: &FitArgs) -> Result<Vec<FitOutcome>> {
    let load_only: Vec<String> = p
        .data
        .train
        .iter()
        .flat_map(|s| s.load_only_coefficients())
        .collect();
    let map_fit: Vec<(usize, Parameter)> = p
        .map_fit
        .iter()
        .filter(|(i, _)| !load_only.contains(&p.data.map_names[*i]))
        .cloned()
        .collect();
    let all_steady = p.data.train.iter().all(Source::is_steady);
    let mut out = Vec::new();
    for kind in BaselineKind::ALL {
        if kind == BaselineKind::LuGre && all_steady {
            eprintln!("fit: LuGre skipped: on steady curves it is Stribeck");
            continue;
        }
        let model = Baseline::new(
            kind,
            LoadForm::for_data(p.loads_vary, p.other_loads),
            &p.scale,
            p.mean_abs_n,
        );
        // A classic model costs microseconds per evaluation: give it ten
        // times the budget, so that a non-converged baseline is never the
        // budget's fault.
        let mut opts = options(args, kind.label());
        opts.max_evaluations = args.max_evaluations.saturating_mul(10);
        let o = fit(&model, &p.data, map_fit.clone(), &opts)?;
        out.push(o);
    }
    Ok(out)
}

fn slug(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .split('-')
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

/// Run `fit`; exits with status 4 (after writing) when the fit did not
/// converge.
pub fn run(config: &Config, args: &FitArgs) -> Result<()> {
    let p = prepare(config, args)?;
    // Outputs are checked before any computation.
    let out_probe = friction_node::output::AtomicFile::create(&args.out)?;
    drop(out_probe);
    if let Some(r) = &args.report {
        friction_node::output::prepare_dir(r)?;
    }
    let n_model = p.model.parameters_len();
    eprintln!(
        "fit: {} parameter(s) on {} file(s) ({} validation), {} local run(s), {} global points",
        n_model + p.map_fit.len(),
        p.data.train.len(),
        p.data.validate.len(),
        args.starts,
        args.global_points
    );
    let ours = fit(
        &p.model,
        &p.data,
        p.map_fit.clone(),
        &options(args, "friction-node"),
    )?;
    let fitted_config = p
        .model
        .config(&ours.best[..n_model])
        .context("the fitted configuration")?;
    let mut map = p
        .data
        .map_names
        .iter()
        .cloned()
        .zip(p.data.map_values.iter().copied())
        .collect::<Vec<_>>();
    for (j, (i, _)) in p.map_fit.iter().enumerate() {
        map[*i].1 = ours.best[n_model + j];
    }
    let yaml = report::fitted_yaml(&fitted_config, &ours, &p.names, &map);
    friction_node::output::write_file(&args.out, yaml.as_bytes())?;
    println!("{}", report::summary(&ours, ""));
    let mut extra = String::new();
    if args.baselines {
        let baselines = fit_baselines(&p, args)?;
        let mut rows = vec![ModelRow::from(&ours)];
        rows.extend(baselines.iter().map(ModelRow::from));
        let table = report::models_table(&rows, held_out_scale(&ours));
        println!("## Models on the same data, same optimiser\n\n{table}");
        extra = format!("## Models on the same data, same optimiser\n\n{table}");
        if let Some(r) = &args.report {
            for b in &baselines {
                let dir = r.join(slug(&b.label));
                friction_node::output::prepare_dir(&dir)?;
                report::write_report(&dir, b, "")?;
            }
        }
    }
    if let Some(r) = &args.report {
        let files = report::write_report(r, &ours, &extra)?;
        eprintln!("fit: report in {} ({} files)", r.display(), files.len());
    }
    eprintln!("fit: wrote {}", args.out.display());
    if !ours.converged {
        eprintln!(
            "fit: NOT converged ({}); {} holds the best point found",
            ours.optima[0].termination,
            args.out.display()
        );
        std::process::exit(4);
    }
    Ok(())
}
