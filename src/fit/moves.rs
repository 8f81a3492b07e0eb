//! The moves a step of `--fit auto` tries (`select.rs`, rule 2): each open
//! candidate alone, and each candidate whose requirement the set lacks
//! together with a candidate that holds it.

use super::candidates::{holds, set_keys, Candidate, Tie};

/// The candidates a step tries beside `terms`: not chosen yet, their
/// requirement chosen, and adding a key the set does not fit already (the
/// viscous rise beside the Stribeck curve, which holds it, would be the
/// same set fitted again).
pub(super) fn open_candidates<'c>(
    candidates: &'c [&'static Candidate],
    terms: &[&'static str],
) -> Vec<&'c &'static Candidate> {
    let fitted = set_keys(terms);
    candidates
        .iter()
        .filter(|c| !terms.contains(&c.name))
        .filter(|c| c.requires.is_none_or(|r| holds(terms, r)))
        .filter(|c| c.keys.iter().any(|k| !fitted.contains(k)))
        .collect()
}

/// The moves a step tries beside `terms`, each the terms it adds: every
/// open candidate alone ([`open_candidates`]), and every candidate whose
/// requirement the set does not hold together with an open candidate that
/// holds it — the bend or the quadratic with the viscous rise, or with the
/// Stribeck curve. Hierarchical selection adds a term with its parent
/// (the marginality principle still holds: never without it); a term that
/// pays only with its parent is otherwise out of reach wherever the parent
/// alone does not pay, or a rival (the boundary rate's logarithmic rise)
/// took its place first. A part of its requirement (the bristle's damping)
/// is not paired: it comes with its term by rule 4b.
pub(super) fn open_moves(
    candidates: &[&'static Candidate],
    terms: &[&'static str],
) -> Vec<Vec<&'static str>> {
    let singles = open_candidates(candidates, terms);
    let mut moves: Vec<Vec<&'static str>> = singles.iter().map(|c| vec![c.name]).collect();
    for c in candidates
        .iter()
        .filter(|c| c.tie != Tie::Part && !terms.contains(&c.name))
    {
        let Some(r) = c.requires.filter(|r| !holds(terms, r)) else {
            continue;
        };
        for h in singles
            .iter()
            .filter(|h| h.name != c.name && holds(&[h.name], r))
        {
            let mut with: Vec<&'static str> = terms.to_vec();
            with.push(h.name);
            let fitted = set_keys(&with);
            if c.keys.iter().any(|k| !fitted.contains(k)) {
                moves.push(vec![h.name, c.name]);
            }
        }
    }
    moves
}

/// A move's terms as the report names it: "a + b".
pub(super) fn move_label(terms: &[&str]) -> String {
    terms.join(" + ")
}

#[cfg(test)]
mod tests {
    use super::super::candidates::CANDIDATES;
    use super::*;

    #[test]
    fn a_candidate_whose_keys_the_set_already_fits_is_not_tried_again() {
        let all: Vec<&'static Candidate> = CANDIDATES.iter().collect();
        let names = |open: Vec<&&Candidate>| open.iter().map(|c| c.name).collect::<Vec<_>>();
        let beside_stribeck = names(open_candidates(&all, &["drivetrain Stribeck"]));
        assert!(
            !beside_stribeck.contains(&"drivetrain viscous"),
            "{beside_stribeck:?}"
        );
        assert!(
            beside_stribeck.contains(&"drivetrain quadratic"),
            "{beside_stribeck:?}"
        );
        // The other way round the Stribeck curve adds its static excess and
        // speed: still a candidate.
        let beside_viscous = names(open_candidates(&all, &["drivetrain viscous"]));
        assert!(
            beside_viscous.contains(&"drivetrain Stribeck"),
            "{beside_viscous:?}"
        );
    }

    #[test]
    fn the_quadratic_rise_is_a_candidate_only_beside_a_viscous_rise() {
        let all: Vec<&'static Candidate> = CANDIDATES.iter().collect();
        let names = |terms: &[&'static str]| {
            open_candidates(&all, terms)
                .iter()
                .map(|c| c.name)
                .collect::<Vec<_>>()
        };
        let quadratic = "drivetrain quadratic";
        assert!(!names(&[]).contains(&quadratic), "{:?}", names(&[]));
        assert!(!names(&["film", "drivetrain asymmetry"]).contains(&quadratic));
        assert!(names(&["drivetrain viscous"]).contains(&quadratic));
        // The Stribeck curve holds the viscous rise.
        assert!(names(&["drivetrain Stribeck"]).contains(&quadratic));
    }

    #[test]
    fn a_term_whose_requirement_the_set_lacks_is_tried_with_each_term_that_holds_it() {
        let all: Vec<&'static Candidate> = CANDIDATES.iter().collect();
        let (viscous, stribeck) = ("drivetrain viscous", "drivetrain Stribeck");
        let (bend, quadratic) = ("drivetrain bend", "drivetrain quadratic");
        let base = open_moves(&all, &[]);
        for m in [
            vec![viscous, bend],
            vec![stribeck, bend],
            vec![viscous, quadratic],
            vec![stribeck, quadratic],
        ] {
            assert!(base.contains(&m), "{m:?} not in {base:?}");
        }
        // Never without its requirement, and a part of a term (the
        // bristle's damping) comes with it by rule 4b, not as a pair.
        assert!(!base.contains(&vec![bend]) && !base.contains(&vec![quadratic]));
        assert!(base.iter().all(|m| !m.contains(&"pre-sliding damping")));
        // Beside a term that holds the requirement, alone.
        let beside = open_moves(&all, &["boundary rate", stribeck]);
        assert!(beside.contains(&vec![bend]) && beside.contains(&vec![quadratic]));
        assert!(beside.iter().all(|m| m.len() == 1), "{beside:?}");
    }
}
