//! `--fit auto`'s rule 9: a term that grows without end past the data
//! faster than the viscous rise is admitted into a set only where the
//! set's fit shows the start of that growth inside the data; rule 9b: a
//! term that bends is kept only where the set's fit shows the bend inside
//! the data; rule 9c: a viscous rise is bent only where the set's fit
//! tells its exponent from the straight rise's, and a Stribeck fall
//! shaped only where it tells its exponent from the Gaussian fall's and
//! shows the fall and the rise beside it ([`SHOWN_BESIDE`]).
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | c₂ | the drivetrain's quadratic loss, F = c₂ v² sgn v | N·s²/m² |
//! | δ | the viscous rise's exponent, F = b v_b sgn v \|v/v_b\|^δ | – |
//! | μ_r | the boundary rate, μ = μ_bl + μ_r asinh(\|v\|/v_a) | – |
//! | v_a | the boundary rate's activation speed, its bend | m/s |
//! | V | the data's top contact speed | m/s |
//!
//! Shown: the 95 % interval of c₂ excludes zero; of δ, excludes 1 (the
//! straight rise, past which the bent rise predicts less and less). Where it holds zero, the
//! folds may still favour the term (they reach one speed range past the
//! rest, about 1.25× on a steady curve, where a curvature of the noise or
//! of a Stribeck dip's bottom pays), and past the data it adds a growth
//! with v² that they never showed.
//!
//! A bend is shown where v_a and its 95 % interval lie below V, with a
//! finite lower end. Below v_a the rate rises linearly with |v|, past it
//! logarithmically. Where the interval reaches V, the rate is a viscous
//! rise inside the data that bends where they stop. The term being
//! added is then refused. A term already chosen gives way: a newcomer
//! that leaves the rate's bend unshown is tried in the set without the
//! rate (`trial.rs`). So does a quadratic or a bend chosen before: a
//! newcomer that leaves it unshown (the bristle's damping, beside which
//! a bend's exponent no longer differs from 1) explains what it did, and
//! the set is tried without it.

use super::candidates::CANDIDATES;
use super::driver::FitOutcome;

/// Terms whose effect past the data grows with the speed away from the
/// straight viscous rise a classic curve holds, each with the value of
/// its key that is that rise: the drivetrain quadratic (0; it grows
/// faster) and the bend (δ = 1; it grows slower). Such a term is admitted
/// into a set only where the set's fit tells its key from that value (its
/// 95 % interval excludes it), `select.rs` rules 9 and 9c: where the data
/// cannot, they do not show the start of the departure, and past them it
/// adds what they never showed.
pub const SHOWN_BEFORE_ADMITTED: &[(&str, f64)] = &[
    ("drivetrain quadratic", 0.0),
    (super::candidates::BEND, 1.0),
    (super::candidates::STRIBECK_SHAPE, 2.0),
];

/// Refinements of a form that the data tell from its null value only
/// where the keys beside it are shown as well (their 95 % intervals
/// exclude zero): the Stribeck fall's exponent beside the fall's level and
/// the viscous rise above it. The exponent shapes the approach to the
/// rise, and the approach and the rise's slope trade: where the slope is
/// not shown, a fall that ends slowly takes up what a steeper rise would,
/// and past the data the slope is what counts. On the steady families
/// 823 and 827 (`SHAPE=0.5`, ten speeds of 0.5–20 deg/s predicting 25–90)
/// six joints admitted the exponent with the slope's interval holding
/// zero: four predicted 1.5–7.1× worse than the best classic, two
/// 0.70–0.73×. The bend is not here: it shapes the rise itself, and its
/// own interval speaks for the rise past the data.
pub const SHOWN_BESIDE: &[(&str, &[&str])] = &[(
    super::candidates::STRIBECK_SHAPE,
    &["drivetrain.stribeck_n", "drivetrain.viscous_n_s_m"],
)];

/// The term of [`SHOWN_BEFORE_ADMITTED`] in the set `terms`, fitted as
/// `o`, whose key's 95 % interval at `o` does not exclude its straight
/// value (or has no finite bound: the data do not determine it), and why
/// the set is not admitted with it. None when every such term is shown.
pub fn unshown(terms: &[&'static str], o: &FitOutcome) -> Option<(&'static str, String)> {
    unshown_by(terms, |key| fitted(o, key))
}

/// The term whose bend must lie inside the data: the boundary rate.
pub const BENT: &str = "boundary rate";

/// Its bend: the activation speed v_a, in contact units (m/s).
const BEND_KEY: &str = "contact.boundary_activation_speed_m_s";

/// Why the boundary rate in `terms`, fitted as `o`, shows no bend: its
/// activation speed v_a or the upper end of v_a's 95 % interval reaches
/// `top_speed_m_s` (the data's top contact speed), or the interval has no
/// finite lower end. Such a rate is a viscous rise that bends where the
/// data stop: inside them the viscous term says the same, and past them
/// it flattens to a logarithmic growth they never showed (`select.rs`
/// rule 9b).
/// None when the set holds no rate or its bend is shown.
pub fn bend_unshown(terms: &[&'static str], o: &FitOutcome, top_speed_m_s: f64) -> Option<String> {
    if !terms.contains(&BENT) {
        return None;
    }
    bend_unshown_at(terms, fitted(o, BEND_KEY)?, top_speed_m_s)
}

/// [`bend_unshown`] with v_a's value and 95 % interval given.
fn bend_unshown_at(
    terms: &[&'static str],
    (value, lo, hi): (f64, f64, f64),
    top_speed_m_s: f64,
) -> Option<String> {
    if hi < top_speed_m_s && lo.is_finite() && value < top_speed_m_s {
        return None;
    }
    Some(format!(
        "{BENT}{}: its fit places `{BEND_KEY}` at {} with a 95 % interval [{}, {}] that reaches the data's top speed {}: a bend the data do not show",
        beside(terms, BENT),
        crate::text::Num::sig(value, 4),
        crate::text::Num::sig(lo, 3),
        crate::text::Num::sig(hi, 3),
        crate::text::Num::sig(top_speed_m_s, 4)
    ))
}

/// [`unshown`] with `fitted` giving a fitted key's value and 95 % interval
/// (None: the key is not fitted).
fn unshown_by(
    terms: &[&'static str],
    fitted: impl Fn(&str) -> Option<(f64, f64, f64)>,
) -> Option<(&'static str, String)> {
    for (t, straight) in SHOWN_BEFORE_ADMITTED
        .iter()
        .filter(|(t, _)| terms.contains(t))
    {
        let Some(c) = CANDIDATES.iter().find(|c| c.name == *t) else {
            continue;
        };
        for key in c.keys {
            let Some((value, lo, hi)) = fitted(key) else {
                continue;
            };
            let (lo_ok, hi_ok) = (
                lo > *straight && lo.is_finite(),
                hi < *straight && hi.is_finite(),
            );
            if !(lo_ok || hi_ok) {
                let (holds, what) = if *straight == 0.0 {
                    ("zero".to_string(), "grows without end")
                } else if *t == super::candidates::STRIBECK_SHAPE {
                    (format!("{straight} (the Gaussian fall)"), "falls otherwise")
                } else {
                    (format!("{straight} (the straight rise)"), "bends")
                };
                return Some((*t, format!(
                    "{t}{}: its fit gives `{key}` = {} with a 95 % interval [{}, {}] that holds {holds}; a term that {what} past the data is admitted only where they show it",
                    beside(terms, t),
                    crate::text::Num::sig(value, 4),
                    crate::text::Num::sig(lo, 3),
                    crate::text::Num::sig(hi, 3)
                )));
            }
        }
        if let Some(why) = beside_unshown(t, terms, &fitted) {
            return Some((*t, why));
        }
    }
    None
}

/// Why refinement `t` of `terms` is not admitted for a key beside it that
/// its fit leaves unshown ([`SHOWN_BESIDE`]: the interval holds zero or
/// has no finite bound); None when there is none.
fn beside_unshown(
    t: &'static str,
    terms: &[&'static str],
    fitted: impl Fn(&str) -> Option<(f64, f64, f64)>,
) -> Option<String> {
    let (_, keys) = SHOWN_BESIDE.iter().find(|(r, _)| *r == t)?;
    keys.iter().find_map(|key| {
        let (value, lo, hi) = fitted(key)?;
        let shown = (lo > 0.0 && lo.is_finite()) || (hi < 0.0 && hi.is_finite());
        (!shown).then(|| {
            format!(
                "{t}{}: its fit leaves `{key}` = {} with a 95 % interval [{}, {}] that holds zero; the fall's shape is told from the rise beside it only where the data show both",
                beside(terms, t),
                crate::text::Num::sig(value, 4),
                crate::text::Num::sig(lo, 3),
                crate::text::Num::sig(hi, 3)
            )
        })
    })
}

/// " beside a, b": the terms of `terms` other than `t`, as a refusal names
/// them; empty where `t` stands alone on the base (the boundary friction).
fn beside(terms: &[&'static str], t: &str) -> String {
    let others: Vec<&str> = terms.iter().copied().filter(|x| *x != t).collect();
    if others.is_empty() {
        String::new()
    } else {
        format!(" beside {}", others.join(", "))
    }
}

/// `key`'s value and 95 % interval at `o`; None when `key` is not fitted.
/// An interval not computed reads as NaN, which shows nothing.
fn fitted(o: &FitOutcome, key: &str) -> Option<(f64, f64, f64)> {
    let j = o.params.iter().position(|q| q.name == key)?;
    let (lo, hi) = o.statistics.interval95_of(j);
    Some((o.best[j], lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUADRATIC: &str = "drivetrain quadratic";
    const C2: &str = "drivetrain.quadratic_n_s2_m2";

    /// `unshown_by` with one fitted key, `C2`, at `value` in `[lo, hi]`.
    fn with_c2(terms: &[&'static str], (value, lo, hi): (f64, f64, f64)) -> Option<String> {
        unshown_by(terms, move |k| (k == C2).then_some((value, lo, hi))).map(|(t, why)| {
            assert_eq!(t, QUADRATIC);
            why
        })
    }

    #[test]
    fn a_quadratic_whose_interval_holds_zero_is_not_admitted_and_the_report_says_why() {
        let why = with_c2(&["drivetrain Stribeck", QUADRATIC], (5.0, -1.0, 11.0)).unwrap();
        assert_eq!(
            why,
            "drivetrain quadratic beside drivetrain Stribeck: its fit gives `drivetrain.quadratic_n_s2_m2` = 5 with a 95 % interval [-1, 11] that holds zero; a term that grows without end past the data is admitted only where they show it"
        );
    }

    #[test]
    fn a_quadratic_whose_interval_excludes_zero_on_either_side_is_admitted() {
        assert_eq!(with_c2(&[QUADRATIC], (5.0, 1.0, 9.0)), None);
        assert_eq!(with_c2(&[QUADRATIC], (-5.0, -9.0, -1.0)), None);
    }

    #[test]
    fn a_quadratic_whose_interval_was_not_computed_is_not_admitted() {
        assert!(with_c2(&[QUADRATIC], (5.0, f64::NAN, f64::NAN)).is_some());
        assert!(with_c2(&[QUADRATIC], (5.0, f64::NEG_INFINITY, f64::INFINITY)).is_some());
    }

    #[test]
    fn a_rate_whose_bend_or_its_interval_reaches_the_top_speed_shows_no_bend() {
        let terms = ["pre-sliding", BENT];
        assert_eq!(bend_unshown_at(&terms, (0.2, 0.1, 0.3), 0.5), None);
        let why = bend_unshown_at(&terms, (0.2, 0.1, 0.6), 0.5).unwrap();
        assert_eq!(
            why,
            "boundary rate beside pre-sliding: its fit places `contact.boundary_activation_speed_m_s` at 0.2 with a 95 % interval [0.1, 0.6] that reaches the data's top speed 0.5: a bend the data do not show"
        );
        assert!(bend_unshown_at(&terms, (0.5, 0.4, 0.45), 0.5).is_some());
        assert!(bend_unshown_at(&terms, (1e-8, 0.0, f64::INFINITY), 0.5).is_some());
        assert!(bend_unshown_at(&terms, (0.2, f64::NAN, f64::NAN), 0.5).is_some());
    }

    #[test]
    fn a_refusal_of_a_term_alone_on_the_base_names_no_empty_set_beside_it() {
        let why = bend_unshown_at(&[BENT], (0.2, 0.1, 0.6), 0.5).unwrap();
        assert!(why.starts_with("boundary rate: its fit places"), "{why}");
    }

    #[test]
    fn a_bend_whose_exponents_interval_holds_the_straight_rise_is_not_admitted() {
        const DELTA: &str = "drivetrain.viscous_exponent";
        let bend = super::super::candidates::BEND;
        let with = |(value, lo, hi): (f64, f64, f64)| {
            unshown_by(&["drivetrain viscous", bend], move |k| {
                (k == DELTA).then_some((value, lo, hi))
            })
            .map(|(t, why)| {
                assert_eq!(t, bend);
                why
            })
        };
        let why = with((0.45, 0.08, 2.5)).unwrap();
        assert_eq!(
            why,
            "drivetrain bend beside drivetrain viscous: its fit gives `drivetrain.viscous_exponent` = 0.45 with a 95 % interval [0.08, 2.5] that holds 1 (the straight rise); a term that bends past the data is admitted only where they show it"
        );
        assert_eq!(with((0.62, 0.55, 0.69)), None);
        assert!(with((0.62, f64::NAN, f64::NAN)).is_some());
        // Zero, the quadratic's straight value, is not the bend's.
        assert_eq!(with((0.62, 0.3, 0.9)), None);
    }

    #[test]
    fn a_stribeck_exponent_beside_a_rise_its_fit_leaves_unshown_is_not_admitted() {
        // Joint 4 of the steady family 827 (SHAPE=0.5): alpha_s 1.247 in
        // [1.02, 1.52], told from 2, but the viscous key's interval
        // [-851, 1.01e4] holds zero; admitted, it predicted 25-90 deg/s
        // 7.1x worse than the Stribeck classic.
        let shape = super::super::candidates::STRIBECK_SHAPE;
        let terms = ["drivetrain Stribeck", shape];
        let with = |b: (f64, f64, f64)| {
            unshown_by(&terms, move |k| match k {
                "drivetrain.stribeck_exponent" => Some((1.247, 1.023, 1.519)),
                "drivetrain.stribeck_n" => Some((-75.7, -84.9, -66.5)),
                "drivetrain.viscous_n_s_m" => Some(b),
                _ => None,
            })
        };
        let (t, why) = with((4627.0, -851.3, 10105.0)).unwrap();
        assert_eq!(t, shape);
        assert_eq!(
            why,
            "drivetrain Stribeck shape beside drivetrain Stribeck: its fit leaves `drivetrain.viscous_n_s_m` = 4627 with a 95 % interval [-851, 10100] that holds zero; the fall's shape is told from the rise beside it only where the data show both"
        );
        // The rise shown (the time-series draw d199): admitted.
        assert_eq!(with((1.8302e5, 1.8276e5, 1.8329e5)), None);
        // The bend is not held to the keys beside it.
        let bend = super::super::candidates::BEND;
        let bent = unshown_by(&["drivetrain viscous", bend], |k| match k {
            "drivetrain.viscous_exponent" => Some((0.1, 0.0138, 0.727)),
            "drivetrain.viscous_n_s_m" => Some((6.66e4, -4.37e4, 1.77e5)),
            _ => None,
        });
        assert_eq!(bent, None);
    }

    #[test]
    fn a_set_without_such_a_term_is_admitted_whatever_its_keys() {
        assert_eq!(with_c2(&["drivetrain viscous"], (5.0, -1.0, 11.0)), None);
    }
}
