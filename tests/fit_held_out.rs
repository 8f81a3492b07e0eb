//! `fit --holdout`: what is held out reaches no choice of the fit. A fit
//! with `--holdout F` must choose exactly what a fit of the training part
//! alone chooses (the contact's scale, the terms, the starts and bounds, the
//! optimum), and only then predict the held-out part.

mod common;
use common::cli::{quick_fit, run};

use std::path::Path;

fn dir(name: &str) -> common::cli::FreshDir {
    common::cli::fresh_dir("held-out", name)
}

/// The rows of a CSV (header first).
fn rows(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// `simulate` with `args`, into `out`.
fn simulate(out: &Path, args: &[&str]) {
    let mut all = vec!["simulate", "--set", "solver.cells=32", "--out"];
    all.push(out.to_str().unwrap());
    all.extend_from_slice(args);
    let (code, _, err) = run(&all);
    assert_eq!(code, 0, "{err}");
}

/// The lines of `text` from the one starting with `from` up to the first
/// empty line after it, without the selection's wall time and without the
/// sets' film-solve counts (the sets are fitted in parallel on shared film
/// traces, so which of them solves a film first varies from run to run;
/// what each predicts does not).
fn section(text: &str, from: &str) -> Vec<String> {
    text.lines()
        .skip_while(|l| !l.starts_with(from))
        .take_while(|l| !l.is_empty())
        .map(|l| l.split(" Selection took").next().unwrap())
        .map(|l| match l.strip_suffix(" |") {
            Some(row) if l.starts_with("| ") => {
                row[..row.rfind(" |").unwrap_or(row.len())].to_string()
            }
            _ => l.to_string(),
        })
        .collect()
}

/// The fit's `--fit auto` and parameter sections and its rotary scale.
struct Choices {
    scale: Vec<String>,
    terms: Vec<String>,
    chosen: Vec<String>,
    parameters: Vec<String>,
    held_out_line: Option<String>,
}

fn fit(data: &Path, extra: &[&str]) -> Choices {
    let out = data.with_extension("yaml");
    let args = [&["--max-evaluations", "20"], extra].concat();
    let (code, stdout, err) = quick_fit(data, "auto", &out, &args);
    assert!(code == 0 || code == 4, "{err}");
    Choices {
        scale: err
            .lines()
            .filter(|l| l.contains("the contact's scale: gain"))
            .map(str::to_string)
            .collect(),
        terms: section(&stdout, "| set (boundary friction +)"),
        chosen: section(&stdout, "Chosen:"),
        parameters: section(&stdout, "| parameter |"),
        held_out_line: stdout
            .lines()
            .find(|l| l.starts_with("held-out RMS"))
            .map(str::to_string),
    }
}

#[test]
fn a_held_out_end_of_a_joint_record_reaches_neither_its_rotary_scale_nor_the_terms_chosen() {
    let d = dir("joint");
    // A joint through a 20 mm lever: 0.5 rad/s for 4 s, then 1 rad/s for
    // 2 s. The last third (held out) is faster than anything before it,
    // so a scale or a selection that saw it would differ.
    let mut v = String::from("t_s,v\n");
    for k in 0..=600 {
        let t = k as f64 * 0.01;
        let amplitude = if t < 4.0 { 0.5 } else { 1.0 };
        let w = amplitude * (std::f64::consts::PI * t).sin();
        v += &format!("{t},{}\n", 0.02 * w);
    }
    std::fs::write(d.join("v.csv"), v).unwrap();
    let contact = d.join("contact.csv");
    let velocity = format!("csv:{}@v", d.join("v.csv").display());
    simulate(&contact, &["--velocity", &velocity, "--duration", "6"]);
    let sim = rows(&contact);
    let head: Vec<&str> = sim[0].split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (t, vv, f) = (col("t_s"), col("velocity_m_s"), col("friction_n"));
    let mut joint = vec!["t_s,velocity_rad_s,friction_nm".to_string()];
    for line in sim[1..].iter().step_by(10) {
        let c: Vec<f64> = line.split(',').map(|x| x.parse().unwrap_or(0.0)).collect();
        joint.push(format!("{},{},{}", c[t], c[vv] / 0.02, c[f] * 0.02));
    }
    let n = joint.len() - 1;
    // The training part --holdout 0.3333 keeps: the first round(2/3 n) rows.
    let cut = ((1.0 - 0.3333) * n as f64).round() as usize;
    std::fs::write(d.join("joint.csv"), joint.join("\n") + "\n").unwrap();
    std::fs::write(d.join("first.csv"), joint[..=cut].join("\n") + "\n").unwrap();
    let rotary = [
        "--rotary",
        "--velocity",
        "velocity_rad_s",
        "--friction",
        "friction_nm",
    ];
    let with_holdout = fit(
        &d.join("joint.csv"),
        &[&rotary[..], &["--holdout", "0.3333"]].concat(),
    );
    let training_part = fit(&d.join("first.csv"), &rotary);
    assert_eq!(with_holdout.scale.len(), 1, "{:?}", with_holdout.scale);
    assert_eq!(with_holdout.scale, training_part.scale);
    assert!(with_holdout.terms.len() > 2, "{:?}", with_holdout.terms);
    assert_eq!(with_holdout.terms, training_part.terms);
    assert_eq!(with_holdout.chosen, training_part.chosen);
    assert_eq!(with_holdout.parameters, training_part.parameters);
    // The held-out part is predicted, and only with --holdout.
    assert!(
        with_holdout
            .held_out_line
            .as_deref()
            .is_some_and(|l| l.contains("N·m")),
        "{:?}",
        with_holdout.held_out_line
    );
    assert_eq!(training_part.held_out_line, None);
}

#[test]
fn held_out_points_of_a_steady_curve_reach_neither_the_bounds_nor_the_terms_chosen() {
    let d = dir("steady");
    let curve = d.join("curve.csv");
    let (code, _, err) = run(&[
        "stribeck",
        "--v-min",
        "0.01",
        "--v-max",
        "3",
        "--points",
        "15",
        "--log",
        "--set",
        "solver.cells=32",
        "--out",
        curve.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    // Every third point is held out (k % 3 == 1); the others are the fit's.
    let all = rows(&curve);
    let mut kept = vec![all[0].clone()];
    kept.extend(
        all[1..]
            .iter()
            .enumerate()
            .filter(|(k, _)| k % 3 != 1)
            .map(|(_, l)| l.clone()),
    );
    let part = d.join("part.csv");
    std::fs::write(&part, kept.join("\n") + "\n").unwrap();
    let with_holdout = fit(&curve, &["--holdout", "0.34"]);
    let training_part = fit(&part, &[]);
    assert!(with_holdout.terms.len() > 2, "{:?}", with_holdout.terms);
    assert_eq!(with_holdout.terms, training_part.terms);
    assert_eq!(with_holdout.parameters, training_part.parameters);
    assert!(with_holdout.held_out_line.is_some());
}
