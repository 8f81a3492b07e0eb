//! Synthetic calibration data: friction of the transient model (or of any
//! predictor) along a reciprocating motion, with white noise. Used by the
//! calibration benchmark (`bench-fit`) and the tests, so that both measure
//! the same thing.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | t | time of a sample | s |
//! | v = A sin 2πft | sliding velocity, amplitude A, frequency f | m/s |
//! | F_ext | normal load of a segment | N |
//! | F_f + ε | friction with noise ε ~ N(0, (r · RMS F_f)²) | N |

use crate::config::Config;
use crate::physics::{SetupError, Solver};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

/// One segment of a motion: amplitude A (m/s), frequency f (Hz), load (N),
/// for a duration (s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Velocity amplitude V1, m/s.
    pub amplitude_m_s: f64,
    /// Frequency f, Hz.
    pub frequency_hz: f64,
    /// Normal load, N.
    pub load_n: f64,
    /// Length, s.
    pub duration_s: f64,
}

/// One sample of a motion: (t s, v m/s, load N).
pub type Sample = (f64, f64, f64);

/// Samples every `dt` s through the segments one after the other (the
/// phase runs on across segments, so the velocity is continuous when the
/// frequency is). The first sample is at `dt`.
pub fn motion(segments: &[Segment], dt: f64) -> Vec<Sample> {
    let total: f64 = segments.iter().map(|s| s.duration_s).sum();
    let n = (total / dt).round() as usize;
    let mut out = Vec::with_capacity(n);
    let mut phase = 0.0;
    let (mut seg, mut seg_end) = (0usize, segments.first().map_or(0.0, |s| s.duration_s));
    for k in 1..=n {
        let t = k as f64 * dt;
        while t > seg_end + 1e-12 && seg + 1 < segments.len() {
            seg += 1;
            seg_end += segments[seg].duration_s;
        }
        let s = segments[seg];
        phase += std::f64::consts::TAU * s.frequency_hz * dt;
        out.push((t, s.amplitude_m_s * phase.sin(), s.load_n));
    }
    out
}

/// The four-quarter motion of the calibration targets: amplitudes 0.5 and
/// 1 m/s, loads 10 and 20 kN, 1 Hz, `duration_s` in all.
pub fn two_amplitudes_two_loads(duration_s: f64, dt: f64) -> Vec<Sample> {
    let q = duration_s / 4.0;
    let seg = |a, l| Segment {
        amplitude_m_s: a,
        frequency_hz: 1.0,
        load_n: l,
        duration_s: q,
    };
    motion(
        &[
            seg(0.5, 10_000.0),
            seg(0.5, 20_000.0),
            seg(1.0, 10_000.0),
            seg(1.0, 20_000.0),
        ],
        dt,
    )
}

/// Gaussian noise (Box–Muller) of standard deviation `sd`.
pub fn gaussian(rng: &mut StdRng, sd: f64) -> f64 {
    let (u, v): (f64, f64) = (rng.random(), rng.random());
    sd * (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// Friction of the transient model configured by `config` along `motion`,
/// as `simulate` runs it: from the steady state at rest at t = 0 (the
/// motion's first sample is at `dt`), one step per sample.
pub fn model_friction(config: &Config, motion: &[Sample]) -> Result<Vec<f64>, SetupError> {
    let mut solver = Solver::new(&config.model(), &config.solver_settings())?;
    let Some(&(_, _, l0)) = motion.first() else {
        return Ok(Vec::new());
    };
    solver.initialize_steady(0.0, l0);
    Ok(motion
        .iter()
        .map(|&(_, v, l)| solver.step(v, l).friction_force)
        .collect())
}

/// `friction` plus white noise of `relative` times its RMS, as CSV text
/// `t_s,velocity_m_s,friction_n,load_n` (what `fit` reads).
pub fn noisy_csv(motion: &[Sample], friction: &[f64], relative: f64, seed: u64) -> String {
    let rms = (friction.iter().map(|x| x * x).sum::<f64>() / friction.len().max(1) as f64).sqrt();
    let mut rng = StdRng::seed_from_u64(seed);
    let mut s = String::from("t_s,velocity_m_s,friction_n,load_n\n");
    for (&(t, v, l), f) in motion.iter().zip(friction) {
        s += &format!("{t},{v},{},{l}\n", f + gaussian(&mut rng, relative * rms));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_motion_runs_its_segments_in_order_with_a_continuous_phase() {
        let seg = |a, f, l| Segment {
            amplitude_m_s: a,
            frequency_hz: f,
            load_n: l,
            duration_s: 1.0,
        };
        let m = motion(&[seg(0.5, 1.0, 1e4), seg(1.0, 1.0, 2e4)], 1e-3);
        assert_eq!(m.len(), 2000);
        approx::assert_relative_eq!(m[999].0, 1.0, max_relative = 1e-12);
        assert_eq!(m[999].2, 1e4);
        assert_eq!(m[1000].2, 2e4);
        // 1 Hz for one second: the phase is back at zero at t = 1 s.
        approx::assert_abs_diff_eq!(m[999].1, 0.0, epsilon = 1e-9);
        approx::assert_relative_eq!(m[249].1, 0.5, max_relative = 1e-6);
        approx::assert_relative_eq!(m[1249].1, 1.0, max_relative = 1e-6);
    }

    #[test]
    fn the_noise_has_the_asked_standard_deviation() {
        let mut rng = StdRng::seed_from_u64(3);
        let n = 200_000;
        let x: Vec<f64> = (0..n).map(|_| gaussian(&mut rng, 2.0)).collect();
        let mean = x.iter().sum::<f64>() / n as f64;
        let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        approx::assert_abs_diff_eq!(mean, 0.0, epsilon = 0.02);
        approx::assert_relative_eq!(sd, 2.0, max_relative = 0.01);
    }
}
