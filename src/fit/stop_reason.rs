//! Why `--fit auto`'s stepwise selection (`select.rs`) stopped, in words:
//! the best next term does not pay on the folds (rule 3), or it pays there
//! and the whole curve's small-sample Akaike criterion refuses it (rule 10).

use super::cross_validate::TERM_COST;
use super::removal::pays;
use super::trial::Scored;

/// Why the selection stopped: the best next term does not pay.
pub(super) fn does_not_pay(name: &str, gain: f64, se: f64, share: f64) -> String {
    if !(gain.is_finite() && se.is_finite()) {
        return format!(
            "the best next term, {name}, cannot be scored on these folds (a fold too small for the keys it adds, or a refit that failed), so it is not added"
        );
    }
    format!(
        "the best next term, {name}, lowers the folds' mean squared error by {} ± {} (standard error), {:.2} % of it: a term must lower it by more than its standard error and by more than {:.0} % (the cost of a term), so it does not pay for itself",
        crate::text::Num::sig(gain, 5),
        crate::text::Num::sig(se, 5),
        100.0 * share,
        100.0 * TERM_COST
    )
}

/// Why the selection stopped when no set of the step is supported by the
/// whole curve (rule 10): the best of them on the folds, and why it is not
/// added — it does not pay there (rule 3), or it does and the criterion
/// refuses it.
pub(super) fn not_supported(current: &Scored, unsupported: &[Scored]) -> String {
    let Some(best) = unsupported
        .iter()
        .filter(|t| super::removal::is_scored(&t.tried))
        .min_by(|a, b| a.tried.cv_rms.total_cmp(&b.tried.cv_rms))
    else {
        return "no next term could be scored on these folds".to_string();
    };
    let name = best.tried.terms.last().copied().unwrap_or_default();
    let (ok, gain, se, share) = pays(&current.tried, &best.tried);
    if !ok {
        // It does not pay on the folds either: rule 3 is the reason.
        return does_not_pay(name, gain, se, share);
    }
    format!(
        "the best next term on the folds, {name} (CV {} against {}), pays there but does not lower the whole curve's small-sample Akaike criterion by more than {} ({:.1} with it against {:.1}), nor does any other (rule 10), so none is added",
        crate::text::Num::sig(best.tried.cv_rms, 5),
        crate::text::Num::sig(current.tried.cv_rms, 5),
        super::trial::AICC_SUPPORT,
        best.aicc,
        current.aicc
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_term_the_folds_cannot_score_is_said_to_be_unscored_not_to_gain_nan() {
        let text = does_not_pay("film", f64::NAN, f64::NAN, f64::NAN);
        assert!(text.contains("cannot be scored on these folds"), "{text}");
        assert!(!text.contains("NaN"), "{text}");
        let text = does_not_pay("film", 1e-9, 2e-9, 0.5);
        assert!(
            text.contains("lowers the folds' mean squared error by 1e-9 ± 2e-9"),
            "{text}"
        );
    }

    #[test]
    fn a_stop_by_rule_10_names_rule_3_when_the_best_refused_term_does_not_pay_on_the_folds_either()
    {
        let current = Scored::with_folds(&["drivetrain Stribeck"], &[1.0, 1.0, 1.0, 1.0], -169.2);
        // Lower on average but within the folds' spread: rule 3's reason.
        let noisy = Scored::with_folds(
            &["drivetrain Stribeck", "drivetrain quadratic"],
            &[0.2, 1.9, 0.3, 1.4],
            -166.4,
        );
        let why = not_supported(&current, std::slice::from_ref(&noisy));
        assert!(why.contains("does not pay for itself"), "{why}");
        // Lower on every fold: it pays there, and rule 10 refuses it.
        let paying = Scored::with_folds(
            &["drivetrain Stribeck", "film"],
            &[0.5, 0.5, 0.6, 0.5],
            -168.0,
        );
        let why = not_supported(&current, &[noisy, paying]);
        assert!(
            why.starts_with("the best next term on the folds, film") && why.contains("(rule 10)"),
            "{why}"
        );
    }
}
