//! `friction-node bench-fit`: the calibration targets on synthetic data
//! made by the model itself, as a markdown report.
//!
//! | section | what it shows |
//! |---|---|
//! | recovery | σ = 3.5 µm, μ_bl = 0.22, μ_l = 0.08 Pa·s recovered from the defaults on two amplitudes and two loads with 2 % noise, over noise seeds |
//! | drivetrain | σ, μ_bl and Coulomb and viscous drivetrain terms recovered together, from three global-phase seeds |
//! | pre-sliding and losses | σ, μ_bl, the pre-sliding stiffness σ0, a quadratic loss c_q and a direction asymmetry ΔF_c recovered together (the terms of issue 32 on) |
//! | boundary rate | σ, μ_bl and the boundary film's rate sensitivity μ_r and activation speed v_a recovered together |
//! | transfer | fitted at one load, amplitude and frequency, validated at another: ours and the classic models, with the new terms off and on in the data |

use crate::config::Config;
use crate::fit::driver::{fit, FitOutcome};
use crate::fit::models_table::{models_table, ModelRow};
use crate::fit::options::Options;
use crate::fit::prepare::data_scale;
use crate::fit::synthetic::{
    model_friction, motion, noisy_csv, two_amplitudes_two_loads, Sample, Segment,
};
use crate::fit::{
    Baseline, BaselineKind, Data, Delimiter, FitError, LoadForm, Mapping, ParamSpec, PhysicsModel,
    Source, Table,
};
use crate::output::OutputError;
use crate::physics::SetupError;
use std::fmt::Write;
use std::path::Path;

/// What the benchmark runs on.
pub struct FitBenchOptions<'a> {
    /// `solver.cells` of the data and the fits.
    pub cells: usize,
    /// Length of each data set, s.
    pub duration_s: f64,
    /// Noise seeds of the recovery.
    pub seeds: u64,
    /// Where the synthetic data are written (None: nowhere).
    pub out: Option<&'a Path>,
    /// Progress lines.
    pub progress: std::sync::Arc<dyn Fn(&str) + Send + Sync>,
}

/// Why the benchmark could not run.
#[derive(Debug, thiserror::Error)]
pub enum FitBenchError {
    /// A fit could not run.
    #[error(transparent)]
    Fit(#[from] FitError),
    /// The model could not be set up.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// A file could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
}

/// Every section, as markdown.
pub fn run(config: &Config, o: &FitBenchOptions<'_>) -> Result<String, FitBenchError> {
    let mut base = config.clone();
    base.solver.cells = o.cells;
    let mut md = recovery(&base, o)?;
    md += &drivetrain(&base, o)?;
    md += &presliding_and_losses(&base, o)?;
    md += &boundary_rate(&base, o)?;
    md += &transfer(&base, o, false)?;
    md += &transfer(&base, o, true)?;
    if let Some(d) = o.out {
        let _ = writeln!(md, "data in {}", d.display());
    }
    Ok(md)
}

/// A data source from CSV text (written to `out` too).
fn source(o: &FitBenchOptions<'_>, name: &str, csv: &str) -> Result<Source, FitBenchError> {
    if let Some(d) = o.out {
        crate::output::write_file(&d.join(name), csv.as_bytes())?;
    }
    let t =
        Table::parse(csv, Path::new(name), Delimiter::Comma, None, 0).map_err(FitError::from)?;
    Ok(Source::new(t, &Mapping::default())?)
}

fn data(train: Source, validate: Vec<Source>) -> Data {
    Data {
        train: vec![train],
        held_out: vec![],
        validate,
        holdout: Default::default(),
        map_names: vec![],
        map_values: vec![],
        units: Default::default(),
    }
}

fn specs(keys: &[&str]) -> Vec<ParamSpec> {
    keys.iter()
        .map(|k| ParamSpec {
            name: (*k).into(),
            ..Default::default()
        })
        .collect()
}

fn options(o: &FitBenchOptions<'_>, label: &'static str) -> Options {
    let progress = o.progress.clone();
    Options {
        progress: Some(Box::new(move |l| progress(&format!("{label}: {l}")))),
        ..Default::default()
    }
}

/// A model fitted on `d` for `keys` from the configuration's values.
fn fit_ours(
    base: &Config,
    d: &Data,
    keys: &[&str],
    opts: &Options,
) -> Result<FitOutcome, FitBenchError> {
    let (scale, _, _) = data_scale(&d.train, &[], base.contact.load_n)?;
    let model = PhysicsModel::new(base, &specs(keys), &scale)?;
    Ok(fit(&model, d, vec![], opts)?)
}

/// `| name (error) |` cells of fitted values against the truth.
fn error_cells(o: &FitOutcome, truth: &[f64]) -> String {
    o.best
        .iter()
        .zip(truth)
        .map(|(x, t)| {
            let e = if *t == 0.0 { *x } else { 100.0 * (x - t) / t };
            format!(" {x:.4e} ({e:+.2} %) |")
        })
        .collect()
}

fn recovery(base: &Config, o: &FitBenchOptions<'_>) -> Result<String, FitBenchError> {
    let keys = [
        "roughness.sigma_m",
        "contact.boundary_friction",
        "lubricant.viscosity_pa_s",
    ];
    let truth_x = [3.5e-6, 0.22, 0.08];
    let truth = with(base, &keys, &truth_x);
    let dt = base.solver.dt_s;
    let m = two_amplitudes_two_loads(o.duration_s, dt);
    let clean = model_friction(&truth, &m)?;
    (o.progress)(&format!(
        "recovery data: {} samples ({} s at {} Hz), N = {}, 2 % noise, {} noise seeds",
        m.len(),
        o.duration_s,
        1.0 / dt,
        o.cells,
        o.seeds
    ));
    let mut md = format!(
        "## Recovery (from the defaults; {} s, 1 kHz, N = {}, two amplitudes and two loads, 2 % noise)\n\ntruth: σ = {:.2} µm, μ_bl = {}, μ_l = {} Pa·s; start: the defaults\n\n| noise seed |",
        o.duration_s, o.cells, truth_x[0] * 1e6, truth_x[1], truth_x[2]
    );
    for k in keys {
        md += &format!(" `{k}` fitted (error, SE) |");
    }
    md += " simulations | ms / simulation | wall s |\n|---|---|---|---|---|---|---|\n";
    let (mut covered, mut worst) = ([0usize; 3], [0.0f64; 3]);
    for seed in 1..=o.seeds {
        let d = data(
            source(
                o,
                &format!("recovery-seed{seed}.csv"),
                &noisy_csv(&m, &clean, 0.02, seed),
            )?,
            vec![],
        );
        let f = fit_ours(base, &d, &keys, &options(o, "recovery"))?;
        md += &format!("| {seed} |");
        for j in 0..3 {
            let (lo, hi) = f.statistics.interval95[j];
            let inside = (lo..=hi).contains(&truth_x[j]);
            covered[j] += usize::from(inside);
            let err = (f.best[j] - truth_x[j]) / truth_x[j];
            worst[j] = worst[j].max(err.abs());
            md += &format!(
                " {:.4e} ({:+.2} %, {:.2} %){} |",
                f.best[j],
                100.0 * err,
                100.0 * f.statistics.standard_error[j] / f.best[j],
                if inside { "" } else { " ✗" }
            );
        }
        md += &format!(
            " {} | {:.1} | {:.1}{} |\n",
            f.simulations,
            f.simulation_mean_s * 1e3,
            f.wall_s,
            if f.converged { "" } else { " (not converged)" }
        );
    }
    md += "\n| parameter | largest error over the seeds | 95 % interval covers the truth |\n|---|---|---|\n";
    for (j, k) in keys.iter().enumerate() {
        md += &format!(
            "| `{k}` | {:.2} % | {} of {} |\n",
            100.0 * worst[j],
            covered[j],
            o.seeds
        );
    }
    md += "\n✗: the 95 % interval misses the truth (expected in about 1 seed in 20 per parameter)\n\n";
    Ok(md)
}

/// `base` with `keys` set to `values` (numeric keys of the configuration).
fn with(base: &Config, keys: &[&str], values: &[f64]) -> Config {
    let names: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    crate::fit::unknowns::ConfigKeys::new(base)
        .with(&names, values)
        .expect("the benchmark's truth is a valid configuration")
}

/// A table of fits from three global-phase seeds against the truth.
fn seeds_table(
    base: &Config,
    o: &FitBenchOptions<'_>,
    d: &Data,
    keys: &[&str],
    truth: &[f64],
    label: &'static str,
) -> Result<String, FitBenchError> {
    let mut md = String::from("| global-phase seed |");
    for k in keys {
        md += &format!(" `{k}` (error) |");
    }
    md += " cost ½Σr² (N²) | wall s |\n|---|";
    md += &"---|".repeat(keys.len() + 2);
    md += "\n";
    for seed in 1..=3u64 {
        let mut opts = options(o, label);
        opts.seed = seed;
        let f = fit_ours(base, d, keys, &opts)?;
        md += &format!(
            "| {seed} |{} {:.6e} | {:.1}{} |\n",
            error_cells(&f, truth),
            f.optima[0].cost,
            f.wall_s,
            if f.converged { "" } else { " (not converged)" }
        );
    }
    Ok(md + "\n")
}

/// One recovery experiment: data made by the model with the contact's σ =
/// 3.5 µm and μ_bl = 0.22 and the `terms` set to `truth`, along the
/// two-amplitude, two-load motion with 2 % noise (noise seed `noise_seed`,
/// written as `file`), all fitted from the defaults with three
/// global-phase seeds: `title` and `truth_line` (the terms') over the table.
struct Recovery<'a> {
    terms: &'a [&'a str],
    truth: &'a [f64],
    noise_seed: u64,
    file: &'a str,
    label: &'static str,
    title: &'a str,
    truth_line: String,
}

fn recover(
    base: &Config,
    o: &FitBenchOptions<'_>,
    r: &Recovery<'_>,
) -> Result<String, FitBenchError> {
    let keys: Vec<&str> = ["roughness.sigma_m", "contact.boundary_friction"]
        .into_iter()
        .chain(r.terms.iter().copied())
        .collect();
    let truth: Vec<f64> = [3.5e-6, 0.22]
        .into_iter()
        .chain(r.truth.iter().copied())
        .collect();
    let m = two_amplitudes_two_loads(o.duration_s, base.solver.dt_s);
    let clean = model_friction(&with(base, &keys, &truth), &m)?;
    let csv = noisy_csv(&m, &clean, 0.02, r.noise_seed);
    let d = data(source(o, r.file, &csv)?, vec![]);
    let mut md = format!(
        "## {}\n\ntruth: σ = 3.50 µm, μ_bl = 0.22, {}; same motion, 2 % noise\n\n",
        r.title, r.truth_line
    );
    md += &seeds_table(base, o, &d, &keys, &truth, r.label)?;
    Ok(md)
}

fn drivetrain(base: &Config, o: &FitBenchOptions<'_>) -> Result<String, FitBenchError> {
    let truth = [300.0, 800.0];
    recover(
        base,
        o,
        &Recovery {
            terms: &[
                "drivetrain.coulomb_n",
                "drivetrain.viscous_n_s_m",
            ],
            truth: &truth,
            noise_seed: 11,
            file: "drivetrain.csv",
            label: "drivetrain",
            title: "Drivetrain terms beside the contact (from the defaults; global phase with three seeds)",
            truth_line: format!(
                "drivetrain Coulomb {} N, viscous {} N·s/m",
                truth[0], truth[1]
            ),
        },
    )
}

/// The terms a real drive shows, on: pre-sliding stiffness, a quadratic
/// loss and a direction asymmetry, recovered with the contact.
fn presliding_and_losses(base: &Config, o: &FitBenchOptions<'_>) -> Result<String, FitBenchError> {
    let truth = [5e7, 400.0, 150.0];
    recover(
        base,
        o,
        &Recovery {
            terms: &[
                "contact.presliding_stiffness_n_m",
                "drivetrain.quadratic_n_s2_m2",
                "drivetrain.coulomb_asymmetry_n",
            ],
            truth: &truth,
            noise_seed: 12,
            file: "presliding-losses.csv",
            label: "pre-sliding and losses",
            title: "Pre-sliding and drivetrain losses (from the defaults, the stiffness from the data's reversals; global phase with three seeds)",
            truth_line: format!(
                "pre-sliding stiffness {:.0e} N/m, quadratic loss {} N·s²/m², direction asymmetry {} N",
                truth[0], truth[1], truth[2]
            ),
        },
    )
}

/// A boundary film whose friction rises with the logarithm of speed,
/// recovered with the contact (μ_r from zero, v_a from the default).
fn boundary_rate(base: &Config, o: &FitBenchOptions<'_>) -> Result<String, FitBenchError> {
    let truth = [0.02, 3e-3];
    recover(
        base,
        o,
        &Recovery {
            terms: &[
                "contact.boundary_friction_rate",
                "contact.boundary_activation_speed_m_s",
            ],
            truth: &truth,
            noise_seed: 13,
            file: "boundary-rate.csv",
            label: "boundary rate",
            title: "Boundary film rate (from the defaults: μ_r = 0, v_a = 1 mm/s; global phase with three seeds)",
            truth_line: format!(
                "μ_r = {}, v_a = {} m/s",
                truth[0], truth[1]
            ),
        },
    )
}

/// Fitted at one operating point, validated at another: ours and the
/// classic models; `terms_on`: the data hold pre-sliding and a quadratic
/// loss, and ours fits them.
fn transfer(
    base: &Config,
    o: &FitBenchOptions<'_>,
    terms_on: bool,
) -> Result<String, FitBenchError> {
    let dt = base.solver.dt_s;
    let seg = |a, f, l| Segment {
        amplitude_m_s: a,
        frequency_hz: f,
        load_n: l,
        duration_s: o.duration_s,
    };
    let mut keys = vec![
        "roughness.sigma_m",
        "contact.boundary_friction",
        "lubricant.viscosity_pa_s",
    ];
    let mut truth_x = vec![3.5e-6, 0.22, 0.08];
    if terms_on {
        keys.extend([
            "contact.presliding_stiffness_n_m",
            "drivetrain.quadratic_n_s2_m2",
        ]);
        truth_x.extend([5e7, 400.0]);
    }
    let truth = with(base, &keys, &truth_x);
    let train_m = motion(&[seg(0.5, 1.0, 10_000.0)], dt);
    let valid_m = motion(&[seg(1.0, 2.0, 20_000.0)], dt);
    let tag = if terms_on { "-terms" } else { "" };
    let csv = |m: &[Sample], seed| -> Result<String, FitBenchError> {
        Ok(noisy_csv(m, &model_friction(&truth, m)?, 0.02, seed))
    };
    let train = source(o, &format!("transfer{tag}-train.csv"), &csv(&train_m, 2)?)?;
    let valid = source(
        o,
        &format!("transfer{tag}-validate.csv"),
        &csv(&valid_m, 3)?,
    )?;
    let d = data(train, vec![valid]);
    let ours = fit_ours(base, &d, &keys, &options(o, "transfer: ours"))?;
    let mut rows = vec![ModelRow::from(&ours)];
    let series = vec![d.train[0].series(&[])?];
    let (scale, mean_abs, _) = data_scale(&d.train, &[], base.contact.load_n)?;
    for kind in BaselineKind::ALL {
        // The training data hold one load: the classic models get levels
        // proportional to the load (Amontons), the one form that carries a
        // fit at one load to another.
        let b = Baseline::from_data(
            kind,
            LoadForm::for_data(false, true),
            &scale,
            mean_abs,
            &series,
        )
        .with_max_step(base.solver.dt_s);
        let mut opts = options(o, kind.label());
        opts.max_evaluations = 2000;
        rows.push(ModelRow::from(&fit(&b, &d, vec![], &opts)?));
    }
    let scale_n = {
        let s = d.validate[0].series(&[])?;
        (s.friction.iter().map(|f| f * f).sum::<f64>() / s.len().max(1) as f64).sqrt()
    };
    let what = if terms_on {
        "; the data with pre-sliding (5e7 N/m) and a quadratic loss (400 N·s²/m²), both fitted"
    } else {
        ""
    };
    Ok(format!(
        "## Transfer (fit: 0.5 m/s, 1 Hz, 10 kN; validate: 1 m/s, 2 Hz, 20 kN; {} s each, 2 % noise{what})\n\n{}\n",
        o.duration_s,
        models_table(&rows, scale_n)
    ))
}
