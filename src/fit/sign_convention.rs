//! Friction's sign against the velocity's, checked before anything is
//! fitted. Friction is the force the motion loses: it has the velocity's
//! sign, sliding forward and backward alike. Two recording conventions
//! break that, and a fit on them ends "converged" on nonsense (the
//! drivetrain asymmetry, a level that differs by direction, carries a
//! flipped level or the whole of a magnitude), so both are refused with
//! the fix named:
//!
//! | data | what they show | refused when |
//! |---|---|---|
//! | the reaction logged (a drive's torque with the other sign) | friction opposing the velocity in nearly every sliding sample | more than [`OPPOSED_SHARE_REFUSED`] of them oppose it |
//! | the magnitude \|F\| (a tribometer's μ, a curve mirrored from one direction) | friction of one sign in both directions: its odd part, (F̄₊ − F̄₋)/2, is nothing | one direction opposes the velocity in more than [`OPPOSED_SHARE_REFUSED`] of its samples and the odd part is not above [`ODD_PART_T`] standard errors |
//!
//! A level that differs by direction (an offset, gravity on a vertical
//! axis) also gives friction of one sign in both directions, but its odd
//! part is the friction level, F̄₊ − F̄₋ = 2 F_c > 0: it passes, and the
//! asymmetry term fits it.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F̄₊, F̄₋ | the mean friction of the samples sliding forward, backward (faster than a tenth of the top speed) | N or N·m |
//! | s₊, s₋, n₊, n₋ | their standard deviations and counts | N or N·m, – |
//! | t | the odd part over its standard error: (F̄₊ − F̄₋) / √(s₊²/n₊ + s₋²/n₋) | – |

use super::series::Series;
use super::FitError;

/// The share of sliding samples whose friction opposes the velocity above
/// which the data are refused: friction is the force the motion loses, with
/// the velocity's sign (a share near 1 is a sign convention, not friction).
pub const OPPOSED_SHARE_REFUSED: f64 = 0.9;

/// The sliding samples of a time series the checks need: fewer say
/// nothing of a convention (a few samples of a reversal's transient).
pub const SIGN_CHECK_SAMPLES: usize = 10;

/// The sliding points of a steady curve the checks need (per direction for
/// the magnitude's): each point is a steady state, the mean of many
/// samples, so three that all oppose the velocity are a convention, not
/// noise.
pub const SIGN_CHECK_POINTS: usize = 3;

/// How many standard errors above zero friction's odd part must lie when
/// one direction opposes the velocity throughout: below, the data do not
/// show friction changing sign with the motion (two standard errors, a
/// one-sided test at about 2.5 %).
pub const ODD_PART_T: f64 = 2.0;

/// Sliding samples of one direction of motion.
#[derive(Default)]
struct Direction {
    n: usize,
    opposed: usize,
    sum: f64,
    sum_sq: f64,
}

impl Direction {
    fn add(&mut self, f: f64, opposed: bool) {
        self.n += 1;
        self.opposed += usize::from(opposed);
        self.sum += f;
        self.sum_sq += f * f;
    }

    fn mean(&self) -> f64 {
        self.sum / self.n.max(1) as f64
    }

    /// The squared standard error of the mean (sample variance / n).
    fn se_sq(&self) -> f64 {
        let n = self.n as f64;
        let var = ((self.sum_sq - self.sum * self.sum / n) / (n - 1.0).max(1.0)).max(0.0);
        var / n
    }

    fn opposed_share(&self) -> f64 {
        self.opposed as f64 / self.n.max(1) as f64
    }
}

/// Refuse friction that opposes the velocity in more than
/// [`OPPOSED_SHARE_REFUSED`] of the sliding samples (|v| above a tenth of
/// the top speed `v_top`), or that has one sign in both directions with no
/// odd part (a magnitude), when there are enough samples to tell
/// ([`SIGN_CHECK_SAMPLES`] of a time series, [`SIGN_CHECK_POINTS`] steady
/// points).
pub fn check_sign(all: &[Series], v_top: f64) -> Result<(), FitError> {
    let (mut forward, mut backward) = (Direction::default(), Direction::default());
    let mut steady = false;
    for se in all {
        for (v, f) in se.velocity.iter().zip(&se.friction) {
            if v.abs() > 0.1 * v_top && *f != 0.0 {
                steady |= se.steady;
                let d = if *v > 0.0 {
                    &mut forward
                } else {
                    &mut backward
                };
                d.add(*f, v.signum() != f.signum());
            }
        }
    }
    let need = if steady {
        SIGN_CHECK_POINTS
    } else {
        SIGN_CHECK_SAMPLES
    };
    let sliding = forward.n + backward.n;
    let opposed = forward.opposed + backward.opposed;
    let share = opposed as f64 / sliding.max(1) as f64;
    if sliding >= need && share > OPPOSED_SHARE_REFUSED {
        return Err(FitError::Data {
            what: "friction".into(),
            message: format!(
                "its sign opposes the velocity's in {:.1} % of the sliding samples ({opposed} of {sliding} faster than a tenth of the top speed): friction is the force the motion loses and has the velocity's sign; if the recording's convention is the other one, fit its negative (--friction '-(EXPR)')",
                100.0 * share
            ),
        });
    }
    if forward.n < need || backward.n < need {
        return Ok(());
    }
    let one_sign = forward.opposed_share().max(backward.opposed_share()) > OPPOSED_SHARE_REFUSED;
    let odd = forward.mean() - backward.mean();
    let se = (forward.se_sq() + backward.se_sq()).sqrt();
    // False for a NaN too: data that cannot show an odd part are refused.
    let shows_odd_part = odd > ODD_PART_T * se;
    if one_sign && !shows_odd_part {
        return Err(FitError::Data {
            what: "friction".into(),
            message: format!(
                "it has one sign in both directions and does not change with the direction of motion: its mean sliding forward is {:.4e} and backward {:.4e} ({} and {} samples faster than a tenth of the top speed; their difference, twice the friction level, is {:.2} standard errors, not above {ODD_PART_T}); friction has the velocity's sign, so these look like its magnitude |F|: fit it with the velocity's sign (--friction 'if(VELOCITY < 0, -(EXPR), EXPR)', VELOCITY and EXPR the columns or expressions of --velocity and --friction)",
                forward.mean(),
                backward.mean(),
                forward.n,
                backward.n,
                odd / se.max(f64::MIN_POSITIVE),
            ),
        });
    }
    Ok(())
}

/// [`check_sign`] on one `--validate` file, `se` through the maps' start
/// values, over its own top speed: a held-out file in the other convention
/// would otherwise be scored against a model with the right one, and every
/// model's held-out error would be the convention's. The error names the
/// file.
pub fn check_validation(se: &Series) -> Result<(), FitError> {
    let top = se.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if top == 0.0 {
        return Ok(());
    }
    check_sign(std::slice::from_ref(se), top).map_err(|e| match e {
        FitError::Data { message, .. } => FitError::Data {
            what: format!("the friction of --validate {}", se.name),
            message,
        },
        other => other,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A steady curve of `points` (velocity, friction).
    fn curve(points: &[(f64, f64)]) -> Series {
        Series {
            name: "curve".into(),
            steady: true,
            t: (0..points.len()).map(|k| k as f64).collect(),
            velocity: points.iter().map(|p| p.0).collect(),
            friction: points.iter().map(|p| p.1).collect(),
            load: None,
            temperature: None,
            fit: vec![true; points.len()],
        }
    }

    /// Friction 1 + 0.1 |v| at ±1..±5, with the sign given by `sign(v)`.
    fn mirrored(sign: impl Fn(f64) -> f64) -> Series {
        let pts: Vec<(f64, f64)> = (1..=5)
            .flat_map(|k| [k as f64, -(k as f64)])
            .map(|v| (v, sign(v) * (1.0 + 0.1 * v.abs() + 0.01 * (v * 7.3).sin())))
            .collect();
        curve(&pts)
    }

    #[test]
    fn friction_with_the_velocitys_sign_passes() {
        assert!(check_sign(&[mirrored(f64::signum)], 5.0).is_ok());
    }

    #[test]
    fn friction_opposing_the_velocity_everywhere_is_refused_as_a_sign_convention() {
        let e = check_sign(&[mirrored(|v| -v.signum())], 5.0).unwrap_err();
        assert!(
            e.to_string().contains("opposes the velocity's in 100.0 %"),
            "{e}"
        );
    }

    #[test]
    fn a_magnitude_of_one_sign_both_ways_is_refused_naming_the_fix() {
        let e = check_sign(&[mirrored(|_| 1.0)], 5.0).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("one sign in both directions"), "{text}");
        assert!(text.contains("if(VELOCITY < 0, -(EXPR), EXPR)"), "{text}");
    }

    #[test]
    fn an_offset_larger_than_the_level_passes_as_friction_that_differs_by_direction() {
        // Gravity on a vertical axis: 3 + sgn(v) (1 + 0.1 |v|), positive
        // both ways, its odd part the friction level.
        assert!(check_sign(
            &[mirrored(|v| 3.0 / (1.0 + 0.1 * v.abs()) + v.signum())],
            5.0
        )
        .is_ok());
    }

    #[test]
    fn a_validation_file_in_the_other_convention_is_refused_by_its_name() {
        let mut se = mirrored(|v| -v.signum());
        se.name = "fast.csv".into();
        let e = check_validation(&se).unwrap_err().to_string();
        assert!(e.contains("--validate fast.csv"), "{e}");
        assert!(check_validation(&mirrored(f64::signum)).is_ok());
    }

    #[test]
    fn a_short_curve_one_way_is_checked_with_three_points() {
        let pts: Vec<(f64, f64)> = (1..=3).map(|k| (k as f64, -1.0)).collect();
        assert!(check_sign(&[curve(&pts)], 3.0).is_err());
        let two: Vec<(f64, f64)> = (1..=2).map(|k| (k as f64, -1.0)).collect();
        assert!(check_sign(&[curve(&two)], 2.0).is_ok());
    }
}
