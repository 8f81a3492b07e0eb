//! What a fit tells its user: the parameter table (standard errors, 95 %
//! intervals, flags), correlations, the distinct optima, the residuals,
//! the baselines table; `summary.md`, `fit.csv` and plots in a report
//! directory; the fitted parameter file.

use super::driver::FitOutcome;
use super::problem::{Role, SeriesFit};
use super::stats::CORRELATION_FLAG;
use crate::config::Config;
use crate::output::{AtomicFile, OutputError};
use crate::text::Num;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A parameter's value as it acts on the data's axis (our model behind a
/// gain), e.g. `2.1e-4 N·m` on a joint; empty for a property of the
/// contact itself or without a gain.
fn on_joint(o: &FitOutcome, name: &str, value: f64) -> String {
    o.contact_scale
        .as_ref()
        .and_then(|j| super::contact_scale::joint_equivalent(name, value, j.gain, o.units))
        .map_or(String::new(), |(v, unit)| {
            format!("{} {unit}", Num::sig(v, 5))
        })
}

/// Parameters: value, SE, 95 % interval, bounds, flags (and, on a rotary
/// joint, each value as it acts on the joint).
pub fn parameter_table(o: &FitOutcome) -> String {
    let joint = o.contact_scale.is_some();
    let mut s = String::from("| parameter | value | std. error | 95 % interval | bounds | flag |");
    if joint {
        s.push_str(if o.units == super::Units::Rotary {
            " on the joint |"
        } else {
            " on the axis |"
        });
    }
    s.push_str("\n|---|---|---|---|---|---|");
    s.push_str(if joint { "---|\n" } else { "\n" });
    for (j, p) in o.params.iter().enumerate() {
        let st = &o.statistics;
        let flag = parameter_flag(st.at_bound[j], o.best[j], st.standard_error[j]);
        let _ = write!(
            s,
            "| `{}` | {} | {} | [{}, {}] | [{}, {}]{} | {flag} |",
            p.name,
            Num(o.best[j]).sci(4),
            Num(st.standard_error[j]).sci(4),
            Num(st.interval95[j].0).sci(4),
            Num(st.interval95[j].1).sci(4),
            Num(p.lo).sci(4),
            Num(p.hi).sci(4),
            if p.log { " log" } else { "" },
        );
        if joint {
            let _ = write!(s, " {} |", on_joint(o, &p.name, o.best[j]));
        }
        s.push('\n');
    }
    s
}

/// The gain our model ran through: gain, load and how they were found
/// (empty when the data are the contact's own).
pub fn joint_lines(o: &FitOutcome) -> String {
    o.contact_scale.as_ref().map_or(String::new(), |j| {
        if o.units == super::Units::Rotary {
            format!(
                "\n## The joint\n\nThe data are a rotary joint's (rad/s, N·m). The model's contact slides at r ω and puts r F on the joint: lever arm r = {} m (the fitted file's `gain`), contact load F_N = {} N; {}. Every table below is in the joint's units; the parameter table also gives each term as it acts on the joint.\n",
                Num::sig(j.gain, 5),
                Num::sig(j.load_n, 5),
                j.how
            )
        } else {
            format!(
                "\n## The contact's scale\n\nThe model's contact slides at g v and puts g F on the axis: gain g = {} (the fitted file's `gain`: the axis is written as a joint, driven by its JointState), contact load F_N = {} N; {}. The tables are in the data's units; the parameter table also gives each term as it acts on the axis.\n",
                Num::sig(j.gain, 5),
                Num::sig(j.load_n, 5),
                j.how
            )
        }
    })
}

/// What a parameter's row warns of: at a bound; not identifiable (no
/// finite standard error); or poorly identified, a standard error as large
/// as the value itself (the 95 % interval then spans zero, or the whole
/// bounds: the data hardly constrain it).
fn parameter_flag(at_bound: bool, value: f64, standard_error: f64) -> &'static str {
    if at_bound {
        "at a bound"
    } else if !standard_error.is_finite() {
        "not identifiable"
    } else if standard_error > 0.0 && standard_error >= value.abs() {
        "poorly identified (std. error ≥ |value|)"
    } else {
        ""
    }
}

/// The correlation matrix with pairs above the flag named.
pub fn correlation_table(o: &FitOutcome) -> String {
    let names: Vec<&str> = o.params.iter().map(|p| p.name.as_str()).collect();
    let mut s = format!(
        "| | {} |\n|---|{}\n",
        names.join(" | "),
        "---|".repeat(names.len())
    );
    for (i, row) in o.statistics.correlation.iter().enumerate() {
        let cells: Vec<String> = row.iter().map(|r| format!("{r:+.3}")).collect();
        let _ = writeln!(s, "| {} | {} |", names[i], cells.join(" | "));
    }
    let pairs = o.statistics.correlated_pairs();
    if !pairs.is_empty() {
        s.push('\n');
        for (i, j, r) in pairs {
            let _ = writeln!(
                s,
                "- `{}` and `{}` are correlated ({r:+.3}, |ρ| > {CORRELATION_FLAG}): these data do not separate them",
                names[i], names[j]
            );
        }
    }
    if o.statistics.rank_deficient {
        s.push_str("- JᵀJ is singular: some parameters do not change the residual at all\n");
    }
    s
}

/// The distinct optima, best first.
pub fn optima_table(o: &FitOutcome) -> String {
    let u = match o.units {
        super::Units::Linear => "N²".to_string(),
        super::Units::Rotary => format!("({})²", o.units.force()),
    };
    let mut s = format!(
        "| # | cost ½Σr² ({u}) | {} | outcome |\n|---|---|{}---|\n",
        o.params
            .iter()
            .map(|p| format!("`{}`", p.name))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(o.params.len())
    );
    for (k, r) in o.optima.iter().take(3).enumerate() {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            k + 1,
            Num(r.cost).sci(4),
            r.x.iter()
                .map(|v| Num(*v).sci(4))
                .collect::<Vec<_>>()
                .join(" | "),
            r.termination
        );
    }
    s
}

/// Residual summary lines.
pub fn residual_lines(o: &FitOutcome) -> String {
    let u = o.units.force();
    let mut s = format!(
        "training RMS {} {u}, max |residual| {} {u} (σ = {} {u})\n",
        Num::sig(o.train_rms, 5),
        Num::sig(o.train_max, 5),
        Num::sig(o.statistics.sigma, 5)
    );
    if let Some(h) = o.holdout_rms {
        let _ = writeln!(
            s,
            "held-out RMS {} {u} (the held-out parts of the training files: --holdout)",
            Num::sig(h, 5)
        );
    }
    if let Some(v) = o.validate_rms {
        let _ = writeln!(s, "validation RMS {} {u} (--validate data)", Num::sig(v, 5));
    }
    if let Some(why) = &o.validate_failure {
        let _ = writeln!(s, "no prediction on the --validate data: {why}");
    }
    let _ = writeln!(
        s,
        "{} simulations{}, {:.1} ms each on average, {:.1} s in all",
        o.simulations,
        o.film_solves.map_or(String::new(), |f| format!(
            " ({f} solved the film, the others recomposed its friction)"
        )),
        1e3 * o.simulation_mean_s,
        o.wall_s
    );
    s
}

/// One row of the baselines table.
#[derive(Debug, Clone)]
pub struct ModelRow {
    /// The model's name.
    pub label: String,
    /// Its fitted parameters: name, value, and the value as it acts on a
    /// rotary joint when it differs (else empty).
    pub parameters: Vec<(String, f64, String)>,
    /// The data's units.
    pub units: super::Units,
    /// RMS residual on the training samples, N.
    pub train_rms: f64,
    /// Cross-validated RMS on the training data's folds, N.
    pub cv_rms: Option<f64>,
    /// RMS residual on the held-out samples, N.
    pub held_out_rms: Option<f64>,
    /// Why there is no held-out prediction, when there is none.
    pub held_out_failure: Option<String>,
    /// Whether its fit converged.
    pub converged: bool,
    /// How the best local run ended.
    pub termination: String,
    /// ½ Σ r² on the fitted samples, N².
    pub cost: f64,
}

impl From<&FitOutcome> for ModelRow {
    fn from(o: &FitOutcome) -> Self {
        Self {
            label: o.label.clone(),
            units: o.units,
            // Ours on a joint: a term's contact value with what it is on
            // the joint; a classic model: its names in the data's units.
            parameters: o
                .params
                .iter()
                .zip(&o.best)
                .map(|(p, v)| {
                    let joint = match on_joint(o, &p.name, *v) {
                        j if j.is_empty() => j,
                        j if o.units == super::Units::Rotary => format!("{j} on the joint"),
                        j => format!("{j} on the axis"),
                    };
                    let name = if o.contact_scale.is_some() {
                        p.name.clone()
                    } else {
                        super::baselines::parameter_name(&p.name, o.units)
                    };
                    (name, *v, joint)
                })
                .collect(),
            train_rms: o.train_rms,
            cv_rms: o.fold_mse.as_deref().map(super::cross_validate::cv_rms),
            held_out_rms: o.held_out_rms(),
            held_out_failure: o.validate_failure.clone(),
            converged: o.converged,
            termination: o
                .optima
                .first()
                .map_or(String::new(), |r| r.termination.clone()),
            cost: o.optima.first().map_or(f64::NAN, |r| r.cost),
        }
    }
}

/// Model | parameters | training RMS | held-out RMS (relative to `floor_n`
/// when given).
pub fn models_table(rows: &[ModelRow], scale_n: f64) -> String {
    let u = rows.first().map_or("N", |r| r.units.force());
    let mut s = format!(
        "| model | n | parameters | fit | training RMS ({u}) | CV RMS ({u}) | held-out RMS ({u}) | held-out / friction scale |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let params: Vec<String> = r
            .parameters
            .iter()
            .map(|(n, v, joint)| {
                if joint.is_empty() {
                    format!("{n}={}", Num::sig(*v, 4))
                } else {
                    format!("{n}={} ({joint})", Num::sig(*v, 4))
                }
            })
            .collect();
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            r.label,
            r.parameters.len(),
            params.join(", "),
            if r.converged {
                "converged".to_string()
            } else {
                format!(
                    "NOT converged: {}",
                    r.termination
                        .trim_start_matches("not converged: ")
                        .replace('|', "/")
                )
            },
            Num::sig(r.train_rms, 5),
            r.cv_rms
                .map_or("–".to_string(), |c| Num::sig(c, 5).to_string()),
            match (&r.held_out_rms, &r.held_out_failure) {
                (Some(h), _) => Num::sig(*h, 5).to_string(),
                (None, Some(why)) => format!("none: {}", why.replace('|', "/")),
                (None, None) => "–".into(),
            },
            r.held_out_rms
                .map_or("–".into(), |h| format!("{:.1} %", 100.0 * h / scale_n)),
        );
    }
    let _ = writeln!(
        s,
        "\nCV RMS: the training data's folds, each predicted by the model refitted without it (the same folds for every model). held-out / friction scale: the held-out RMS divided by the RMS of the measured friction on the held-out samples ({} {u}), the same for every model.",
        Num::sig(scale_n, 5)
    );
    s
}

/// RMS of the measured friction on held-out samples (validation data, else
/// the held-out parts), N: the scale of the held-out error.
pub fn held_out_scale(o: &FitOutcome) -> f64 {
    let fits = if o.validate.is_empty() {
        &o.held_out
    } else {
        &o.validate
    };
    let (ss, n) = fits
        .iter()
        .flat_map(|sf| sf.series.friction.iter())
        .fold((0.0, 0usize), |(ss, n), f| (ss + f * f, n + 1));
    (ss / n.max(1) as f64).sqrt()
}

/// Which model predicts best, in one sentence for the summary's first
/// lines: on the held-out data when there are any, else cross-validated
/// on the training data's folds; said plainly when ours is not the best.
pub fn verdict(ours: &FitOutcome, classic: &[FitOutcome]) -> String {
    let held = ours.held_out_rms().is_some();
    let score = |o: &FitOutcome| -> Option<f64> {
        if held {
            o.held_out_rms()
        } else {
            o.fold_mse.as_deref().map(super::cross_validate::cv_rms)
        }
    };
    let what = if held { "held-out" } else { "cross-validated" };
    let u = ours.units.force();
    let Some(mine) = score(ours) else {
        return String::new();
    };
    let best = classic
        .iter()
        .filter_map(|o| score(o).map(|s| (o, s)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let Some((b, theirs)) = best else {
        return String::new();
    };
    if mine <= theirs {
        format!(
            "**Verdict:** ours predicts best: {what} RMS {} {u}, the best classic model ({}) {} {u} ({:.1} % lower).",
            Num::sig(mine, 5),
            b.label,
            Num::sig(theirs, 5),
            100.0 * (1.0 - mine / theirs)
        )
    } else {
        format!(
            "**Verdict: ours is not the best here.** {} predicts better: {what} RMS {} {u} against ours {} {u} ({:.1} % higher). Use it, or the terms it points at (see the models table).",
            b.label,
            Num::sig(theirs, 5),
            Num::sig(mine, 5),
            100.0 * (mine / theirs - 1.0)
        )
    }
}

/// The models table of ours and the classic models fitted beside it.
pub fn models_table_of(ours: &FitOutcome, classic: &[FitOutcome]) -> String {
    let mut rows = vec![ModelRow::from(ours)];
    rows.extend(classic.iter().map(ModelRow::from));
    models_table(&rows, held_out_scale(ours))
}

/// The comparison section of a fit with classic models (markdown): the
/// models table, then every model's level and offset error by source.
pub fn models_section(ours: &FitOutcome, classic: &[FitOutcome]) -> String {
    let all: Vec<&FitOutcome> = std::iter::once(ours).chain(classic).collect();
    format!(
        "## Models on the same data, same optimiser\n\n{}\n## Error by direction of motion, every model\n\n{}",
        models_table_of(ours, classic),
        super::by_direction::models_direction_table(&all)
    )
}

/// The fitted parameter file: the complete configuration, a header naming
/// the fit, and the map coefficients (which are not configuration keys) as
/// comments.
pub fn fitted_yaml(
    config: &Config,
    o: &FitOutcome,
    sources: &[String],
    map: &[(String, f64)],
) -> String {
    let mut s = format!(
        "# Fitted by friction-node fit on {}\n# {} — training RMS {} {u}{}\n",
        sources.join(", "),
        if o.converged {
            "converged"
        } else {
            "NOT CONVERGED: the best point found"
        },
        Num::sig(o.train_rms, 5),
        o.held_out_rms().map_or(String::new(), |h| format!(
            ", held-out RMS {} {}",
            Num::sig(h, 5),
            o.units.force()
        )),
        u = o.units.force(),
    );
    for (j, p) in o.params.iter().enumerate() {
        let _ = writeln!(
            s,
            "# {} = {} ± {}",
            p.name,
            Num(o.best[j]),
            Num(o.statistics.standard_error[j]).sci(4)
        );
    }
    if !map.is_empty() {
        s.push_str("# input map coefficients (not configuration keys):");
        for (n, v) in map {
            let _ = write!(s, " {n}={}", Num(*v));
        }
        s.push('\n');
    }
    s + &config.to_yaml()
}

/// `fit.csv`: every sample of every source with the prediction.
fn write_samples(path: &Path, o: &FitOutcome) -> Result<PathBuf, OutputError> {
    let units = o.units;
    let mut f = AtomicFile::create(path)?;
    let (v, n) = (units.speed_column(), units.force_column());
    f.line(format_args!(
        "source,role,t_s,velocity_{v},load_n,measured_{n},predicted_{n},residual_{n}"
    ))?;
    for (fits, role) in [
        (&o.train, Role::Train),
        (&o.held_out, Role::HeldOut),
        (&o.validate, Role::Validate),
    ] {
        for sf in fits {
            let s = &sf.series;
            for k in 0..s.len() {
                let role = super::by_direction::sample_role(role, s.fit[k]);
                f.line(format_args!(
                    "{},{role},{},{},{},{},{},{}",
                    s.name.replace(',', ";"),
                    Num(s.t[k]),
                    Num(s.velocity[k]),
                    s.load
                        .as_ref()
                        .map_or(String::new(), |l| Num(l[k]).to_string()),
                    Num(s.friction[k]),
                    Num(sf.predicted[k]),
                    Num(sf.predicted[k] - s.friction[k]),
                ))?;
            }
        }
    }
    f.commit()
}

/// The whole markdown summary of one fit.
pub fn summary(o: &FitOutcome, verdict: &str, extra: &str) -> String {
    format!(
        "# Fit of {}: {}\n\n{}{}{}\n## Parameters\n\n{}\n## Correlations\n\n{}\n## Distinct optima (best first)\n\n{}\n## Residual by direction of motion\n\n{}\n{}",
        o.label,
        if o.converged { "converged" } else { "NOT converged (best point found)" },
        if verdict.is_empty() {
            String::new()
        } else {
            format!("{verdict}\n\n")
        },
        residual_lines(o),
        joint_lines(o),
        parameter_table(o),
        correlation_table(o),
        optima_table(o),
        super::by_direction::direction_table(o),
        extra
    )
}

/// Write `summary.md`, `fit.csv` and the plots into `dir` (which exists).
pub fn write_report(
    dir: &Path,
    o: &FitOutcome,
    verdict: &str,
    extra: &str,
) -> Result<Vec<PathBuf>, OutputError> {
    let files = vec![
        crate::output::write_file(
            &dir.join("summary.md"),
            summary(o, verdict, extra).as_bytes(),
        )?,
        write_samples(&dir.join("fit.csv"), o)?,
    ];
    #[cfg(feature = "plots")]
    let files = [files, plots::write(dir, o)?].concat();
    Ok(files)
}

/// The report of a fit and of the classic models fitted beside it: ours
/// in `dir` (with `extra` appended to its summary), each classic model in
/// a folder named for it, and, with classic models, the residual of every
/// model against velocity on the held-out data in one figure. Returns the
/// files written.
pub fn write_models_report(
    dir: &Path,
    ours: &FitOutcome,
    classic: &[FitOutcome],
    verdict: &str,
    extra: &str,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut files = Vec::new();
    for b in classic {
        let sub = dir.join(slug(&b.label));
        crate::output::prepare_dir(&sub)?;
        files.extend(write_report(&sub, b, "", "")?);
    }
    files.extend(write_report(dir, ours, verdict, extra)?);
    #[cfg(feature = "plots")]
    if !classic.is_empty() {
        let all: Vec<&FitOutcome> = std::iter::once(ours).chain(classic).collect();
        files.extend(plots::residual_by_velocity(dir, &all)?);
    }
    Ok(files)
}

/// The mean residual (model − measured, N) in `bins` equal bins of
/// velocity over the samples of `fit`: (bin centre, mean) for bins that
/// hold samples.
pub fn binned_residual(fit: &SeriesFit, bins: usize) -> Vec<(f64, f64)> {
    let v = &fit.series.velocity;
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Vec::new();
    }
    let w = (hi - lo) / bins as f64;
    let mut sum = vec![(0.0, 0usize); bins];
    for (k, vk) in v.iter().enumerate() {
        let r = fit.predicted[k] - fit.series.friction[k];
        if r.is_finite() {
            let b = (((vk - lo) / w) as usize).min(bins - 1);
            sum[b].0 += r;
            sum[b].1 += 1;
        }
    }
    sum.iter()
        .enumerate()
        .filter(|(_, (_, n))| *n > 0)
        .map(|(b, (s, n))| (lo + (b as f64 + 0.5) * w, s / *n as f64))
        .collect()
}

#[cfg(feature = "plots")]
mod plots {
    use super::*;
    use crate::plot::{figure, Axes, Line, Panel, COLORS};
    use plotters::prelude::SeriesLabelPosition;

    fn line(label: &str, c: usize, points: Vec<(f64, f64)>, dashed: bool) -> Line {
        Line {
            label: Some(label.into()),
            points,
            color: COLORS[c % COLORS.len()],
            dashed,
        }
    }

    fn panels(
        fits: &[SeriesFit],
        role: &str,
        x: impl Fn(&SeriesFit, usize) -> f64,
        resid: bool,
    ) -> Vec<Panel> {
        fits.iter()
            .map(|f| {
                let n = f.series.len();
                let pts = |y: &dyn Fn(usize) -> f64| (0..n).map(|k| (x(f, k), y(k))).collect();
                let name = Path::new(&f.series.name)
                    .file_name()
                    .map_or(f.series.name.clone(), |s| s.to_string_lossy().into_owned());
                let lines = if resid {
                    vec![line(
                        "residual",
                        2,
                        pts(&|k| f.predicted[k] - f.series.friction[k]),
                        false,
                    )]
                } else {
                    vec![
                        line("measured", 0, pts(&|k| f.series.friction[k]), false),
                        line("model", 1, pts(&|k| f.predicted[k]), true),
                    ]
                };
                Panel {
                    title: format!("{name} ({role})"),
                    lines,
                }
            })
            .collect()
    }

    /// One panel per held-out source (validation data, else the training
    /// data), one line per model: its residual against velocity, averaged
    /// in 40 bins of velocity.
    pub(super) fn residual_by_velocity(
        dir: &Path,
        models: &[&FitOutcome],
    ) -> Result<Vec<PathBuf>, OutputError> {
        // The data not fitted: --validate files, else the held-out parts,
        // else (nothing held out) the training data.
        fn pick(o: &FitOutcome) -> (&[SeriesFit], &'static str) {
            if !o.validate.is_empty() {
                (&o.validate, "validation")
            } else if !o.held_out.is_empty() {
                (&o.held_out, "held out")
            } else {
                (&o.train, "training")
            }
        }
        let (sources, role) = pick(models[0]);
        let panels: Vec<Panel> = (0..sources.len())
            .map(|j| {
                let name = Path::new(&sources[j].series.name)
                    .file_name()
                    .map_or(sources[j].series.name.clone(), |s| {
                        s.to_string_lossy().into_owned()
                    });
                Panel {
                    title: format!("{name} ({role})"),
                    lines: models
                        .iter()
                        .enumerate()
                        .filter_map(|(m, o)| {
                            pick(o)
                                .0
                                .get(j)
                                .map(|f| line(&o.label, m, binned_residual(f, 40), m > 0))
                        })
                        .collect(),
                }
            })
            .collect();
        if panels.is_empty() {
            return Ok(Vec::new());
        }
        let u = models[0].units;
        let (x, y) = (
            format!("velocity ({})", u.speed()),
            format!("mean residual, model − measured ({})", u.force()),
        );
        let ax = Axes {
            x: &x,
            y: &y,
            log_x: false,
            log_y: false,
            legend: SeriesLabelPosition::UpperLeft,
            legend_everywhere: false,
        };
        Ok(vec![figure(
            &dir.join("residual_velocity.svg"),
            "residual against velocity, every model",
            &panels,
            &ax,
        )?])
    }

    pub(super) fn write(dir: &Path, o: &FitOutcome) -> Result<Vec<PathBuf>, OutputError> {
        let (f, v) = (o.units.force(), o.units.speed());
        let (friction, velocity, residual) = (
            format!("friction ({f})"),
            format!("velocity ({v})"),
            format!("residual ({f})"),
        );
        fn ax<'a>(x: &'a str, y: &'a str) -> Axes<'a> {
            Axes {
                x,
                y,
                log_x: false,
                log_y: false,
                legend: SeriesLabelPosition::UpperRight,
                legend_everywhere: true,
            }
        }
        let roles = [
            (&o.train, "training"),
            (&o.held_out, "held out"),
            (&o.validate, "validation"),
        ];
        let every = |x: &dyn Fn(&SeriesFit, usize) -> f64, resid: bool| -> Vec<Panel> {
            roles
                .iter()
                .flat_map(|(fits, role)| panels(fits, role, x, resid))
                .collect()
        };
        let all = every(&|f, k| f.series.t[k], false);
        let vel = every(&|f, k| f.series.velocity[k], false);
        let res = every(&|f, k| f.series.t[k], true);
        let steady = o.train.iter().all(|f| f.series.steady);
        let tx = if steady { "point" } else { "time (s)" };
        Ok(vec![
            figure(
                &dir.join("friction_time.svg"),
                &format!("{}: measured and fitted friction", o.label),
                &all,
                &ax(tx, &friction),
            )?,
            figure(
                &dir.join("friction_velocity.svg"),
                &format!("{}: friction against velocity", o.label),
                &vel,
                &ax(&velocity, &friction),
            )?,
            figure(
                &dir.join("residual.svg"),
                &format!("{}: residual (model − measured)", o.label),
                &res,
                &ax(tx, &residual),
            )?,
        ])
    }
}

/// A model's label as a directory name (`Coulomb + viscous` → `coulomb-viscous`).
pub fn slug(label: &str) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_standard_error_that_dwarfs_its_value_is_flagged() {
        // The case: σ = 2.7e-5 ± 6.5e-2 had an empty flag column.
        assert!(parameter_flag(false, 2.7e-5, 6.5e-2).starts_with("poorly identified"));
        assert_eq!(parameter_flag(false, 0.3, 0.001), "");
        assert_eq!(
            parameter_flag(false, 0.3, f64::INFINITY),
            "not identifiable"
        );
        assert_eq!(parameter_flag(true, 0.3, 1.0), "at a bound");
        assert_eq!(parameter_flag(false, 0.0, 0.0), "");
    }
}
