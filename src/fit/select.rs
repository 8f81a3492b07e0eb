//! `fit --fit auto`: the data choose the physical terms.
//!
//! **Candidates** ([`CANDIDATES`]) are the terms a recording can show,
//! each a group of configuration keys: the film (viscosity), the boundary
//! film's rate sensitivity, pre-sliding stiffness and damping, and the
//! drivetrain's Coulomb, viscous, quadratic, asymmetry and load terms. The
//! boundary friction (the contact's sliding level) is always fitted, and so
//! is every name given after `auto` (`--fit auto,a_eff,f_off`).
//!
//! **Rule** (one for every data set; the `--validate` data are never seen):
//! 1. Blocked cross-validation: each training time series is cut into
//!    [`FOLDS`] contiguous blocks (a steady curve into interleaved point
//!    sets); block b is predicted by the parameters refitted without it.
//!    The refit is one Gauss–Newton step from the set's optimum on all
//!    the training data ([`super::stats::block_cv`]: exact for a model
//!    linear in its parameters, the usual approximate cross-validation for
//!    a nonlinear one), so a set costs one fit and one Jacobian instead of
//!    one fit per block. A set's CV error is the RMS of all blocks'
//!    held-out residuals. Contiguous blocks keep the residuals' correlation
//!    in time out of the score: a term is judged on motion it was not
//!    fitted to.
//! 2. Forward selection: each step fits every candidate not yet chosen
//!    (whose prerequisite is chosen), warm-started from the current set's
//!    optimum with the new keys at their starts, and keeps the candidate
//!    with the lowest CV error.
//! 3. The cost of a term: it is kept only if it lowers the CV mean squared
//!    error by more than [`TERM_COST`] (1 %) of it **and** by more than
//!    the standard error of that lowering over the blocks (the
//!    one-standard-error rule, on the blocks' paired differences). A term
//!    must pay for itself beyond what the blocks' spread could give by
//!    chance, and by a margin that matters; otherwise the selection stops.
//! 4. The chosen set is fitted on all the training data with the usual
//!    search (global phase, local runs).
//!
//! The report lists every set tried with its CV error per fold, the set
//! chosen and why the selection stopped.

use super::driver::fit;
use super::options::Options;
use super::options::SearchSettings;
use super::prepared::{model_for, Prepared};
use super::problem::Data;
use super::unknowns::ParamSpec;
use super::FitError;
use rayon::prelude::*;
use std::fmt::Write as _;

/// The word in `--fit` that asks for the selection.
pub const AUTO: &str = "auto";

/// Blocks of the blocked cross-validation.
pub const FOLDS: usize = 4;

/// The cost of a term: the smallest fraction of the cross-validated mean
/// squared error it must remove to be kept (1 %: about half a percent of
/// the RMS). Below it, a term fits the data's fine structure — a noise
/// floor's texture, a systematic residue of another effect — consistently
/// enough to beat the blocks' spread while predicting no better in any
/// sense a controller would notice.
pub const TERM_COST: f64 = 0.01;

/// A term the selection may add.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Its name in the report.
    pub name: &'static str,
    /// The keys it fits.
    pub keys: &'static [&'static str],
    /// A candidate that must be chosen first.
    pub requires: Option<&'static str>,
    /// Only when the training loads vary.
    pub needs_varying_load: bool,
}

/// The candidate terms, in the order they are tried.
pub const CANDIDATES: &[Candidate] = &[
    Candidate {
        name: "film",
        keys: &["lubricant.viscosity_pa_s"],
        requires: None,
        needs_varying_load: false,
    },
    Candidate {
        name: "boundary rate",
        keys: &[
            "contact.boundary_friction_rate",
            "contact.boundary_activation_speed_m_s",
        ],
        requires: None,
        needs_varying_load: false,
    },
    Candidate {
        name: "pre-sliding",
        keys: &["contact.presliding_stiffness_n_m"],
        requires: None,
        needs_varying_load: false,
    },
    Candidate {
        name: "pre-sliding damping",
        keys: &["contact.presliding_damping_n_s_m"],
        requires: Some("pre-sliding"),
        needs_varying_load: false,
    },
    Candidate {
        name: "drivetrain Coulomb",
        keys: &["drivetrain.coulomb_n"],
        requires: None,
        needs_varying_load: false,
    },
    Candidate {
        name: "drivetrain viscous",
        keys: &["drivetrain.viscous_n_s_m"],
        requires: None,
        needs_varying_load: false,
    },
    Candidate {
        name: "drivetrain quadratic",
        keys: &["drivetrain.quadratic_n_s2_m2"],
        requires: None,
        needs_varying_load: false,
    },
    Candidate {
        name: "drivetrain asymmetry",
        keys: &["drivetrain.coulomb_asymmetry_n"],
        requires: None,
        needs_varying_load: false,
    },
    Candidate {
        name: "drivetrain load",
        keys: &["drivetrain.load_coefficient"],
        requires: None,
        needs_varying_load: true,
    },
];

/// The keys of the catalogue that are not candidates, and why.
pub const NOT_CANDIDATES: &[(&str, &str)] = &[
    (
        "contact.boundary_friction",
        "always fitted: the contact's sliding level",
    ),
    (
        "contact.sign_regularization_m_s",
        "a numerical device, not a property of the contact",
    ),
    (
        "contact.width_load_exponent",
        "the contact's material (rigid or soft): set in the configuration",
    ),
    (
        "contact.width_reference_load_n",
        "the contact's material (rigid or soft): set in the configuration",
    ),
];

/// The key always fitted.
pub const BASE_KEY: &str = "contact.boundary_friction";

/// Whether the selection may fit configuration key `key` (the base key,
/// or a key of a candidate): a bound or start on it is accepted under
/// `--fit auto`, and used if its term is chosen.
pub fn may_choose(key: &str) -> bool {
    key == BASE_KEY || CANDIDATES.iter().any(|c| c.keys.contains(&key))
}

/// Every key the selection may fit, the base key first.
pub fn choosable_keys() -> Vec<&'static str> {
    std::iter::once(BASE_KEY)
        .chain(CANDIDATES.iter().flat_map(|c| c.keys.iter().copied()))
        .collect()
}

/// Whether `--fit` asks for the selection; the names besides `auto`.
pub fn split(keys: &[String]) -> (bool, Vec<String>) {
    let auto = keys.iter().any(|k| k.trim() == AUTO);
    (
        auto,
        keys.iter().filter(|k| k.trim() != AUTO).cloned().collect(),
    )
}

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
}

/// The outcome of the selection.
#[derive(Debug, Clone, PartialEq)]
pub struct Selection {
    /// Every set tried, in order.
    pub tried: Vec<Tried>,
    /// Candidates left out on these data, each with why.
    pub excluded: Vec<String>,
    /// The chosen candidates.
    pub chosen: Vec<&'static str>,
    /// The keys to fit: the base, the chosen candidates', the names given.
    pub keys: Vec<String>,
    /// Why the selection stopped.
    pub why: String,
    /// Wall time, s.
    pub wall_s: f64,
}

/// The training data alone (neither the held-out parts nor the
/// --validate data are even predicted).
fn training_data(p: &Prepared) -> Data {
    p.data.training_only()
}

/// The specs of a set: the set's keys, then the given names' specs (a
/// given spec replaces a key's default one; a spec given only in case its
/// term is chosen, [`ParamSpec::if_chosen`], is used only then).
pub fn set_specs(given: &[ParamSpec], keys: &[&str]) -> Vec<ParamSpec> {
    let mut specs: Vec<ParamSpec> = keys
        .iter()
        .map(|k| ParamSpec {
            name: k.to_string(),
            ..Default::default()
        })
        .collect();
    for g in given {
        if let Some(s) = specs.iter_mut().find(|s| s.name == g.name) {
            *s = ParamSpec {
                if_chosen: false,
                ..g.clone()
            };
        } else if !g.if_chosen {
            specs.push(g.clone());
        }
    }
    specs
}

/// The keys of a set of candidates, the base key first.
fn set_keys(terms: &[&'static str]) -> Vec<&'static str> {
    let mut keys = vec![BASE_KEY];
    for t in terms {
        if let Some(c) = CANDIDATES.iter().find(|c| c.name == *t) {
            keys.extend(c.keys);
        }
    }
    keys
}

/// A candidate set's fit, for warm starts and the report.
type Optimum = Vec<(String, f64)>;

/// Fit the set `terms` on the training data, warm-started from `warm`,
/// and score it by one-step blocked cross-validation.
fn try_set(
    p: &Prepared,
    data: &Data,
    search: &SearchSettings,
    stop: &crate::interrupt::Stop,
    given: &[ParamSpec],
    terms: &[&'static str],
    warm: &Optimum,
) -> Result<(Tried, Optimum), FitError> {
    let specs = set_specs(given, &set_keys(terms));
    let (model, map_fit) = model_for(p, &specs, warm)?;
    let options = Options {
        starts: 1,
        global_points: 0,
        max_evaluations: search.max_evaluations,
        stop: stop.clone(),
        jacobian: search.jacobian,
        // The selection compares sets at the percent level: a looser
        // convergence than the final fit's.
        ftol: 1e-6,
        xtol: 1e-5,
        cv_blocks: FOLDS,
        ..Default::default()
    };
    let (fold_mse, simulations, optimum) = match fit(&model, data, map_fit, &options) {
        Ok(o) => (
            o.block_mse.clone().unwrap_or_default(),
            o.simulations,
            o.params
                .iter()
                .map(|q| q.name.clone())
                .zip(o.best.iter().copied())
                .collect(),
        ),
        Err(FitError::Interrupted(i)) => return Err(FitError::Interrupted(i)),
        Err(_) => (vec![f64::INFINITY; FOLDS], 0, Vec::new()),
    };
    let cv_rms = (fold_mse.iter().sum::<f64>() / fold_mse.len().max(1) as f64).sqrt();
    Ok((
        Tried {
            terms: terms.to_vec(),
            fold_mse,
            cv_rms,
            simulations,
        },
        optimum,
    ))
}

/// Mean and standard error of the folds' paired differences a − b.
fn paired(a: &[f64], b: &[f64]) -> (f64, f64) {
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    let n = d.len() as f64;
    let mean = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, (var / n).sqrt())
}

/// The candidates on `p`'s data: those whose keys can be set up (a
/// candidate without bounds to derive, pre-sliding without a reversal, is
/// not one here, and is returned with why), that the loads allow and that
/// no given name already fits.
fn candidates_here(p: &Prepared, given: &[ParamSpec]) -> (Vec<&'static Candidate>, Vec<String>) {
    let mut excluded: Vec<String> = Vec::new();
    let mut candidates = Vec::new();
    let no_reversal = p.scale.reversal_stiffness_n_m.is_none();
    for c in CANDIDATES {
        if c.needs_varying_load && !p.loads_vary {
            continue;
        }
        // A name given to --fit already fits it (a bound or start given in
        // case it is chosen does not).
        let fitted = |k: &&str| given.iter().any(|g| g.name == *k && !g.if_chosen);
        if c.keys.iter().any(fitted) {
            continue;
        }
        if no_reversal && c.keys.iter().any(|k| k.contains("presliding_")) {
            excluded.push(format!(
                "{}: the data hold no velocity reversal, and pre-sliding shows only through one",
                c.name
            ));
            continue;
        }
        let keys: Vec<&str> = std::iter::once(BASE_KEY)
            .chain(c.keys.iter().copied())
            .collect();
        match model_for(p, &set_specs(given, &keys), &[]) {
            Ok(_) => candidates.push(c),
            Err(e) => excluded.push(format!("{}: {e}", c.name)),
        }
    }
    (candidates, excluded)
}

/// Choose the terms (see the module's rule). `given` are the specs of the
/// names after `auto`; `say` receives a line per set tried.
pub fn select(
    p: &Prepared,
    search: &SearchSettings,
    given: &[ParamSpec],
    say: &(dyn Fn(&str) + Sync),
    stop: &crate::interrupt::Stop,
) -> Result<Selection, FitError> {
    let wall = std::time::Instant::now();
    let (candidates, excluded) = candidates_here(p, given);
    for e in &excluded {
        say(&format!("auto: not a candidate on these data: {e}"));
    }
    let data = training_data(p);
    let (base, mut warm) = try_set(p, &data, search, stop, given, &[], &Vec::new())?;
    say(&format!(
        "auto: base (boundary friction): CV RMS {}",
        cv(&base, p)
    ));
    let mut tried = vec![base.clone()];
    let mut current = base;
    let why = loop {
        let open: Vec<&&Candidate> = candidates
            .iter()
            .filter(|c| !current.terms.contains(&c.name))
            .filter(|c| c.requires.is_none_or(|r| current.terms.contains(&r)))
            .collect();
        if open.is_empty() {
            break "every candidate was chosen".to_string();
        }
        // The candidates of a step side by side (each fit is serial in
        // its secant phase).
        let step: Vec<(Tried, Optimum)> = open
            .par_iter()
            .map(|c| {
                let mut terms = current.terms.clone();
                terms.push(c.name);
                let (t, o) = try_set(p, &data, search, stop, given, &terms, &warm)?;
                say(&format!("auto: + {}: CV RMS {}", c.name, cv(&t, p)));
                Ok((t, o))
            })
            .collect::<Result<_, FitError>>()?;
        tried.extend(step.iter().map(|(t, _)| t.clone()));
        let (best, optima) = step
            .into_iter()
            .min_by(|a, b| a.0.cv_rms.total_cmp(&b.0.cv_rms))
            .expect("a candidate was open");
        let (gain, se) = paired(&current.fold_mse, &best.fold_mse);
        let name = best.terms.last().copied().unwrap_or_default();
        let mse = current.cv_rms * current.cv_rms;
        if !(gain.is_finite() && gain > se && gain > TERM_COST * mse) {
            break format!(
                "the best next term, {name}, lowers the blocks' mean squared error by {} ± {} (standard error), {:.2} % of it: a term must lower it by more than its standard error and by more than {:.0} % (the cost of a term), so it does not pay for itself",
                crate::text::Num::sig(gain, 5),
                crate::text::Num::sig(se, 5),
                100.0 * gain / mse,
                100.0 * TERM_COST
            );
        }
        current = best;
        warm = optima;
    };
    let keys = set_keys(&current.terms)
        .into_iter()
        .map(String::from)
        .chain(
            given
                .iter()
                .filter(|g| !g.if_chosen)
                .map(|g| g.name.clone()),
        )
        .fold(Vec::<String>::new(), |mut v, k| {
            if !v.contains(&k) {
                v.push(k);
            }
            v
        });
    Ok(Selection {
        tried,
        excluded,
        chosen: current.terms,
        keys,
        why,
        wall_s: wall.elapsed().as_secs_f64(),
    })
}

fn cv(t: &Tried, p: &Prepared) -> String {
    format!(
        "{} {}",
        crate::text::Num::sig(t.cv_rms, 5),
        p.data.units.force()
    )
}

/// The selection as a markdown section.
pub fn report(s: &Selection, units: super::Units) -> String {
    let u = units.force();
    let mut md = format!(
        "## Terms chosen by the data (`--fit auto`)\n\nRule: forward selection on blocked cross-validation of the training data ({FOLDS} contiguous time blocks per record, each predicted by the parameters refitted without it in one Gauss–Newton step); a term is kept only if it lowers the blocks' mean squared error by more than the standard error of that lowering and by more than {:.0} % of it (the cost of a term). The --validate data are not used.\n\n| set (boundary friction +) | CV RMS ({u}) | RMS per block ({u}) | simulations |\n|---|---|---|---|\n",
        100.0 * TERM_COST
    );
    for t in &s.tried {
        let folds: Vec<String> = t
            .fold_mse
            .iter()
            .map(|m| crate::text::Num::sig(m.sqrt(), 5).to_string())
            .collect();
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} |",
            if t.terms.is_empty() {
                "—".to_string()
            } else {
                t.terms.join(", ")
            },
            crate::text::Num::sig(t.cv_rms, 5),
            folds.join(" / "),
            t.simulations
        );
    }
    for e in &s.excluded {
        let _ = writeln!(md, "\nNot a candidate on these data: {e}");
    }
    let _ = write!(
        md,
        "\nChosen: boundary friction{}. Stopped: {}. Keys fitted: {}. Selection took {:.1} s.\n",
        s.chosen
            .iter()
            .map(|c| format!(", {c}"))
            .collect::<String>(),
        s.why,
        s.keys.join(", "),
        s.wall_s
    );
    md
}

/// `--fit` as `auto`, the names given besides it, and the specs our model
/// starts with (with `auto`: the base key first; the selection chooses the
/// rest).
pub fn initial_specs(params: &[ParamSpec]) -> (bool, Vec<ParamSpec>, Vec<ParamSpec>) {
    let auto = params.iter().any(|s| s.name == AUTO);
    let given: Vec<ParamSpec> = params.iter().filter(|s| s.name != AUTO).cloned().collect();
    // A bound or start given in case its term is chosen fits nothing yet
    // (the base key's applies at once: it is always fitted).
    let mut specs: Vec<ParamSpec> = given
        .iter()
        .filter(|s| !s.if_chosen || s.name == BASE_KEY)
        .map(|s| ParamSpec {
            if_chosen: false,
            ..s.clone()
        })
        .collect();
    if auto && !specs.iter().any(|s| s.name == BASE_KEY) {
        specs.insert(
            0,
            ParamSpec {
                name: BASE_KEY.into(),
                ..Default::default()
            },
        );
    }
    (auto, given, specs)
}

/// `--fit auto`: choose the terms (see the module's rule) and set `p`'s
/// model to the chosen keys; `given` are the names after `auto`; `say`
/// receives a line per set tried.
pub fn select_terms(
    p: &mut Prepared,
    given: &[ParamSpec],
    search: &SearchSettings,
    say: &(dyn Fn(&str) + Sync),
    stop: &crate::interrupt::Stop,
) -> Result<Selection, FitError> {
    let s = select(p, search, given, say, stop)?;
    let keys: Vec<&str> = s.keys.iter().map(String::as_str).collect();
    let specs = set_specs(given, &keys);
    let (model, map_fit) = model_for(p, &specs, &[])?;
    p.model = model;
    p.map_fit = map_fit;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_of_the_term_catalogue_is_a_candidate_or_says_why_not() {
        for k in crate::physics::terms::catalogue() {
            let candidate = CANDIDATES.iter().any(|c| c.keys.contains(&k.key));
            let excluded = NOT_CANDIDATES.iter().any(|(n, _)| *n == k.key);
            assert!(
                candidate ^ excluded,
                "{}: a candidate of --fit auto, or in NOT_CANDIDATES with a reason",
                k.key
            );
        }
    }

    #[test]
    fn auto_is_found_among_the_names_and_the_rest_kept() {
        let (auto, rest) = split(&["auto".into(), "a_eff".into(), "f0".into()]);
        assert!(auto);
        assert_eq!(rest, vec!["a_eff".to_string(), "f0".to_string()]);
        assert!(!split(&["contact.boundary_friction".into()]).0);
    }

    #[test]
    fn a_term_pays_only_beyond_the_folds_spread() {
        // Lower on every fold by about 1: pays.
        let (g, se) = paired(&[10.0, 11.0, 12.0, 13.0], &[9.0, 10.1, 10.9, 12.0]);
        assert!(g > se);
        // Lower on average, but not beyond the spread: does not pay.
        let (g, se) = paired(&[10.0, 11.0, 12.0, 13.0], &[8.0, 12.0, 10.0, 14.5]);
        assert!(g <= se, "{g} vs {se}");
    }
}
