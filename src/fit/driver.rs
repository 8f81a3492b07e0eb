//! The fit's driver: global phase (`search.rs`), local runs
//! (`local_run.rs`), statistics at the optimum (`stats.rs`), and the
//! predictions and errors on the training and validation data. The problem
//! it solves is `problem.rs`.

use super::data::{Data, Role};
use super::local_run::LocalRun;
use super::options::Options;
use super::problem::{Model, Problem, SeriesFit};
use super::unknowns::FittedParameter;
use std::sync::atomic::Ordering;
use std::time::Instant;

/// The whole outcome of a fit.
#[derive(Debug, Clone)]
pub struct FitOutcome {
    /// The model's name.
    pub label: String,
    /// The data's units.
    pub units: super::Units,
    /// The fitted parameters with their bounds.
    pub params: Vec<FittedParameter>,
    /// The best point, one value per parameter.
    pub best: Vec<f64>,
    /// Distinct optima, best first.
    pub optima: Vec<LocalRun>,
    /// Whether the best local run converged.
    pub converged: bool,
    /// Standard errors, intervals and correlations at the best point.
    pub statistics: super::stats::Statistics,
    /// Cross-validation: each fold's mean squared held-out residual
    /// (`cross_validate.rs`; None until computed).
    pub fold_mse: Option<Vec<f64>>,
    /// The training sources with the prediction.
    pub train: Vec<SeriesFit>,
    /// The held-out parts of the training files with the prediction.
    pub held_out: Vec<SeriesFit>,
    /// The validation sources with the prediction.
    pub validate: Vec<SeriesFit>,
    /// RMS and max |residual| on the fitted samples, N.
    pub train_rms: f64,
    /// Max |residual| on the fitted samples, N.
    pub train_max: f64,
    /// RMS on the held-out parts of the training files, N.
    pub holdout_rms: Option<f64>,
    /// RMS on the validation sources, N.
    pub validate_rms: Option<f64>,
    /// Why the fitted model gives no prediction on the validation sources
    /// or the held-out parts (e.g. LuGre's g(v) ≤ 0 beyond the training
    /// velocities): an outcome to report, not an error.
    pub validate_failure: Option<String>,
    /// Model evaluations (simulations of a source).
    pub simulations: usize,
    /// Of those, the film solves (the others recomposed the friction along
    /// a kept film); None for a model without a film.
    pub film_solves: Option<usize>,
    /// Mean wall time of one, s.
    pub simulation_mean_s: f64,
    /// Wall time of the whole fit, s.
    pub wall_s: f64,
    /// Our model through a gain: the contact's gain and load (None: the
    /// data are the contact's own, or a classic model, fitted in the data's
    /// own units).
    pub contact_scale: Option<super::contact_scale::ContactScale>,
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
    map_fit: Vec<(usize, FittedParameter)>,
    options: &Options,
) -> Result<FitOutcome, super::FitError> {
    let wall = Instant::now();
    let films_before = model.film_solves();
    let mut problem = Problem::new(model, data, map_fit)?;
    problem.stop = options.stop.clone();
    problem.profile_cheap = options.cheap_keys == super::options::CheapKeys::Profiled;
    problem.cheap_ftol = super::profile::INNER_FTOL * options.ftol;
    let separable = if options.linear_keys == super::options::LinearKeys::Solved {
        super::separable::Separable::new(&problem)
    } else {
        None
    };
    let optima = super::multistart::search(&problem, separable.as_ref(), options);
    options.stop.check()?;
    let best = optima[0].clone();
    let statistics = if options.statistics {
        let (r0, jac) = super::stats::jacobian(&problem, &best.x);
        super::stats::from_jacobian(&problem, &best.x, &r0, &jac)
    } else {
        super::stats::Statistics::default()
    };
    let collect = |v: Vec<Result<SeriesFit, super::PredictError>>| -> Result<Vec<SeriesFit>, super::FitError> {
        v.into_iter()
            .map(|r| {
                r.map_err(|message| super::FitError::Data {
                    what: model.label(),
                    message: format!("no prediction at the optimum: {message}"),
                })
            })
            .collect()
    };
    let train = collect(problem.predict_sources(&best.x, Role::Train))?;
    let mut validate_failure = None;
    let mut not_fitted = |role: Role| match collect(problem.predict_sources(&best.x, role)) {
        Ok(v) => v,
        Err(e) => {
            validate_failure.get_or_insert(e.to_string());
            Vec::new()
        }
    };
    let held_out = not_fitted(Role::HeldOut);
    let validate = not_fitted(Role::Validate);
    let (train_rms, train_max) = pooled(&train, |f, i| f.series.fit[i]).unwrap_or((f64::NAN, 0.0));
    let holdout_rms = pooled(&held_out, |_, _| true).map(|p| p.0);
    let validate_rms = pooled(&validate, |_, _| true).map(|p| p.0);
    let simulations = problem.simulations.load(Ordering::Relaxed);
    let ns = problem.simulation_ns.load(Ordering::Relaxed);
    Ok(FitOutcome {
        label: model.label(),
        units: data.units,
        params: problem.params.clone(),
        best: best.x.clone(),
        converged: best.converged,
        optima,
        statistics,
        fold_mse: None,
        train,
        held_out,
        validate,
        train_rms,
        train_max,
        holdout_rms,
        validate_rms,
        validate_failure,
        simulations,
        film_solves: model
            .film_solves()
            .zip(films_before)
            .map(|(after, before)| after - before),
        simulation_mean_s: ns as f64 / 1e9 / simulations.max(1) as f64,
        wall_s: wall.elapsed().as_secs_f64(),
        contact_scale: None,
    })
}

/// An outcome of `train` alone (for tests of what reads outcomes).
#[cfg(test)]
pub(crate) fn tests_outcome(train: Vec<SeriesFit>) -> FitOutcome {
    FitOutcome {
        label: "model".into(),
        units: super::Units::Linear,
        params: Vec::new(),
        best: Vec::new(),
        optima: Vec::new(),
        converged: true,
        statistics: Default::default(),
        fold_mse: None,
        train,
        held_out: Vec::new(),
        validate: Vec::new(),
        train_rms: 0.0,
        train_max: 0.0,
        holdout_rms: None,
        validate_rms: None,
        validate_failure: None,
        simulations: 0,
        film_solves: None,
        simulation_mean_s: 0.0,
        wall_s: 0.0,
        contact_scale: None,
    }
}
