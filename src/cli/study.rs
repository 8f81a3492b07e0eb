//! `study`: the paper's parametric studies, every case in parallel.

use super::args::StudyName;
use anyhow::Result;
use friction_node::config::Config;
use friction_node::studies::{self, claims, report, StudyKind, StudyOptions, StudyResult};
use std::path::Path;

/// One unit of work: a steady curve of a study, or a transient case.
enum Job {
    Steady(StudyKind, studies::SteadySpec),
    Case(studies::Case),
}

/// What a job gave.
enum Done {
    Steady(
        StudyKind,
        Result<studies::SteadyCurve, friction_node::offline::SimulationError>,
    ),
    Case(Box<studies::CaseResult>),
}

/// Progress units of a steady curve (per velocity).
const STEADY_UNITS: u64 = 20;

pub fn run(
    config: &Config,
    name: StudyName,
    out: &Path,
    cycles: usize,
    jobs: Option<usize>,
) -> Result<()> {
    if cycles < 1 {
        anyhow::bail!("--cycles must be at least 1 (the paper's loops need 3)");
    }
    friction_node::output::prepare_dir(out)?;
    let kinds = kinds_of(name);
    if let Some(j) = jobs {
        rayon::ThreadPoolBuilder::new()
            .num_threads(j.max(1))
            .build_global()
            .ok();
    }
    let opts = StudyOptions {
        cycles,
        ..Default::default()
    };
    let started = std::time::Instant::now();
    let (list, total) = job_list(&kinds, config, &opts);
    let n_cases = list.iter().filter(|j| matches!(j, Job::Case(_))).count();
    eprintln!(
        "study {}: {} cases and {} steady curves on {} threads, N = {}, dt = {} s, {} cycles per case",
        kinds
            .iter()
            .map(|k| k.name())
            .collect::<Vec<_>>()
            .join(", "),
        n_cases,
        list.len() - n_cases,
        rayon::current_num_threads(),
        config.solver.cells,
        config.solver.dt_s,
        cycles
    );
    let stop = friction_node::interrupt::Stop::process();
    let done = run_jobs(list, total, stop);
    // Nothing is written after a stop.
    stop.check()?;
    let results = gather(&kinds, done)?;
    let compute_s = started.elapsed().as_secs_f64();
    let failed = write_studies(out, &results)?;
    stop.check()?;
    write_claims(out, &results, config, &failed)?;
    println!(
        "done in {:.1} s ({:.1} s computing on {} threads)",
        started.elapsed().as_secs_f64(),
        compute_s,
        rayon::current_num_threads()
    );
    Ok(())
}

/// The studies the argument names.
fn kinds_of(name: StudyName) -> Vec<StudyKind> {
    match name {
        StudyName::All => StudyKind::ALL.to_vec(),
        other => {
            let n = <StudyName as clap::ValueEnum>::to_possible_value(&other).expect("named");
            vec![StudyKind::from_name(n.get_name()).expect("study names match")]
        }
    }
}

/// Every steady curve and case of every study, as one job list, and the
/// progress units of all.
fn job_list(kinds: &[StudyKind], config: &Config, opts: &StudyOptions) -> (Vec<Job>, u64) {
    let mut list = Vec::new();
    let mut total = 0u64;
    for &k in kinds {
        let cases = studies::cases(k, config, opts);
        for s in studies::steady_specs(k, config, &cases, opts) {
            total += s.velocities.len() as u64 * STEADY_UNITS;
            list.push(Job::Steady(k, s));
        }
        for c in cases {
            total += c.steps() as u64;
            list.push(Job::Case(c));
        }
    }
    (list, total)
}

/// Run the jobs in parallel with a progress bar; a stop ends the cases
/// early.
fn run_jobs(list: Vec<Job>, total: u64, stop: &friction_node::interrupt::Stop) -> Vec<Done> {
    use indicatif::{ProgressBar, ProgressStyle};
    use rayon::prelude::*;
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent:>3}% {msg}")
            .expect("template")
            .progress_chars("=> "),
    );
    let done = list
        .into_par_iter()
        .map(|j| match j {
            Job::Steady(k, s) => {
                let r = studies::steady_curve(&s);
                bar.inc(s.velocities.len() as u64 * STEADY_UNITS);
                Done::Steady(k, r)
            }
            Job::Case(c) => {
                bar.set_message(format!("{} {}", c.study.name(), c.id));
                Done::Case(Box::new(studies::run_case(&c, &|n| {
                    bar.inc(n as u64);
                    !stop.requested()
                })))
            }
        })
        .collect();
    bar.finish_and_clear();
    done
}

/// The jobs' results, by study.
fn gather(kinds: &[StudyKind], done: Vec<Done>) -> Result<claims::Results> {
    let mut results: claims::Results = kinds
        .iter()
        .map(|&k| {
            (
                k,
                StudyResult {
                    study: k,
                    cases: Vec::new(),
                    steady: Vec::new(),
                },
            )
        })
        .collect();
    for d in done {
        match d {
            Done::Steady(k, r) => results.get_mut(&k).expect("study").steady.push(r?),
            Done::Case(c) => results
                .get_mut(&c.case.study)
                .expect("study")
                .cases
                .push(*c),
        }
    }
    Ok(results)
}

/// Write every study's files and print a line each; the failed cases.
fn write_studies(out: &Path, results: &claims::Results) -> Result<Vec<String>> {
    let mut failed = Vec::new();
    for r in results.values() {
        let files = report::write_study(out, r)?;
        let bad: Vec<String> = r
            .cases
            .iter()
            .filter_map(|c| c.failure.as_ref().map(|f| format!("{} ({f})", c.case.id)))
            .collect();
        // A study is transient cases, steady curves, or both.
        let count =
            |n: usize, one: &str, many: &str| format!("{n:>3} {}", if n == 1 { one } else { many });
        let mut parts = Vec::new();
        if !r.cases.is_empty() {
            parts.push(count(r.cases.len(), "case", "cases"));
        }
        if !r.steady.is_empty() {
            parts.push(count(r.steady.len(), "steady curve", "steady curves"));
        }
        println!(
            "{:<20} {}, {} files in {}{}",
            r.study.name(),
            parts.join(", "),
            files.len(),
            out.join(r.study.name()).display(),
            if bad.is_empty() {
                String::new()
            } else {
                format!(" — FAILED: {}", bad.join(", "))
            }
        );
        failed.extend(bad);
    }
    Ok(failed)
}

/// The paper's claims (docs/model.md §9) the studies evaluate: `claims.md` and a
/// line each.
fn write_claims(
    out: &Path,
    results: &claims::Results,
    config: &Config,
    failed: &[String],
) -> Result<()> {
    let evaluated = claims::evaluate(results, config.contact.boundary_friction);
    if evaluated
        .iter()
        .all(|c| c.verdict() == claims::Verdict::NotEvaluated)
    {
        return Ok(());
    }
    let path = out.join("claims.md");
    friction_node::output::write_file(
        &path,
        report::claims_markdown(&evaluated, failed).as_bytes(),
    )?;
    println!(
        "\nclaims (docs/model.md §9), details in {}:",
        path.display()
    );
    for c in &evaluated {
        if c.verdict() != claims::Verdict::NotEvaluated {
            let passed = c.checks.iter().filter(|k| k.pass).count();
            println!(
                "  {}. {:<18} {}/{} checks",
                c.number,
                c.verdict().as_str(),
                passed,
                c.checks.len()
            );
        }
    }
    Ok(())
}
