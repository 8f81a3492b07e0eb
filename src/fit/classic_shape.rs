//! Rule 7 of `--fit auto` (`select.rs`): a steady curve starts from its
//! classic shape — the base alone (Coulomb), the viscous rise or the
//! Stribeck curve, the simplest whose small-sample Akaike criterion on all
//! the training points is within [`AICC_SUPPORT`] of the lowest — and that
//! shape is presumed: it leaves the set only when the set without it pays
//! over it (`removal.rs`, `confirm.rs`).

use super::candidates::{set_keys, Candidate, STRIBECK, VISCOUS};
use super::trial::{Ctx, Scored, Tried};
use super::FitError;

/// The chosen `terms` without those whose keys another chosen term fits
/// as well (the viscous rise beside the Stribeck curve, which holds its
/// key: the same set, named once), and the `presumed` terms with each
/// such term's place taken by the term that holds it.
pub(super) fn without_subsumed(
    terms: &[&'static str],
    presumed: &[&'static str],
) -> (Vec<&'static str>, Vec<&'static str>) {
    let holder = |t: &'static str| {
        let keys = set_keys(&[t]);
        terms.iter().copied().find(|u| {
            *u != t && {
                let theirs = set_keys(&[*u]);
                theirs.len() > keys.len() && keys.iter().all(|k| theirs.contains(k))
            }
        })
    };
    let chosen: Vec<&'static str> = terms
        .iter()
        .copied()
        .filter(|t| holder(t).is_none())
        .collect();
    let mut kept: Vec<&'static str> = Vec::new();
    for p in presumed {
        let q = holder(p).unwrap_or(p);
        if !kept.contains(&q) {
            kept.push(q);
        }
    }
    (chosen, kept)
}

/// How much lower (better) a richer classic shape's small-sample Akaike
/// criterion must be to be preferred to a simpler one (rule 7): a
/// difference below 2 is one the data do not resolve (Burnham & Anderson
/// 2002, *Model Selection and Multimodel Inference*, §2.6), and the
/// simpler shape is taken.
pub const AICC_SUPPORT: f64 = 2.0;

/// The classic shapes of a steady curve that are candidates here (rule
/// 7): the viscous rise (with the base, Coulomb + viscous) and the
/// Stribeck curve.
pub(super) fn classic_shapes(candidates: &[&'static Candidate]) -> Vec<&'static str> {
    [VISCOUS, STRIBECK]
        .into_iter()
        .filter(|s| candidates.iter().any(|c| c.name == *s))
        .collect()
}

impl Ctx<'_> {
    /// Rule 7: on a steady curve the selection starts from the classic
    /// shape that the whole curve supports — the base alone (Coulomb), the
    /// viscous rise or the Stribeck curve: the simplest whose small-sample
    /// Akaike criterion on all the training points
    /// ([`super::trial::aicc`]) is within [`AICC_SUPPORT`] of the lowest —
    /// and that shape is presumed: it leaves
    /// the set only when the set without it pays over it. With `shapes`
    /// empty (a time series) the start is the base.
    pub(super) fn presume(
        &self,
        base: Scored,
        shapes: &[&'static str],
        tried: &mut Vec<Tried>,
        start: &mut String,
        say: &(dyn Fn(&str) + Sync),
    ) -> Result<Scored, FitError> {
        let mut sets = vec![base];
        for s in shapes {
            let t = self.try_set(&[*s], &sets[0].optimum)?;
            tried.push(t.tried.clone());
            sets.push(t);
        }
        let text: Vec<String> = sets
            .iter()
            .map(|s| {
                format!(
                    "{} {:.1}",
                    s.tried.terms.first().copied().unwrap_or("the base alone"),
                    s.aicc
                )
            })
            .collect();
        // The simplest shape within AICC_SUPPORT of the lowest: the data
        // do not prefer a richer one over it (Burnham & Anderson 2002).
        let lowest = sets.iter().map(|s| s.aicc).fold(f64::INFINITY, f64::min);
        let best = sets
            .into_iter()
            .find(|s| s.aicc <= lowest + AICC_SUPPORT)
            .expect("the lowest is within its own support");
        let _ = self.presumed.set(best.tried.terms.clone());
        if !shapes.is_empty() {
            let shape = best
                .tried
                .terms
                .first()
                .copied()
                .unwrap_or("the base alone");
            let why = format!(
                "the selection starts from {shape}, the classic shape the whole steady curve supports (small-sample Akaike criterion on all the training points: {}); it stays unless the set without it pays over it",
                text.join(", ")
            );
            say(&format!("auto: {why}"));
            *start = why;
        }
        Ok(best)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_viscous_rise_beside_the_stribeck_curve_is_named_once_and_its_presumption_passes_to_the_curve(
    ) {
        let (chosen, presumed) = without_subsumed(
            &["drivetrain viscous", "drivetrain Stribeck", "pre-sliding"],
            &["drivetrain viscous"],
        );
        assert_eq!(chosen, vec!["drivetrain Stribeck", "pre-sliding"]);
        assert_eq!(presumed, vec!["drivetrain Stribeck"]);
        let (chosen, presumed) = without_subsumed(&["drivetrain viscous"], &["drivetrain viscous"]);
        assert_eq!(chosen, vec!["drivetrain viscous"]);
        assert_eq!(presumed, vec!["drivetrain viscous"]);
    }
}
