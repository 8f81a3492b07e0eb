//! `replay`: the model over the velocity recorded in a bag.

use super::args::{FormatArg, ReplayArgs};
use anyhow::{Context, Result};
use std::path::PathBuf;

pub fn run(args: ReplayArgs, config: Option<PathBuf>, overrides: Vec<String>) -> Result<()> {
    use friction_node::bag::Bag;
    use friction_node::replay::{self, OutputFormat, OutputStream, ReplayOptions};
    let ReplayArgs {
        bag: bag_path,
        topic,
        joint,
        load_topic,
        temperature_topic,
        velocity_map,
        load_map,
        out,
        format,
        report,
        expect_identical,
    } = args;
    let started = std::time::Instant::now();
    let format = match (format, OutputFormat::from_path(&out)) {
        (Some(FormatArg::Csv), _) => OutputFormat::Csv,
        (Some(FormatArg::Mcap), _) => OutputFormat::Mcap,
        (None, Some(f)) => f,
        (None, None) => anyhow::bail!(
            "--out {}: the output must end in .mcap or .csv, or give --format csv|mcap",
            out.display()
        ),
    };
    // Validate the input completely before touching any output.
    let in_bag = || format!("bag {}", bag_path.display());
    let bag = Bag::open(&bag_path)?;
    let opts = ReplayOptions {
        topic,
        joint,
        load_topic,
        temperature_topic,
        config,
        overrides,
        velocity_map,
        load_map,
    };
    let prepared = replay::prepare(&bag, &opts).with_context(in_bag)?;
    if expect_identical && !prepared.mode.has_recorded_estimates() {
        // Nothing to compare: not a difference (3), its own status.
        eprintln!(
            "error: --expect-identical: bag {} holds no estimates recorded by friction-node ({}), so there is nothing to compare the replay with; replay it without --expect-identical",
            bag_path.display(),
            prepared.mode.describe()
        );
        std::process::exit(5);
    }
    if let Some(r) = &report {
        friction_node::output::prepare_dir(r)?;
    }
    let steps = prepared
        .commands
        .iter()
        .filter(|c| {
            matches!(
                c.kind,
                friction_node::msgs::CommandKind::Velocity
                    | friction_node::msgs::CommandKind::JointVelocity { last: true, .. }
            )
        })
        .count();
    eprintln!(
        "replay {}: {} ({} velocity messages → {} steps of {} s), configuration {}",
        bag_path.display(),
        prepared.mode.describe(),
        prepared.velocity_messages,
        steps,
        prepared.config.solver.dt_s,
        prepared.config_source,
    );
    if let Some(d) = &prepared.scan.damage {
        eprintln!("warning: the bag is damaged {d}; replaying everything before it");
    }
    if !prepared.gaps.is_empty() {
        eprintln!(
            "warning: {} velocity gaps longer than node.command_timeout_s = {} s (the node's timeout rule applied): {}",
            prepared.gaps.len(),
            prepared.config.node.command_timeout_s,
            replay::gap_list(&prepared.gaps, prepared.commands.first().map_or(0, |c| c.stamp_ns))
        );
    }
    // Written to a temporary sibling while the model runs; moved into place
    // only when complete.
    let mut stream = OutputStream::start(&out, format, &prepared, &bag_path)?;
    let bar = super::progress::bar(prepared.commands.len() as u64, "commands");
    let stop = friction_node::interrupt::Stop::process();
    let model_started = std::time::Instant::now();
    let result = replay::run(
        &prepared,
        &mut |done, _| {
            bar.set_position(done as u64);
            stop.check()
        },
        &mut |e, rec, k| stream.push(e, rec, k),
    )?;
    let model_wall = model_started.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let written = stream.finish(result.oracle.as_ref())?;
    let wall = started.elapsed().as_secs_f64();
    let e = &result.estimates;
    let span = match (e.first(), e.last()) {
        (Some(a), Some(b)) => (b.1.stamp_ns.saturating_sub(a.1.stamp_ns)) as f64 / 1e9,
        _ => 0.0,
    };
    println!(
        "steps            {} over {:.3} s of bag time",
        e.len(),
        span
    );
    let rate = |w: f64| if w > 0.0 { span / w } else { f64::NAN };
    println!(
        "replay time      {:.3} s ({:.0}× real time; reading, model and writing), model {:.3} s ({:.0}×)",
        wall,
        rate(wall),
        model_wall,
        rate(model_wall)
    );
    if prepared.scan.files.len() > 1 {
        println!(
            "bag              rosbag2 directory: {} split files, replayed in order as one run",
            prepared.scan.files.len()
        );
    }
    println!("commands         {} rejected", result.commands_rejected);
    if !prepared.parameter_changes.is_empty() {
        println!(
            "parameters       {} changes re-applied at the steps that used them (recorded /parameter_events)",
            prepared.parameter_changes.len()
        );
    }
    if let Some(d) = &prepared.scan.damage {
        println!("damaged bag      stopped {d}");
    }
    if !result.contacts.is_empty() {
        println!(
            "contacts         {} replayed together (the report and figures show the first, `{}`)",
            result.contacts.len(),
            result.contacts[0].name
        );
        for c in &result.contacts {
            if c.oracle.is_none() {
                println!("  {:<22} {} steps", c.name, c.estimates.len());
            }
            if let Some(o) = &c.oracle {
                println!(
                    "  {:<22} {}",
                    c.name,
                    if o.identical {
                        format!("bit-identical ({} steps)", o.compared)
                    } else {
                        let worst = o
                            .deviations
                            .iter()
                            .map(|d| format!("{} {:.3e}", d.0, d.1))
                            .collect::<Vec<_>>()
                            .join(", ");
                        format!("DIFFERS over {} steps: {worst}", o.compared)
                    }
                );
            }
        }
    }
    let mut identical = true;
    if let Some(o) = &result.oracle {
        identical = o.identical;
        if o.identical {
            println!(
                "determinism      bit-identical to the recorded estimates ({} steps)",
                o.compared
            );
        } else {
            println!(
                "determinism      DIFFERS from the recording over {} steps:",
                o.compared
            );
            for (f, d, k) in &o.deviations {
                println!("                 {f:<22} up to {d:.3e} (first largest at step {k})");
            }
            if let Some((a, b)) = o.count_mismatch {
                println!("                 {a} steps recorded, {b} replayed");
            }
        }
    }
    println!("wrote {}", written.display());
    if let Some(r) = &report {
        let files = replay::write_report(r, &bag_path, &prepared, &result, wall)?;
        println!(
            "report           {} ({} files)",
            r.join("summary.md").display(),
            files.len()
        );
    }
    if expect_identical && !identical {
        eprintln!("error: --expect-identical: the re-simulation differs");
        std::process::exit(3);
    }
    Ok(())
}
