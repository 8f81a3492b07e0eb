//! The command line's argument types, shared by the subcommands. Every
//! numeric argument is parsed with its allowed range, which the error
//! message states.

use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "friction-node",
    version,
    about = "Physics-based sliding-friction estimate: transient mixed lubrication (Driesen et al. 2023)",
    long_about = None
)]
pub struct Cli {
    #[command(flatten)]
    pub common: Common,
    #[command(subcommand)]
    pub command: Command,
}

/// The fine reference the accuracy benches compare with, and the cycles
/// they run (`bench-accuracy`, `bench-cases`).
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct ReferenceArgs {
    /// The reference grid, in [8, 65536] (bench-cases: with the muscl_van_leer flux).
    #[arg(long, default_value = "2048", value_parser = cells)]
    pub reference_cells: usize,
    /// The reference step (s), in [1e-6, 0.1].
    #[arg(long, default_value = "0.000125", value_parser = accuracy_dt)]
    pub reference_dt: f64,
    /// Cycles per run (the last one is measured), in [2, 100].
    #[arg(long, default_value = "3", value_parser = accuracy_cycles)]
    pub cycles: u32,
}

/// Accepted before and after the subcommand; overrides accumulate in order
/// (clap's `global` would replace the earlier ones).
#[derive(clap::Args, Clone, Default)]
pub struct Common {
    /// ROS 2 parameter file (default: the built-in launch-config/default.yaml).
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Override a parameter, e.g. --set contact.load_n=5762 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
}

/// A number in an interval; the message states the interval and the unit.
fn ranged(s: &str, lo: f64, lo_open: bool, hi: f64, unit: &str) -> Result<f64, String> {
    let range = format!(
        "must be {unit} in {}{}, {}]",
        if lo_open { "(" } else { "[" },
        friction_node::text::Num(lo),
        friction_node::text::Num(hi)
    );
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number: {range}"))?;
    let ok = v.is_finite() && (if lo_open { v > lo } else { v >= lo }) && v <= hi;
    if ok {
        Ok(v)
    } else {
        Err(range)
    }
}

/// A whole number in [lo, hi].
fn count(s: &str, lo: u64, hi: u64, what: &str) -> Result<u64, String> {
    let range = format!("must be {what} in [{lo}, {hi}]");
    let v: u64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number: {range}"))?;
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(range)
    }
}

/// The longest simulated or run time a command accepts, s (about 31 years).
pub const MAX_SECONDS: f64 = 1e9;

/// Seconds of simulated time: (0, 1e7].
pub fn sim_seconds(s: &str) -> Result<f64, String> {
    ranged(s, 0.0, true, 1e7, "a number of seconds")
}

/// Seconds of run time: (0, 1e9].
pub fn run_seconds(s: &str) -> Result<f64, String> {
    ranged(s, 0.0, true, MAX_SECONDS, "a number of seconds")
}

/// A sliding velocity within the physics core's envelope: [-100, 100] m/s.
pub fn velocity(s: &str) -> Result<f64, String> {
    ranged(s, -100.0, false, 100.0, "a velocity in m/s")
}

/// A normal load: (0, 1e9] N.
pub fn load(s: &str) -> Result<f64, String> {
    ranged(s, 0.0, true, 1e9, "a load in N")
}

/// A prescribed gap h0: (0, 1e-3] m.
pub fn gap(s: &str) -> Result<f64, String> {
    ranged(s, 0.0, true, 1e-3, "a gap in m")
}

fn points(s: &str) -> Result<usize, String> {
    count(s, 2, 1_000_000, "a number of points").map(|v| v as usize)
}

fn cycles(s: &str) -> Result<usize, String> {
    count(s, 1, 10_000, "a number of cycles").map(|v| v as usize)
}

fn jobs(s: &str) -> Result<usize, String> {
    count(s, 1, 1024, "a number of threads").map(|v| v as usize)
}

fn samples(s: &str) -> Result<usize, String> {
    count(s, 1, 100_000_000, "a number of samples").map(|v| v as usize)
}

fn warmup(s: &str) -> Result<usize, String> {
    count(s, 0, 10_000_000, "a number of samples").map(|v| v as usize)
}

fn hours(s: &str) -> Result<u64, String> {
    count(s, 1, 10_000, "a number of hours")
}

fn accuracy_dt(s: &str) -> Result<f64, String> {
    ranged(s, 1e-6, false, 0.1, "a step in s")
}

fn accuracy_cycles(s: &str) -> Result<u32, String> {
    count(s, 2, 100, "a number of cycles").map(|v| v as u32)
}

fn case_count(s: &str) -> Result<usize, String> {
    count(s, 1, 10_000, "a number of cases").map(|v| v as usize)
}

fn flux(s: &str) -> Result<friction_node::config::FluxKind, String> {
    use friction_node::config::FluxKind;
    [
        FluxKind::Upwind,
        FluxKind::MusclMinmod,
        FluxKind::MusclVanLeer,
        FluxKind::MusclVanAlbada,
    ]
    .into_iter()
    .find(|f| f.name() == s.trim())
    .ok_or_else(|| format!("`{s}` is not a flux: expected one of {}", FluxKind::NAMES))
}

fn seeds(s: &str) -> Result<u64, String> {
    count(s, 1, 1000, "a number of seeds")
}

fn cells(s: &str) -> Result<usize, String> {
    count(s, 8, 65_536, "a number of cells").map(|v| v as usize)
}

fn reference_steps(s: &str) -> Result<usize, String> {
    count(s, 0, 100_000, "a number of steps").map(|v| v as usize)
}

#[derive(Subcommand)]
pub enum Command {
    /// Run the transient model over a velocity (and load) history; write a CSV.
    Simulate {
        #[command(flatten)]
        common: Common,
        /// Velocity in m/s: const:V | sine:V0,V1,F[,PHASE] | csv:FILE[@COLUMN].
        #[arg(long, value_name = "SPEC", allow_hyphen_values = true)]
        velocity: String,
        /// Load in N (same forms; default: contact.load_n).
        #[arg(long, value_name = "SPEC", allow_hyphen_values = true)]
        load: Option<String>,
        /// Lubricant temperature in °C (same forms; default:
        /// lubricant.reference_temperature_c); with lubricant.viscosity_model:
        /// vogel the viscosity follows it.
        #[arg(long, value_name = "SPEC", allow_hyphen_values = true)]
        temperature: Option<String>,
        /// Simulated time, s, in (0, 1e7].
        #[arg(long, value_name = "S", value_parser = sim_seconds, allow_hyphen_values = true)]
        duration: f64,
        /// Output CSV.
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Steady Stribeck curve over a velocity range; write a CSV.
    Stribeck {
        #[command(flatten)]
        common: Common,
        /// Lowest velocity, m/s, in [-100, 100].
        #[arg(long, value_name = "V", value_parser = velocity, allow_hyphen_values = true)]
        v_min: f64,
        /// Highest velocity, m/s, in [-100, 100].
        #[arg(long, value_name = "V", value_parser = velocity, allow_hyphen_values = true)]
        v_max: f64,
        /// Points, in [2, 1e6].
        #[arg(long, value_name = "N", default_value = "60", value_parser = points)]
        points: usize,
        /// Logarithmic spacing (the range must not contain 0).
        #[arg(long)]
        log: bool,
        /// Load in N, in (0, 1e9] (default: contact.load_n).
        #[arg(long, value_name = "N", value_parser = load, allow_hyphen_values = true)]
        load: Option<f64>,
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Steady fields along the slider at one velocity; write a CSV.
    Profile {
        #[command(flatten)]
        common: Common,
        /// Velocity, m/s, in [-100, 100].
        #[arg(long, value_name = "V", value_parser = velocity, allow_hyphen_values = true)]
        velocity: f64,
        /// Prescribed minimum separation h0, m, in (0, 1e-3].
        #[arg(
            long,
            value_name = "M",
            conflicts_with = "load",
            required_unless_present = "load",
            value_parser = gap,
            allow_hyphen_values = true
        )]
        h0: Option<f64>,
        /// Load in N, in (0, 1e9]: h0 from the load balance.
        #[arg(long, value_name = "N", value_parser = load, allow_hyphen_values = true)]
        load: Option<f64>,
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Run the real-time node: ROS 2 / iceoryx2 topics, fixed steps, MCAP recording.
    Run {
        #[command(flatten)]
        common: Common,
        /// Transport (default: node.transport).
        #[arg(long, value_enum)]
        transport: Option<TransportArg>,
        /// Record inputs and outputs to this MCAP file.
        #[arg(long, value_name = "FILE.mcap")]
        record: Option<PathBuf>,
        /// Drive the node with the paper's reciprocating velocity (V1 = 1 m/s,
        /// f = 1 Hz) on its own topics for this many seconds, in (0, 1e9], then stop.
        #[arg(long, value_name = "SECONDS", value_parser = run_seconds, allow_hyphen_values = true)]
        demo: Option<f64>,
        /// Stop after this many seconds, in (0, 1e9] (default: run until SIGINT/SIGTERM).
        #[arg(long, value_name = "SECONDS", conflicts_with = "demo", value_parser = run_seconds, allow_hyphen_values = true)]
        duration: Option<f64>,
        /// No live status line.
        #[arg(long)]
        quiet: bool,
        /// Resolve the configuration (file, --set, --ros-args), validate it,
        /// print the node's name, topics and the parameters that differ from
        /// the defaults, and exit without starting the node.
        #[arg(long, conflicts_with_all = ["demo", "duration", "record"])]
        check: bool,
    },
    /// The node for hours under a reproducible random motion (iceoryx2 by default), memory sampled.
    Soak {
        #[command(flatten)]
        common: Common,
        /// Transport (default: iceoryx2).
        #[arg(long, value_enum, default_value = "iceoryx2")]
        transport: TransportArg,
        /// How long, s, in (0, 1e9].
        #[arg(long, value_name = "SECONDS", value_parser = run_seconds, allow_hyphen_values = true)]
        duration: f64,
        /// Seed of the random motion.
        #[arg(long, default_value = "1")]
        seed: u64,
        /// Resident memory samples (CSV: t_s,rss_bytes).
        #[arg(long, value_name = "FILE", default_value = "soak-rss.csv")]
        rss_csv: PathBuf,
        /// Seconds between memory samples, in (0, 1e9].
        #[arg(long, default_value = "10", value_parser = run_seconds)]
        every: f64,
    },
    /// Re-run the model over the velocity recorded in a ROS 2 bag (MCAP file or rosbag2 directory).
    Replay {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        args: ReplayArgs,
    },
    /// Fit configuration keys (and input-map coefficients) to recorded friction; compare with the classic models.
    Fit {
        #[command(flatten)]
        common: Common,
        #[command(flatten)]
        args: Box<super::fit::FitArgs>,
    },
    /// Reproduce the paper's parametric studies: CSVs, loop metrics, plots, claims.
    Study {
        #[command(flatten)]
        common: Common,
        /// Which study (or `all`).
        #[arg(value_enum)]
        name: StudyName,
        /// Output directory (created if needed).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
        /// Cycles per case, in [1, 1e4]; metrics are those of the last one.
        #[arg(long, default_value = "3", value_parser = cycles)]
        cycles: usize,
        /// Worker threads, in [1, 1024] (default: one per core).
        #[arg(long, value_parser = jobs)]
        jobs: Option<usize>,
    },
    /// Command → estimate latency through a transport (release build!).
    BenchLatency {
        #[command(flatten)]
        common: Common,
        #[arg(long, value_enum, default_value = "iceoryx2")]
        transport: TransportArg,
        /// Round trips measured, in [1, 1e8].
        #[arg(long, default_value = "10000", value_parser = samples)]
        samples: usize,
        /// Round trips before measuring, in [0, 1e7].
        #[arg(long, default_value = "500", value_parser = warmup)]
        warmup: usize,
    },
    /// The recorder over simulated hours at the node's full rate: split files, budget, memory per hour.
    BenchRecorder {
        #[command(flatten)]
        common: Common,
        /// Simulated hours, in [1, 1e4].
        #[arg(long, default_value = "24", value_parser = hours)]
        hours: u64,
        /// The split directory to write (must not exist or be empty).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// The accuracy guide: the paper's reciprocating case over grids and steps against a fine reference, with the cost per step (release build!).
    BenchAccuracy {
        #[command(flatten)]
        common: Common,
        /// Grid sizes at the configured step, comma-separated, each in [8, 65536].
        #[arg(long, default_value = "32,64,128,256,512,1024", value_delimiter = ',', value_parser = cells)]
        grids: Vec<usize>,
        /// Steps (s) at the configured grid, comma-separated, each in [1e-6, 0.1].
        #[arg(long, default_value = "0.004,0.002,0.001,0.0005,0.00025", value_delimiter = ',', value_parser = accuracy_dt)]
        steps: Vec<f64>,
        #[command(flatten)]
        reference: ReferenceArgs,
    },
    /// The accuracy guide over a family of transient cases (speeds, frequencies, loads, viscosities): how many pass against a fine reference per grid and flux (release build!).
    BenchCases {
        #[command(flatten)]
        common: Common,
        /// Number of cases, in [1, 10000].
        #[arg(long, default_value = "64", value_parser = case_count)]
        count: usize,
        /// Grid sizes to test at the configured step, comma-separated, each in [8, 65536].
        #[arg(long, default_value = "64,128,256", value_delimiter = ',', value_parser = cells)]
        grids: Vec<usize>,
        /// Couette fluxes to test, comma-separated (upwind, muscl_minmod, muscl_van_leer, muscl_van_albada).
        #[arg(long, default_value = "upwind,muscl_van_leer", value_delimiter = ',', value_parser = flux)]
        fluxes: Vec<friction_node::config::FluxKind>,
        #[command(flatten)]
        reference: ReferenceArgs,
        /// Cases run at once (0: one per core).
        #[arg(long, default_value = "0")]
        jobs: usize,
    },
    /// The calibration targets on synthetic data: recovery of three parameters, transfer to another load and frequency against the classic models (release build!).
    BenchFit {
        #[command(flatten)]
        common: Common,
        /// Grid cells of the model (data and fit), in [8, 65536].
        #[arg(long, default_value = "128", value_parser = cells)]
        cells: usize,
        /// Seconds of data per set, at the configured solver.dt_s, in (0, 1e7].
        #[arg(long, default_value = "10", value_parser = sim_seconds)]
        duration: f64,
        /// Noise seeds of the recovery test (one fit each), in [1, 1000].
        #[arg(long, default_value = "5", value_parser = seeds)]
        seeds: u64,
        /// Also write the synthetic data sets (CSV) into this directory.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
    /// Benchmark one step of the paper's reciprocating case (release build!).
    Bench {
        #[command(flatten)]
        common: Common,
        /// Grid sizes, each in [8, 65536].
        #[arg(long, value_delimiter = ',', default_value = "64,256,1024", value_parser = cells)]
        cells: Vec<usize>,
        /// Timed cycles per grid (after one warm-up cycle), in [1, 1e4].
        #[arg(long, default_value = "3", value_parser = cycles)]
        cycles: usize,
        /// States at which the reference solver is timed, in [0, 1e5].
        #[arg(long, default_value = "12", value_parser = reference_steps)]
        reference_steps: usize,
        /// Also write the results as CSV.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Also time each part of a Newton iteration alone (EOS, faces,
        /// rows, the bordered solve, post-processing).
        #[arg(long)]
        breakdown: bool,
    },
}

impl Command {
    pub fn common(&self) -> &Common {
        match self {
            Command::Study { common, .. }
            | Command::Run { common, .. }
            | Command::BenchLatency { common, .. }
            | Command::Replay { common, .. }
            | Command::Simulate { common, .. }
            | Command::Stribeck { common, .. }
            | Command::Profile { common, .. }
            | Command::Bench { common, .. }
            | Command::BenchRecorder { common, .. }
            | Command::BenchFit { common, .. }
            | Command::BenchAccuracy { common, .. }
            | Command::BenchCases { common, .. }
            | Command::Soak { common, .. }
            | Command::Fit { common, .. } => common,
        }
    }

    /// Offline work that SIGINT/SIGTERM stop cleanly (the node and its
    /// benches handle signals themselves, or are short).
    pub fn is_offline_work(&self) -> bool {
        matches!(
            self,
            Command::Simulate { .. }
                | Command::Stribeck { .. }
                | Command::Study { .. }
                | Command::Replay { .. }
                | Command::Fit { .. }
                | Command::BenchFit { .. }
                | Command::BenchAccuracy { .. }
                | Command::BenchCases { .. }
        )
    }

    /// Whether it is one of the benchmarks (`bench*`).
    pub fn is_bench(&self) -> bool {
        matches!(
            self,
            Command::Bench { .. }
                | Command::BenchLatency { .. }
                | Command::BenchRecorder { .. }
                | Command::BenchAccuracy { .. }
                | Command::BenchCases { .. }
                | Command::BenchFit { .. }
        )
    }
}

/// `replay`'s arguments.
#[derive(clap::Args, Clone)]
pub struct ReplayArgs {
    /// The bag to replay: an MCAP file or a rosbag2 directory.
    #[arg(value_name = "BAG")]
    pub bag: PathBuf,
    /// Velocity topic (std_msgs/Float64, geometry_msgs/TwistStamped or
    /// sensor_msgs/JointState); default: detected. For a friction-node bag
    /// the default is its recorded estimates (the determinism oracle).
    #[arg(long, value_name = "NAME")]
    pub topic: Option<String>,
    /// JointState: the joint whose velocity drives the slider.
    #[arg(long, value_name = "NAME")]
    pub joint: Option<String>,
    /// Load topic (std_msgs/Float64); default: one ending in normal_load.
    #[arg(long, value_name = "NAME")]
    pub load_topic: Option<String>,
    /// Temperature topic (sensor_msgs/Temperature); default: one ending in temperature.
    #[arg(long, value_name = "NAME")]
    pub temperature_topic: Option<String>,
    /// The velocity, m/s, as an expression of the velocity topic's value x
    /// (e.g. `0.005 * x`: a joint's rad/s through a 5 mm lever).
    #[arg(long, value_name = "EXPR", allow_hyphen_values = true)]
    pub velocity_map: Option<String>,
    /// The load, N, as an expression of the load topic's value x (e.g.
    /// `5.2e-4 * x + 20`: a pressure through an area, plus a preload).
    #[arg(long, value_name = "EXPR", allow_hyphen_values = true)]
    pub load_map: Option<String>,
    /// Output: OUT.mcap (ROS 2 profile) or OUT.csv (the simulate columns).
    #[arg(long, value_name = "OUT.mcap|OUT.csv")]
    pub out: PathBuf,
    /// The output format when --out does not end in .mcap or .csv (e.g. /dev/null).
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,
    /// Also write a report (loop metrics, plots, markdown) into DIR.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Exit with status 3 unless the re-simulation is bit-identical to
    /// the recorded estimates.
    #[arg(long)]
    pub expect_identical: bool,
}

/// An output file's format.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    Csv,
    Mcap,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TransportArg {
    Ros2,
    Iceoryx2,
    Both,
}

impl TransportArg {
    pub fn kind(self) -> friction_node::config::TransportKind {
        use friction_node::config::TransportKind;
        match self {
            TransportArg::Ros2 => TransportKind::Ros2,
            TransportArg::Iceoryx2 => TransportKind::Iceoryx2,
            TransportArg::Both => TransportKind::Both,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StudyName {
    Stribeck,
    AmplitudeFrequency,
    Load,
    Viscosity,
    Inertia,
    Unidirectional,
    Roughness,
    Hersey,
    All,
}

/// The command line as clap parses it: the derived command with every
/// option that takes a value accepting a negative number as that value
/// (`--holdout -0.5` reaches the option's range check and gets its message,
/// instead of clap's "unexpected argument '-0'").
pub fn command() -> clap::Command {
    use clap::CommandFactory;
    fn negatives(c: clap::Command) -> clap::Command {
        c.mut_args(|a| {
            if a.get_action().takes_values() && !a.is_positional() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negatives)
    }
    negatives(Cli::command())
}

/// Parse `argv` (the program name first) with [`command`].
pub fn parse<I, T>(argv: I) -> Result<Cli, clap::Error>
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    use clap::FromArgMatches;
    let matches = command().try_get_matches_from(argv)?;
    Cli::from_arg_matches(&matches)
}

/// A clap error as one line that names the argument and what is allowed
/// (clap's own rendering ends with a bare "For more information" line).
pub fn one_line_error(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue};
    let rendered = e.render().to_string();
    let mut parts: Vec<String> = Vec::new();
    for line in rendered.lines() {
        let l = line.trim();
        if l.is_empty()
            || l.starts_with("For more information")
            || l.starts_with("Usage:")
            || l.starts_with("tip:")
        {
            continue;
        }
        parts.push(l.trim_start_matches("error: ").to_string());
    }
    // A line that ends in a colon introduces the next ("not provided:"
    // then the argument): joined by a space, the others by "; ".
    let mut msg = String::new();
    for p in &parts {
        if !msg.is_empty() {
            msg.push_str(if msg.ends_with(':') { " " } else { "; " });
        }
        msg.push_str(p);
    }
    if let Some(ContextValue::Strings(valid)) = e.get(ContextKind::ValidValue) {
        if !msg.contains("possible values") {
            msg.push_str(&format!("; allowed values: {}", valid.join(", ")));
        }
    }
    if let Some(ContextValue::String(arg)) = e.get(ContextKind::InvalidArg) {
        if !msg.contains(arg.as_str()) {
            msg = format!("{arg}: {msg}");
        }
    }
    format!("error: {msg} (see friction-node --help)")
}
