//! The models table: ours and each classic model on the same yardstick
//! (training, cross-validated and held-out error), and the plain verdict
//! that leads a report's summary.

use super::driver::FitOutcome;
use crate::text::Num;
use std::fmt::Write as _;

/// A parameter's value as it acts on the data's axis (our model behind a
/// gain), e.g. `2.1e-4 N·m` on a joint; empty for a property of the
/// contact itself or without a gain.
pub(super) fn on_joint(o: &FitOutcome, name: &str, value: f64) -> String {
    o.contact_scale
        .as_ref()
        .and_then(|j| super::contact_scale::joint_equivalent(name, value, j.gain, o.units))
        .map_or(String::new(), |(v, unit)| {
            format!("{} {unit}", Num::sig(v, 5))
        })
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
    /// RMS residual on the held-out parts of the training files
    /// (`--holdout`, a later part of each) when the held-out column is the
    /// validation data's, N: the second thing a calibration is judged on.
    pub later_part_rms: Option<f64>,
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
            later_part_rms: o.validate_rms.and(o.holdout_rms),
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
    // The `--holdout` part's column, after the others, when there is one
    // beside validation data.
    let later = rows.iter().any(|r| r.later_part_rms.is_some());
    let mut s = format!(
        "| model | n | parameters | fit | training RMS ({u}) | CV RMS ({u}) | held-out RMS ({u}) | held-out / friction scale |{}\n|---|---|---|---|---|---|---|---|{}\n",
        if later { format!(" --holdout part RMS ({u}) |") } else { String::new() },
        if later { "---|" } else { "" },
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
        let later_cell = match (later, r.later_part_rms) {
            (false, _) => String::new(),
            (true, Some(h)) => format!(" {} |", Num::sig(h, 5)),
            (true, None) => " – |".into(),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} |{later_cell}",
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
        "\nCV RMS: the training data's folds, each predicted by the model refitted without it (the same folds for every model). held-out / friction scale: the held-out RMS divided by the RMS of the measured friction on the held-out samples ({} {u}), the same for every model.{}",
        Num::sig(scale_n, 5),
        if later {
            " --holdout part RMS: the held-out (later) parts of the training files, which no model was fitted on."
        } else {
            ""
        }
    );
    s
}

/// RMS of the measured friction on held-out samples (validation data, else
/// the held-out parts), N: the scale of the held-out error.
pub fn held_out_scale(o: &FitOutcome) -> f64 {
    friction_rms(if o.validate.is_empty() {
        &o.held_out
    } else {
        &o.validate
    })
}

/// The RMS of the measured friction over `fits`.
fn friction_rms(fits: &[super::problem::SeriesFit]) -> f64 {
    let (ss, n) = fits
        .iter()
        .flat_map(|sf| sf.series.friction.iter())
        .fold((0.0, 0usize), |(ss, n), f| (ss + f * f, n + 1));
    (ss / n.max(1) as f64).sqrt()
}

/// An error below this fraction of the measured friction's RMS is at the
/// resolution of a model's own arithmetic (a record a model made without
/// noise), not of a measurement: no force sensor resolves a millionth of
/// the friction it measures, so below it the verdict compares nothing.
pub const EXACT_FRACTION: f64 = 1e-6;

/// How ours stands against the best classic model on the verdict's
/// yardstick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Standing {
    /// Ours predicts better, by more than the comparison can resolve.
    Ahead,
    /// The two differ by no more than the standard error of their paired
    /// difference, or by no more than a term must pay for itself
    /// ([`super::cross_validate::TERM_COST`] of the mean squared error): the data
    /// cannot tell them apart, or the difference is one no controller
    /// would notice.
    Level,
    /// The classic predicts better, by more than that.
    Behind,
}

/// The standing of `mine` against `theirs`, two models' squared errors on
/// the same samples (or mean squared errors on the same folds), paired:
/// the yardstick by which `--fit auto` lets a term pay for itself.
pub fn standing(mine: &[f64], theirs: &[f64]) -> Standing {
    let (a, b): (Vec<f64>, Vec<f64>) = mine
        .iter()
        .zip(theirs)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| (*x, *y))
        .unzip();
    if a.is_empty() {
        return Standing::Level;
    }
    let (mean, se) = super::cross_validate::paired(&a, &b);
    let mse = b.iter().sum::<f64>() / b.len() as f64;
    if mean.abs() <= se || mean.abs() <= super::cross_validate::TERM_COST * mse {
        Standing::Level
    } else if mean < 0.0 {
        Standing::Ahead
    } else {
        Standing::Behind
    }
}

/// Contiguous batches a held-out time series is cut into for the
/// verdict's standard error (batch means; Schmeiser 1982 recommends 10 to
/// 30). A time series' errors are correlated from sample to sample (at
/// 1 kHz a residual lasts many samples), so the samples' own standard
/// error understates the spread of their mean: on EMPS's pulses record
/// the paired difference's autocorrelation is 0.84 at one sample, and its
/// batch-means standard error 1.7× the samples'.
pub const HELD_OUT_BATCHES: usize = 20;

/// The units the verdict pairs, in the order of the sources: each
/// held-out sample's squared error of a steady curve (its points are
/// separate operating points), the mean squared error of each of
/// [`HELD_OUT_BATCHES`] contiguous batches of a time series. The
/// validation data's, else the held-out parts'; the same units for every
/// model fitted to the same data.
fn held_out_squared_errors(o: &FitOutcome) -> Vec<f64> {
    let fits = if o.validate.is_empty() {
        &o.held_out
    } else {
        &o.validate
    };
    fits.iter()
        .flat_map(|f| {
            let sq: Vec<f64> = f
                .predicted
                .iter()
                .zip(f.series.friction.iter())
                .map(|(p, m)| (p - m).powi(2))
                .collect();
            if f.series.steady {
                sq
            } else {
                batch_means(&sq, HELD_OUT_BATCHES)
            }
        })
        .collect()
}

/// The means of `batches` contiguous batches of `x` (`stats::contiguous`: as equal as the
/// length allows; one per sample when there are fewer samples).
fn batch_means(x: &[f64], batches: usize) -> Vec<f64> {
    super::stats::contiguous(x.len(), batches)
        .map(|r| x[r.clone()].iter().sum::<f64>() / r.len() as f64)
        .collect()
}

/// Which model predicts best, in one sentence for the summary's first
/// lines: on the held-out data when there are any, else cross-validated
/// on the training data's folds; said plainly when ours is not the best,
/// and called level when the difference is within its standard error
/// (of a time series' batch means, [`HELD_OUT_BATCHES`]; of a steady
/// curve's points; of the folds).
pub fn verdict(ours: &FitOutcome, classic: &[FitOutcome]) -> String {
    let held = ours.held_out_rms().is_some();
    let score = |o: &FitOutcome| -> Option<f64> {
        if held {
            o.held_out_rms()
        } else {
            o.fold_mse.as_deref().map(super::cross_validate::cv_rms)
        }
    };
    let paired = |o: &FitOutcome| -> Vec<f64> {
        if held {
            held_out_squared_errors(o)
        } else {
            o.fold_mse.clone().unwrap_or_default()
        }
    };
    let what = if held { "held-out" } else { "cross-validated" };
    let held_fits = if ours.validate.is_empty() {
        &ours.held_out
    } else {
        &ours.validate
    };
    let of = if !held {
        " over the folds".to_string()
    } else if held_fits.iter().any(|f| !f.series.steady) {
        format!(" (a time series' errors taken in {HELD_OUT_BATCHES} contiguous batches, as they are correlated from sample to sample)")
    } else {
        String::new()
    };
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
    let (m, t) = (Num::sig(mine, 5), Num::sig(theirs, 5));
    let scale = if held {
        held_out_scale(ours)
    } else {
        friction_rms(&ours.train)
    };
    if mine.max(theirs) <= EXACT_FRACTION * scale {
        return format!(
            "**Verdict: ours and {} both reproduce these data exactly** ({what} RMS {m} {u} against {t} {u}, both below {EXACT_FRACTION:e} of the measured friction's RMS {} {u}, the resolution of the models' own arithmetic). Data without noise, a model's own output, cannot tell the models apart: judge them on a measured record, or on a synthetic one with a measurement's noise.",
            b.label,
            Num::sig(scale, 5)
        );
    }
    let apart = 100.0 * (mine / theirs - 1.0);
    match standing(&paired(ours), &paired(b)) {
        Standing::Level => format!(
            "**Verdict: ours and {} predict alike here** ({what} RMS {m} {u} against {t} {u}, {apart:+.2} %: their mean squared errors differ by less than the standard error of that difference{of} or by less than {:.0} % of it, what a term must gain to be chosen). The terms ours chose say which physics the data show.",
            b.label,
            100.0 * super::cross_validate::TERM_COST
        ),
        Standing::Ahead => format!(
            "**Verdict:** ours predicts best: {what} RMS {m} {u}, the best classic model ({}) {t} {u} ({:.1} % lower).",
            b.label,
            -apart
        ),
        Standing::Behind => format!(
            "**Verdict: ours is not the best here.** {} predicts better: {what} RMS {t} {u} against ours {m} {u} ({apart:.1} % higher). Use it, or the terms it points at (see the models table).",
            b.label
        ),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_models_whose_errors_differ_by_less_than_their_standard_error_are_level() {
        // Paired squared errors that differ by ±3 around a mean of 0.2
        // (1.5 % of the mean squared error 13, beyond the term's cost).
        let theirs: Vec<f64> = (0..100).map(|k| 10.0 + (k % 7) as f64).collect();
        let mine: Vec<f64> = theirs
            .iter()
            .enumerate()
            .map(|(k, t)| t + if k % 2 == 0 { 3.2 } else { -2.8 })
            .collect();
        assert_eq!(standing(&mine, &theirs), Standing::Level);
    }

    #[test]
    fn a_consistent_difference_smaller_than_a_terms_cost_is_level() {
        // Every sample 0.5 % worse: resolved, but less than 1 % of the MSE.
        let theirs: Vec<f64> = (0..100).map(|k| 10.0 + (k % 7) as f64).collect();
        let mine: Vec<f64> = theirs.iter().map(|t| t * 1.005).collect();
        assert_eq!(standing(&mine, &theirs), Standing::Level);
        let worse: Vec<f64> = theirs.iter().map(|t| t * 1.02).collect();
        assert_eq!(standing(&worse, &theirs), Standing::Behind);
    }

    #[test]
    fn a_model_whose_errors_are_lower_beyond_their_standard_error_is_ahead_and_the_other_behind() {
        let theirs: Vec<f64> = (0..100).map(|k| 10.0 + (k % 7) as f64).collect();
        let mine: Vec<f64> = theirs
            .iter()
            .enumerate()
            .map(|(k, t)| t - 0.5 + if k % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        assert_eq!(standing(&mine, &theirs), Standing::Ahead);
        assert_eq!(standing(&theirs, &mine), Standing::Behind);
    }

    #[test]
    fn identical_errors_are_level() {
        let e = [1.0, 2.0, 3.0];
        assert_eq!(standing(&e, &e), Standing::Level);
    }

    #[test]
    fn a_time_series_difference_that_wanders_in_long_stretches_is_level_though_its_samples_would_call_it_behind(
    ) {
        // 2000 samples 0.5 worse on average, the difference swinging ±6
        // over 400-sample stretches (correlated residuals, as at 1 kHz):
        // the samples' standard error (0.095) would resolve it, the 20
        // batches' (about 0.6) does not.
        let theirs: Vec<f64> = (0..2000).map(|k| 13.0 + (k % 7) as f64 * 0.1).collect();
        let mine: Vec<f64> = theirs
            .iter()
            .enumerate()
            .map(|(k, t)| t + 0.5 + 6.0 * (std::f64::consts::TAU * k as f64 / 400.0 + 0.3).sin())
            .collect();
        assert_eq!(standing(&mine, &theirs), Standing::Behind, "per sample");
        let (m, t) = (
            batch_means(&mine, HELD_OUT_BATCHES),
            batch_means(&theirs, HELD_OUT_BATCHES),
        );
        assert_eq!(m.len(), HELD_OUT_BATCHES);
        assert_eq!(standing(&m, &t), Standing::Level, "batch means");
        // A steady 0.5 (no wandering) stays resolved in batches.
        let steady: Vec<f64> = theirs.iter().map(|t| t + 0.5).collect();
        assert_eq!(
            standing(&batch_means(&steady, HELD_OUT_BATCHES), &t),
            Standing::Behind
        );
    }

    #[test]
    fn batch_means_cover_every_sample_once_and_shorter_series_give_one_per_sample() {
        let x: Vec<f64> = (0..45).map(f64::from).collect();
        let b = batch_means(&x, 20);
        assert_eq!(b.len(), 20);
        // Batches of 2 or 3 samples: their sizes times their means sum to
        // the whole.
        let total: f64 = (0..20)
            .map(|i| b[i] * ((i + 1) * 45 / 20 - i * 45 / 20) as f64)
            .sum();
        approx::assert_relative_eq!(total, x.iter().sum::<f64>(), max_relative = 1e-12);
        assert_eq!(batch_means(&x[..5], 20), x[..5].to_vec());
        assert!(batch_means(&[], 20).is_empty());
    }

    fn row(label: &str, later: Option<f64>) -> ModelRow {
        ModelRow {
            label: label.into(),
            parameters: vec![("fc_n".into(), 1.0, String::new())],
            units: crate::fit::Units::Linear,
            train_rms: 0.5,
            cv_rms: Some(0.6),
            held_out_rms: Some(0.7),
            held_out_failure: None,
            later_part_rms: later,
            converged: true,
            termination: String::new(),
            cost: 1.0,
        }
    }

    #[test]
    fn the_later_part_of_the_training_files_gets_its_own_column_beside_validation_data() {
        let with = models_table(&[row("ours", Some(0.25)), row("LuGre", None)], 1.0);
        let lines: Vec<&str> = with.lines().collect();
        assert!(
            lines[0].ends_with("| --holdout part RMS (N) |"),
            "{}",
            lines[0]
        );
        assert_eq!(lines[1].matches("---").count(), 9);
        assert!(
            lines[2].ends_with("| 0.7 | 70.0 % | 0.25 |"),
            "{}",
            lines[2]
        );
        assert!(lines[3].ends_with("| 70.0 % | – |"), "{}", lines[3]);
        assert!(with.contains("--holdout part RMS: the held-out (later) parts"));
        // Without it the table keeps its eight columns.
        let without = models_table(&[row("ours", None)], 1.0);
        assert!(!without.contains("--holdout part"), "{without}");
        assert_eq!(without.lines().nth(1).unwrap().matches("---").count(), 8);
    }
}
