//! Hysteresis-loop metrics per motion cycle (docs/model.md §9).
//!
//! | metric | definition | unit |
//! |---|---|---|
//! | `friction_loop_area` | Σ over half-cycles (between velocity zero crossings) of the absolute enclosed area of the F_f–v loop | N·m/s |
//! | `cof_loop_area` | the same for the COF–v loop | m/s |
//! | `cof_v0_accelerating`, `cof_v0_decelerating` | one-sided limits of the COF at v = 0: linear extrapolation from the two samples after (accelerating) or before (decelerating) each zero crossing, averaged over the crossings of the cycle; the boundary rate's part of the COF, which is 0 at v = 0 and steep near it, is taken out before extrapolating | – |
//! | `peak_cof`, `peak_cof_velocity` | maximum COF in the cycle and the velocity where it occurs | –, m/s |
//! | `h0_min`, `h0_max` | range of the minimum separation | m |
//! | `mean_asperity_share` | mean F_asp/F_ext | – |
//! | `branch_cof_gap` | mean COF while |v| increases minus mean COF while |v| decreases | – |
//! | `branch_h0_gap` | the same for h0 | m |
//! | `inertia_share` | max |m h0''| / F_ext over the cycle (raw, includes spikes) | – |
//! | `inertia_share_smooth` | the same for the first `harmonics` Fourier harmonics of h0(t) over the cycle | – |
//!
//! Cycles are `(t0 + kT, t0 + (k+1)T]`; a cycle is reported only when it is
//! complete. Periodic runs should report the last of at least three.

use crate::physics::Estimate;

/// What the metrics need of one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopSample {
    /// Time, s.
    pub t: f64,
    /// Velocity, m/s.
    pub velocity: f64,
    /// Friction force, N.
    pub friction: f64,
    /// Coefficient of friction.
    pub cof: f64,
    /// The boundary rate's part of the COF (zero at v = 0; see
    /// [`Estimate::boundary_rate_cof`]).
    pub boundary_rate_cof: f64,
    /// Film thickness h0, m.
    pub h0: f64,
    /// F_asp / F_ext.
    pub asperity_share: f64,
    /// m ḧ0, N.
    pub inertia_force: f64,
    /// F_ext, N.
    pub load: f64,
    /// Load carried by the film, N.
    pub hydrodynamic_force: f64,
    /// Load carried by the asperities, N.
    pub asperity_force: f64,
}

impl From<&Estimate> for LoopSample {
    fn from(e: &Estimate) -> Self {
        Self {
            t: e.time,
            velocity: e.velocity,
            friction: e.friction_force,
            cof: e.cof,
            boundary_rate_cof: e.boundary_rate_cof,
            h0: e.h0,
            asperity_share: e.asperity_load_share,
            inertia_force: e.inertia_force,
            load: e.load,
            hydrodynamic_force: e.hydrodynamic_force,
            asperity_force: e.asperity_force,
        }
    }
}

/// Metrics of one cycle (see the module table).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopMetrics {
    /// The cycle, 0-based.
    pub cycle: usize,
    /// Its start, s.
    pub t_start: f64,
    /// Its end, s.
    pub t_end: f64,
    /// Area of the F_f–v loop, N·m/s (module table).
    pub friction_loop_area: f64,
    /// Area of the COF–v loop, m/s.
    pub cof_loop_area: f64,
    /// COF at v = 0 approached while accelerating.
    pub cof_v0_accelerating: Option<f64>,
    /// COF at v = 0 approached while decelerating.
    pub cof_v0_decelerating: Option<f64>,
    /// Largest COF in the cycle.
    pub peak_cof: f64,
    /// The velocity where it occurs, m/s.
    pub peak_cof_velocity: f64,
    /// Mean COF.
    pub mean_cof: f64,
    /// Smallest h0, m.
    pub h0_min: f64,
    /// Largest h0, m.
    pub h0_max: f64,
    /// Mean F_asp / F_ext.
    pub mean_asperity_share: f64,
    /// Mean F_hyd / F_ext.
    pub mean_fluid_share: f64,
    /// Mean COF while |v| rises minus while it falls.
    pub branch_cof_gap: Option<f64>,
    /// The same for h0, m.
    pub branch_h0_gap: Option<f64>,
    /// max |m ḧ0| / F_ext (raw).
    pub inertia_share: f64,
    /// The same from the first harmonics of h0(t).
    pub inertia_share_smooth: f64,
}

/// CSV columns of [`LoopMetrics::csv_fields`] (studies' summary, replay's
/// cycles.csv).
pub const LOOP_METRIC_COLUMNS: &str = "friction_loop_area_n_m_s,cof_loop_area_m_s,cof_v0_accelerating,cof_v0_decelerating,peak_cof,peak_cof_velocity_m_s,mean_cof,h0_min_m,h0_max_m,mean_asperity_share,mean_fluid_share,branch_cof_gap,branch_h0_gap_m,inertia_share,inertia_share_smooth";

impl LoopMetrics {
    /// The metrics as CSV fields in the order of [`LOOP_METRIC_COLUMNS`]
    /// (shortest round-trip floats; empty for undefined values).
    pub fn csv_fields(&self) -> String {
        use crate::text::Num;
        self.values()
            .iter()
            .map(|x| x.map_or(String::new(), |v| Num(v).to_string()))
            .collect::<Vec<_>>()
            .join(",")
    }

    /// The metrics in the order of [`LOOP_METRIC_COLUMNS`] (None: undefined).
    pub fn values(&self) -> [Option<f64>; Self::COLUMNS] {
        [
            Some(self.friction_loop_area),
            Some(self.cof_loop_area),
            self.cof_v0_accelerating,
            self.cof_v0_decelerating,
            Some(self.peak_cof),
            Some(self.peak_cof_velocity),
            Some(self.mean_cof),
            Some(self.h0_min),
            Some(self.h0_max),
            Some(self.mean_asperity_share),
            Some(self.mean_fluid_share),
            self.branch_cof_gap,
            self.branch_h0_gap,
            Some(self.inertia_share),
            Some(self.inertia_share_smooth),
        ]
    }

    /// Number of columns in [`LOOP_METRIC_COLUMNS`].
    pub const COLUMNS: usize = 15;
}

/// Split `samples` into cycles of `period` starting at `t0` and compute the
/// metrics of every complete cycle. `mass` (kg) is used for the smooth
/// inertia share; `harmonics` is the number of Fourier harmonics kept.
pub fn cycle_metrics(
    samples: &[LoopSample],
    t0: f64,
    period: f64,
    mass: f64,
    harmonics: usize,
) -> Vec<LoopMetrics> {
    if period.is_nan() || period <= 0.0 || samples.len() < 4 {
        return Vec::new();
    }
    let dt = if samples.len() > 1 {
        samples[1].t - samples[0].t
    } else {
        0.0
    };
    let last_t = samples[samples.len() - 1].t;
    let count = ((last_t - t0) / period + 1e-9).floor().max(0.0) as usize;
    let mut out = Vec::new();
    for k in 0..count {
        let (a, b) = (t0 + k as f64 * period, t0 + (k + 1) as f64 * period);
        let tol = 1e-6 * dt.abs();
        let cyc: Vec<LoopSample> = samples
            .iter()
            .copied()
            .filter(|s| s.t > a + tol && s.t <= b + tol)
            .collect();
        if cyc.len() < 4 {
            continue;
        }
        out.push(one_cycle(k, a, b, &cyc, mass, harmonics));
    }
    out
}

/// [`cycle_metrics`] computed while the samples arrive, holding only the
/// current cycle's samples (a run of any length uses bounded memory).
#[derive(Debug, Clone)]
pub struct CycleCollector {
    t0: f64,
    period: f64,
    mass: f64,
    harmonics: usize,
    /// Time of the first sample (the step, with the second one).
    first_t: Option<f64>,
    tol: f64,
    k: usize,
    buf: Vec<LoopSample>,
    last_t: f64,
    done: Vec<LoopMetrics>,
}

impl CycleCollector {
    /// Cycles of `period` (s) from `t0` (s), for a slider of `mass` (kg), the smooth inertia share from `harmonics` harmonics.
    pub fn new(t0: f64, period: f64, mass: f64, harmonics: usize) -> Self {
        Self {
            t0,
            period,
            mass,
            harmonics,
            first_t: None,
            tol: 0.0,
            k: 0,
            buf: Vec::new(),
            last_t: f64::NEG_INFINITY,
            done: Vec::new(),
        }
    }

    fn bounds(&self, k: usize) -> (f64, f64) {
        (
            self.t0 + k as f64 * self.period,
            self.t0 + (k + 1) as f64 * self.period,
        )
    }

    fn close(&mut self) {
        let (a, b) = self.bounds(self.k);
        if self.buf.len() >= 4 {
            let m = one_cycle(self.k, a, b, &self.buf, self.mass, self.harmonics);
            self.done.push(m);
        }
        self.buf.clear();
        self.k += 1;
    }

    /// Add a sample; a completed cycle's metrics are computed then.
    pub fn push(&mut self, s: LoopSample) {
        if self.period.is_nan() || self.period <= 0.0 {
            return;
        }
        match self.first_t {
            None => self.first_t = Some(s.t),
            Some(t1) if self.last_t == t1 => self.tol = 1e-6 * (s.t - t1).abs(),
            _ => {}
        }
        self.last_t = s.t;
        while s.t > self.bounds(self.k).1 + self.tol {
            self.close();
        }
        if s.t > self.bounds(self.k).0 + self.tol {
            self.buf.push(s);
        }
    }

    /// The metrics of every complete cycle.
    pub fn finish(mut self) -> Vec<LoopMetrics> {
        let complete = ((self.last_t - self.t0) / self.period + 1e-9)
            .floor()
            .max(0.0) as usize;
        if self.k < complete {
            self.close();
        }
        self.done
    }
}

/// Metrics of samples forming one cycle.
pub fn one_cycle(
    index: usize,
    t_start: f64,
    t_end: f64,
    cyc: &[LoopSample],
    mass: f64,
    harmonics: usize,
) -> LoopMetrics {
    let n = cyc.len();
    let mean = |f: &dyn Fn(&LoopSample) -> f64| cyc.iter().map(f).sum::<f64>() / n as f64;
    let (peak_cof, peak_cof_velocity) = cyc.iter().fold((f64::NEG_INFINITY, 0.0), |(m, v), s| {
        if s.cof > m {
            (s.cof, s.velocity)
        } else {
            (m, v)
        }
    });
    let h0_min = cyc.iter().map(|s| s.h0).fold(f64::INFINITY, f64::min);
    let h0_max = cyc.iter().map(|s| s.h0).fold(f64::NEG_INFINITY, f64::max);
    let inertia_share = cyc
        .iter()
        .map(|s| (s.inertia_force / s.load).abs())
        .fold(0.0, f64::max);
    let crossings = zero_crossings(cyc);
    let (acc, dec) = cof_at_reversals(cyc, &crossings);
    let avg = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
    // Loop areas per half-cycle lobe.
    let friction_loop_area = lobe_areas(cyc, &crossings, |s| s.friction);
    let cof_loop_area = lobe_areas(cyc, &crossings, |s| s.cof);
    let branches = Branches::of(cyc);
    let gap = |a: &[f64], b: &[f64]| match (avg(a), avg(b)) {
        (Some(x), Some(y)) => Some(x - y),
        _ => None,
    };
    let inertia_share_smooth =
        smooth_inertia_share(cyc, t_end - t_start, mass, harmonics, mean(&|s| s.load));
    LoopMetrics {
        cycle: index,
        t_start,
        t_end,
        friction_loop_area,
        cof_loop_area,
        cof_v0_accelerating: avg(&acc),
        cof_v0_decelerating: avg(&dec),
        peak_cof,
        peak_cof_velocity,
        mean_cof: mean(&|s| s.cof),
        h0_min,
        h0_max,
        mean_asperity_share: mean(&|s| s.asperity_share),
        mean_fluid_share: mean(&|s| s.hydrodynamic_force / s.load),
        branch_cof_gap: gap(&branches.cof_accelerating, &branches.cof_decelerating),
        branch_h0_gap: gap(&branches.h0_accelerating, &branches.h0_decelerating),
        inertia_share,
        inertia_share_smooth,
    }
}

/// Zero crossings of the velocity between samples j and j+1, cyclically
/// (the motion is periodic, so a crossing can fall between the cycle's
/// last and first samples).
fn zero_crossings(cyc: &[LoopSample]) -> Vec<usize> {
    let n = cyc.len();
    (0..n)
        .filter(|&j| {
            let (a, b) = (cyc[j].velocity, cyc[(j + 1) % n].velocity);
            (a > 0.0 && b <= 0.0) || (a < 0.0 && b >= 0.0)
        })
        .collect()
}

/// The COF extrapolated to v = 0 at every crossing: from the two samples
/// after it (accelerating) and the two before it (decelerating).
fn cof_at_reversals(cyc: &[LoopSample], crossings: &[usize]) -> (Vec<f64>, Vec<f64>) {
    let n = cyc.len();
    let extrapolate = |s1: &LoopSample, s2: &LoopSample| -> Option<f64> {
        let dv = s2.velocity - s1.velocity;
        if dv == 0.0 {
            return None;
        }
        // The boundary rate's part is exactly 0 at v = 0 and steep near it
        // (asinh): only the smooth remainder is extrapolated.
        let (c1, c2) = (s1.cof - s1.boundary_rate_cof, s2.cof - s2.boundary_rate_cof);
        Some(c2 + (c2 - c1) * (0.0 - s2.velocity) / dv)
    };
    let (mut acc, mut dec) = (Vec::new(), Vec::new());
    let at = |k: usize| &cyc[k % n];
    for &j in crossings {
        if let Some(c) = extrapolate(at(j + n - 1), at(j)) {
            dec.push(c);
        }
        if let Some(c) = extrapolate(at(j + 2), at(j + 1)) {
            acc.push(c);
        }
    }
    (acc, dec)
}

/// The samples of the accelerating (|v| rising) and the decelerating
/// branch.
struct Branches {
    cof_accelerating: Vec<f64>,
    cof_decelerating: Vec<f64>,
    h0_accelerating: Vec<f64>,
    h0_decelerating: Vec<f64>,
}

impl Branches {
    fn of(cyc: &[LoopSample]) -> Self {
        let mut b = Branches {
            cof_accelerating: Vec::new(),
            cof_decelerating: Vec::new(),
            h0_accelerating: Vec::new(),
            h0_decelerating: Vec::new(),
        };
        for j in 1..cyc.len().saturating_sub(1) {
            let (before, after) = (cyc[j - 1].velocity.abs(), cyc[j + 1].velocity.abs());
            if after > before {
                b.cof_accelerating.push(cyc[j].cof);
                b.h0_accelerating.push(cyc[j].h0);
            } else if after < before {
                b.cof_decelerating.push(cyc[j].cof);
                b.h0_decelerating.push(cyc[j].h0);
            }
        }
        b
    }
}

/// Σ |area| of the closed polygons between consecutive (cyclic) zero
/// crossings; the whole cycle when the velocity never changes sign.
fn lobe_areas(cyc: &[LoopSample], crossings: &[usize], y: impl Fn(&LoopSample) -> f64) -> f64 {
    let n = cyc.len();
    let pt = |s: &LoopSample| (s.velocity, y(s));
    if crossings.is_empty() {
        let poly: Vec<(f64, f64)> = cyc.iter().map(pt).collect();
        return shoelace(&poly).abs();
    }
    let zero_point = |j: usize| -> (f64, f64) {
        let (a, b) = (&cyc[j % n], &cyc[(j + 1) % n]);
        let dv = b.velocity - a.velocity;
        let w = if dv == 0.0 { 0.0 } else { -a.velocity / dv };
        (0.0, y(a) + w * (y(b) - y(a)))
    };
    let mut total = 0.0;
    for (k, &c0) in crossings.iter().enumerate() {
        let c1 = if k + 1 < crossings.len() {
            crossings[k + 1]
        } else {
            crossings[0] + n
        };
        let mut poly = vec![zero_point(c0)];
        poly.extend((c0 + 1..=c1).map(|j| pt(&cyc[j % n])));
        poly.push(zero_point(c1));
        total += shoelace(&poly).abs();
    }
    total
}

fn shoelace(poly: &[(f64, f64)]) -> f64 {
    let n = poly.len();
    if n < 3 {
        return 0.0;
    }
    let mut s = 0.0;
    for i in 0..n {
        let (x1, y1) = poly[i];
        let (x2, y2) = poly[(i + 1) % n];
        s += x1 * y2 - x2 * y1;
    }
    0.5 * s
}

/// m max|h0''| / F_ext for the first `harmonics` Fourier harmonics of h0
/// over one period (discrete projection; exact for uniform samples covering
/// the period).
fn smooth_inertia_share(
    cyc: &[LoopSample],
    period: f64,
    mass: f64,
    harmonics: usize,
    load: f64,
) -> f64 {
    let n = cyc.len();
    if n < 2 * harmonics + 1 || period.is_nan() || period <= 0.0 {
        return f64::NAN;
    }
    let w0 = 2.0 * core::f64::consts::PI / period;
    let t_ref = cyc[0].t;
    let mut coef = Vec::with_capacity(harmonics);
    for k in 1..=harmonics {
        let (mut a, mut b) = (0.0, 0.0);
        for s in cyc {
            let ph = k as f64 * w0 * (s.t - t_ref);
            a += s.h0 * ph.cos();
            b += s.h0 * ph.sin();
        }
        coef.push((2.0 * a / n as f64, 2.0 * b / n as f64));
    }
    let mut max_acc: f64 = 0.0;
    for s in cyc {
        let mut acc = 0.0;
        for (k, (a, b)) in coef.iter().enumerate() {
            let kw = (k + 1) as f64 * w0;
            let ph = kw * (s.t - t_ref);
            acc -= kw * kw * (a * ph.cos() + b * ph.sin());
        }
        max_acc = max_acc.max(acc.abs());
    }
    mass * max_acc / load
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn sample(t: f64, v: f64, cof: f64, h0: f64) -> LoopSample {
        LoopSample {
            t,
            velocity: v,
            friction: cof * 100.0 * v.signum(),
            cof,
            boundary_rate_cof: 0.0,
            h0,
            asperity_share: 0.5,
            inertia_force: 0.0,
            load: 100.0,
            hydrodynamic_force: 50.0,
            asperity_force: 50.0,
        }
    }

    #[test]
    fn loop_area_of_an_ellipse_is_pi_a_b_per_lobe() {
        // Unidirectional: v = 1 + 0.5 sin, cof = 0.2 + 0.1 cos → ellipse, area π·0.5·0.1.
        let n = 4000;
        let s: Vec<LoopSample> = (1..=n)
            .map(|j| {
                let ph = 2.0 * std::f64::consts::PI * j as f64 / n as f64;
                sample(
                    j as f64 / n as f64,
                    1.0 + 0.5 * ph.sin(),
                    0.2 + 0.1 * ph.cos(),
                    1e-5,
                )
            })
            .collect();
        let m = cycle_metrics(&s, 0.0, 1.0, 1.0, 3);
        assert_eq!(m.len(), 1);
        assert_relative_eq!(
            m[0].cof_loop_area,
            std::f64::consts::PI * 0.05,
            max_relative = 1e-4
        );
        assert!(m[0].cof_v0_accelerating.is_none());
    }

    #[test]
    fn smooth_inertia_share_recovers_a_harmonic_acceleration() {
        // h0 = A sin(2π f t): max |h0''| = A (2π f)².
        let (a, f, n) = (1e-6, 2.0, 1000);
        let s: Vec<LoopSample> = (1..=n)
            .map(|j| {
                let t = j as f64 / (f * n as f64);
                sample(
                    t,
                    (2.0 * std::f64::consts::PI * f * t).sin(),
                    0.2,
                    a * (2.0 * std::f64::consts::PI * f * t).sin(),
                )
            })
            .collect();
        let m = cycle_metrics(&s, 0.0, 1.0 / f, 3.0, 4);
        let expect = 3.0 * a * (2.0 * std::f64::consts::PI * f).powi(2) / 100.0;
        assert_relative_eq!(m[0].inertia_share_smooth, expect, max_relative = 1e-6);
    }

    #[test]
    fn one_sided_cof_limits_extrapolate_each_branch_to_zero_velocity() {
        // cof = 0.3 − 0.1|v| on the decelerating side, 0.25 − 0.1|v| accelerating.
        let n = 1000;
        let s: Vec<LoopSample> = (1..=n)
            .map(|j| {
                let t = j as f64 / n as f64;
                let ph = 2.0 * std::f64::consts::PI * t;
                let v = ph.sin();
                let rising = ph.cos() * v.signum() > 0.0;
                let c = if rising { 0.25 } else { 0.3 } - 0.1 * v.abs();
                sample(t, v, c, 1e-5)
            })
            .collect();
        let m = &cycle_metrics(&s, 0.0, 1.0, 1.0, 3)[0];
        assert_relative_eq!(m.cof_v0_accelerating.unwrap(), 0.25, epsilon = 1e-9);
        assert_relative_eq!(m.cof_v0_decelerating.unwrap(), 0.3, epsilon = 1e-9);
        assert_relative_eq!(m.branch_cof_gap.unwrap(), -0.05, epsilon = 1e-3);
    }

    #[test]
    fn reciprocating_cof_lobes_of_opposite_orientation_add_up() {
        // cof = 0.2 + 0.05 sin(2φ)·sign: each half-cycle lobe is traversed in
        // the opposite sense; a crossing falls on the cycle boundary.
        let n = 2000;
        let s: Vec<LoopSample> = (1..=n)
            .map(|j| {
                let ph = 2.0 * std::f64::consts::PI * j as f64 / n as f64;
                sample(
                    j as f64 / n as f64,
                    ph.sin(),
                    0.2 + 0.05 * ph.cos() * ph.sin().signum(),
                    1e-5,
                )
            })
            .collect();
        let m = &cycle_metrics(&s, 0.0, 1.0, 1.0, 3)[0];
        // Each lobe: half an ellipse with semi-axes 1 and 0.05 → π·0.05/2.
        // (The synthetic COF jumps at v = 0; interpolating the zero point
        // there trims a sliver of 2e-3 relative.)
        assert_relative_eq!(
            m.cof_loop_area,
            std::f64::consts::PI * 0.05,
            max_relative = 5e-3
        );
    }
}

#[cfg(test)]
mod collector_tests {
    use super::*;

    #[test]
    fn cycles_collected_while_streaming_equal_those_of_the_whole_run() {
        let dt = 1e-3;
        let samples: Vec<LoopSample> = (1..=3500)
            .map(|k| {
                let t = k as f64 * dt;
                let v = (2.0 * std::f64::consts::PI * t).sin();
                LoopSample {
                    t,
                    velocity: v,
                    friction: 100.0 * v + 10.0 * (t * 7.0).cos(),
                    cof: 0.1 + 0.01 * v.abs(),
                    boundary_rate_cof: 0.0,
                    h0: 1e-5 + 1e-6 * v,
                    asperity_share: 0.5,
                    inertia_force: 1e-3 * v,
                    load: 1000.0,
                    hydrodynamic_force: 500.0,
                    asperity_force: 500.0,
                }
            })
            .collect();
        let whole = cycle_metrics(&samples, 0.0, 1.0, 1.0, 6);
        let mut c = CycleCollector::new(0.0, 1.0, 1.0, 6);
        for s in &samples {
            c.push(*s);
        }
        let streamed = c.finish();
        assert_eq!(whole.len(), 3);
        assert_eq!(streamed, whole);
    }
}
