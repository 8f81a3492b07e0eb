//! Cross-validation by what a calibration is used for: each fold of the
//! training data predicted by the model refitted without it.
//!
//! The folds ([`Folds`]) follow the data:
//!
//! | training data | folds | what each fold asks |
//! |---|---|---|
//! | three files or more (loads, temperatures, motions) | one per file | predict a file from the others |
//! | two files | [`FOLDS`] contiguous blocks within each, fold b the b-th of every file | (a fit on one file alone sees one operating point) |
//! | one time series | [`FOLDS`] contiguous time blocks | predict a stretch of motion the fit did not see |
//! | one steady curve | [`FOLDS`] contiguous speed ranges | predict the slowest and the fastest points from the rest (extrapolation), and the middle ones |
//!
//! A fold's refit is a whole fit (one local run) on the other folds,
//! started from the optimum on all the training data; its error is the
//! mean squared residual on the fold's samples. The same folds and refits
//! score our model's candidate sets and every classic model, so their
//! cross-validated errors compare on one yardstick.

use super::data::{Data, Folds, HoldOut};
use super::driver::{fit, FitOutcome};
use super::options::Options;
use super::problem::Model;
use super::{FitError, FittedParameter};
use rayon::prelude::*;

/// The cost of a term: the smallest fraction of the cross-validated mean
/// squared error it must remove to be kept (1 %: about half a percent of
/// the RMS). Below it, a term fits the data's fine structure — a noise
/// floor's texture, a systematic residue of another effect — consistently
/// enough to beat the blocks' spread while predicting no better in any
/// sense a controller would notice.
pub const TERM_COST: f64 = 0.01;

/// Mean and standard error of the paired differences (of folds or samples) a − b.
pub fn paired(a: &[f64], b: &[f64]) -> (f64, f64) {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, (var / n).sqrt())
}

/// Folds of one training record (time blocks or speed ranges).
pub const FOLDS: usize = 4;

/// Training files from which each is predicted from the others: with
/// fewer, the fit without one sees a single operating point, which leaves
/// what changes between files (an area times a pressure, a load's
/// coefficient) unidentified.
pub const FILES_FOR_FILE_FOLDS: usize = 3;

/// The folds of `data`'s training sources: one per file when there are
/// [`FILES_FOR_FILE_FOLDS`] or more, else [`FOLDS`] within each.
pub fn folds_for(data: &Data) -> Folds {
    if data.train.len() >= FILES_FOR_FILE_FOLDS {
        Folds::Files(data.train.len())
    } else {
        Folds::Within(FOLDS)
    }
}

/// The folds in words, for reports.
pub fn describe(folds: Folds, steady: bool) -> String {
    match folds {
        Folds::Files(n) => format!("{n} folds, one per training file: each predicted from the others"),
        Folds::Within(n) if steady => format!(
            "{n} contiguous speed ranges of the training curve: the slowest and the fastest points predicted from the rest, and the middle ones"
        ),
        Folds::Within(n) => format!("{n} contiguous time blocks of the training record, each predicted from the others"),
    }
}

/// Each fold's mean squared residual, the model refitted without it from
/// `at` (its optimum on all the training data); a fold whose refit fails
/// scores infinity. `options` are the whole fit's (one local run from `at`
/// is taken, without statistics).
pub fn cross_validate(
    model: &dyn Model,
    data: &Data,
    map_fit: &[(usize, FittedParameter)],
    at: &[f64],
    folds: Folds,
    options: &Options,
) -> Result<Vec<f64>, FitError> {
    (0..folds.count())
        .into_par_iter()
        .map(|index| {
            let fold = Data {
                holdout: HoldOut::Fold { index, folds },
                ..data.training_only()
            };
            let opts = Options {
                starts: 1,
                global_points: 0,
                start: Some(at.to_vec()),
                statistics: false,
                progress: None,
                extra_starts: Vec::new(),
                stop: options.stop.clone(),
                ..*options
            };
            match fit(model, &fold, map_fit.to_vec(), &opts) {
                Ok(o) => Ok(held_mse(&o)),
                Err(FitError::Interrupted(i)) => Err(FitError::Interrupted(i)),
                Err(_) => Ok(f64::INFINITY),
            }
        })
        .collect()
}

/// The mean squared residual on the samples left out of `o`'s fit.
fn held_mse(o: &FitOutcome) -> f64 {
    let (mut ss, mut n) = (0.0, 0usize);
    for f in &o.train {
        for k in (0..f.series.len()).filter(|&k| !f.series.fit[k]) {
            let r = f.predicted[k] - f.series.friction[k];
            ss += r * r;
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        ss / n as f64
    }
}

/// The pooled cross-validated RMS of fold errors `mse` (NaN folds left out).
pub fn cv_rms(mse: &[f64]) -> f64 {
    let ok: Vec<f64> = mse.iter().copied().filter(|m| !m.is_nan()).collect();
    (ok.iter().sum::<f64>() / ok.len().max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::problem::tests_data;
    use crate::fit::series::Series;
    use crate::fit::{Mapping, PredictError};

    /// Friction = a + b v (two parameters).
    struct Line(Vec<FittedParameter>);

    impl Model for Line {
        fn label(&self) -> String {
            "line".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.0
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, PredictError> {
            Ok(s.velocity.iter().map(|v| x[0] + x[1] * v).collect())
        }
    }

    #[test]
    fn a_steady_curve_is_cut_by_speed_and_each_range_predicted_from_the_rest() {
        // A line with a kink at its fast end: the fastest range is
        // extrapolated from the others, so its error is the kink's.
        let mut text = String::from("velocity_m_s,friction_n\n");
        let mut v: Vec<f64> = (1..=8).map(|k| k as f64 * 0.1).collect();
        v.reverse(); // the table's order is not the speed's
        for x in &v {
            let f = 1.0 + 2.0 * x + if *x > 0.65 { 1.0 } else { 0.0 };
            text += &format!("{x},{f}\n");
        }
        let data = tests_data(&text, &Mapping::default());
        let folds = folds_for(&data);
        assert_eq!(folds, Folds::Within(FOLDS));
        let s = data.train[0].series(&[]).unwrap();
        // Two points per range, ranked by speed whatever the table's order.
        assert_eq!(folds.of(0, &s), vec![3, 3, 2, 2, 1, 1, 0, 0]);
        let model = Line(vec![
            FittedParameter::new("a", 1.0, -10.0, 10.0),
            FittedParameter::new("b", 1.0, -10.0, 10.0),
        ]);
        let opts = Options {
            global_points: 0,
            starts: 1,
            ..Default::default()
        };
        let all = fit(&model, &data, vec![], &opts).unwrap();
        let mse = cross_validate(&model, &data, &[], &all.best, folds, &opts).unwrap();
        // The fastest range, extrapolated from the line the rest lie on,
        // misses it by the kink: 1 N exactly. The others are predicted by
        // lines the kink bends, and miss by less.
        assert!((mse[3] - 1.0).abs() < 1e-6, "{mse:?}");
        assert!(mse[..3].iter().all(|m| *m > 0.0 && *m < mse[3]), "{mse:?}");
    }
}
