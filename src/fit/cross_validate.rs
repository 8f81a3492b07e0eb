//! Cross-validation by what a calibration is used for: each fold of the
//! training data predicted by the model refitted without it.
//!
//! The folds ([`Folds`]) follow the data:
//!
//! | training data | folds | what each fold asks |
//! |---|---|---|
//! | three files or more (loads, temperatures, motions) | one per file | predict a file from the others |
//! | two files | as one file, fold b the b-th of every file | (a fit on one file alone sees one operating point) |
//! | one or two time series | [`FOLDS`] contiguous time blocks of the samples slower than [`FASTEST_FROM`](super::data::FASTEST_FROM) of the top speed, and those faster as one more fold ([`Folds::Motion`]) | predict a stretch of motion the fit did not see, and a faster motion |
//! | one or two steady curves | [`FOLDS`] contiguous speed ranges | predict the slowest and the fastest points from the rest (extrapolation), and the middle ones |
//!
//! The fastest fold is a time series' counterpart of a steady curve's
//! fastest speed range: a calibration is used at the speeds a machine
//! will be commanded, which may exceed the record's, and contiguous time
//! blocks alone each hold the whole speed range, so they reward a term
//! that bends where the data stop (a Stribeck rise saturating at the top
//! speed, in place of the viscous rise: joint draw d80 of
//! `docs/joint-series-draws.sh`, `START=sliding`, predicted a 2.5× faster
//! motion 2.35× worse than LuGre; with this fold it chooses the viscous
//! rise, 0.53×). The whole record is simulated in every refit (the
//! bristle and the film keep their history); only the cost leaves the
//! fold's samples out.
//!
//! A fold's refit is a whole fit (one local run) on the other folds,
//! started from the optimum on all the training data; its error is the
//! mean squared residual on the fold's samples. The same folds and refits
//! score our model's candidate sets and every classic model, so their
//! cross-validated errors compare on one yardstick.

use super::data::{motion_cuts, Data, Folds, HoldOut};
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
/// [`FILES_FOR_FILE_FOLDS`] or more, else [`FOLDS`] within each, and a
/// time series' fastest samples as one more ([`Folds::Motion`]) where
/// every time series can be so cut ([`motion_cuts`]; a record at one
/// speed cannot, and keeps its time blocks alone).
pub fn folds_for(data: &Data) -> Folds {
    if data.train.len() >= FILES_FOR_FILE_FOLDS {
        Folds::Files(data.train.len())
    } else {
        let mut series = data.train.iter().filter(|s| !s.steady).peekable();
        let motion = series.peek().is_some()
            && series.all(|s| {
                s.series(&data.map_values)
                    .is_ok_and(|x| motion_cuts(&x, FOLDS))
            });
        if motion {
            Folds::Motion(FOLDS)
        } else {
            Folds::Within(FOLDS)
        }
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
        Folds::Motion(n) => format!(
            "{n} contiguous time blocks of the training record and its fastest samples (above {:.0} % of its top speed), each predicted from the others",
            super::data::FASTEST_FROM * 100.0
        ),
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
    use crate::fit::data::FASTEST_FROM;
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

    /// Each fold's mean squared error of [`Line`] fitted to `data` and
    /// refitted without the fold.
    fn line_fold_mse(data: &Data, folds: Folds) -> Vec<f64> {
        let model = Line(vec![
            FittedParameter::new("a", 1.0, -10.0, 10.0),
            FittedParameter::new("b", 1.0, -10.0, 10.0),
        ]);
        let opts = Options {
            global_points: 0,
            starts: 1,
            ..Default::default()
        };
        let all = fit(&model, data, vec![], &opts).unwrap();
        cross_validate(&model, data, &[], &all.best, folds, &opts).unwrap()
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
        let mse = line_fold_mse(&data, folds);
        // The fastest range, extrapolated from the line the rest lie on,
        // misses it by the kink: 1 N exactly. The others are predicted by
        // lines the kink bends, and miss by less.
        assert!((mse[3] - 1.0).abs() < 1e-6, "{mse:?}");
        assert!(mse[..3].iter().all(|m| *m > 0.0 && *m < mse[3]), "{mse:?}");
    }

    #[test]
    fn a_time_series_fastest_samples_are_one_more_fold_predicted_from_the_slower_ones() {
        // A line that steps up past 0.8 of the top speed: the time blocks
        // hold only the slower samples, on the line; the fastest fold is
        // extrapolated from them and misses by the step.
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        let n = 200;
        for k in 0..n {
            let t = k as f64 * 0.01;
            let v = (std::f64::consts::TAU * t / 2.0).sin();
            let f = 1.0 + 2.0 * v + if v.abs() > 0.8 { 0.5 * v.signum() } else { 0.0 };
            text += &format!("{t},{v},{f}\n");
        }
        let data = tests_data(&text, &Mapping::default());
        let folds = folds_for(&data);
        assert_eq!(folds, Folds::Motion(FOLDS));
        assert_eq!(folds.count(), FOLDS + 1);
        let s = data.train[0].series(&[]).unwrap();
        let of = folds.of(0, &s);
        for (k, fold) in of.iter().enumerate() {
            if s.velocity[k].abs() > FASTEST_FROM {
                assert_eq!(*fold, FOLDS, "sample {k} at {}", s.velocity[k]);
            } else {
                assert_eq!(*fold, k * FOLDS / n, "sample {k}");
            }
        }
        let mse = line_fold_mse(&data, folds);
        // The fastest fold, extrapolated from the slower samples alone
        // (all on the line), misses by the step: 0.5 N, a mean squared
        // error of 0.25 N². Each time block is predicted by a line the
        // fast samples of the other folds pull, and misses by less.
        approx::assert_relative_eq!(mse[FOLDS], 0.25, max_relative = 1e-6);
        assert!(
            mse[..FOLDS].iter().all(|m| *m > 0.0 && *m < 0.25),
            "{mse:?}"
        );
    }

    #[test]
    fn a_record_that_peaks_briefly_still_puts_a_twentieth_of_its_samples_in_its_fastest_fold() {
        // 1000 samples at 0.1..0.5 m/s and one peak of 10 samples at 1 m/s:
        // 0.8 of the top would leave 1 % of the samples; the fold starts at
        // the 95th percentile of the speeds instead.
        let mut v: Vec<f64> = (0..1000).map(|k| 0.1 + 0.4 * k as f64 / 999.0).collect();
        v[500..510].iter_mut().for_each(|x| *x = -1.0);
        let from = crate::fit::data::fastest_from(&v);
        let share = v.iter().filter(|x| x.abs() > from).count() as f64 / v.len() as f64;
        approx::assert_abs_diff_eq!(share, 0.05, epsilon = 0.002);
        assert!(from < 0.8 && from > 0.45, "{from}");
        // A record that spends long near its top keeps 0.8 of it.
        let sine: Vec<f64> = (0..1000).map(|k| (k as f64 * 0.01).sin()).collect();
        let top = sine.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        approx::assert_relative_eq!(crate::fit::data::fastest_from(&sine), FASTEST_FROM * top);
        assert_eq!(crate::fit::data::fastest_from(&[]), 0.0);
    }

    #[test]
    fn a_record_at_one_speed_keeps_its_time_blocks_alone() {
        // Every sample at the top speed: a fastest fold would hold them all
        // and leave the blocks and its own refit nothing to fit.
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        for k in 0..400 {
            let t = k as f64 * 0.01;
            text += &format!("{t},0.05,{}\n", 1.0 + 0.01 * (k % 7) as f64);
        }
        let data = tests_data(&text, &Mapping::default());
        assert_eq!(folds_for(&data), Folds::Within(FOLDS));
        let s = data.train[0].series(&[]).unwrap();
        assert!(!motion_cuts(&s, FOLDS));
        // A record whose first quarter is all at its top speed would leave
        // its first time block empty: time blocks alone as well.
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        for k in 0..400 {
            let t = k as f64 * 0.01;
            let v = if k < 100 { 1.0 } else { 0.5 * (t * 3.0).sin() };
            text += &format!("{t},{v},1.0\n");
        }
        let data = tests_data(&text, &Mapping::default());
        assert_eq!(folds_for(&data), Folds::Within(FOLDS));
    }
}
