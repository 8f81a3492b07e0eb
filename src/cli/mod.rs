//! The command line: argument types (`args.rs`) and one file per group of
//! subcommands. `main.rs` parses, dispatches and maps errors to exit codes.
//!
//! | file | job |
//! |---|---|
//! | `mod.rs` | the subcommand enum and its dispatch |
//! | `args.rs` | argument types shared by the subcommands (signals, overrides, paths) |
//! | `node.rs` | `run` (the real-time node) and `soak` |
//! | `offline.rs` | `simulate`, `stribeck`, `profile` |
//! | `study.rs` | `study`: the paper's studies, every case in parallel |
//! | `replay.rs` | `replay`: the model over a recorded motion |
//! | `fit.rs` | `fit`: calibration and its report |
//! | `bench.rs` | `bench`, `bench-latency`, `bench-recorder`, `bench-accuracy`, `bench-cases`, `bench-fit` |
//! | `progress.rs` | progress bars on a terminal's stderr |
//! | `logging.rs` | `tracing` to the terminal |

pub mod args;
pub mod bench;
pub mod fit;
pub mod logging;
pub mod node;
pub mod offline;
pub mod progress;
#[cfg(feature = "mcap")]
pub mod replay;
pub mod study;

use anyhow::Result;
use args::{Cli, Command};
use friction_node::config::Config;

/// Run one parsed command line (`ros`: its `--ros-args`, for `run` and
/// `soak`, the commands that are ROS 2 nodes).
pub fn dispatch(
    cli: Cli,
    ros: Option<friction_node::config::RosArgs>,
    allocations: &dyn Fn() -> u64,
) -> Result<()> {
    if cli.command.is_offline_work() {
        // SIGINT/SIGTERM stop the work and remove what is half-written
        // (the node's `run` has handlers of its own).
        friction_node::interrupt::Stop::process().install_signal_handlers()?;
    }
    let sub = cli.command.common().clone();
    if cli.common.config.is_some() && sub.config.is_some() {
        anyhow::bail!("--config given twice (before and after the subcommand)");
    }
    let path = sub.config.or(cli.common.config);
    let sets: Vec<String> = cli.common.sets.iter().chain(&sub.sets).cloned().collect();
    if let Command::Replay { args, .. } = cli.command {
        #[cfg(feature = "mcap")]
        return replay::run(args, path, sets);
        #[cfg(not(feature = "mcap"))]
        {
            let _ = args;
            anyhow::bail!("replay needs the `mcap` feature");
        }
    }
    let config = load_config(&cli.command, ros.as_ref(), path.as_deref(), &sets)?;
    if cli.command.is_bench() {
        bench_command(&config, cli.command, allocations)
    } else {
        work_command(&config, cli.command)
    }
}

/// The configuration: `--config` and `--set`, and `--ros-args` for the
/// commands that start a ROS 2 node.
fn load_config(
    command: &Command,
    ros: Option<&friction_node::config::RosArgs>,
    path: Option<&std::path::Path>,
    sets: &[String],
) -> Result<Config> {
    Ok(match (command, ros) {
        (Command::Run { .. } | Command::Soak { .. }, Some(r)) => {
            Config::load_with_ros_args(path, sets, r)?
        }
        (_, Some(_)) => anyhow::bail!(
            "--ros-args: only `run` and `soak` start a ROS 2 node; give the configuration with --config/--set"
        ),
        (_, None) => Config::load(path, sets)?,
    })
}

/// The node, the offline jobs, the studies and the fit.
fn work_command(config: &Config, command: Command) -> Result<()> {
    match command {
        Command::Simulate {
            velocity,
            load,
            temperature,
            duration,
            out,
            ..
        } => offline::simulate(
            config,
            &velocity,
            load.as_deref(),
            temperature.as_deref(),
            duration,
            &out,
        ),
        Command::Stribeck {
            v_min,
            v_max,
            points,
            log,
            load,
            out,
            ..
        } => offline::stribeck(config, v_min, v_max, points, log, load, &out),
        Command::Profile {
            velocity,
            h0,
            load,
            out,
            ..
        } => offline::profile(config, velocity, h0, load, &out),
        Command::Run {
            transport,
            record,
            demo,
            duration,
            quiet,
            check,
            ..
        } => {
            if check {
                node::check(config, transport);
                Ok(())
            } else {
                node::run(config, transport, record, demo, duration, quiet)
            }
        }
        Command::Soak {
            transport,
            duration,
            seed,
            rss_csv,
            every,
            ..
        } => node::soak(config, Some(transport), duration, seed, &rss_csv, every),
        Command::Study {
            name,
            out,
            cycles,
            jobs,
            ..
        } => study::run(config, name, &out, cycles, jobs),
        Command::Fit { args, .. } => fit::run(config, &args),
        Command::Replay { .. } => {
            unreachable!("dispatch runs replay before loading a configuration")
        }
        _ => unreachable!("dispatch sends the benchmarks to bench_command"),
    }
}

/// The benchmarks.
fn bench_command(config: &Config, command: Command, allocations: &dyn Fn() -> u64) -> Result<()> {
    match command {
        Command::BenchLatency {
            transport,
            samples,
            warmup,
            ..
        } => bench::latency(config, transport, samples, warmup),
        Command::BenchRecorder { hours, out, .. } => bench::recorder(config, hours, out),
        Command::BenchAccuracy {
            grids,
            steps,
            reference: r,
            ..
        } => bench::accuracy(
            config,
            &grids,
            &steps,
            (r.reference_cells, r.reference_dt),
            r.cycles,
        ),
        Command::BenchCases {
            count,
            grids,
            fluxes,
            reference: r,
            jobs,
            ..
        } => bench::cases(
            config,
            count,
            &grids,
            &fluxes,
            (r.reference_cells, r.reference_dt),
            r.cycles,
            jobs,
        ),
        Command::BenchFit {
            cells,
            duration,
            seeds,
            out,
            ..
        } => bench::fit_targets(config, cells, duration, seeds, out),
        Command::Bench {
            cells,
            cycles,
            reference_steps,
            out,
            breakdown,
            ..
        } => bench::step(
            config,
            cells,
            cycles,
            reference_steps,
            out,
            breakdown,
            allocations,
        ),
        _ => unreachable!("dispatch sends only the benchmarks here"),
    }
}
