//! The candidate terms of `--fit auto` ([`CANDIDATES`]): the groups of
//! configuration keys a recording can show, the keys that are not
//! candidates and why, the keys of a set, and which candidates the data at
//! hand allow. The rule that chooses among them is `select.rs`'s.

use super::prepared::{model_for, Prepared};
use super::unknowns::ParamSpec;

/// The word in `--fit` that asks for the selection.
pub const AUTO: &str = "auto";

/// A term the selection may add.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Its name in the report.
    pub name: &'static str,
    /// The keys it fits.
    pub keys: &'static [&'static str],
    /// A candidate whose keys the set must fit first (that term, or one
    /// that holds its keys: the Stribeck curve holds the viscous rise).
    pub requires: Option<&'static str>,
    /// Only when the training loads vary.
    pub needs_varying_load: bool,
    /// How it stands to the term it requires ([`Tie`]).
    pub tie: Tie,
}

/// How a candidate stands to the term it requires.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tie {
    /// A term of its own: where a key of it correlates above 0.95 with a
    /// key of another chosen term, the data cannot tell the two apart
    /// (rule 4), and one of them goes.
    Own,
    /// A part of the term it requires, not a rival explanation: LuGre's
    /// bristle damping σ1 beside its stiffness σ0. Once that term is
    /// chosen, the part is added unless the set without it pays over it
    /// (`select.rs`, rule 4b); rule 4's flags still drop it.
    Part,
    /// The form of the term it requires, not a rival explanation: an
    /// exponent whose null value gives the plain form (the bend's δ = 1,
    /// the Stribeck fall's α_s = 2). An exponent trades against its own
    /// term's level by the way the form is written, so their correlation
    /// is no sign of two explanations: it is a plain flag (rule 4, the
    /// folds decide), and whether the data show the exponent is rule 9c's
    /// question (its interval, which that correlation widens).
    Refinement,
}

/// The candidate terms, in the order they are tried.
pub const CANDIDATES: &[Candidate] = &[
    Candidate {
        name: "film",
        keys: &["lubricant.viscosity_pa_s"],
        requires: None,
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        name: "boundary rate",
        keys: &[
            "contact.boundary_friction_rate",
            "contact.boundary_activation_speed_m_s",
        ],
        requires: None,
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        name: "pre-sliding",
        keys: &["contact.presliding_stiffness_n_m"],
        requires: None,
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        name: "pre-sliding damping",
        keys: &["contact.presliding_damping_n_s_m"],
        requires: Some("pre-sliding"),
        needs_varying_load: false,
        tie: Tie::Part,
    },
    Candidate {
        name: "drivetrain Coulomb",
        keys: &["drivetrain.coulomb_n"],
        requires: None,
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        name: VISCOUS,
        keys: &["drivetrain.viscous_n_s_m"],
        requires: None,
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        // The quadratic rise only on top of the viscous rise (the viscous
        // term, or the Stribeck curve that holds it): the marginality
        // principle of polynomial models (Nelder 1977, "A reformulation of
        // linear models"; Peixoto 1987). Alone, a parabola that the data
        // cannot tell from a straight rise replaces it and grows 20× past
        // a curve fitted at 0.5–20 deg/s by 90 deg/s: 9–17× worse than
        // Coulomb + viscous there.
        name: "drivetrain quadratic",
        keys: &["drivetrain.quadratic_n_s2_m2"],
        requires: Some(VISCOUS),
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        // The viscous rise bent below the line, b v_b sgn v |v/v_b|^δ with
        // δ < 1: a rolling bearing's viscous moment grows with (ν n)^(2/3)
        // (Palmgren), a film's shear with the speed over a film that
        // thickens with it. Only on a viscous rise (the viscous term, or
        // the Stribeck curve that holds it), and only where the fit tells
        // δ from 1 (rule 9c, `admission.rs`).
        name: BEND,
        keys: &["drivetrain.viscous_exponent"],
        requires: Some(VISCOUS),
        needs_varying_load: false,
        tie: Tie::Refinement,
    },
    Candidate {
        // The Stribeck fall's own exponent: measured falls have 0.5–2
        // (Armstrong-Hélouvry), the classic curve and LuGre 2. Only on the
        // Stribeck curve, and only where the fit tells α_s from 2 (rule
        // 9c, `admission.rs`): elsewhere the bend or the rate takes up the
        // tail a Gaussian fall misses, and bends the prediction past the
        // data.
        name: STRIBECK_SHAPE,
        keys: &["drivetrain.stribeck_exponent"],
        requires: Some(STRIBECK),
        needs_varying_load: false,
        tie: Tie::Refinement,
    },
    Candidate {
        // The classic Stribeck curve on our level: the static excess, its
        // speed and the viscous rise (a dip needs the rise beside it; alone
        // neither pays).
        name: STRIBECK,
        keys: &[
            "drivetrain.stribeck_n",
            "drivetrain.stribeck_speed_m_s",
            "drivetrain.viscous_n_s_m",
        ],
        requires: None,
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        name: ASYMMETRY,
        keys: &["drivetrain.coulomb_asymmetry_n"],
        requires: None,
        needs_varying_load: false,
        tie: Tie::Own,
    },
    Candidate {
        name: "drivetrain load",
        keys: &["drivetrain.load_coefficient"],
        requires: None,
        needs_varying_load: true,
        tie: Tie::Own,
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
        "drivetrain.viscous_reference_speed_m_s",
        "where the bent viscous rise's slope is read: set to the data's top speed",
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

/// The keys of a set of candidates, the base key first, each once (two
/// candidates may share one: the Stribeck curve's viscous rise).
pub(super) fn set_keys(terms: &[&str]) -> Vec<&'static str> {
    let mut keys = vec![BASE_KEY];
    for t in terms {
        if let Some(c) = CANDIDATES.iter().find(|c| c.name == *t) {
            keys.extend(
                c.keys
                    .iter()
                    .filter(|k| !keys.contains(k))
                    .collect::<Vec<_>>(),
            );
        }
    }
    keys
}

/// Whether `terms` fit every key of candidate `r` (hold it): `r` itself,
/// or a term whose keys include its own.
pub(super) fn holds(terms: &[&str], r: &str) -> bool {
    let fitted = set_keys(terms);
    CANDIDATES
        .iter()
        .find(|c| c.name == r)
        .is_some_and(|c| c.keys.iter().all(|k| fitted.contains(k)))
}

/// The term candidate `o` requires, if any.
fn requirement(o: &str) -> Option<&'static str> {
    CANDIDATES
        .iter()
        .find(|c| c.name == o)
        .and_then(|c| c.requires)
}

/// Whether term `o` of `set` needs its term `t`: `o` requires a term that
/// `set` holds, and holds no more without `t`.
pub(super) fn needs(o: &str, t: &str, set: &[&'static str]) -> bool {
    let without: Vec<&'static str> = set.iter().copied().filter(|x| *x != t).collect();
    o != t && requirement(o).is_some_and(|r| holds(set, r) && !holds(&without, r))
}

/// Whether term `o` requires a term that `terms` do not hold.
pub(super) fn needs_unheld(o: &str, terms: &[&'static str]) -> bool {
    requirement(o).is_some_and(|r| !holds(terms, r))
}

/// Whether candidate `t` is a part of the term it requires ([`Tie::Part`]).
pub(super) fn is_part(t: &str) -> bool {
    CANDIDATES.iter().any(|c| c.name == t && c.tie == Tie::Part)
}

/// Whether terms `a` and `b` are one element: one is a part of the other
/// ([`Tie::Part`], the bristle's damping beside its stiffness) or its form
/// ([`Tie::Refinement`], the Stribeck fall's exponent beside the curve),
/// so they are not two explanations of the data.
pub(super) fn one_element(a: &str, b: &str) -> bool {
    let tied_to = |p: &str, t: &str| {
        CANDIDATES
            .iter()
            .any(|c| c.name == p && c.tie != Tie::Own && c.requires == Some(t))
    };
    tied_to(a, b) || tied_to(b, a)
}

/// The parts ([`Tie::Part`]) among `candidates` that
/// `terms` lacks while holding the term each requires, and that add a key
/// the set does not fit already.
pub(super) fn parts_to_add(
    candidates: &[&'static Candidate],
    terms: &[&'static str],
) -> Vec<&'static Candidate> {
    let fitted = set_keys(terms);
    candidates
        .iter()
        .copied()
        .filter(|c| c.tie == Tie::Part && !terms.contains(&c.name))
        .filter(|c| c.requires.is_some_and(|r| holds(terms, r)))
        .filter(|c| c.keys.iter().any(|k| !fitted.contains(k)))
        .collect()
}

/// The lighter forms of candidate `t` that `set` does not hold: the
/// candidates whose keys are a strict part of `t`'s (the Stribeck curve's
/// viscous rise), `t`'s place taken by one of them when its other keys do
/// not pay.
pub(super) fn lighter_forms(t: &str, set: &[&'static str]) -> Vec<&'static str> {
    let Some(big) = CANDIDATES.iter().find(|c| c.name == t) else {
        return Vec::new();
    };
    CANDIDATES
        .iter()
        .filter(|c| {
            c.name != t
                && c.keys.len() < big.keys.len()
                && c.keys.iter().all(|k| big.keys.contains(k))
                && !set.contains(&c.name)
        })
        .map(|c| c.name)
        .collect()
}

/// The candidates on `p`'s data: those whose keys can be set up (a
/// candidate without bounds to derive, pre-sliding without a reversal, is
/// not one here, and is returned with why), that the loads allow and that
/// no given name already fits.
pub(super) fn candidates_here(
    p: &Prepared,
    given: &[ParamSpec],
) -> (Vec<&'static Candidate>, Vec<String>) {
    let mut excluded: Vec<String> = Vec::new();
    let mut candidates = Vec::new();
    let no_reversal = p.scale.reversal_stiffness_n_m.is_none();
    let one_way = moves_one_way(p);
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
        if one_way && c.name == ASYMMETRY {
            excluded.push(format!(
                "{}: the training data slide one way only, and a level that differs by direction shows only where they slide both ways (it would be the level itself)",
                c.name
            ));
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

/// Whether `p`'s training data slide one way only: no sample faster than
/// [`SLIDING_FRACTION`](super::by_direction::SLIDING_FRACTION) of the top
/// speed in one of the two directions.
fn moves_one_way(p: &Prepared) -> bool {
    let slow = super::by_direction::SLIDING_FRACTION * p.scale.velocity_m_s;
    let (mut forward, mut backward) = (false, false);
    for s in &p.data.train {
        let Ok(se) = s.series(&p.data.map_values) else {
            return false;
        };
        forward |= se.velocity.iter().any(|&v| v >= slow);
        backward |= se.velocity.iter().any(|&v| v <= -slow);
    }
    !(forward && backward)
}

/// The candidate named `film` (the viscosity), and its key.
pub(super) const FILM: &str = "film";
/// The drivetrain's Stribeck curve, one of the classic shapes a steady
/// curve may be presumed to have (`select.rs`, rule 7).
pub(super) const STRIBECK: &str = "drivetrain Stribeck";

/// The Stribeck fall's exponent (a fuller form of the curve's shape).
pub(super) const STRIBECK_SHAPE: &str = "drivetrain Stribeck shape";
/// The drivetrain's viscous rise (Coulomb + viscous with the base), the
/// other classic shape of rule 7.
pub(super) const VISCOUS: &str = "drivetrain viscous";
/// The viscous rise bent below the line (its exponent δ < 1).
pub(super) const BEND: &str = "drivetrain bend";
/// The drivetrain's direction asymmetry (a level higher one way than the
/// other: an offset of the moving friction), which rule 7 also compares
/// the classic shapes beside.
pub(super) const ASYMMETRY: &str = "drivetrain asymmetry";
/// See [`FILM`].
pub(super) const FILM_KEY: &str = "lubricant.viscosity_pa_s";

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_of_the_term_catalogue_is_a_candidate_or_says_why_not() {
        for k in crate::physics::terms::configured_catalogue() {
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
    fn the_stribeck_curve_has_its_viscous_rise_as_its_lighter_form() {
        assert_eq!(
            lighter_forms("drivetrain Stribeck", &["pre-sliding"]),
            vec!["drivetrain viscous"]
        );
        assert!(lighter_forms("drivetrain Stribeck", &["drivetrain viscous"]).is_empty());
        assert!(lighter_forms("drivetrain viscous", &[]).is_empty());
        assert!(lighter_forms("pre-sliding", &[]).is_empty());
    }
}
