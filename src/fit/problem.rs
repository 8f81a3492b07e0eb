//! The least-squares problem: a model, the data (with its map
//! coefficients), the residuals on the samples used for the fit, the
//! Jacobian by forward differences of whole simulations run in parallel,
//! and one Levenberg–Marquardt run.

use super::params::Parameter;
use super::series::{Series, Source};
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// A friction model with fitted parameters.
pub trait Model: Sync {
    /// Its name in tables.
    fn label(&self) -> String;
    /// Its fitted parameters (values are passed in this order).
    fn parameters(&self) -> &[Parameter];
    /// Friction, N, at every sample of `series` for parameter values `x`;
    /// `Err` says why these values give no prediction.
    fn predict(&self, x: &[f64], series: &Series) -> Result<Vec<f64>, String>;
}

/// The data of a fit: training sources (a part may be held out) and
/// validation sources, with the input maps' coefficients.
pub struct Data {
    pub train: Vec<Source>,
    pub validate: Vec<Source>,
    /// Fraction of each training source held out (see [`Series::hold_out`]).
    pub holdout: f64,
    /// Map coefficient names and their values (fixed or starts).
    pub map_names: Vec<String>,
    pub map_values: Vec<f64>,
}

/// Where progress lines go.
pub type Progress = Box<dyn Fn(&str) + Sync>;

/// How a fit searches.
pub struct Options {
    /// Local (LM) runs: the start and the best distinct points of the
    /// global phase.
    pub starts: usize,
    /// Points of the global phase (0: none).
    pub global_points: usize,
    pub seed: u64,
    /// Residual evaluations per LM run (the Jacobian's are extra).
    pub max_evaluations: usize,
    /// Progress lines (the command prints them).
    pub progress: Option<Progress>,
    /// Requested from outside (SIGINT, Ctrl-C): the search ends at its next
    /// evaluation and the fit is [`super::FitError::Interrupted`].
    pub stop: crate::interrupt::Stop,
    /// More starts, each a whole point (the model's parameters, then the
    /// fitted map coefficients), run besides the given start and the global
    /// points: e.g. a nested model's optimum.
    pub extra_starts: Vec<Vec<f64>>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            starts: 3,
            global_points: 16,
            seed: 1,
            max_evaluations: 200,
            progress: None,
            stop: crate::interrupt::Stop::new(),
            extra_starts: Vec::new(),
        }
    }
}

impl Options {
    pub fn say(&self, line: &str) {
        if let Some(p) = &self.progress {
            p(line);
        }
    }
}

/// A model's prediction beside the measurement, for one source.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesFit {
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
    pub model: &'a dyn Model,
    pub data: &'a Data,
    /// Fitted map coefficients: index into `data.map_names` and bounds.
    pub map_fit: Vec<(usize, Parameter)>,
    /// The model's parameters, then the fitted map coefficients.
    pub params: Vec<Parameter>,
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
    pub simulations: AtomicUsize,
    pub simulation_ns: AtomicU64,
}

impl<'a> Problem<'a> {
    /// `map_fit` must name coefficients of `data`.
    pub fn new(
        model: &'a dyn Model,
        data: &'a Data,
        map_fit: Vec<(usize, Parameter)>,
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

    pub fn fitted_samples(&self) -> usize {
        self.fitted_samples
    }

    pub fn to_internal(&self, x: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(x)
            .map(|(p, v)| p.to_internal(*v))
            .collect()
    }

    pub fn from_internal(&self, u: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(u)
            .map(|(p, v)| p.from_internal(*v))
            .collect()
    }
}

/// The result of one local run.
#[derive(Debug, Clone, PartialEq)]
pub struct LocalRun {
    pub x: Vec<f64>,
    pub cost: f64,
    pub converged: bool,
    pub termination: String,
    pub evaluations: usize,
}

/// Forward-difference step in the unbounded variable.
const FD_STEP: f64 = 1e-4;

struct Lm<'p, 'a> {
    problem: &'p Problem<'a>,
    u: DVector<f64>,
    r: DVector<f64>,
    /// Every point evaluated: (cost, u), for what was still moving when a
    /// run stops on its budget.
    trail: Vec<(f64, Vec<f64>)>,
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Lm<'_, '_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
        let x = self.problem.from_internal(u.as_slice());
        self.r = DVector::from_vec(self.problem.residuals(&x));
        self.trail
            .push((0.5 * self.r.norm_squared(), u.as_slice().to_vec()));
    }

    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        // None ends the run (TerminationReason::User) when a stop is asked.
        (!self.problem.stop.requested()).then(|| self.r.clone())
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        if self.problem.stop.requested() {
            return None;
        }
        let n = self.u.len();
        let columns: Vec<Vec<f64>> = (0..n)
            .into_par_iter()
            .map(|j| {
                let mut u = self.u.clone();
                u[j] += FD_STEP;
                let x = self.problem.from_internal(u.as_slice());
                self.problem
                    .residuals(&x)
                    .iter()
                    .zip(self.r.iter())
                    .map(|(a, b)| (a - b) / FD_STEP)
                    .collect()
            })
            .collect();
        let m = self.r.len();
        Some(DMatrix::from_fn(m, n, |i, j| columns[j][i]))
    }
}

/// One Levenberg–Marquardt run from `x0`.
pub fn local_run(problem: &Problem<'_>, x0: &[f64], max_evaluations: usize) -> LocalRun {
    let u0 = DVector::from_vec(problem.to_internal(x0));
    let n = u0.len();
    let mut lm = Lm {
        problem,
        u: u0.clone(),
        r: DVector::zeros(0),
        trail: Vec::new(),
    };
    lm.set_params(&u0);
    let patience = max_evaluations.div_ceil(n + 1).max(1);
    let (lm, report) = LevenbergMarquardt::new()
        .with_ftol(1e-10)
        .with_xtol(1e-8)
        .with_gtol(1e-10)
        .with_patience(patience)
        .minimize(lm);
    let converged = report.termination.was_successful()
        || matches!(
            report.termination,
            TerminationReason::NoImprovementPossible(_)
        );
    let x = problem.from_internal(lm.u.as_slice());
    let cost = 0.5 * lm.r.norm_squared();
    let mut termination = termination_text(&report.termination);
    if matches!(report.termination, TerminationReason::LostPatience) {
        let moving = still_moving(problem, &lm.trail);
        if !moving.is_empty() {
            termination.push_str(&format!("; still moving: {}", moving.join(", ")));
        }
    }
    LocalRun {
        x,
        cost,
        converged,
        termination,
        evaluations: report.number_of_evaluations,
    }
}

/// The parameters that moved by more than 0.1 % of their scaled range
/// between the best point of the first three quarters of a run and the
/// best point of all of it: what a larger budget would still change.
fn still_moving(problem: &Problem<'_>, trail: &[(f64, Vec<f64>)]) -> Vec<String> {
    let best = |t: &[(f64, Vec<f64>)]| {
        t.iter()
            .filter(|(c, _)| c.is_finite())
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, u)| problem.from_internal(u))
    };
    let early = trail.len() * 3 / 4;
    let (Some(a), Some(b)) = (best(&trail[..early.max(1).min(trail.len())]), best(trail)) else {
        return Vec::new();
    };
    problem
        .params
        .iter()
        .zip(a.iter().zip(&b))
        .filter(|(p, (x, y))| (p.fraction(**x) - p.fraction(**y)).abs() > 1e-3)
        .map(|(p, _)| p.name.clone())
        .collect()
}

fn termination_text(t: &TerminationReason) -> String {
    match t {
        TerminationReason::Converged { ftol, xtol } => match (ftol, xtol) {
            (true, true) => "converged (cost and step)".into(),
            (true, false) => "converged (cost)".into(),
            _ => "converged (step)".into(),
        },
        TerminationReason::Orthogonal => "converged (gradient)".into(),
        TerminationReason::ResidualsZero => "converged (zero residual)".into(),
        TerminationReason::NoImprovementPossible(w) => {
            format!("converged to machine precision ({w})")
        }
        TerminationReason::LostPatience => "not converged: evaluation limit reached".into(),
        other => format!("not converged: {other:?}"),
    }
}

/// The whole outcome of a fit.
#[derive(Debug, Clone)]
pub struct FitOutcome {
    pub label: String,
    pub params: Vec<Parameter>,
    pub best: Vec<f64>,
    /// Distinct optima, best first.
    pub optima: Vec<LocalRun>,
    pub converged: bool,
    pub statistics: super::stats::Statistics,
    pub train: Vec<SeriesFit>,
    pub validate: Vec<SeriesFit>,
    /// RMS and max |residual| on the fitted samples, N.
    pub train_rms: f64,
    pub train_max: f64,
    /// RMS on held-out samples of the training sources, N.
    pub holdout_rms: Option<f64>,
    /// RMS on the validation sources, N.
    pub validate_rms: Option<f64>,
    /// Why the fitted model gives no prediction on the validation sources
    /// (e.g. LuGre's g(v) ≤ 0 beyond the training velocities): an outcome
    /// to report, not an error.
    pub validate_failure: Option<String>,
    pub simulations: usize,
    pub simulation_mean_s: f64,
    pub wall_s: f64,
}

impl FitOutcome {
    /// Held-out RMS: validation sources when given, else the held-out part.
    pub fn held_out_rms(&self) -> Option<f64> {
        self.validate_rms.or(self.holdout_rms)
    }
}

fn pooled(fits: &[SeriesFit], select: impl Fn(&SeriesFit, usize) -> bool) -> Option<(f64, f64)> {
    let (mut ss, mut max, mut n) = (0.0, 0.0f64, 0usize);
    for f in fits {
        if let Some((rms, m, k)) = f.residual_stats(|i| select(f, i)) {
            ss += rms * rms * k as f64;
            max = max.max(m);
            n += k;
        }
    }
    (n > 0).then(|| ((ss / n as f64).sqrt(), max))
}

/// Fit `model` to `data`: global phase, local runs, statistics, the
/// predictions on training and validation data.
pub fn fit(
    model: &dyn Model,
    data: &Data,
    map_fit: Vec<(usize, Parameter)>,
    options: &Options,
) -> Result<FitOutcome, super::FitError> {
    let wall = Instant::now();
    let mut problem = Problem::new(model, data, map_fit)?;
    problem.stop = options.stop.clone();
    let optima = super::search::search(&problem, options);
    options.stop.check()?;
    let best = optima[0].clone();
    let statistics = super::stats::at_optimum(&problem, &best.x);
    let collect = |v: Vec<Result<SeriesFit, String>>| -> Result<Vec<SeriesFit>, super::FitError> {
        v.into_iter()
            .map(|r| {
                r.map_err(|message| super::FitError::Data {
                    what: model.label(),
                    message: format!("no prediction at the optimum: {message}"),
                })
            })
            .collect()
    };
    let train = collect(problem.predict_sources(&best.x, true))?;
    let (validate, validate_failure) = match collect(problem.predict_sources(&best.x, false)) {
        Ok(v) => (v, None),
        Err(e) => (Vec::new(), Some(e.to_string())),
    };
    let (train_rms, train_max) = pooled(&train, |f, i| f.series.fit[i]).unwrap_or((f64::NAN, 0.0));
    let holdout_rms = pooled(&train, |f, i| !f.series.fit[i]).map(|p| p.0);
    let validate_rms = pooled(&validate, |_, _| true).map(|p| p.0);
    let simulations = problem.simulations.load(Ordering::Relaxed);
    let ns = problem.simulation_ns.load(Ordering::Relaxed);
    Ok(FitOutcome {
        label: model.label(),
        params: problem.params.clone(),
        best: best.x.clone(),
        converged: best.converged,
        optima,
        statistics,
        train,
        validate,
        train_rms,
        train_max,
        holdout_rms,
        validate_rms,
        validate_failure,
        simulations,
        simulation_mean_s: ns as f64 / 1e9 / simulations.max(1) as f64,
        wall_s: wall.elapsed().as_secs_f64(),
    })
}
