//! Our model and the classic models fitted on the same data with the same
//! optimiser: our fit (its configuration and map coefficients), the
//! classic models' (each also started from the simpler one's optimum).

use super::driver::{fit, FitOutcome};
use super::options::{LabelledProgress, Options, SearchSettings};
use super::prepared::Prepared;
use super::problem::Model;
use super::{Baseline, BaselineKind, FitError, FittedParameter, LoadForm, Source};
use crate::config::Config;
use crate::interrupt::Stop;

/// Our model's fit: the outcome, the fitted configuration and the map
/// coefficients (fitted or fixed) by name.
pub struct OursFitted {
    /// The fit.
    pub outcome: FitOutcome,
    /// The configuration with the fitted values.
    pub config: Config,
    /// Map coefficients by name.
    pub map: Vec<(String, f64)>,
}

/// Fit our model; `cross_validated`: also its error on the folds of the
/// training data (`cross_validate.rs`), the yardstick the classic models
/// are compared on.
pub fn fit_ours(
    p: &Prepared,
    search: &SearchSettings,
    progress: Option<&LabelledProgress>,
    stop: &Stop,
    cross_validated: bool,
) -> Result<OursFitted, FitError> {
    let options = search.options("friction-node", progress, stop);
    let mut outcome = fit(&p.model, &p.data, p.map_fit.clone(), &options)?;
    if cross_validated {
        outcome.fold_mse = Some(fold_errors(p, &p.model, &p.map_fit, &outcome, &options)?);
    }
    outcome.contact_scale = p.contact_scale.clone();
    let n_model = p.model.parameters_len();
    let mut config = p.model.config(&outcome.best[..n_model])?;
    if let Some(l) = &p.contact_scale {
        config = super::contact_scale::on_joint(config, &p.joint, l.gain);
    }
    let mut map = p
        .data
        .map_names
        .iter()
        .cloned()
        .zip(p.data.map_values.iter().copied())
        .collect::<Vec<_>>();
    for (j, (i, _)) in p.map_fit.iter().enumerate() {
        map[*i].1 = outcome.best[n_model + j];
    }
    Ok(OursFitted {
        outcome,
        config,
        map,
    })
}

/// `o`'s error on each fold of `p`'s training data: `model` refitted
/// without it, from `o`'s optimum.
fn fold_errors(
    p: &Prepared,
    model: &dyn Model,
    map_fit: &[(usize, FittedParameter)],
    o: &FitOutcome,
    options: &Options,
) -> Result<Vec<f64>, FitError> {
    let data = p.data.training_only();
    let folds = super::cross_validate::folds_for(&data);
    super::cross_validate::cross_validate(model, &data, map_fit, &o.best, folds, options)
}

/// The optimiser's options for classic model `kind`.
fn baseline_options(
    search: &SearchSettings,
    kind: BaselineKind,
    progress: Option<&LabelledProgress>,
    stop: &Stop,
) -> Options {
    let mut opts = search.options(kind.label(), progress, stop);
    // A classic model costs microseconds per evaluation: give it ten times
    // the budget, so that a non-converged baseline is never the budget's
    // fault.
    opts.max_evaluations = search.max_evaluations.saturating_mul(10);
    // The secant update saves simulations; a classic model costs
    // microseconds, so it keeps the exact Jacobian (whose path the classic
    // models' optima were checked on against SciPy).
    opts.jacobian = super::options::JacobianRule::Differences;
    // For the same reason every later run walks to its end: the valley test
    // saves simulations at the risk of missing a better optimum, a risk the
    // baselines need not take.
    opts.later_runs = super::options::LaterRuns::Full;
    opts
}

/// Fit the classic models with the same optimiser; load-only map
/// coefficients stay at their starts (the load-linear levels absorb them).
/// Returns the outcomes and a note for each model skipped.
pub fn fit_baselines(
    p: &Prepared,
    search: &SearchSettings,
    progress: Option<&LabelledProgress>,
    stop: &Stop,
) -> Result<(Vec<FitOutcome>, Vec<String>), FitError> {
    let load_only: Vec<String> = p
        .data
        .train
        .iter()
        .flat_map(|s| s.load_only_coefficients())
        .collect();
    let map_fit: Vec<(usize, FittedParameter)> = p
        .map_fit
        .iter()
        .filter(|(i, _)| !load_only.contains(&p.data.map_names[*i]))
        .cloned()
        .collect();
    let all_steady = p.data.train.iter().all(Source::is_steady);
    // The training data at the maps' starts: the classic models' starts.
    let series = p
        .data
        .train
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let mut se = s.series(&p.data.map_values)?;
            p.data.holdout.apply(&mut se, i);
            Ok(se)
        })
        .collect::<Result<Vec<_>, FitError>>()?;
    let (mut out, mut skipped) = (Vec::new(), Vec::new());
    let mut previous: Option<(Baseline, FitOutcome)> = None;
    for kind in BaselineKind::ALL {
        if kind == BaselineKind::LuGre && all_steady {
            skipped.push("LuGre skipped: on steady curves it is Stribeck".to_string());
            continue;
        }
        // LuGre's bristle on no coarser a step than our model's film.
        let model = Baseline::from_data(
            kind,
            LoadForm::for_data(p.loads_vary, p.load_given),
            &p.scale,
            p.mean_abs_n,
            &series,
        )
        .with_max_step(p.model_config.solver.dt_s);
        let mut opts = baseline_options(search, kind, progress, stop);
        // Each model contains the one before it: it also starts from that
        // one's optimum, so it never ends worse than the simpler model; and
        // from generic starts that ignore the data (mean level, static
        // level half as high again), in case the data's starts sit in
        // another basin.
        if let Some((inner, o)) = &previous {
            opts.extra_starts = model.nested_starts(inner, &o.best, map_fit.len());
        }
        let generic = Baseline::from_data(
            kind,
            LoadForm::for_data(p.loads_vary, p.load_given),
            &p.scale,
            p.mean_abs_n,
            &[],
        );
        opts.extra_starts.push(
            generic
                .parameters()
                .iter()
                .map(|q| q.start)
                .chain(map_fit.iter().map(|(i, _)| p.data.map_values[*i]))
                .collect(),
        );
        let mut o = fit(&model, &p.data, map_fit.clone(), &opts)?;
        o.fold_mse = Some(fold_errors(p, &model, &map_fit, &o, &opts)?);
        out.push(o.clone());
        previous = Some((model, o));
    }
    Ok((out, skipped))
}
