//! One set of candidate terms tried by `--fit auto`: fitted on the
//! training data (warm-started from the set before it, speed-like keys of
//! a new term also started where the data could bend the curve), then
//! scored by cross-validation, each fold predicted by the set refitted
//! without it.

use super::admission::{bend_unshown, unshown, BENT};
use super::candidates::{set_keys, set_specs, FILM, FILM_KEY};
use super::cross_validate::cross_validate;
use super::data::{Data, Folds};
use super::driver::fit;
use super::options::{Options, SearchSettings};
use super::prepared::{model_for, Prepared};
use super::trial_starts::{film_placements, Starts};
use super::unknowns::ParamSpec;
use super::FitError;

/// One set tried: its candidates, CV error per fold and pooled.
#[derive(Debug, Clone, PartialEq)]
pub struct Tried {
    /// The candidates in the set (besides the base).
    pub terms: Vec<&'static str>,
    /// Held-out mean squared error per fold.
    pub fold_mse: Vec<f64>,
    /// The pooled CV RMS.
    pub cv_rms: f64,
    /// Model evaluations it took.
    pub simulations: usize,
    /// Why the set was not scored (its errors then infinite): not
    /// admitted, or its fit failed.
    pub unscored: Option<&'static str>,
}

/// A candidate set's fit, for warm starts and the report.
pub(super) type Optimum = Vec<(String, f64)>;

/// A set fitted and scored: its report line, its optimum (by name) and
/// what its fit says of each key.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Scored {
    pub(super) tried: Tried,
    pub(super) optimum: Optimum,
    /// What its fit says of each fitted parameter.
    pub(super) flags: Vec<KeyFlag>,
    /// The small-sample Akaike criterion of its fit on all the training
    /// data ([`aicc`]; infinite when it could not be fitted).
    pub(super) aicc: f64,
}

#[cfg(test)]
impl Scored {
    /// A set scored with these fold errors and criterion, for tests of
    /// the rules that read them.
    pub(super) fn with_folds(terms: &[&'static str], fold_mse: &[f64], aicc: f64) -> Self {
        Scored {
            tried: Tried {
                terms: terms.to_vec(),
                fold_mse: fold_mse.to_vec(),
                cv_rms: super::cross_validate::cv_rms(fold_mse),
                simulations: 0,
                unscored: None,
            },
            optimum: Vec::new(),
            flags: Vec::new(),
            aicc,
        }
    }
}

/// How much lower (better) a richer set's small-sample Akaike criterion
/// must be for the whole curve to support it over a simpler one: a
/// difference below 2 is one the data do not resolve (Burnham & Anderson
/// 2002, *Model Selection and Multimodel Inference*, §2.6), and the
/// simpler set is taken (rule 7's start, `classic_shape.rs`; rule 10's
/// terms, `curve_support.rs`).
pub const AICC_SUPPORT: f64 = 2.0;

/// The Akaike difference past which a presumed shape's lighter classic
/// shape has essentially no support (Burnham & Anderson 2002, §2.6: above
/// 10, an evidence ratio e^5 ≈ 150 against it). Below it, a presumed
/// shape whose keys the data cannot separate (rule 4's flag) gives way to
/// its lighter shape when that predicts the folds no worse
/// (`removal.rs`): the flag, the folds and the criterion all leave the
/// richer shape's extra keys in doubt.
pub const AICC_DECISIVE: f64 = 10.0;

/// The small-sample Akaike information criterion (Hurvich & Tsai 1989) of
/// a least-squares fit of `k` parameters to `n` samples with residual
/// sum of squares n·rms²: n ln(rms²) + 2k + 2k(k+1)/(n−k−1). `k` counts
/// the fitted parameters, not the noise variance beside them (Hurvich &
/// Tsai count both): counting σ² too penalises the Stribeck curve more,
/// and on 96 random joints (`docs/fit-auto-judged.md`, "steady curves") that lost more (a
/// rise started from the viscous rise predicted 14× worse); +∞ when
/// n ≤ k + 1 or the fit failed, −∞ for an exact fit. Lower is better; it estimates the fit's error on new
/// samples of the same kind (asymptotically leave-one-out
/// cross-validation, Stone 1977) from all the samples at once.
pub(super) fn aicc(rms: f64, n: usize, k: usize) -> f64 {
    if n <= k + 1 || !rms.is_finite() || rms < 0.0 {
        return f64::INFINITY;
    }
    if rms == 0.0 {
        // An exact fit: nothing is better.
        return f64::NEG_INFINITY;
    }
    let (n, k) = (n as f64, k as f64);
    n * (rms * rms).ln() + 2.0 * k + 2.0 * k * (k + 1.0) / (n - k - 1.0)
}

/// What a set's fit says of one fitted parameter: whether it ended at a
/// bound or at zero, and the parameter it correlates with most.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct KeyFlag {
    /// The parameter.
    pub(super) name: String,
    /// At a bound or at zero.
    pub(super) edge: bool,
    /// The largest |correlation| with another parameter (1 where it is
    /// undefined).
    pub(super) rho: f64,
    /// That other parameter.
    pub(super) partner: Option<String>,
}

/// What a selection's fits share: the data, the settings, the names given.
pub(super) struct Ctx<'a> {
    pub(super) p: &'a Prepared,
    pub(super) data: Data,
    pub(super) folds: Folds,
    pub(super) search: &'a SearchSettings,
    pub(super) stop: &'a crate::interrupt::Stop,
    pub(super) given: &'a [ParamSpec],
    /// The terms presumed (`select.rs`, rule 7): they leave the set only
    /// when the set without them predicts the folds better, by the rule a
    /// term must meet to enter.
    pub(super) presumed: std::sync::OnceLock<Vec<&'static str>>,
    /// The starts of a set's fit besides its warm start.
    pub(super) starts: Starts<'a>,
    /// Every set scored so far, by its terms in catalogue order: a set
    /// that the removal or the flag checks come back to is the same
    /// problem on the same folds, and is not fitted again.
    pub(super) scored: std::sync::Mutex<Vec<Scored>>,
    /// Why sets were not admitted (rule 9: a term that grows without end
    /// whose coefficient their fit could not tell from zero).
    pub(super) not_admitted: std::sync::Mutex<Vec<String>>,
}

impl<'a> Ctx<'a> {
    /// A selection's shared state on `p`'s training data, cut into the
    /// folds that suit them (`cross_validate::folds_for`).
    pub(super) fn new(
        p: &'a Prepared,
        search: &'a SearchSettings,
        given: &'a [ParamSpec],
        stop: &'a crate::interrupt::Stop,
    ) -> Self {
        let data = p.data.training_only();
        let folds = super::cross_validate::folds_for(&data);
        Ctx {
            p,
            data,
            folds,
            search,
            stop,
            given,
            presumed: std::sync::OnceLock::new(),
            starts: Starts::new(p),
            scored: std::sync::Mutex::new(Vec::new()),
            not_admitted: std::sync::Mutex::new(Vec::new()),
        }
    }
}

/// The parameter specs of the chosen set `terms` for the final fit: each
/// key in its own range, the viscosity's too. Under a scale chosen from
/// the data that range keeps the film's transition at least 100× above the
/// data's top speed, so a film that a trial placed inside the data is not
/// shipped there: the final fit ends with the film where the data cannot
/// see it, and the confirmation (`confirm.rs`) drops it unless it still
/// pays. A transition placed inside the data by its trial was measured to
/// predict past the data badly: on a joint's Stribeck curve fitted at
/// 0.5–20 deg/s and predicted at 25–90 deg/s, 0.092 N·m against the
/// Stribeck curve's 0.014 (past the data the film bends the curve 2.5 %
/// below the measured rise).
pub(super) fn final_specs(given: &[ParamSpec], terms: &[&'static str]) -> Vec<ParamSpec> {
    set_specs(given, &set_keys(terms))
}

/// Set `p`'s model to the final fit's of the set `terms` ([`final_specs`]),
/// started from `optimum` (the set's in the selection).
pub(super) fn set_final_model(
    p: &mut Prepared,
    given: &[ParamSpec],
    terms: &[&'static str],
    optimum: &Optimum,
) -> Result<(), FitError> {
    let (model, map_fit) = model_for(p, &final_specs(given, terms), optimum)?;
    p.model = model;
    p.map_fit = map_fit;
    Ok(())
}

/// The parameter specs of the set `terms` for its trial: the keys of
/// `given` as given; with the film placed inside the data
/// ([`film_placements`]) the viscosity key's bounds wide enough for every
/// placement, unless given.
fn set_specs_for(p: &Prepared, given: &[ParamSpec], terms: &[&'static str]) -> Vec<ParamSpec> {
    let mut specs = set_specs(given, &set_keys(terms));
    if terms.contains(&FILM) && !film_placements(p).is_empty() {
        if let Some(s) = specs
            .iter_mut()
            .find(|s| s.name == FILM_KEY && s.bounds.is_none())
        {
            let mu0 = p.model_config.lubricant.viscosity_pa_s;
            s.bounds = Some((mu0 / 10.0, 100.0));
        }
    }
    specs
}

impl Ctx<'_> {
    /// Fit the set `terms` on the training data, warm-started from `warm`,
    /// and score it by cross-validation (each fold refitted without it).
    pub(super) fn try_set(
        &self,
        terms: &[&'static str],
        warm: &Optimum,
    ) -> Result<Scored, FitError> {
        let lock = || self.scored.lock().unwrap_or_else(|p| p.into_inner());
        let same = |t: &Scored| {
            t.tried.terms.len() == terms.len() && terms.iter().all(|x| t.tried.terms.contains(x))
        };
        if let Some(known) = lock().iter().find(|t| same(t)) {
            // In the order asked (the last term is the one just added).
            let mut known = known.clone();
            known.tried.terms = terms.to_vec();
            return Ok(known);
        }
        let scored = self.score_set(terms, warm)?;
        // A set scored as a smaller one (rule 9b) was cached as that one.
        if same(&scored) {
            lock().push(scored.clone());
        }
        Ok(scored)
    }

    /// The set's parameter specs ([`set_specs_for`]) and the film's
    /// placements.
    fn specs_and_placements(&self, terms: &[&'static str]) -> (Vec<ParamSpec>, Vec<f64>) {
        let placements = if terms.contains(&FILM) {
            film_placements(self.p)
        } else {
            Vec::new()
        };
        (set_specs_for(self.p, self.given, terms), placements)
    }

    /// A set the fit could not fit: scored as predicting nothing.
    fn unfitted(&self, terms: &[&'static str], why: &'static str) -> Scored {
        Scored {
            tried: Tried {
                terms: terms.to_vec(),
                fold_mse: vec![f64::INFINITY; self.folds.count()],
                cv_rms: f64::INFINITY,
                simulations: 0,
                unscored: Some(why),
            },
            optimum: Vec::new(),
            flags: Vec::new(),
            aicc: f64::INFINITY,
        }
    }

    /// [`Ctx::try_set`]'s fit and score of a set not scored before.
    fn score_set(&self, terms: &[&'static str], warm: &Optimum) -> Result<Scored, FitError> {
        let (specs, placements) = self.specs_and_placements(terms);
        let (model, map_fit) = model_for(self.p, &specs, warm)?;
        let mut options = Options {
            starts: 1,
            global_points: 0,
            max_evaluations: self.search.max_evaluations,
            stop: self.stop.clone(),
            jacobian: self.search.jacobian,
            linear_keys: self.search.linear_keys,
            cheap_keys: self.search.cheap_keys,
            // The selection compares sets at the percent level: a looser
            // convergence than the final fit's.
            ftol: 1e-6,
            xtol: 1e-5,
            ..Default::default()
        };
        options.extra_starts = self
            .starts
            .extra(&model, &map_fit, terms, warm, &placements);
        options
            .extra_starts
            .extend(self.starts.own(&specs, &model, &map_fit, warm)?);
        let fitted = match fit(&model, &self.data, map_fit.clone(), &options) {
            Ok(o) => o,
            Err(FitError::Interrupted(i)) => return Err(FitError::Interrupted(i)),
            Err(_) => return Ok(self.unfitted(terms, "its fit failed")),
        };
        let not_admitted = |why: String| {
            self.not_admitted
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .push(why)
        };
        // Rules 9, 9b and 9c: a term the set's fit does not show (a
        // quadratic or bend told from the straight rise, the rate's bend
        // inside the data) is refused when it is the one entering; one
        // chosen before gives way to the newcomer that left it unshown.
        // Nothing requires such a term, so the rest is a set.
        let unshown_term = unshown(terms, &fitted).or_else(|| {
            bend_unshown(terms, &fitted, self.p.model_scale.velocity_m_s).map(|why| (BENT, why))
        });
        if let Some((term, why)) = unshown_term {
            if terms.last() == Some(&term) {
                not_admitted(why);
                return Ok(self.unfitted(terms, "not admitted (below)"));
            }
            not_admitted(format!("{why}; the set is tried without it"));
            let rest: Vec<&'static str> = terms.iter().copied().filter(|t| *t != term).collect();
            return self.try_set(&rest, &optimum_of(&fitted));
        }
        let fold_mse = cross_validate(
            &model,
            &self.data,
            &map_fit,
            &fitted.best,
            self.folds,
            &options,
        )?;
        let cv_rms = super::cross_validate::cv_rms(&fold_mse);
        let flags = flags_of(&fitted);
        let samples = fitted
            .train
            .iter()
            .map(|f| f.series.fit.iter().filter(|b| **b).count())
            .sum();
        let aicc = aicc(fitted.train_rms, samples, fitted.best.len());
        Ok(Scored {
            tried: Tried {
                terms: terms.to_vec(),
                fold_mse,
                cv_rms,
                simulations: model.film_solves(),
                unscored: None,
            },
            optimum: optimum_of(&fitted),
            flags,
            aicc,
        })
    }
}

/// The fitted keys of `o` and their values.
fn optimum_of(o: &super::driver::FitOutcome) -> Optimum {
    o.params
        .iter()
        .map(|q| q.name.clone())
        .zip(o.best.iter().copied())
        .collect()
}

/// Per fitted parameter of `o`: its name, whether it ended at a bound or
/// at zero, and its largest |correlation| with another parameter.
pub(super) fn flags_of(o: &super::driver::FitOutcome) -> Vec<KeyFlag> {
    let st = &o.statistics;
    o.params
        .iter()
        .enumerate()
        .map(|(j, q)| {
            let at_bound = st.at_bound.get(j).copied().unwrap_or(false);
            let zero = o.best[j] == 0.0;
            let (partner, rho) = st
                .correlation
                .get(j)
                .and_then(|row| {
                    row.iter()
                        .enumerate()
                        .filter(|(i, _)| *i != j)
                        .map(|(i, r)| (i, if r.is_nan() { 1.0 } else { r.abs() }))
                        .max_by(|a, b| a.1.total_cmp(&b.1))
                })
                .map_or((None, 0.0), |(i, r)| {
                    (o.params.get(i).map(|p| p.name.clone()), r)
                });
            KeyFlag {
                name: q.name.clone(),
                edge: at_bound || zero,
                rho,
                partner,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::aicc;
    use approx::assert_relative_eq;

    use super::super::prepared::Prepared;
    use super::super::unknowns::ParamSpec;

    /// `--fit auto` prepared on a rising curve swept both ways, friction
    /// 20 N + 400 N·s/m v (a Coulomb level and a viscous rise), and the
    /// names given after `auto`.
    fn prepared_on_a_rising_curve(tag: &str) -> (Prepared, Vec<ParamSpec>) {
        use super::super::candidates::{initial_specs, AUTO};
        use super::super::inputs::DataRequest;
        let d = std::env::temp_dir().join(format!("fn-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let csv = d.join("curve.csv");
        let mut text = String::from("t_s,velocity_m_s,friction_n\n");
        for k in 0..400 {
            let t = k as f64 * 0.01;
            let v = 0.05 * (1.5 * t).sin();
            text += &format!("{t},{v},{}\n", 20.0 * (v / 1e-3).tanh() + 400.0 * v);
        }
        std::fs::write(&csv, text).unwrap();
        let req = DataRequest {
            files: vec![csv],
            ..Default::default()
        };
        let auto = ParamSpec {
            name: AUTO.into(),
            bounds: None,
            start: None,
            if_chosen: false,
        };
        let (_, given, specs) = initial_specs(&[auto]);
        let config = crate::config::Config::default();
        let p = super::super::prepare::prepare(&config, &req, &specs, true).unwrap();
        std::fs::remove_dir_all(&d).unwrap();
        (p, given)
    }

    #[test]
    fn a_set_reached_by_taking_a_term_away_is_also_started_where_it_would_be_fitted_alone() {
        use super::super::candidates::{BASE_KEY, STRIBECK};
        use super::super::prepared::model_for;
        use super::super::problem::Model;
        use super::super::trial_starts::{STRIBECK_AMPLITUDE_KEY, STRIBECK_SPEED_KEY};
        use super::{set_specs_for, Ctx};
        let (p, given) = prepared_on_a_rising_curve("own-starts");
        let search = super::super::options::SearchSettings::default();
        let stop = crate::interrupt::Stop::new();
        let ctx = Ctx::new(&p, &search, &given, &stop);
        let set = [STRIBECK];
        let specs = set_specs_for(&p, &given, &set);
        // The Stribeck curve's optimum beside a boundary rate that carried
        // the rise: a peak, the base at its lower end.
        let mut warm: Vec<(String, f64)> = vec![
            (BASE_KEY.into(), 0.03),
            (STRIBECK_AMPLITUDE_KEY.into(), 50.0),
            (STRIBECK_SPEED_KEY.into(), 1e-3),
            ("drivetrain.viscous_n_s_m".into(), 0.0),
        ];
        let (model, map_fit) = model_for(&p, &specs, &warm).unwrap();
        // Reached by adding to a set it holds: its warm start is its own.
        let own = ctx.starts.own(&specs, &model, &map_fit, &warm).unwrap();
        assert!(own.is_empty(), "{own:?}");
        // Reached by taking the boundary rate away: also started alone.
        warm.push(("contact.boundary_friction_rate".into(), 0.2));
        let own = ctx.starts.own(&specs, &model, &map_fit, &warm).unwrap();
        let (cold, _) = model_for(&p, &specs, &[]).unwrap();
        let configured: Vec<f64> = cold.parameters().iter().map(|q| q.start).collect();
        let warmed: Vec<f64> = model.parameters().iter().map(|q| q.start).collect();
        assert_ne!(configured, warmed, "the two starts differ");
        assert!(own.contains(&configured), "{own:?} lacks {configured:?}");
        // With the Stribeck curve at its classic starts (a curve fitted to
        // the data by variable projection), not at the warm peak.
        let at = |k: &str| cold.parameters().iter().position(|q| q.name == k).unwrap();
        let (speed, amplitude) = (at(STRIBECK_SPEED_KEY), at(STRIBECK_AMPLITUDE_KEY));
        assert!(own.len() > 1, "{own:?}");
        assert!(own.iter().any(|x| x[amplitude] != configured[amplitude]
            && x[speed] != configured[speed]
            && x[amplitude] != 50.0));
    }

    #[test]
    fn a_rate_whose_bend_a_newcomer_leaves_unshown_gives_way_and_one_entering_so_is_refused() {
        use super::super::admission::BENT;
        use super::Ctx;
        const VISCOUS: &str = "drivetrain viscous";
        // The viscous rise is the data's own; beside it a boundary rate has
        // no bend to show.
        let (p, given) = prepared_on_a_rising_curve("bend");
        let search = super::super::options::SearchSettings::default();
        let stop = crate::interrupt::Stop::new();
        let ctx = Ctx::new(&p, &search, &given, &stop);
        // The viscous rise added to a set holding the rate: the set is
        // tried without the rate, and the report says so.
        let displaced = ctx.try_set(&[BENT, VISCOUS], &Vec::new()).unwrap();
        assert_eq!(displaced.tried.terms, vec![VISCOUS]);
        assert_eq!(displaced.tried.unscored, None);
        let alone = ctx.try_set(&[VISCOUS], &Vec::new()).unwrap();
        assert_eq!(alone.tried.fold_mse, displaced.tried.fold_mse);
        // The rate added to a set holding the viscous rise: refused.
        let entering = ctx.try_set(&[VISCOUS, BENT], &Vec::new()).unwrap();
        assert_eq!(entering.tried.terms, vec![VISCOUS, BENT]);
        assert_eq!(entering.tried.unscored, Some("not admitted (below)"));
        assert_eq!(entering.tried.cv_rms, f64::INFINITY);
        let said = ctx.not_admitted.lock().unwrap().clone();
        assert_eq!(said.len(), 2, "{said:?}");
        assert!(said[0].starts_with("boundary rate beside drivetrain viscous: its fit places `contact.boundary_activation_speed_m_s`"), "{said:?}");
        assert!(
            said[0].ends_with("a bend the data do not show; the set is tried without it"),
            "{said:?}"
        );
        assert!(said[1].ends_with("a bend the data do not show"), "{said:?}");
    }

    #[test]
    fn the_small_sample_akaike_criterion_is_n_ln_mse_plus_its_corrected_penalty() {
        // n = 20, k = 4, rms 0.1: 20 ln 0.01 + 8 + 40/15.
        assert_relative_eq!(
            aicc(0.1, 20, 4),
            20.0 * 0.01f64.ln() + 8.0 + 40.0 / 15.0,
            max_relative = 1e-12
        );
        // Two extra parameters must lower the mean square by more than
        // their penalty: at n = 20 a 2-key fit at rms 0.1 (−87.4) beats a
        // 4-key fit at rms 0.09 (−85.7), not one at 0.08 (−90.4).
        assert!(aicc(0.1, 20, 2) < aicc(0.09, 20, 4));
        assert!(aicc(0.1, 20, 2) > aicc(0.08, 20, 4));
        // No degrees of freedom left or no fit: +∞; an exact fit: −∞.
        assert_eq!(aicc(0.1, 5, 4), f64::INFINITY);
        assert_eq!(aicc(f64::NAN, 20, 2), f64::INFINITY);
        assert_eq!(aicc(0.0, 20, 2), f64::NEG_INFINITY);
    }
}
