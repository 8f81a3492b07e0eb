//! The sets a term's removal may go to during `--fit auto`'s selection
//! (`removal.rs`, rules 2 and 4): the term replaced by a lighter form of
//! it (the Stribeck curve by its viscous rise) or taken away with what
//! requires it, and, where one of two confounded terms goes, the set it
//! leaves with a fuller form a newcomer had displaced taken back; how the
//! progress lines name each change.

use super::candidates::{holds, lighter_forms, needs, CANDIDATES};

/// `options` (as [`lighter`] gives them), each set without its term also
/// with a fuller form taken back ([`with_fuller_forms`]) where `may(u)`
/// lets the form `u` be taken back (a steady curve's presumed shape is
/// rule 7's choice, not taken back).
pub(super) fn with_fuller_options(
    options: Vec<(&'static str, Option<&'static str>, Vec<&'static str>)>,
    may: &dyn Fn(&str) -> bool,
) -> Vec<(&'static str, Option<&'static str>, Vec<&'static str>)> {
    let mut out = Vec::new();
    for (t, form, terms) in options {
        if form.is_none() {
            for (set, _, _) in with_fuller_forms(&terms)
                .into_iter()
                .filter(|(_, u, _)| may(u))
            {
                out.push((t, None, set));
            }
        }
        out.push((t, form, terms));
    }
    out
}

/// The sets lighter than `set` by its term `t`: `t` replaced by each of
/// its lighter forms (those without `flagged_key`), then `t` removed with
/// the terms that require it. Each as (t, the form taking its place, the
/// set).
pub(super) fn lighter(
    set: &[&'static str],
    t: &'static str,
    flagged_key: Option<&str>,
) -> Vec<(&'static str, Option<&'static str>, Vec<&'static str>)> {
    let mut out: Vec<(&'static str, Option<&'static str>, Vec<&'static str>)> =
        lighter_forms(t, set)
            .into_iter()
            .filter(|form| {
                let keys = CANDIDATES.iter().find(|c| c.name == *form).map(|c| c.keys);
                !keys.is_some_and(|k| flagged_key.is_some_and(|f| k.contains(&f)))
            })
            .map(|form| {
                let terms = set
                    .iter()
                    .map(|x| if *x == t { form } else { *x })
                    .collect();
                (t, Some(form), terms)
            })
            .collect();
    let without = set
        .iter()
        .copied()
        .filter(|x| *x != t && !needs(x, t, set))
        .collect();
    out.push((t, None, without));
    out
}

/// The sets that one of two confounded terms leaves behind when it goes
/// outright: `without`, and `without` with a lighter form in it taken back
/// to a fuller form that holds it (the viscous rise back to the Stribeck
/// curve), one at a time. A newcomer can make a chosen term give way to a
/// lighter form (rule 2's removal: the Stribeck curve to its rise beside a
/// boundary rate); when the data then cannot tell the newcomer from that
/// form and the newcomer goes, the reason the fuller form gave way goes
/// with it. Each as (the set, the form taken back, the fuller form).
pub(super) fn with_fuller_forms(
    without: &[&'static str],
) -> Vec<(Vec<&'static str>, &'static str, &'static str)> {
    let mut out = Vec::new();
    for u in without {
        for c in CANDIDATES.iter().filter(|c| !without.contains(&c.name)) {
            if !lighter_forms(c.name, &[]).contains(u) {
                continue;
            }
            let set: Vec<&'static str> = without
                .iter()
                .map(|x| if x == u { c.name } else { *x })
                .collect();
            if c.requires.is_none_or(|r| holds(&set, r)) {
                out.push((set, *u, c.name));
            }
        }
    }
    out
}

/// What a set differs from `from` by, beside the change: the fuller forms
/// taken back (", drivetrain viscous back to drivetrain Stribeck"), or "".
pub(super) fn taken_back(from: &[&'static str], to: &[&'static str]) -> String {
    with_fuller_forms(from)
        .into_iter()
        .filter(|(_, u, c)| !to.contains(u) && to.contains(c))
        .map(|(_, u, c)| format!(", {u} back to {c}"))
        .collect()
}

/// "− t", or "t → form" when a lighter form takes its place.
pub(super) fn change_text(t: &str, form: Option<&str>) -> String {
    match form {
        Some(f) => format!("{t} → {f}"),
        None => format!("− {t}"),
    }
}

#[cfg(test)]
mod tests {
    use super::super::candidates::VISCOUS;
    use super::*;

    #[test]
    fn a_confounded_term_that_goes_leaves_its_set_also_with_the_fuller_form_it_displaced() {
        // d190's path (a LuGre joint whose Stribeck fall is not Gaussian):
        // the boundary rate made the Stribeck curve give way to its rise,
        // then the data could not tell the rate from that rise.
        let chosen = [
            "pre-sliding",
            "pre-sliding damping",
            "boundary rate",
            VISCOUS,
        ];
        let options = with_fuller_options(lighter(&chosen, "boundary rate", None), &|_| true);
        let back = ["pre-sliding", "pre-sliding damping", "drivetrain Stribeck"];
        let sets: Vec<&Vec<&str>> = options.iter().map(|(_, _, s)| s).collect();
        assert!(
            sets.iter()
                .any(|s| s.len() == 3 && back.iter().all(|t| s.contains(t))),
            "{sets:?}"
        );
        // The set without the rate as it is stays an option.
        assert!(
            sets.iter().any(|s| s.len() == 3 && s.contains(&VISCOUS)),
            "{sets:?}"
        );
        assert_eq!(
            taken_back(&chosen, &back),
            ", drivetrain viscous back to drivetrain Stribeck"
        );
        // A form that may not be taken back (a steady curve's presumed
        // shape) is not.
        let kept = with_fuller_options(lighter(&chosen, "boundary rate", None), &|u| u != VISCOUS);
        assert!(
            kept.iter()
                .all(|(_, _, s)| !s.contains(&"drivetrain Stribeck")),
            "{kept:?}"
        );
        // A set without a lighter form has nothing to take back.
        assert!(with_fuller_forms(&["pre-sliding", "film"]).is_empty());
    }

    #[test]
    fn a_stribeck_curve_gives_way_to_its_viscous_rise_before_it_is_removed() {
        let set = ["pre-sliding", "drivetrain Stribeck", "drivetrain quadratic"];
        let alternatives = lighter(&set, "drivetrain Stribeck", None);
        assert_eq!(
            alternatives,
            vec![
                (
                    "drivetrain Stribeck",
                    Some("drivetrain viscous"),
                    vec!["pre-sliding", "drivetrain viscous", "drivetrain quadratic"]
                ),
                // Without the curve the quadratic rise has no viscous rise
                // beneath it, and goes too.
                ("drivetrain Stribeck", None, vec!["pre-sliding"]),
            ]
        );
        // A flag on the viscous key itself: its form would keep the flag.
        let flagged = lighter(
            &set,
            "drivetrain Stribeck",
            Some("drivetrain.viscous_n_s_m"),
        );
        assert_eq!(flagged.len(), 1);
        assert_eq!(flagged[0].1, None);
        // A term without a lighter form is only removed.
        assert_eq!(lighter(&set, "pre-sliding", None).len(), 1);
        // The viscous rise removed takes the quadratic on top of it along;
        // the quadratic removed leaves the viscous rise.
        let rise = ["drivetrain viscous", "drivetrain quadratic", "film"];
        assert_eq!(
            lighter(&rise, "drivetrain viscous", None),
            vec![("drivetrain viscous", None, vec!["film"])]
        );
        assert_eq!(
            lighter(&rise, "drivetrain quadratic", None),
            vec![(
                "drivetrain quadratic",
                None,
                vec!["drivetrain viscous", "film"]
            )]
        );
        assert!(needs("drivetrain quadratic", "drivetrain viscous", &rise));
        assert!(!needs("film", "drivetrain viscous", &rise));
        // Beside the Stribeck curve the quadratic needs the curve, not a
        // viscous rise it does not hold; with both, neither alone.
        assert!(needs("drivetrain quadratic", "drivetrain Stribeck", &set));
        let both = [
            "drivetrain viscous",
            "drivetrain Stribeck",
            "drivetrain quadratic",
        ];
        assert!(!needs("drivetrain quadratic", "drivetrain Stribeck", &both));
        assert_eq!(
            change_text("drivetrain Stribeck", Some("drivetrain viscous")),
            "drivetrain Stribeck → drivetrain viscous"
        );
    }
}
