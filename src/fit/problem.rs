//! The least-squares problem: a model, the data (with its map
//! coefficients), the residuals on the samples used for the fit and the
//! predictions per source. How it is solved is `driver.rs`.

use super::params::FittedParameter;
use super::series::{Series, Source};
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
    /// `Err` says why these values give no prediction.
    fn predict(&self, x: &[f64], series: &Series) -> Result<Vec<f64>, String>;
}

/// The data of a fit: training sources (a part may be held out) and
/// validation sources, with the input maps' coefficients.
pub struct Data {
    /// Training sources.
    pub train: Vec<Source>,
    /// Validation sources (not fitted).
    pub validate: Vec<Source>,
    /// Fraction of each training source held out (see [`Series::hold_out`]).
    pub holdout: f64,
    /// Map coefficient names and their values (fixed or starts).
    pub map_names: Vec<String>,
    /// Their values.
    pub map_values: Vec<f64>,
}

/// A model's prediction beside the measurement, for one source.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesFit {
    /// The data as the model saw them (maps applied).
    pub series: Series,
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

/// Series computed for one set of map coefficients: (training?, the
/// coefficients' bits, one series or error per source).
type SeriesEntry = (bool, Vec<u64>, Arc<Vec<Result<Series, String>>>);

/// Map-coefficient values whose series are kept.
const RECENT_SERIES: usize = 8;

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
    friction_scale: f64,
    /// The series of every training and validation source when no map
    /// coefficient is fitted (they do not change).
    fixed: Option<(Vec<Series>, Vec<Series>)>,
    /// The series of the last few map-coefficient values (training or
    /// validation): a Jacobian column that moves only a model parameter
    /// reuses them instead of evaluating the column expressions again.
    recent: Mutex<Vec<SeriesEntry>>,
    /// A stop requested from outside ends the local runs at once.
    pub stop: crate::interrupt::Stop,
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
        let mut scale = 0.0f64;
        for s in &data.train {
            let mut series = s.series(&data.map_values)?;
            series.hold_out(data.holdout);
            fitted_samples += series.fit.iter().filter(|f| **f).count();
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
            let all = |sources: &[Source], holdout: f64| {
                sources
                    .iter()
                    .map(|s| {
                        let mut se = s.series(&data.map_values)?;
                        se.hold_out(holdout);
                        Ok(se)
                    })
                    .collect::<Result<Vec<_>, super::FitError>>()
            };
            Some((all(&data.train, data.holdout)?, all(&data.validate, 0.0)?))
        } else {
            None
        };
        Ok(Self {
            model,
            data,
            map_fit,
            params,
            fitted_samples,
            friction_scale: scale,
            fixed,
            recent: Mutex::new(Vec::new()),
            stop: crate::interrupt::Stop::new(),
            simulations: AtomicUsize::new(0),
            simulation_ns: AtomicU64::new(0),
        })
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

    /// The model on the training (or validation) sources, in parallel,
    /// with the held-out part marked on training sources.
    pub fn predict_sources(&self, x: &[f64], train: bool) -> Vec<Result<SeriesFit, String>> {
        let n = self.model.parameters().len();
        let (sources, holdout) = if train {
            (&self.data.train, self.data.holdout)
        } else {
            (&self.data.validate, 0.0)
        };
        let map = self.map_values(x);
        let computed = if self.fixed.is_none() {
            Some(self.series_for(&map, train, sources, holdout))
        } else {
            None
        };
        (0..sources.len())
            .into_par_iter()
            .map(|i| {
                let series = match (&self.fixed, &computed) {
                    (Some((t, v)), _) => (if train { t } else { v })[i].clone(),
                    (None, Some(c)) => c[i].clone()?,
                    (None, None) => unreachable!("computed when not fixed"),
                };
                let start = Instant::now();
                let predicted = self.model.predict(&x[..n], &series);
                self.simulations.fetch_add(1, Ordering::Relaxed);
                self.simulation_ns.fetch_add(
                    u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX),
                    Ordering::Relaxed,
                );
                Ok(SeriesFit {
                    series,
                    predicted: predicted?,
                })
            })
            .collect()
    }

    /// The series of `sources` for map values `map`, from the recent ones
    /// when they were computed already.
    fn series_for(
        &self,
        map: &[f64],
        train: bool,
        sources: &[Source],
        holdout: f64,
    ) -> Arc<Vec<Result<Series, String>>> {
        let key: Vec<u64> = map.iter().map(|v| v.to_bits()).collect();
        let lock = || self.recent.lock().unwrap_or_else(|p| p.into_inner());
        if let Some((_, _, s)) = lock().iter().find(|(t, k, _)| *t == train && *k == key) {
            return s.clone();
        }
        let computed: Arc<Vec<Result<Series, String>>> = Arc::new(
            sources
                .par_iter()
                .map(|s| {
                    let mut se = s.series(map).map_err(|e| e.to_string())?;
                    se.hold_out(holdout);
                    Ok(se)
                })
                .collect(),
        );
        let mut recent = lock();
        if recent.len() >= RECENT_SERIES {
            recent.remove(0);
        }
        recent.push((train, key, computed.clone()));
        computed
    }

    /// Residuals on the fitted samples; a failed prediction gives large
    /// residuals (a step there is rejected).
    pub fn residuals(&self, x: &[f64]) -> Vec<f64> {
        let fits = self.predict_sources(x, true);
        let penalty = vec![PENALTY * self.friction_scale; self.fitted_samples];
        let mut r = Vec::with_capacity(self.fitted_samples);
        for f in fits {
            let Ok(f) = f else { return penalty };
            for k in 0..f.predicted.len() {
                if f.series.fit[k] {
                    let d = f.predicted[k] - f.series.friction[k];
                    if !d.is_finite() {
                        return penalty;
                    }
                    r.push(d);
                }
            }
        }
        if r.len() != self.fitted_samples {
            return penalty;
        }
        r
    }

    /// ½ Σ r².
    pub fn cost(&self, x: &[f64]) -> f64 {
        0.5 * self.residuals(x).iter().map(|r| r * r).sum::<f64>()
    }

    /// Samples the cost sums over.
    pub fn fitted_samples(&self) -> usize {
        self.fitted_samples
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
