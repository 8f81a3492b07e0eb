//! The report of `--fit auto`'s selection (`select.rs`): its rule in
//! words, every set tried with its error per fold, the candidates left
//! out, the sets not admitted, the start, the terms added and removed,
//! the set chosen and why the steps stopped.

use super::cross_validate::TERM_COST;
use super::select::Selection;
use std::fmt::Write as _;

/// The selection as a markdown section.
pub fn report(s: &Selection, units: super::Units) -> String {
    let u = units.force();
    let mut md = format!(
        "## Terms chosen by the data (`--fit auto`)\n\nRule: stepwise selection on cross-validation of the training data ({}; each fold predicted by the set refitted without it); each step takes the candidate with the lowest CV error (a term that needs another, the quadratic or the bend on a viscous rise, also tried together with a term that holds it), unless one with fewer keys predicts as well (the best does not pay for its extra keys over it); a term is added only if it lowers the folds' mean squared error by more than the standard error of that lowering and by more than {:.0} % of it (the cost of a term), and a term chosen earlier goes, or gives way to a lighter form of it (the Stribeck curve to its viscous rise), when it no longer pays beside a later one; a part of a chosen term (the pre-sliding bristle's damping, LuGre's σ1 beside its stiffness σ0) comes with it unless the set without it pays over it; a term that ends at zero or at a bound, or that the data cannot tell from another parameter (|ρ| > 0.95), is dropped or reduced and the set fitted again unless that predicts worse, and of two chosen terms that the data cannot tell apart (a key of one correlated so with a key of the other; a part of a term or the exponent of its form, and the term, are one element, not two) one goes, whichever the folds miss least (the set it leaves also tried with a form it displaced back, the rise back to the Stribeck curve); the chosen set's final fit is scored on the same folds, and gives way to the best set with one term fewer when it no longer pays over it, unless that set, fitted in its turn, is beaten by the same rule, each set weighed at the optimum that would be shipped; a steady curve starts from its rising classic shape (the viscous rise or the Stribeck curve: the simplest whose small-sample Akaike criterion on all the training points is within 2 of the lowest, compared beside the direction asymmetry where that lowers the criterion by more than 2), presumed with its viscous rise: it is never removed for the flat base (the curve gives way to its rise when that pays over it or, the curve's keys flagged, predicts the folds no worse within 10 of its Akaike criterion; the rise goes only when its key ends at zero), and of it and a term confounded with it the term goes; the quadratic rise comes only on top of a viscous rise and only where the fit tells its coefficient from zero (its 95 % interval excludes zero), the rise's bend only where the fit tells its exponent from 1, the Stribeck fall's own exponent only where it tells it from 2 (the Gaussian fall) and shows the fall and the rise beside it, and a Stribeck speed lies within the data's speeds; on a steady curve a term enters only where its set's small-sample Akaike criterion on all the training points is also more than 2 below the current set's, and a path that ends on a set its start beats on both the folds and that criterion goes back to the start. Neither --validate nor --holdout data are used.\n\n| set (boundary friction +) | CV RMS ({u}) | RMS per fold ({u}) | film solves |\n|---|---|---|---|\n",
        s.folds,
        100.0 * TERM_COST
    );
    for t in &s.tried {
        let (cv, folds) = match t.unscored {
            Some(why) => ("—".to_string(), why.to_string()),
            None => (
                crate::text::Num::sig(t.cv_rms, 5).to_string(),
                t.fold_mse
                    .iter()
                    .map(|m| crate::text::Num::sig(m.sqrt(), 5).to_string())
                    .collect::<Vec<_>>()
                    .join(" / "),
            ),
        };
        let _ = writeln!(
            md,
            "| {} | {cv} | {folds} | {} |",
            if t.terms.is_empty() {
                "—".to_string()
            } else {
                t.terms.join(", ")
            },
            t.simulations
        );
    }
    for e in &s.excluded {
        let _ = writeln!(md, "\nNot a candidate on these data: {e}");
    }
    for e in &s.not_admitted {
        let _ = writeln!(md, "\nNot admitted: {e}");
    }
    if !s.start.is_empty() {
        let _ = writeln!(md, "\nStart: {}", s.start);
    }
    for a in &s.added {
        let _ = writeln!(md, "\nAdded: {a}");
    }
    for r in &s.removed {
        let _ = writeln!(md, "\nRemoved: {r}");
    }
    for k in &s.kept {
        let _ = writeln!(md, "\nKept: {k}");
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
