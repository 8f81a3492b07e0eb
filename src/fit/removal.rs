//! Terms taken away during `--fit auto`'s selection (`select.rs`, rules
//! 2 and 4): a term chosen earlier that no longer pays beside a later
//! one; a term whose key ended at zero or at a bound, or correlates above
//! [`super::stats::CORRELATION_FLAG`] with another parameter; of two
//! confounded terms (a key of one correlated so with a key of the other,
//! not a part and the term it belongs to), one. A term gives way to a
//! lighter form of it where one fits (the Stribeck curve to its viscous
//! rise) before it is removed. Whether a
//! change pays is [`pays`], the one yardstick of the selection and of its
//! confirmation (`confirm.rs`).

use super::candidates::{is_part, lighter_forms, needs, needs_unheld, one_element, CANDIDATES};
use super::cross_validate::{paired, TERM_COST};
use super::prepared::Prepared;
use super::trial::{Ctx, Scored, Tried};
use super::FitError;
use rayon::prelude::*;

/// Whether going from `from` to `to` pays: it lowers the folds' mean
/// squared error by more than the standard error of that lowering and by
/// more than [`TERM_COST`] of it. Returns (pays, lowering, its SE, share).
pub(super) fn pays(from: &Tried, to: &Tried) -> (bool, f64, f64, f64) {
    let (gain, se) = paired(&from.fold_mse, &to.fold_mse);
    let mse = from.cv_rms * from.cv_rms;
    let share = gain / mse;
    (
        gain.is_finite() && gain > se && gain > TERM_COST * mse,
        gain,
        se,
        share,
    )
}

/// Whether a part of a chosen term ([`super::candidates::is_part`]) stays:
/// the set `with` it predicts the folds no worse than the set `without`
/// it (the folds' mean squared error not raised on average). A part is
/// not a rival explanation that must pay for itself; it goes when the
/// folds predict worse with it, or by a flag (rule 4).
pub(super) fn keeps_part(without: &Tried, with: &Tried) -> bool {
    let (gain, _) = paired(&without.fold_mse, &with.fold_mse);
    gain.is_finite() && gain >= 0.0
}

impl Ctx<'_> {
    /// Whether term `t` may leave the set `with` it for the set `without`
    /// it (or its lighter form): a part of a chosen term when the folds
    /// predict worse with it; a presumed term (rule 7) when the set
    /// without it pays over the set with it; any other term when it does
    /// not pay over the set without it.
    pub(super) fn may_leave(&self, t: &str, without: &Tried, with: &Tried) -> bool {
        if is_part(t) {
            !keeps_part(without, with)
        } else if self.is_presumed(t) {
            pays(with, without).0
        } else {
            !pays(without, with).0
        }
    }

    /// Whether `t` is a presumed term (`select.rs`, rule 7).
    pub(super) fn is_presumed(&self, t: &str) -> bool {
        self.presumed.get().is_some_and(|p| p.contains(&t))
    }

    /// Remove, one at a time, each chosen term (but `newest`) that does not
    /// pay beside the others any more: the one whose removal costs least.
    pub(super) fn prune(
        &self,
        mut current: Scored,
        newest: &'static str,
        tried: &mut Vec<Tried>,
        removed: &mut Vec<String>,
        say: &(dyn Fn(&str) + Sync),
    ) -> Result<Scored, FitError> {
        loop {
            let set = &current.tried.terms;
            let older: Vec<&'static str> = set.iter().copied().filter(|t| *t != newest).collect();
            // A term others need stays while they are there; it may still
            // give way to a lighter form that keeps what they need (the
            // Stribeck curve to its viscous rise beside the quadratic).
            let needed = |t: &str| set.iter().any(|o| needs(o, t, set));
            let alternatives: Vec<(&'static str, Option<&'static str>, Vec<&'static str>)> = older
                .iter()
                .flat_map(|t| lighter(set, t, None))
                .filter(|(t, form, terms)| {
                    !needed(t) || (form.is_some() && terms.iter().all(|o| !needs_unheld(o, terms)))
                })
                .collect();
            if alternatives.is_empty() {
                return Ok(current);
            }
            let scored: Vec<(&'static str, Option<&'static str>, Scored)> = alternatives
                .par_iter()
                .map(|(t, form, terms)| Ok((*t, *form, self.try_set(terms, &current.optimum)?)))
                .collect::<Result<_, FitError>>()?;
            tried.extend(scored.iter().map(|(_, _, s)| s.tried.clone()));
            // The one whose removal (or reduction) costs least, if the term
            // does not pay over it (a part: if the set predicts worse with it).
            let Some((t, form, lighter)) = scored
                .into_iter()
                .filter(|(t, _, s)| self.may_leave(t, &s.tried, &current.tried))
                .min_by(|a, b| a.2.tried.cv_rms.total_cmp(&b.2.tried.cv_rms))
            else {
                return Ok(current);
            };
            let change = change_text(t, form);
            say(&format!(
                "auto: {change}: no longer pays beside {newest} (CV RMS {})",
                cv(&lighter.tried, self.p)
            ));
            removed.push(format!(
                "{change}: no longer paid for itself beside {newest}"
            ));
            current = lighter;
        }
    }

    /// Drop the terms whose keys ended at zero or at a bound, or correlate
    /// above [`super::stats::CORRELATION_FLAG`] with another parameter
    /// (the latest chosen first), refitting after each. A term whose key
    /// correlates so with a key of another chosen term is confounded with
    /// it: the data cannot tell the two apart, and each extrapolates its
    /// own way, so one of them goes, whichever the folds miss least. Any
    /// other flagged term goes unless the set without it cross-validates
    /// worse by more than a term's cost (a flag makes a term suspect; the
    /// folds decide).
    pub(super) fn drop_flagged(
        &self,
        mut current: Scored,
        tried: &mut Vec<Tried>,
        removed: &mut Vec<String>,
        say: &(dyn Fn(&str) + Sync),
    ) -> Result<Scored, FitError> {
        let mut kept: Vec<&'static str> = Vec::new();
        loop {
            let Some(f) = flagged(&current, &kept) else {
                return Ok(current);
            };
            // Its lighter forms without the flagged key, then the set
            // without it; when confounded, the same for the other term.
            let mut options = lighter(&current.tried.terms, f.term, Some(f.key));
            if let Some((other, other_key)) = f.confounded {
                options.extend(lighter(&current.tried.terms, other, Some(other_key)));
            }
            let scored: Vec<(&'static str, Option<&'static str>, Scored)> = options
                .par_iter()
                .map(|(t, form, terms)| Ok((*t, *form, self.try_set(terms, &current.optimum)?)))
                .collect::<Result<_, FitError>>()?;
            tried.extend(scored.iter().map(|(_, _, s)| s.tried.clone()));
            let best = scored
                .into_iter()
                .filter(|(t, _, s)| {
                    if self.is_presumed(t) {
                        // Confounded or flagged, a presumed shape leaves
                        // only when the set without it pays over it.
                        pays(&current.tried, &s.tried).0
                    } else {
                        f.confounded.is_some() || !pays(&s.tried, &current.tried).0
                    }
                })
                .min_by(|a, b| a.2.tried.cv_rms.total_cmp(&b.2.tried.cv_rms));
            let Some((t, form, next)) = best else {
                say(&format!(
                    "auto: {} kept: {}, but the set without it cross-validates worse",
                    f.term, f.why
                ));
                kept.push(f.term);
                continue;
            };
            let change = change_text(t, form);
            let outcome = if f.confounded.is_some() {
                "so one of the two goes (the one the folds miss least)"
            } else {
                "and that set predicts as well"
            };
            say(&format!(
                "auto: {change}: {}, {outcome} (CV RMS {})",
                f.why,
                cv(&next.tried, self.p)
            ));
            removed.push(format!("{change}: {}, {outcome}", f.why));
            current = next;
        }
    }
}

/// A flagged term of a set: its key that ended at zero or at a bound or
/// correlates above [`super::stats::CORRELATION_FLAG`] with another, why,
/// and the other chosen term whose key that is, if any.
pub(super) struct Flagged {
    pub(super) term: &'static str,
    pub(super) key: &'static str,
    pub(super) why: String,
    /// The other term and its key, when the flag is a correlation with a
    /// key of another chosen term (not the base's, not a given name's).
    pub(super) confounded: Option<(&'static str, &'static str)>,
}

/// The latest flagged term of `s` not in `kept`.
pub(super) fn flagged(s: &Scored, kept: &[&'static str]) -> Option<Flagged> {
    let terms = &s.tried.terms;
    terms
        .iter()
        .rev()
        .filter(|t| !kept.contains(t))
        .find_map(|t| {
            let c = CANDIDATES.iter().find(|c| c.name == *t)?;
            c.keys.iter().find_map(|k| {
                let f = s.flags.iter().find(|f| f.name == *k)?;
                if f.edge {
                    return Some(Flagged {
                        term: t,
                        key: k,
                        why: format!("{k} ended at zero or at a bound"),
                        confounded: None,
                    });
                }
                if f.rho <= super::stats::CORRELATION_FLAG {
                    return None;
                }
                let partner = f.partner.as_deref().unwrap_or("another parameter");
                let confounded = terms.iter().filter(|o| *o != t).find_map(|o| {
                    let other = CANDIDATES.iter().find(|c| c.name == *o)?;
                    let key = other.keys.iter().find(|x| **x == partner)?;
                    // A part and the term it belongs to are one element,
                    // not two explanations: their correlation is a plain flag.
                    (!c.keys.contains(key) && !one_element(t, o)).then_some((*o, *key))
                });
                let rho = crate::text::Num::sig(f.rho, 3);
                let why = match confounded {
                    Some((o, _)) => format!(
                    "{k} correlates {rho} with {partner} ({o}): the data cannot tell {t} from {o}"
                ),
                    None => format!("{k} correlates {rho} with {partner}"),
                };
                Some(Flagged {
                    term: t,
                    key: k,
                    why,
                    confounded,
                })
            })
        })
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

/// "− t", or "t → form" when a lighter form takes its place.
pub(super) fn change_text(t: &str, form: Option<&str>) -> String {
    match form {
        Some(f) => format!("{t} → {f}"),
        None => format!("− {t}"),
    }
}

pub(super) fn cv(t: &Tried, p: &Prepared) -> String {
    format!(
        "{} {}",
        crate::text::Num::sig(t.cv_rms, 5),
        p.data.units.force()
    )
}

#[cfg(test)]
mod tests {
    use super::super::trial::KeyFlag;
    use super::*;

    fn scored(terms: &[&'static str]) -> Scored {
        Scored {
            tried: Tried {
                terms: terms.to_vec(),
                fold_mse: vec![1.0],
                cv_rms: 1.0,
                simulations: 0,
            },
            optimum: Vec::new(),
            flags: Vec::new(),
            aicc: f64::NAN,
        }
    }

    fn with_flag(terms: &[&'static str], key: &str, rho: f64, partner: &str) -> Scored {
        let mut s = scored(terms);
        s.flags = vec![KeyFlag {
            name: key.into(),
            edge: false,
            rho,
            partner: Some(partner.into()),
        }];
        s
    }

    #[test]
    fn a_term_correlated_with_another_chosen_terms_key_is_confounded_with_that_term() {
        let set = ["drivetrain quadratic", "drivetrain Stribeck"];
        let q = "drivetrain.quadratic_n_s2_m2";
        let f = flagged(&with_flag(&set, q, 0.987, "drivetrain.viscous_n_s_m"), &[]).unwrap();
        assert_eq!((f.term, f.key), ("drivetrain quadratic", q));
        assert_eq!(
            f.confounded,
            Some(("drivetrain Stribeck", "drivetrain.viscous_n_s_m"))
        );
        assert!(
            f.why
                .contains("cannot tell drivetrain quadratic from drivetrain Stribeck"),
            "{}",
            f.why
        );
    }

    #[test]
    fn a_term_correlated_with_the_base_or_with_its_own_key_is_only_suspect() {
        let set = ["drivetrain Stribeck"];
        // With the base's boundary friction: the folds decide.
        let base = with_flag(
            &set,
            "drivetrain.stribeck_n",
            0.99,
            "contact.boundary_friction",
        );
        let f = flagged(&base, &[]).unwrap();
        assert_eq!(f.confounded, None);
        assert!(
            f.why
                .ends_with("correlates 0.99 with contact.boundary_friction"),
            "{}",
            f.why
        );
        // With a key of its own: not another term.
        let own = with_flag(
            &set,
            "drivetrain.stribeck_n",
            0.99,
            "drivetrain.stribeck_speed_m_s",
        );
        assert_eq!(flagged(&own, &[]).unwrap().confounded, None);
        // At 0.95 or below: no flag; a term kept is not flagged again.
        let low = with_flag(
            &set,
            "drivetrain.stribeck_n",
            0.95,
            "contact.boundary_friction",
        );
        assert!(flagged(&low, &[]).is_none());
        assert!(flagged(&base, &["drivetrain Stribeck"]).is_none());
    }

    #[test]
    fn the_bristles_damping_correlated_with_its_stiffness_is_a_plain_flag_not_a_confounding() {
        // One bristle, one element: the correlation of its damping with its
        // stiffness does not make them rivals that "extrapolate each their
        // own way". On the joint draw d16 (rho -0.951, sigma0 611 +- 0.7 %,
        // sigma1 3.28 +- 2.8 %) dropping the damping as confounded lost
        // 1.294x LuGre on the faster motion (README, "Three machines, one rule").
        let set = ["pre-sliding", "drivetrain Stribeck", "pre-sliding damping"];
        let (k0, k1) = (
            "contact.presliding_stiffness_n_m",
            "contact.presliding_damping_n_s_m",
        );
        let f = flagged(&with_flag(&set, k1, 0.988, k0), &[]).unwrap();
        assert_eq!((f.term, f.confounded), ("pre-sliding damping", None));
        assert!(f.why.contains("correlates"), "{}", f.why);
        // The flag on the stiffness's side, against the damping: the same.
        let f = flagged(&with_flag(&set, k0, 0.988, k1), &[]).unwrap();
        assert_eq!((f.term, f.confounded), ("pre-sliding", None));
        // Another term's key correlated with the stiffness is a confounding.
        let f = flagged(&with_flag(&set, "drivetrain.stribeck_n", 0.97, k0), &[]);
        assert_eq!(
            f.map(|f| (f.term, f.confounded)),
            Some(("drivetrain Stribeck", Some(("pre-sliding", k0))))
        );
        // Removing the stiffness takes the damping with it (it requires it).
        let without = lighter(&set, "pre-sliding", Some(k0));
        assert_eq!(without.last().unwrap().2, vec!["drivetrain Stribeck"]);
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
