//! `replay`: the model over the velocity recorded in a bag, through the
//! same [`ReplayRequest`] as Python's `friction_node.replay()`.

use super::args::{FormatArg, ReplayArgs};
use anyhow::Result;
use friction_node::replay::{
    gap_list, OutputFormat, ReadyReplay, ReplayOptions, ReplayOutcome, ReplayRequest,
};
use std::path::{Path, PathBuf};

/// The output's format: `--format`, else the file's extension; the two
/// must not contradict each other (a `.mcap` file holding CSV).
fn output_format(out: &Path, format: Option<FormatArg>) -> Result<OutputFormat> {
    let asked = format.map(|f| match f {
        FormatArg::Csv => OutputFormat::Csv,
        FormatArg::Mcap => OutputFormat::Mcap,
    });
    match (asked, OutputFormat::from_path(out)) {
        (Some(a), Some(e)) if a != e => anyhow::bail!(
            "--out {} ends in .{} but --format {} was given: name the file .{} or leave --format out",
            out.display(),
            e.extension(),
            a.extension(),
            a.extension()
        ),
        (Some(f), _) => Ok(f),
        (None, Some(f)) => Ok(f),
        (None, None) => anyhow::bail!(
            "--out {}: the output must end in .mcap or .csv, or give --format csv|mcap",
            out.display()
        ),
    }
}

/// The request the arguments describe.
fn request(
    args: ReplayArgs,
    config: Option<PathBuf>,
    overrides: Vec<String>,
) -> Result<(ReplayRequest, bool)> {
    let format = output_format(&args.out, args.format)?;
    let request = ReplayRequest {
        bag: args.bag,
        options: ReplayOptions {
            topic: args.topic,
            joint: args.joint,
            load_topic: args.load_topic,
            temperature_topic: args.temperature_topic,
            config,
            overrides,
            velocity_map: args.velocity_map,
            load_map: args.load_map,
        },
        out: Some((args.out, format)),
        report: args.report,
    };
    Ok((request, args.expect_identical))
}

pub fn run(args: ReplayArgs, config: Option<PathBuf>, overrides: Vec<String>) -> Result<()> {
    let (request, expect_identical) = request(args, config, overrides)?;
    let bag = request.bag.display().to_string();
    // The input is validated completely before any output is touched.
    let ready = request.prepare().map_err(|e| {
        if e.names_the_bag() || e.is_configuration() {
            anyhow::Error::new(e)
        } else {
            anyhow::Error::new(e).context(format!("bag {bag}"))
        }
    })?;
    let mode = &ready.prepared.mode;
    if expect_identical && !mode.has_recorded_estimates() {
        // Nothing to compare: not a difference (3), its own status.
        eprintln!(
            "error: --expect-identical: bag {bag} holds no estimates recorded by friction-node ({}), so there is nothing to compare the replay with; replay it without --expect-identical",
            mode.describe()
        );
        std::process::exit(5);
    }
    print_input(&bag, &ready);
    let bar = super::progress::bar(ready.prepared.commands.len() as u64, "commands");
    let stop = friction_node::interrupt::Stop::process();
    let outcome = ready.run(&mut |done, _| {
        bar.set_position(done as u64);
        stop.check()
    })?;
    bar.finish_and_clear();
    print_outcome(&outcome);
    print_contacts(&outcome);
    let identical = print_determinism(&outcome);
    if let Some(w) = &outcome.written {
        println!("wrote {}", w.display());
    }
    if let Some(r) = &request.report {
        println!(
            "report           {} ({} files)",
            r.join("summary.md").display(),
            outcome.report_files.len()
        );
    }
    if expect_identical && !identical {
        eprintln!("error: --expect-identical: the re-simulation differs");
        std::process::exit(3);
    }
    Ok(())
}

/// What will be replayed, and warnings about the input (stderr).
fn print_input(bag: &str, ready: &ReadyReplay<'_>) {
    let p = &ready.prepared;
    eprintln!(
        "replay {bag}: {} ({} velocity messages → {} steps of {} s), configuration {}",
        p.mode.describe(),
        p.velocity_messages,
        ready.steps(),
        p.config.solver.dt_s,
        p.config_source,
    );
    if let Some(d) = &p.scan.damage {
        eprintln!("warning: the bag is damaged {d}; replaying everything before it");
    }
    if !p.gaps.is_empty() {
        eprintln!(
            "warning: {} velocity gaps longer than node.command_timeout_s = {} s (the node's timeout rule applied): {}",
            p.gaps.len(),
            p.config.node.command_timeout_s,
            gap_list(&p.gaps, p.commands.first().map_or(0, |c| c.stamp_ns))
        );
    }
}

/// Steps, speed and what the input held.
fn print_outcome(o: &ReplayOutcome) {
    let (p, r) = (&o.prepared, &o.result);
    let span = o.span_s();
    println!(
        "steps            {} over {:.3} s of bag time",
        r.estimates.len(),
        span
    );
    let rate = |w: f64| if w > 0.0 { span / w } else { f64::NAN };
    println!(
        "replay time      {:.3} s ({:.0}× real time; reading, model and writing), model {:.3} s ({:.0}×)",
        o.wall_s,
        rate(o.wall_s),
        o.model_wall_s,
        rate(o.model_wall_s)
    );
    if p.scan.files.len() > 1 {
        println!(
            "bag              rosbag2 directory: {} split files, replayed in order as one run",
            p.scan.files.len()
        );
    }
    println!("commands         {} rejected", r.commands_rejected);
    println!(
        "calibrated range {} contact steps outside",
        r.steps_outside_calibrated_range
    );
    if !p.parameter_changes.is_empty() {
        println!(
            "parameters       {} changes re-applied at the steps that used them (recorded /parameter_events)",
            p.parameter_changes.len()
        );
    }
    if let Some(d) = &p.scan.damage {
        println!("damaged bag      stopped {d}");
    }
}

/// Several contacts: each one's steps or verdict.
fn print_contacts(o: &ReplayOutcome) {
    let contacts = &o.result.contacts;
    if contacts.is_empty() {
        return;
    }
    println!(
        "contacts         {} replayed together (the report and figures show the first, `{}`)",
        contacts.len(),
        contacts[0].name
    );
    for c in contacts {
        let verdict = match &c.oracle {
            None => format!("{} steps", c.estimates.len()),
            Some(o) if o.identical => format!("bit-identical ({} steps)", o.compared),
            Some(o) => {
                let worst = o
                    .deviations
                    .iter()
                    .map(|d| format!("{} {:.3e}", d.0, d.1))
                    .collect::<Vec<_>>()
                    .join(", ");
                format!("DIFFERS over {} steps: {worst}", o.compared)
            }
        };
        println!("  {:<22} {verdict}", c.name);
    }
}

/// The determinism oracle's verdict; whether the replay is identical (true
/// when there was nothing to compare).
fn print_determinism(o: &ReplayOutcome) -> bool {
    let Some(o) = &o.result.oracle else {
        return true;
    };
    if o.identical {
        println!(
            "determinism      bit-identical to the recorded estimates ({} steps)",
            o.compared
        );
        return true;
    }
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
    false
}
