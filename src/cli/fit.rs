//! `fit`: calibrate configuration keys (and input-map coefficients) to
//! recorded friction; optionally fit the classic models on the same data.

use anyhow::{bail, Result};
use friction_node::config::Config;
use friction_node::fit::inputs::{DataRequest, TopicChoice};
use friction_node::fit::options::{CheapKeys, JacobianRule, LaterRuns, LinearKeys};
use friction_node::fit::options::{LabelledProgress, SearchSettings};
use friction_node::fit::request::{param_specs, FitOutputs, FitRequest};
use friction_node::fit::{Delimiter, Mapping, ParamSpec};
use std::path::PathBuf;
use std::sync::Arc;

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
    /// The data are a rotary joint's: velocity in rad/s, friction in N·m.
    /// The lever arm and the contact's load are chosen from the data (or
    /// taken from the configuration's one contact's `gain`) and written
    /// into the fitted file as the joint's contact.
    #[arg(long)]
    pub rotary: bool,
    /// Jacobians of the local runs: `secant` (Broyden updates between
    /// finite differences, polished on differences) or `differences`
    /// (finite differences at every iteration; slower).
    #[arg(long, default_value = "secant", value_parser = JacobianRule::parse)]
    pub jacobian: JacobianRule,
    /// How the local runs after the first end: `full` (every run walks to
    /// its end, the default) or `valley` (a run whose straight line to an
    /// earlier optimum falls all the way stops there: faster, but it can
    /// miss a better optimum). The classic models always walk to the end.
    #[arg(long, default_value = "full", value_parser = LaterRuns::parse)]
    pub later_runs: LaterRuns,
    /// The parameters the friction is linear in (the drivetrain's viscous
    /// and quadratic losses; map coefficients that only scale or offset
    /// the measured friction): `solved` exactly at every point the local
    /// runs evaluate, which then search the others (the default), or
    /// `searched` like every other parameter (slower on a ridge).
    #[arg(long, default_value = "solved", value_parser = LinearKeys::parse)]
    pub linear_keys: LinearKeys,
    /// The keys whose change only recomposes the friction along the kept
    /// film (the friction terms' keys), when keys that need a film solve
    /// (the film's own: viscosity, roughness, load…) are fitted beside
    /// them: `profiled`, fitted at every point of the film's keys with the
    /// film held, the local runs searching the film's keys alone (the
    /// default: far fewer film solves), or `searched` with them as every
    /// other key (see the README).
    #[arg(long, default_value = "profiled", value_parser = CheapKeys::parse)]
    pub cheap_keys: CheapKeys,
    /// Column names of headerless CSV data (comma-separated).
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// Data rows to skip at the start of every CSV file.
    #[arg(long, default_value = "0")]
    pub skip: usize,
    /// Column separator of CSV data (`auto`: comma, semicolon or tab,
    /// whichever the first line uses; runs of spaces when it has none).
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
    /// Friction, N: an expression of the columns and map coefficients;
    /// `smooth(COL)` smooths a column as `ddt` does (a measured force beside
    /// `ddt(ddt(x))`: `smooth(smooth(F))`).
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
    /// Half-width of the smoothing window of ddt() and smooth(), s, in (0, 1e3].
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

    /// `--fit`, `--bounds` and `--start` → the fitted parameters.
    fn specs(&self) -> Result<Vec<ParamSpec>> {
        let mut bounds = Vec::new();
        for b in &self.bounds {
            let (n, v) = name_value(b, "--bounds")?;
            let Some((lo, hi)) = v.split_once(':') else {
                bail!("--bounds {b}: expected KEY=LO:HI");
            };
            bounds.push((
                n.clone(),
                number(lo.trim(), &format!("--bounds {n}"))?,
                number(hi.trim(), &format!("--bounds {n}"))?,
            ));
        }
        let mut starts = Vec::new();
        for st in &self.start {
            let (n, v) = name_value(st, "--start")?;
            let v = number(&v, &format!("--start {n}"))?;
            starts.push((n, v));
        }
        Ok(param_specs(&self.keys, &bounds, &starts)?)
    }

    /// The request the library runs.
    pub fn request(&self) -> Result<FitRequest> {
        let delimiter = match self.delimiter {
            DelimiterArg::Auto => Delimiter::Auto,
            DelimiterArg::Comma => Delimiter::Comma,
            DelimiterArg::Semicolon => Delimiter::Semicolon,
            DelimiterArg::Tab => Delimiter::Tab,
            DelimiterArg::Whitespace => Delimiter::Whitespace,
        };
        Ok(FitRequest {
            data: DataRequest {
                files: self.data.clone(),
                validate: self.validate.clone(),
                holdout: self.holdout,
                mapping: self.mapping()?,
                columns: self.columns.clone(),
                skip: self.skip,
                delimiter,
                topics: TopicChoice {
                    velocity: self.velocity_topic.clone(),
                    friction: self.friction_topic.clone(),
                    joint: self.joint.clone(),
                    load: self.load_topic.clone(),
                    temperature: self.temperature_topic.clone(),
                },
                rotary: self.rotary,
                friction_offset: None,
            },
            params: self.specs()?,
            search: SearchSettings {
                starts: self.starts,
                global_points: self.global_points,
                seed: self.seed,
                max_evaluations: self.max_evaluations,
                jacobian: self.jacobian,
                later_runs: self.later_runs,
                linear_keys: self.linear_keys,
                cheap_keys: self.cheap_keys,
            },
            baselines: self.baselines,
        })
    }
}

/// Run `fit` (the library's one flow); prints the summary, and exits with
/// status 4 (after writing) when the fit did not converge.
pub fn run(config: &Config, args: &FitArgs) -> Result<()> {
    let req = args.request()?;
    let outputs = FitOutputs {
        fitted: Some(args.out.clone()),
        report: args.report.clone(),
    };
    let progress: LabelledProgress = Arc::new(|label: &str, l: &str| {
        if label == "fit" {
            eprintln!("fit: {l}");
        } else {
            eprintln!("fit [{label}]: {l}");
        }
    });
    let c = req.run(
        config,
        &outputs,
        Some(&progress),
        friction_node::interrupt::Stop::process(),
    )?;
    println!("{}", c.summary_md());
    let ours = &c.ours.outcome;
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

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// `fit`'s arguments as the command line parses them.
    #[derive(Parser)]
    struct Fit {
        #[command(flatten)]
        args: FitArgs,
    }

    #[test]
    fn the_command_lines_defaults_are_the_librarys() {
        let args = Fit::try_parse_from([
            "fit",
            "data.csv",
            "--fit",
            "contact.boundary_friction",
            "--out",
            "fitted.yaml",
        ])
        .expect("the least a fit needs parses")
        .args;
        let req = args.request().expect("a request");
        assert_eq!(req.search, SearchSettings::default());
        assert_eq!(req.data.mapping, Mapping::default());
        assert_eq!(req.data.delimiter, Delimiter::default());
        assert_eq!((req.data.holdout, req.data.skip), (0.0, 0));
        assert!(!req.data.rotary && !req.baselines);
    }
}
