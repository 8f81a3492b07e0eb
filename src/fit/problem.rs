//! The least-squares problem: a model, the data (with its map
//! coefficients), the residuals on the samples used for the fit and the
//! predictions per source. How it is solved is `driver.rs`.

use super::data::{Data, HoldOut, Role};
use super::series::{Series, Source};
use super::unknowns::FittedParameter;
use super::PredictError;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// A friction model with fitted parameters.
pub trait Model: Sync {
    /// Its name in tables.
    fn label(&self) -> String;
    /// Its fitted parameters (values are passed in this order).
    fn parameters(&self) -> &[FittedParameter];
    /// Friction, N, at every sample of `series` for parameter values `x`;
    /// `Err` says why these values give no prediction. It reads only the
    /// series' inputs (time, velocity, load, temperature, steady), not the
    /// measured friction or which samples are fitted: a prediction is
    /// reused when only those change (a map coefficient of the friction).
    fn predict(&self, x: &[f64], series: &Series) -> Result<Vec<f64>, PredictError>;
    /// [`Model::predict`] given `inputs`, the series'
    /// [`Series::inputs_fingerprint`] (the fit computes it once per
    /// series): a model that keys kept work on it need not hash the
    /// series' columns again at every evaluation. By default, `predict`.
    fn predict_fingerprinted(
        &self,
        x: &[f64],
        series: &Series,
        inputs: u64,
    ) -> Result<Vec<f64>, PredictError> {
        let _ = inputs;
        self.predict(x, series)
    }
    /// The film solves so far, for a model that solves a film (None: a
    /// model whose every evaluation costs the same).
    fn film_solves(&self) -> Option<usize> {
        None
    }
    /// The parameters every prediction depends on linearly, each with a
    /// slope that no parameter changes (only the series' inputs): the
    /// prediction is q(the others) + Σ x_k φ_k. A fit solves them for
    /// each point of the others instead of searching them
    /// (`separable.rs`). None by default.
    fn linear_parameters(&self) -> Vec<usize> {
        Vec::new()
    }
    /// The parameters a change of which needs a whole simulation, when
    /// the others are cheaper (our model: the keys the film depends on;
    /// the others recompose the friction along a kept film). None: every
    /// parameter costs the same.
    fn costly_parameters(&self) -> Option<Vec<usize>> {
        None
    }
}

/// A model's prediction beside the measurement, for one source.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesFit {
    /// The data as the model saw them (maps applied; shared with the
    /// problem's kept series, not copied per evaluation).
    pub series: Arc<Series>,
    /// Model friction at every sample, N (NaN where there is none).
    pub predicted: Vec<f64>,
}

impl SeriesFit {
    /// RMS and max |residual| over the samples where `select` holds.
    pub fn residual_stats(&self, select: impl Fn(usize) -> bool) -> Option<(f64, f64, usize)> {
        let (mut ss, mut max, mut n) = (0.0, 0.0f64, 0usize);
        for k in 0..self.predicted.len() {
            if select(k) {
                let r = self.predicted[k] - self.series.friction[k];
                ss += r * r;
                max = max.max(r.abs());
                n += 1;
            }
        }
        (n > 0).then(|| ((ss / n as f64).sqrt(), max, n))
    }
}

/// A residual of a failed prediction, times the data's friction scale.
const PENALTY: f64 = 1e3;

/// A series with the fingerprint of its model inputs (shared: every
/// evaluation at the same map coefficients reads the same one).
type Fingerprinted = (Arc<Series>, u64);

/// Series computed for one set of map coefficients: (role, the
/// coefficients' bits, one series or error per source).
type SeriesEntry = (
    Role,
    Vec<u64>,
    Arc<Vec<Result<Fingerprinted, PredictError>>>,
);

/// Map-coefficient values whose series are kept.
const RECENT_SERIES: usize = 8;

/// A prediction kept for reuse: (role, source index, the model
/// parameters' bits, the fingerprint of the series' inputs, the
/// prediction).
type PredictionEntry = (Role, usize, Vec<u64>, u64, Arc<Vec<f64>>);

/// Predictions kept: enough for one Jacobian's columns and its base point.
fn predictions_kept(params: usize, sources: usize) -> usize {
    2 * (params + 2) * sources.max(1)
}

/// A model on data, with the map coefficients that are fitted.
pub struct Problem<'a> {
    /// The model fitted.
    pub model: &'a dyn Model,
    /// The data.
    pub data: &'a Data,
    /// Fitted map coefficients: index into `data.map_names` and bounds.
    pub map_fit: Vec<(usize, FittedParameter)>,
    /// The model's parameters, then the fitted map coefficients.
    pub params: Vec<FittedParameter>,
    fitted_samples: usize,
    /// Each training source's fitted samples, in the residuals' order,
    /// and whether it is a steady curve (its points independent) or a
    /// time series (its samples consecutive in time).
    fitted_by_source: Vec<(usize, bool)>,
    friction_scale: f64,
    /// The series of every source (training, held out, validation) with
    /// their inputs' fingerprints, when no map coefficient is fitted (they
    /// do not change).
    fixed: Option<[Vec<Fingerprinted>; 3]>,
    /// The series of the last few map-coefficient values (training or
    /// validation): a Jacobian column that moves only a model parameter
    /// reuses them instead of evaluating the column expressions again.
    recent: Mutex<Vec<SeriesEntry>>,
    /// Predictions of the last model parameters, per source: a Jacobian
    /// column of a map coefficient that moves only the measured friction
    /// reuses them instead of simulating again.
    predictions: Mutex<Vec<PredictionEntry>>,
    /// A stop requested from outside ends the local runs at once.
    pub stop: crate::interrupt::Stop,
    /// Whether the local runs fit the cheap keys at every point of the
    /// costly ones (`profile.rs`), or search them all together.
    pub profile_cheap: bool,
    /// The profiled inner fit ends on a step that lowers its cost by less
    /// than this fraction: `profile::INNER_FTOL` (1e-2) × the runs'
    /// `ftol`, so the inner fits stay well inside the runs' tolerance.
    pub cheap_ftol: f64,
    /// Model evaluations so far.
    pub simulations: AtomicUsize,
    /// Their total wall time, ns.
    pub simulation_ns: AtomicU64,
}

impl<'a> Problem<'a> {
    /// `map_fit` must name coefficients of `data`.
    pub fn new(
        model: &'a dyn Model,
        data: &'a Data,
        map_fit: Vec<(usize, FittedParameter)>,
    ) -> Result<Self, super::FitError> {
        let mut params = model.parameters().to_vec();
        params.extend(map_fit.iter().map(|(_, p)| p.clone()));
        let mut fitted_samples = 0;
        let mut fitted_by_source = Vec::with_capacity(data.train.len());
        let mut scale = 0.0f64;
        for (i, s) in data.train.iter().enumerate() {
            let mut series = s.series(&data.map_values)?;
            data.holdout.apply(&mut series, i);
            let fitted = series.fit.iter().filter(|f| **f).count();
            fitted_by_source.push((fitted, series.steady));
            fitted_samples += fitted;
            scale = series.friction.iter().fold(scale, |m, f| m.max(f.abs()));
        }
        if scale == 0.0 {
            return Err(super::FitError::Data {
                what: "friction".into(),
                message: "is zero in every sample: there is nothing to fit".into(),
            });
        }
        if fitted_samples < params.len() {
            return Err(super::FitError::Data {
                what: "data".into(),
                message: format!(
                    "{fitted_samples} samples to fit {} parameters",
                    params.len()
                ),
            });
        }
        let fixed = if map_fit.is_empty() {
            let all = |sources: &[Source], holdout: HoldOut| {
                sources
                    .iter()
                    .enumerate()
                    .map(|(i, s)| {
                        let mut se = s.series(&data.map_values)?;
                        holdout.apply(&mut se, i);
                        let print = se.inputs_fingerprint();
                        Ok((Arc::new(se), print))
                    })
                    .collect::<Result<Vec<_>, super::FitError>>()
            };
            Some([
                all(&data.train, data.holdout)?,
                all(&data.held_out, HoldOut::None)?,
                all(&data.validate, HoldOut::None)?,
            ])
        } else {
            None
        };
        Ok(Self {
            model,
            data,
            map_fit,
            params,
            fitted_samples,
            fitted_by_source,
            friction_scale: scale,
            fixed,
            recent: Mutex::new(Vec::new()),
            predictions: Mutex::new(Vec::new()),
            stop: crate::interrupt::Stop::new(),
            profile_cheap: false,
            // The driver sets it from the runs' ftol; this is a final fit's.
            cheap_ftol: 1e-12,
            simulations: AtomicUsize::new(0),
            simulation_ns: AtomicU64::new(0),
        })
    }

    /// Per parameter (the model's, then the fitted map coefficients):
    /// whether a change of it alone needs a whole simulation. None when
    /// every one does, or none is cheaper than another.
    pub fn costly(&self) -> Option<Vec<bool>> {
        let costly = self.model.costly_parameters()?;
        let n = self.model.parameters().len();
        let mut out: Vec<bool> = (0..n).map(|i| costly.contains(&i)).collect();
        // A map coefficient that moves the model's inputs is simulated
        // again; one of the measured friction alone reuses the prediction.
        out.extend(
            self.map_fit
                .iter()
                .map(|(i, _)| self.data.train.iter().any(|s| s.inputs_read(*i))),
        );
        (out.iter().any(|c| *c) && out.iter().any(|c| !*c)).then_some(out)
    }

    /// The starting point (every parameter's start).
    pub fn start(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.start).collect()
    }

    fn map_values(&self, x: &[f64]) -> Vec<f64> {
        let n = self.model.parameters().len();
        let mut m = self.data.map_values.clone();
        for (j, (i, _)) in self.map_fit.iter().enumerate() {
            m[*i] = x[n + j];
        }
        m
    }

    /// The model on the sources of `role`, in parallel (training sources
    /// with the samples left out of the cost marked).
    pub fn predict_sources(&self, x: &[f64], role: Role) -> Vec<Result<SeriesFit, PredictError>> {
        let n = self.model.parameters().len();
        let sources = self.data.sources(role);
        let holdout = match role {
            Role::Train => self.data.holdout,
            Role::HeldOut | Role::Validate => HoldOut::None,
        };
        let map = self.map_values(x);
        let computed = if self.fixed.is_none() {
            Some(self.series_for(&map, role, sources, holdout))
        } else {
            None
        };
        (0..sources.len())
            .into_par_iter()
            .map(|i| {
                let (series, print) = match (&self.fixed, &computed) {
                    (Some(fixed), _) => fixed[role as usize][i].clone(),
                    (None, Some(c)) => c[i].clone()?,
                    (None, None) => unreachable!("computed when not fixed"),
                };
                let predicted = self.predict_one(&x[..n], role, i, &series, print)?;
                // A held-out part run through the motion before it is
                // scored on its own rows only.
                match sources[i].scored_from() {
                    0 => Ok(SeriesFit { series, predicted }),
                    from => Ok(SeriesFit {
                        series: Arc::new(series.tail(from)),
                        predicted: predicted[from.min(predicted.len())..].to_vec(),
                    }),
                }
            })
            .collect()
    }

    /// The model on one source: a kept prediction when the parameters and
    /// the series' inputs (their fingerprint `print`) are those of one,
    /// else a simulation (kept when map coefficients are fitted, the only
    /// case where it is reused).
    fn predict_one(
        &self,
        x: &[f64],
        role: Role,
        source: usize,
        series: &Series,
        print: u64,
    ) -> Result<Vec<f64>, PredictError> {
        let bits: Vec<u64> = x.iter().map(|v| v.to_bits()).collect();
        let lock = || self.predictions.lock().unwrap_or_else(|p| p.into_inner());
        let keep = self.fixed.is_none();
        if keep {
            if let Some(e) = lock()
                .iter()
                .find(|e| e.0 == role && e.1 == source && e.2 == bits && e.3 == print)
            {
                return Ok(e.4.as_ref().clone());
            }
        }
        let start = Instant::now();
        let predicted = self.model.predict_fingerprinted(x, series, print);
        self.simulations.fetch_add(1, Ordering::Relaxed);
        self.simulation_ns.fetch_add(
            u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX),
            Ordering::Relaxed,
        );
        let predicted = predicted?;
        if keep {
            let mut kept = lock();
            let most = predictions_kept(self.params.len(), self.data.train.len());
            if kept.len() >= most {
                kept.remove(0);
            }
            kept.push((role, source, bits, print, Arc::new(predicted.clone())));
        }
        Ok(predicted)
    }

    /// The series of `sources` for map values `map`, from the recent ones
    /// when they were computed already.
    fn series_for(
        &self,
        map: &[f64],
        role: Role,
        sources: &[Source],
        holdout: HoldOut,
    ) -> Arc<Vec<Result<Fingerprinted, PredictError>>> {
        let key: Vec<u64> = map.iter().map(|v| v.to_bits()).collect();
        let lock = || self.recent.lock().unwrap_or_else(|p| p.into_inner());
        if let Some((_, _, s)) = lock().iter().find(|(r, k, _)| *r == role && *k == key) {
            return s.clone();
        }
        let computed: Arc<Vec<Result<Fingerprinted, PredictError>>> = Arc::new(
            sources
                .par_iter()
                .enumerate()
                .map(|(i, s)| {
                    let mut se = s
                        .series(map)
                        .map_err(|e| PredictError::Inputs(e.to_string()))?;
                    holdout.apply(&mut se, i);
                    let print = se.inputs_fingerprint();
                    Ok((Arc::new(se), print))
                })
                .collect(),
        );
        let mut recent = lock();
        if recent.len() >= RECENT_SERIES {
            recent.remove(0);
        }
        recent.push((role, key, computed.clone()));
        computed
    }

    /// Residuals on the fitted samples; a failed prediction gives large
    /// residuals (a step there is rejected).
    pub fn residuals(&self, x: &[f64]) -> Vec<f64> {
        self.try_residuals(x).unwrap_or_else(|| self.penalty())
    }

    /// The large residuals of a point with no prediction.
    pub fn penalty(&self) -> Vec<f64> {
        vec![PENALTY * self.friction_scale; self.fitted_samples]
    }

    /// Residuals on the fitted samples; None when some prediction fails or
    /// is not finite.
    pub fn try_residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
        let fits = self.predict_sources(x, Role::Train);
        let mut r = Vec::with_capacity(self.fitted_samples);
        for f in fits {
            let f = f.ok()?;
            for k in 0..f.predicted.len() {
                if f.series.fit[k] {
                    let d = f.predicted[k] - f.series.friction[k];
                    if !d.is_finite() {
                        return None;
                    }
                    r.push(d);
                }
            }
        }
        (r.len() == self.fitted_samples).then_some(r)
    }

    /// ½ Σ r².
    pub fn cost(&self, x: &[f64]) -> f64 {
        0.5 * self.residuals(x).iter().map(|r| r * r).sum::<f64>()
    }

    /// Samples the cost sums over.
    pub fn fitted_samples(&self) -> usize {
        self.fitted_samples
    }

    /// Each training source's fitted samples in the residuals' order, and
    /// whether it is a steady curve (see `stats::batches`).
    pub fn fitted_by_source(&self) -> &[(usize, bool)] {
        &self.fitted_by_source
    }

    /// `x` as the optimiser's unbounded variables.
    pub fn to_internal(&self, x: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(x)
            .map(|(p, v)| p.to_internal(*v))
            .collect()
    }

    /// The point of the optimiser's variables `u`.
    pub fn from_internal(&self, u: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(u)
            .map(|(p, v)| p.from_internal(*v))
            .collect()
    }
}

/// Data of one training source, the CSV `text` through `mapping` (its
/// coefficients the maps' values), nothing held out (for tests).
#[cfg(test)]
pub(crate) fn tests_data(text: &str, mapping: &super::series::Mapping) -> Data {
    use crate::table::{Delimiter, Table};
    let table = Table::parse(
        text,
        std::path::Path::new("d.csv"),
        Delimiter::Auto,
        None,
        0,
    )
    .expect("a test's table parses");
    Data {
        train: vec![Source::new(table, mapping).expect("a test's mapping compiles")],
        held_out: vec![],
        validate: vec![],
        holdout: HoldOut::None,
        map_names: mapping.coefficients.iter().map(|c| c.0.clone()).collect(),
        map_values: mapping.coefficients.iter().map(|c| c.1).collect(),
        units: Default::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::series::Mapping;

    /// Friction = c · velocity, one parameter c.
    struct Linear(Vec<FittedParameter>);

    impl Model for Linear {
        fn label(&self) -> String {
            "linear".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.0
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, PredictError> {
            Ok(s.velocity.iter().map(|v| x[0] * v).collect())
        }
    }

    fn data(friction: &str, coefficients: Vec<(String, f64)>) -> Data {
        let mut text = String::from("t_s,v,f\n");
        for k in 0..50 {
            text += &format!("{},{},{}\n", k as f64 * 0.01, (k as f64 * 0.3).sin(), k);
        }
        let mapping = Mapping {
            velocity: "v * g".into(),
            friction: friction.into(),
            coefficients,
            ..Default::default()
        };
        tests_data(&text, &mapping)
    }

    /// Friction = c · the position (the velocity integrated from the first
    /// sample): a model with memory, as a bristle is.
    struct Position(Vec<FittedParameter>);

    impl Model for Position {
        fn label(&self) -> String {
            "position".into()
        }
        fn parameters(&self) -> &[FittedParameter] {
            &self.0
        }
        fn predict(&self, x: &[f64], s: &Series) -> Result<Vec<f64>, PredictError> {
            let mut q = 0.0;
            Ok((0..s.len())
                .map(|k| {
                    if k > 0 {
                        q += s.velocity[k] * (s.t[k] - s.t[k - 1]);
                    }
                    x[0] * q
                })
                .collect())
        }
    }

    #[test]
    fn a_held_out_later_part_is_predicted_in_the_state_the_motion_before_it_left() {
        // f = 2 q, q the position from the record's start: the last 30 %
        // held out. Simulated from its own first row it would start at
        // q = 0 and be off by 2 q(cut) throughout; run through the motion
        // before it, it is exact, and only its own rows are scored.
        let mut text = String::from("t_s,v,f\n");
        let mut q = 0.0;
        for k in 0..100 {
            let v = 1.0 + (k as f64 * 0.2).sin();
            if k > 0 {
                q += v * 0.01;
            }
            text += &format!("{},{v},{}\n", k as f64 * 0.01, 2.0 * q);
        }
        let mapping = Mapping {
            velocity: "v".into(),
            friction: "f".into(),
            ..Default::default()
        };
        let whole = tests_data(&text, &mapping);
        let (train, held) = whole.train[0].split_held_out(0.3, &mapping).unwrap();
        assert_eq!(held.scored_from(), 70);
        assert_eq!(train.scored_from(), 0);
        let d = Data {
            train: vec![train],
            held_out: vec![held],
            ..whole
        };
        let model = Position(vec![FittedParameter::new("c", 1.0, 0.1, 10.0)]);
        let p = Problem::new(&model, &d, vec![]).unwrap();
        let fits = p.predict_sources(&[2.0], Role::HeldOut);
        let fit = fits[0].as_ref().unwrap();
        assert_eq!(fit.predicted.len(), 30);
        assert_eq!(fit.series.len(), 30);
        approx::assert_abs_diff_eq!(fit.series.t[0], 0.7, epsilon = 1e-12);
        for (m, f) in fit.predicted.iter().zip(&fit.series.friction) {
            approx::assert_abs_diff_eq!(m, f, epsilon = 1e-9);
        }
        // The training part is the first 70 rows alone.
        let train = p.predict_sources(&[2.0], Role::Train);
        assert_eq!(train[0].as_ref().unwrap().predicted.len(), 70);
    }

    #[test]
    fn a_map_coefficient_that_moves_only_the_measured_friction_reuses_the_prediction() {
        let d = data("f - b", vec![("g".into(), 1.0), ("b".into(), 0.0)]);
        let model = Linear(vec![FittedParameter::new("c", 1.0, 0.1, 10.0)]);
        let fit_b = (1, FittedParameter::new("b", 0.0, -5.0, 5.0));
        let fit_g = (0, FittedParameter::new("g", 1.0, 0.5, 2.0));
        let p = Problem::new(&model, &d, vec![fit_g, fit_b]).unwrap();
        let count = || p.simulations.load(Ordering::Relaxed);
        let base = p.residuals(&[2.0, 1.0, 0.0]);
        assert_eq!(count(), 1);
        // The friction's offset: the same prediction, residuals shifted.
        let shifted = p.residuals(&[2.0, 1.0, 0.5]);
        assert_eq!(count(), 1);
        for (a, b) in shifted.iter().zip(&base) {
            approx::assert_relative_eq!(*a, b + 0.5, epsilon = 1e-12);
        }
        // The velocity's gain and the model's parameter: simulated again.
        p.residuals(&[2.0, 1.5, 0.5]);
        assert_eq!(count(), 2);
        p.residuals(&[3.0, 1.5, 0.5]);
        assert_eq!(count(), 3);
        // Back at the first point: kept.
        p.residuals(&[2.0, 1.0, 0.0]);
        assert_eq!(count(), 3);
    }
}
