//! The synthetic friction records the fit tests calibrate on.

/// A drive's steady friction: a Stribeck fall with its own exponent over a
/// viscous rise that may bend,
/// F(v) = sgn v (f_c + (f_s − f_c) e^(−|v/v_s|^α)) + sgn v b_top |v/v_top|^δ.
///
/// | symbol | meaning | unit |
/// |---|---|---|
/// | f_c, f_s | the sliding level and the level at rest | N |
/// | v_s, α | the Stribeck speed and the fall's exponent (2: Gaussian) | m/s, – |
/// | b_top, v_top, δ | the viscous part at v_top and its exponent (1: straight) | N, m/s, – |
#[derive(Debug, Clone, Copy)]
pub struct Drive {
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub alpha: f64,
    pub b_top: f64,
    pub v_top: f64,
    pub delta: f64,
}

impl Drive {
    /// The friction at speed `v` (m/s), in N.
    pub fn friction(&self, v: f64) -> f64 {
        let sgn = if v == 0.0 { 0.0 } else { v.signum() };
        sgn * (self.fc
            + (self.fs - self.fc) * (-(v / self.vs).abs().powf(self.alpha)).exp()
            + self.b_top * (v / self.v_top).abs().powf(self.delta))
    }

    /// The friction along `motion` (`(t_s, velocity_m_s)`) with white
    /// noise of 1 % of its RMS (seed `seed`), written to `path` as a CSV
    /// `t_s,velocity_m_s,friction_n`.
    pub fn write_record(&self, path: &std::path::Path, motion: &[(f64, f64)], seed: u64) {
        self.write_record_with(path, motion, seed, |_| 0.0);
    }

    /// [`Self::write_record`] with `extra(v)` added to the friction at
    /// each speed v (an offset at rest as well, a level by direction), the
    /// noise 1 % of the sum's RMS.
    pub fn write_record_with(
        &self,
        path: &std::path::Path,
        motion: &[(f64, f64)],
        seed: u64,
        extra: impl Fn(f64) -> f64,
    ) {
        use rand::SeedableRng;
        use std::fmt::Write as _;
        let f: Vec<f64> = motion
            .iter()
            .map(|&(_, v)| self.friction(v) + extra(v))
            .collect();
        let rms = (f.iter().map(|x| x * x).sum::<f64>() / f.len() as f64).sqrt();
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let mut s = String::from("t_s,velocity_m_s,friction_n\n");
        for ((t, v), f) in motion.iter().zip(&f) {
            let noise = friction_node::fit::synthetic::gaussian(&mut rng, 0.01 * rms);
            writeln!(s, "{t},{v},{}", f + noise).unwrap();
        }
        std::fs::write(path, s).unwrap();
    }

    /// `fit --fit auto --baselines` on 8 s of point-to-point moves of this
    /// drive (noise seed `seeds.0`), validated on the same moves twice as
    /// fast (seed `seeds.1`), 16 cells, in a fresh directory of `suite`:
    /// (exit code, stdout, stderr).
    pub fn fit_auto_on_moves(&self, suite: &str, seeds: (u64, u64)) -> (i32, String, String) {
        self.fit_auto_on_moves_with(suite, "time-series", seeds, |_| 0.0)
    }

    /// [`Self::fit_auto_on_moves`] with `extra(v)` added to the friction
    /// (see [`Self::write_record_with`]), in the fresh directory `name`.
    pub fn fit_auto_on_moves_with(
        &self,
        suite: &str,
        name: &str,
        seeds: (u64, u64),
        extra: impl Fn(f64) -> f64 + Copy,
    ) -> (i32, String, String) {
        let d = super::cli::fresh_dir(suite, name);
        let (train, fast) = (d.join("train.csv"), d.join("fast.csv"));
        let motion = |scale| super::motion::point_to_point(8.0, scale);
        self.write_record_with(&train, &motion(1.0), seeds.0, extra);
        self.write_record_with(&fast, &motion(2.0), seeds.1, extra);
        let out = d.join("fit.yaml");
        super::cli::run(&[
            "fit",
            train.to_str().unwrap(),
            "--validate",
            fast.to_str().unwrap(),
            "--fit",
            "auto",
            "--baselines",
            "--set",
            "solver.cells=16",
            "--out",
            out.to_str().unwrap(),
        ])
    }
}
