//! Rule 7 of `--fit auto` (`select.rs`): a steady curve starts from its
//! classic shape — the viscous rise or the Stribeck curve, the simplest
//! whose small-sample Akaike criterion on all the training points is
//! within [`AICC_SUPPORT`] of the lowest — and that shape is presumed with
//! its viscous rise: the curve gives way only to its rise, and the rise
//! goes only when its key ends at zero (`removal.rs`, `confirm.rs`).
//! Rule 7b: where the direction asymmetry lowers the criterion by more
//! than [`AICC_SUPPORT`], the shapes are compared beside it.

use super::candidates::{lighter_forms, set_keys, Candidate, ASYMMETRY, BEND, STRIBECK, VISCOUS};
use super::trial::{Ctx, Scored, Tried, AICC_SUPPORT};
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

/// The classic shapes of a steady curve that are candidates here (rule
/// 7): the viscous rise (with the base, Coulomb + viscous) and the
/// Stribeck curve.
pub(super) fn classic_shapes(candidates: &[&'static Candidate]) -> Vec<&'static str> {
    [VISCOUS, STRIBECK]
        .into_iter()
        .filter(|s| candidates.iter().any(|c| c.name == *s))
        .collect()
}

/// The start of a steady curve (rule 7), an index of `aiccs` (the base
/// alone, then each classic shape): the simplest within [`AICC_SUPPORT`] of
/// the lowest, where the data do not prefer a richer shape over it
/// (Burnham & Anderson 2002). Where the viscous rise is a candidate
/// (`rises`), the flat base is not one of the shapes: a lubricated drive's
/// friction rises with speed, and the fit decides by how much (its
/// viscous key bounded at zero). Where no rising shape could be fitted
/// (its criterion infinite: a curve at one speed, or with no more points
/// than the shape has keys and one), the data cannot show a rise, and the
/// start is the base.
pub(super) fn start_shape(aiccs: &[f64], rises: bool) -> usize {
    let from = usize::from(rises).min(aiccs.len().saturating_sub(1));
    let lowest = aiccs[from..].iter().copied().fold(f64::INFINITY, f64::min);
    if !lowest.is_finite() && lowest > 0.0 {
        return 0;
    }
    (from..aiccs.len())
        .find(|&k| aiccs[k] <= lowest + AICC_SUPPORT)
        .unwrap_or(from)
}

/// Rule 7b: whether the classic shapes are compared beside the direction
/// asymmetry — the criteria `offset` of each set with it, against `plain`
/// without it. A curve whose level differs by direction (a torque
/// sensor's offset, a load lifted one way) leaves that offset in every
/// shape's residuals, and beside it the shapes' criteria differ by noise;
/// where the asymmetry lowers the lowest criterion by more than
/// [`AICC_SUPPORT`], the data resolve it, and the shapes are compared
/// with it.
pub(super) fn beside_offset(plain: &[f64], offset: &[f64]) -> bool {
    let lowest = |a: &[f64]| a.iter().copied().fold(f64::INFINITY, f64::min);
    lowest(offset) < lowest(plain) - AICC_SUPPORT
}

/// The terms presumed from the start `terms`: those, and each one's
/// lighter classic shape among `shapes` (the Stribeck curve's viscous
/// rise), so that a curve that gives way to it (rule 4) leaves a rise, not
/// the flat base, presumed.
pub(super) fn presumed_terms(terms: &[&'static str], shapes: &[&'static str]) -> Vec<&'static str> {
    let mut presumed = terms.to_vec();
    for t in terms {
        presumed.extend(
            lighter_forms(t, terms)
                .into_iter()
                .filter(|f| shapes.contains(f)),
        );
    }
    presumed
}

/// A shape's name: its terms but the asymmetry beside them ("drivetrain
/// viscous + drivetrain bend"), or "the base alone".
fn shape_name(terms: &[&'static str]) -> String {
    let named: Vec<&str> = terms.iter().copied().filter(|t| *t != ASYMMETRY).collect();
    if named.is_empty() {
        "the base alone".into()
    } else {
        named.join(" + ")
    }
}

/// Each shape's criterion in words ("drivetrain viscous −43.6, …"), a
/// set beside the asymmetry named by its shape; a set that has none says
/// why ("not admitted (below)": rule 9c refused its bend), not "inf".
fn criteria(sets: &[Scored]) -> String {
    sets.iter()
        .map(|s| match s.tried.unscored {
            Some(why) if !s.aicc.is_finite() => {
                format!("{} {why}", shape_name(&s.tried.terms))
            }
            _ => format!("{} {:.1}", shape_name(&s.tried.terms), s.aicc),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

impl Ctx<'_> {
    /// Rule 7b: each of `sets` (the base, then each shape) fitted beside
    /// the direction asymmetry, each warm from the one before (the base's
    /// offset, then the rise beside it, then the curve, whose keys hold the
    /// rise's), not from its own fit without the offset, which the offset
    /// distorted.
    fn beside_asymmetry(
        &self,
        sets: &[Scored],
        tried: &mut Vec<Tried>,
    ) -> Result<Vec<Scored>, FitError> {
        let mut with: Vec<Scored> = Vec::with_capacity(sets.len());
        for s in sets {
            let terms: Vec<&'static str> =
                s.tried.terms.iter().copied().chain([ASYMMETRY]).collect();
            let warm = with.last().map_or(&s.optimum, |w| &w.optimum);
            let t = self.try_set(&terms, warm)?;
            tried.push(t.tried.clone());
            with.push(t);
        }
        Ok(with)
    }

    /// Rule 7: on a steady curve the selection starts from the classic
    /// shape that the whole curve supports ([`start_shape`]: the viscous
    /// rise or the Stribeck curve, the simplest whose small-sample Akaike
    /// criterion on all the training points ([`super::trial::aicc`]) is
    /// within [`AICC_SUPPORT`] of the lowest), and that shape is presumed
    /// with its viscous rise ([`presumed_terms`]; how it may leave:
    /// `removal::holds_rise`, `removal::presumed_gives_way`). With `bends`
    /// each shape is also tried with its viscous rise bent (rule 7c: the
    /// bend is a shape of the rise, as the Stribeck curve is of the
    /// level, and is compared with them, one key more than its shape's,
    /// where rule 9c admits it); the bend itself is not presumed. With
    /// `shapes` empty (a time series) the start is the base.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn presume(
        &self,
        base: Scored,
        shapes: &[&'static str],
        offset: bool,
        bends: bool,
        tried: &mut Vec<Tried>,
        start: &mut String,
        say: &(dyn Fn(&str) + Sync),
    ) -> Result<Scored, FitError> {
        let mut sets = vec![base];
        for s in shapes {
            let t = self.try_set(&[*s], &sets[0].optimum)?;
            tried.push(t.tried.clone());
            let warm = t.optimum.clone();
            sets.push(t);
            if bends {
                let b = self.try_set(&[*s, BEND], &warm)?;
                tried.push(b.tried.clone());
                sets.push(b);
            }
        }
        let aiccs: Vec<f64> = sets.iter().map(|s| s.aicc).collect();
        let mut list = criteria(&sets);
        let mut compared = aiccs;
        if offset && !shapes.is_empty() {
            let with = self.beside_asymmetry(&sets, tried)?;
            let offset_aiccs: Vec<f64> = with.iter().map(|s| s.aicc).collect();
            if beside_offset(&compared, &offset_aiccs) {
                list = format!(
                    "{list}; beside the direction asymmetry, which the criterion resolves (its lowest more than {AICC_SUPPORT} lower with it), and by which the shapes are compared: {}",
                    criteria(&with)
                );
                compared = offset_aiccs;
            }
        }
        let best = sets
            .into_iter()
            .nth(start_shape(&compared, shapes.contains(&VISCOUS)))
            .expect("start_shape is an index of the sets");
        let unbent: Vec<&'static str> = best
            .tried
            .terms
            .iter()
            .copied()
            .filter(|t| *t != BEND)
            .collect();
        let presumed = presumed_terms(&unbent, shapes);
        let _ = self.presumed.set(presumed);
        if !shapes.is_empty() {
            let shape = unbent.first().copied().unwrap_or("the base alone");
            let stays = if shape == VISCOUS {
                "it stays unless its key ends at zero"
            } else if shape == STRIBECK {
                "it stays unless it gives way to its viscous rise (which pays over it, or, its keys flagged, predicts the folds no worse within 10 of its Akaike criterion); the rise stays unless its key ends at zero"
            } else {
                "it stays unless the set without it pays over it"
            };
            let why = if best.tried.terms.is_empty() {
                format!(
                    "the selection starts from the base alone: no rising classic shape could be fitted and scored on these points (a shape's criterion needs more points than its keys + 1; small-sample Akaike criterion on all the training points: {list})"
                )
            } else {
                format!(
                    "the selection starts from {}, the classic shape the whole steady curve supports (small-sample Akaike criterion on all the training points: {list}); {stays}{}",
                    shape_name(&best.tried.terms),
                    if best.tried.terms.contains(&BEND) {
                        "; the bend is not presumed"
                    } else {
                        ""
                    }
                )
            };
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
    fn the_shapes_are_compared_beside_the_direction_asymmetry_only_where_it_is_resolved() {
        // An offset of 0.3 N·m on a 2 N·m rise (tests/fit_direction_offset.rs).
        assert!(beside_offset(
            &[-36.5, -43.6, -37.7],
            &[-53.1, -132.1, -153.5]
        ));
        // A symmetric curve: the asymmetry's key costs more than it gains.
        assert!(!beside_offset(
            &[-36.5, -163.6, -170.0],
            &[-34.3, -161.4, -171.9]
        ));
        // A curve driven one way: the asymmetry is the level's twin.
        assert!(!beside_offset(&[-80.0, -120.0], &[-77.8, -117.8]));
    }

    #[test]
    fn a_steady_curve_starts_from_the_simplest_rising_shape_its_criterion_supports() {
        // The base alone lowest: a rise all the same, the viscous rise.
        assert_eq!(start_shape(&[-226.1, -226.0, -223.5], true), 1);
        // The Stribeck curve 5.7 below the viscous rise: the curve.
        assert_eq!(start_shape(&[-63.3, -164.3, -170.0], true), 2);
        // 1.6 below: within the support, the simpler viscous rise.
        assert_eq!(start_shape(&[-186.2, -201.6, -203.2], true), 1);
        // No viscous rise among the candidates: the base may be the start.
        assert_eq!(start_shape(&[-226.1, -223.5], false), 0);
        assert_eq!(start_shape(&[-10.0], false), 0);
        // A shape that could not be fitted (+inf) is never the start.
        assert_eq!(start_shape(&[-50.0, f64::INFINITY, -40.0], true), 2);
        // None could (a curve at one speed): the base, not a rise the
        // data cannot show.
        assert_eq!(start_shape(&[-20.3, f64::INFINITY, f64::INFINITY], true), 0);
    }

    #[test]
    fn a_shape_refused_before_its_criterion_says_why_not_inf() {
        let rise = Scored::with_folds(&[VISCOUS], &[1.0], -43.62);
        let mut bent = Scored::with_folds(&[VISCOUS, BEND], &[f64::INFINITY], f64::INFINITY);
        bent.tried.unscored = Some("not admitted (below)");
        assert_eq!(
            criteria(&[rise, bent]),
            "drivetrain viscous -43.6, drivetrain viscous + drivetrain bend not admitted (below)"
        );
    }

    #[test]
    fn the_presumption_of_a_curve_covers_its_viscous_rise() {
        let shapes = [VISCOUS, STRIBECK];
        assert_eq!(
            presumed_terms(&[STRIBECK], &shapes),
            vec![STRIBECK, VISCOUS]
        );
        assert_eq!(presumed_terms(&[VISCOUS], &shapes), vec![VISCOUS]);
        assert!(presumed_terms(&[], &shapes).is_empty());
    }

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
