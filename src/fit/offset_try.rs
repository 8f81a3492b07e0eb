//! `--fit auto`'s rule 12: where the direction asymmetry was chosen on a
//! time series with no input map fitted, an offset in the friction as
//! derived is tried as a map, and kept only where it pays.
//!
//! ```text
//! F_data = F_model + c        (the map: the friction column read as F_data − c)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_data | the friction as the data give it (a drive's torque less inertia and gravity) | N or N·m |
//! | F_model | our model's friction | N or N·m |
//! | c | the offset: a torque or current sensor's zero, a gravity model's error at the mean pose | N or N·m |
//!
//! The asymmetry is a friction level that differs by direction while
//! sliding; with the pre-sliding bristle it rides on the bristle's level,
//! so it vanishes at rest. An offset stays at rest: the asymmetry carries
//! it while the joint slides and misses it at every reversal. Measured on
//! LuGre joints with an offset (`docs/fit-auto-judged.md`, stop 97), the
//! asymmetry alone left ours 1.06–1.86× the error of the same joints
//! without the offset, and the offset fitted as a map 0.81–1.01×.
//!
//! So the calibration is run again with the map `friction_offset` fitted
//! in every set (as `--friction '(FRICTION) - friction_offset' --map
//! friction_offset=0 --fit auto,friction_offset` would), within ± the
//! data's largest |friction|. The two are weighed at the optimum each would
//! ship, on the same folds, by the rule every term meets
//! (`removal.rs`, `pays`): the offset is kept only if it lowers the
//! folds' mean squared error by more than its standard error and by more
//! than the cost of a term. An offset is not friction: the fitted file
//! holds the friction without it (a sensor's zero must not be fed forward;
//! a weight on a vertical axis must, and is the user's to add).

use super::candidates::ASYMMETRY;
use super::compare::OursFitted;
use super::cross_validate::cv_rms;
use super::inputs::DataRequest;
use super::prepared::Prepared;
use super::select::Selection;
use super::trial::Tried;
use super::ParamSpec;
use crate::text::Num;

/// The offset's map coefficient.
pub const OFFSET: &str = "friction_offset";

/// Whether rule 12 applies: the asymmetry chosen on a time series with no
/// map fitted (a map the user fits, an offset or an area, is the user's).
pub fn applies(chosen: &[&str], time_series: bool, maps_fitted: bool) -> bool {
    time_series && !maps_fitted && chosen.contains(&ASYMMETRY)
}

/// The data and fitted parameters of a calibration (`data`, `params`)
/// again with the offset fitted as a map, when rule 12 applies to `s` on
/// `p` (None also when the mapping names the offset's coefficient already).
pub fn with_offset(
    data: &DataRequest,
    params: &[ParamSpec],
    p: &Prepared,
    s: Option<&Selection>,
) -> Option<(DataRequest, Vec<ParamSpec>)> {
    let time_series = p.data.train.iter().any(|t| !t.steady);
    let s = s?;
    if !applies(&s.chosen, time_series, !p.map_fit.is_empty())
        || data.friction_offset.is_some()
        || data.mapping.coefficients.iter().any(|(c, _)| c == OFFSET)
    {
        return None;
    }
    let mut data = data.clone();
    data.friction_offset = Some(OFFSET.to_string());
    data.mapping.coefficients.push((OFFSET.to_string(), 0.0));
    let bound = p.scale.friction_n;
    let mut params = params.to_vec();
    params.push(ParamSpec {
        name: OFFSET.to_string(),
        bounds: Some((-bound, bound)),
        start: Some(0.0),
        if_chosen: false,
    });
    Some((data, params))
}

/// Rule 12's verdict: the two calibrations weighed on the same folds.
#[derive(Debug, Clone, PartialEq)]
pub struct OffsetVerdict {
    /// The offset pays: the calibration with it is shipped.
    pub kept: bool,
    /// CV RMS without the offset and with it (at each final optimum).
    pub cv_without: f64,
    /// CV RMS with the offset.
    pub cv_with: f64,
    /// The folds' mean squared error lowered by the offset, and the
    /// lowering's standard error.
    pub gain: f64,
    /// The lowering's standard error.
    pub se: f64,
    /// The fitted offset.
    pub offset: f64,
    /// The terms chosen beside the offset.
    pub chosen_with: Vec<&'static str>,
}

/// Weighs the calibration `without` the offset against the one `with` it
/// (each its final fit with the folds' mean squared errors, and the
/// selection `s_with` of the latter). None when either was not
/// cross-validated.
pub fn weigh(without: &OursFitted, with: &OursFitted, s_with: &Selection) -> Option<OffsetVerdict> {
    let tried = |o: &OursFitted, terms: &[&'static str]| -> Option<Tried> {
        let m = o.outcome.fold_mse.clone()?;
        Some(Tried {
            terms: terms.to_vec(),
            cv_rms: cv_rms(&m),
            fold_mse: m,
            simulations: 0,
            unscored: None,
        })
    };
    let a = tried(without, &[])?;
    let b = tried(with, &s_with.chosen)?;
    if a.fold_mse.len() != b.fold_mse.len() {
        return None;
    }
    let (kept, gain, se, _) = super::removal::pays(&a, &b);
    let offset = with
        .map
        .iter()
        .find(|(n, _)| n == OFFSET)
        .map_or(0.0, |(_, v)| *v);
    Some(OffsetVerdict {
        kept,
        cv_without: a.cv_rms,
        cv_with: b.cv_rms,
        gain,
        se,
        offset,
        chosen_with: s_with.chosen.clone(),
    })
}

/// Rule 12's paragraph of the selection's section: what was tried and
/// what it gave (`verdict`), or why it could not be weighed (`failed`).
pub fn paragraph(
    verdict: Option<&OffsetVerdict>,
    failed: Option<&str>,
    units: super::Units,
) -> String {
    let u = units.force();
    let head = "**An offset, or a level that differs by direction? (rule 12)** The direction \
        asymmetry was chosen: a friction level higher one way than the other while sliding, \
        which vanishes at rest. An offset in the friction as derived (a torque or current \
        sensor's zero, a gravity model's error) stays at rest as well, which the asymmetry \
        misses at every reversal. So the calibration was run again with an offset fitted as \
        an input map in every set (the friction read as FRICTION − friction_offset).";
    let Some(v) = verdict else {
        let why = failed.unwrap_or("it was not cross-validated");
        return format!(
            "{head} It could not be weighed ({why}); to try it yourself: `--friction \
             '(FRICTION) - c' --map c=0 --bounds c=LO:HI --fit auto,c`.\n"
        );
    };
    let chosen: String = v.chosen_with.iter().map(|c| format!(", {c}")).collect();
    let outcome = if v.kept {
        format!(
            "It pays, and is kept: friction_offset = {} {u}, and the report, the models \
             table and the fitted file are those of this calibration. The offset is not \
             friction: the fitted file holds the friction without it (a sensor's zero must \
             not be fed forward; a weight on a vertical axis must, and is yours to add).",
            Num::sig(v.offset, 5)
        )
    } else {
        format!(
            "It does not pay (fitted at {} {u}), and the calibration without it stands.",
            Num::sig(v.offset, 5)
        )
    };
    format!(
        "{head} Chosen beside it: boundary friction{chosen}. CV RMS {} {u} with the offset, \
         {} {u} without; the offset lowers the folds' mean squared error by {} ± {} \
         (standard error), and it must lower it by more than that and by more than the \
         cost of a term. {outcome}\n",
        Num::sig(v.cv_with, 5),
        Num::sig(v.cv_without, 5),
        Num::sig(v.gain, 5),
        Num::sig(v.se, 5),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rule_12_applies_where_the_asymmetry_was_chosen_on_a_time_series_without_a_map() {
        let chosen = ["pre-sliding", ASYMMETRY];
        assert!(applies(&chosen, true, false));
        // A steady curve passes through no rest: the two are one there.
        assert!(!applies(&chosen, false, false));
        // A map fitted already (an offset, an effective area) is the user's.
        assert!(!applies(&chosen, true, true));
        // Without the asymmetry there is nothing to tell apart.
        assert!(!applies(&["pre-sliding"], true, false));
    }

    #[test]
    fn the_paragraph_says_what_was_weighed_and_what_stands() {
        let v = OffsetVerdict {
            kept: true,
            cv_without: 0.05,
            cv_with: 0.03,
            gain: 1.6e-3,
            se: 2e-4,
            offset: -0.343,
            chosen_with: vec!["pre-sliding"],
        };
        let md = paragraph(Some(&v), None, super::super::Units::Rotary);
        assert!(md.contains("friction_offset = -0.343 N·m"), "{md}");
        assert!(md.contains("It pays, and is kept"), "{md}");
        assert!(
            md.contains("Chosen beside it: boundary friction, pre-sliding."),
            "{md}"
        );
        let lost = OffsetVerdict { kept: false, ..v };
        let md = paragraph(Some(&lost), None, super::super::Units::Rotary);
        assert!(md.contains("does not pay"), "{md}");
        let md = paragraph(
            None,
            Some("the data are short"),
            super::super::Units::Linear,
        );
        assert!(
            md.contains("could not be weighed (the data are short)"),
            "{md}"
        );
        assert!(md.contains("--map c=0"), "{md}");
    }
}
