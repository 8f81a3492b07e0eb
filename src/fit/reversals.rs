//! Velocity reversals in recorded data, and the contact's stiffness
//! through them: the start of a pre-sliding (bristle) stiffness, ours or
//! LuGre's.
//!
//! A reversal is a stretch of motion one way (|v| above a tenth of the
//! largest |v|) followed by a stretch the other way. Through it the
//! friction moves from the old direction's level F₋ to the new one's F₊.
//! For a bristle of stiffness σ0 on a level L (LuGre, and our
//! [`crate::physics::terms::presliding`]) the force after a displacement x from
//! the reversal is F = L − 2L e^(−σ0 x / L): it passes the middle of the
//! jump after x½ = (L/σ0) ln 2, so
//!
//! ```text
//! σ0 ≈ ln 2 · (F₊ − F₋) / 2 / x½
//! ```
//!
//! with x½ the displacement (∫ v dt from the last sample before the sign
//! change) at which the measured friction first reaches the middle.

use super::series::Series;

/// What the reversals of some data say.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReversalStiffness {
    /// Reversals found.
    pub reversals: usize,
    /// The median stiffness estimate over them, N/m (None: none usable).
    pub stiffness_n_m: Option<f64>,
}

/// Reversals of the fitted samples of every transient series.
pub fn stiffness(series: &[Series]) -> ReversalStiffness {
    let mut estimates = Vec::new();
    let mut reversals = 0;
    for s in series.iter().filter(|s| !s.steady && s.len() >= 5) {
        let vmax = s.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let th = 0.1 * vmax;
        // Moving stretches: (first, last, sign).
        let mut stretches: Vec<(usize, usize, f64)> = Vec::new();
        for k in 0..s.len() {
            let v = s.velocity[k];
            if v.abs() <= th || !s.fit[k] {
                continue;
            }
            match stretches.last_mut() {
                Some(last) if last.2 == v.signum() => last.1 = k,
                _ => stretches.push((k, k, v.signum())),
            }
        }
        for w in stretches.windows(2) {
            let ((a0, a1, _), (b0, b1, sign)) = (w[0], w[1]);
            reversals += 1;
            let median = |from: usize, to: usize| {
                let mut f: Vec<f64> = s.friction[from..=to].to_vec();
                f.sort_by(f64::total_cmp);
                f[f.len() / 2]
            };
            // The old level from the end of its stretch, the new one from
            // the middle of its stretch (past the transition).
            let before = median(a0 + (a1 - a0) / 2, a1);
            let after = median(b0 + (b1 - b0) / 2, b1);
            let jump = after - before;
            if jump * sign <= 0.0 {
                continue;
            }
            // The last sample before the sign change.
            let Some(r) = (a1..b0.max(a1 + 1))
                .rev()
                .find(|&k| s.velocity[k] * sign <= 0.0)
            else {
                continue;
            };
            let mid = before + 0.5 * jump;
            let mut x = 0.0;
            for k in r + 1..=b1 {
                x += 0.5 * (s.velocity[k] + s.velocity[k - 1]) * (s.t[k] - s.t[k - 1]);
                if (s.friction[k] - mid) * sign >= 0.0 {
                    if x * sign > 0.0 {
                        estimates.push(std::f64::consts::LN_2 * 0.5 * jump.abs() / x.abs());
                    }
                    break;
                }
            }
        }
    }
    estimates.sort_by(f64::total_cmp);
    ReversalStiffness {
        reversals,
        stiffness_n_m: (!estimates.is_empty()).then(|| estimates[estimates.len() / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::Presliding;
    use approx::assert_relative_eq;

    #[test]
    fn the_stiffness_of_a_bristle_is_recovered_from_its_reversals() {
        // A triangle wave of ±10 mm/s, friction through a bristle of 2e4 N/m
        // on ±5 N: the estimator returns σ0.
        let p = Presliding {
            stiffness: 2e4,
            damping: 0.0,
        };
        let dt = 1e-3;
        let (mut t, mut v, mut f) = (Vec::new(), Vec::new(), Vec::new());
        let mut z = p.steady_displacement(-5.0);
        for k in 0..6000 {
            let phase = (k as f64 * dt / 1.0).fract();
            let vel: f64 = if phase < 0.5 { 0.01 } else { -0.01 };
            let (zn, force) = p.advance(z, 5.0 * vel.signum(), vel, dt);
            z = zn;
            t.push(k as f64 * dt);
            v.push(vel);
            f.push(force);
        }
        let n = t.len();
        let s = Series {
            name: "bristle".into(),
            steady: false,
            t,
            velocity: v,
            friction: f,
            load: None,
            temperature: None,
            fit: vec![true; n],
        };
        let r = stiffness(&[s]);
        assert_eq!(r.reversals, 11);
        assert_relative_eq!(r.stiffness_n_m.unwrap(), 2e4, max_relative = 0.05);
    }

    #[test]
    fn data_without_a_reversal_have_no_stiffness() {
        let n = 100;
        let s = Series {
            name: "one way".into(),
            steady: false,
            t: (0..n).map(|k| k as f64 * 0.01).collect(),
            velocity: vec![0.1; n],
            friction: vec![3.0; n],
            load: None,
            temperature: None,
            fit: vec![true; n],
        };
        let r = stiffness(&[s]);
        assert_eq!(r.reversals, 0);
        assert_eq!(r.stiffness_n_m, None);
    }
}
