//! The calibrated range of a fit ([`CalibratedRange`], written into the
//! fitted file) from the training samples, and where the held-out and
//! validation data lie against it: the share outside, how far, and the
//! error inside and outside separately.
//!
//! The data and the range are in the axis's units (m/s and N, or rad/s
//! and N·m): a joint's range is its joint's (the node judges the joint's
//! speed, the contact's ÷ its gain); the one contact's is in m/s and N
//! ([`for_file`]).

use super::problem::SeriesFit;
use super::{FitOutcome, Units};
use crate::config::{CalibratedRange, RangeSide};
use crate::text::Num;
use std::fmt::Write as _;

/// The samples of `s` that the fit used (all, when none is marked).
fn used(s: &SeriesFit) -> impl Iterator<Item = usize> + '_ {
    let all = s.series.fit.iter().all(|f| !*f);
    (0..s.series.len()).filter(move |k| all || s.series.fit.get(*k).copied().unwrap_or(true))
}

/// (min, max) of `values`, None when empty.
fn span(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// The range of the training samples `train` (fitted with RMS error
/// `train_rms`), in the axis's `units`.
pub fn of_training(train: &[SeriesFit], train_rms: f64, units: Units) -> CalibratedRange {
    let samples = || train.iter().flat_map(|s| used(s).map(move |k| (s, k)));
    // A time series starts, stops and reverses through zero speed: its
    // slow end is covered down to zero. A steady curve's slowest point is
    // where its evidence ends.
    let through_zero = train.iter().any(|s| !s.series.steady);
    let speeds = |forward: bool| {
        span(
            samples()
                .map(|(s, k)| s.series.velocity[k])
                .filter(|v| if forward { *v > 0.0 } else { *v < 0.0 })
                .map(f64::abs),
        )
        .map(|(lo, hi)| (if through_zero { 0.0 } else { lo }, hi))
    };
    let column = |pick: fn(&SeriesFit) -> Option<&Vec<f64>>| {
        span(samples().filter_map(|(s, k)| pick(s).map(|c| c[k])))
    };
    let load = column(|s| s.series.load.as_ref());
    let temperature = column(|s| s.series.temperature.as_ref());
    let acceleration = train
        .iter()
        .filter(|s| !s.series.steady)
        .flat_map(|s| {
            let (t, v) = (&s.series.t, &s.series.velocity);
            (1..v.len()).filter_map(move |k| {
                let dt = t[k] - t[k - 1];
                (dt > 0.0).then(|| ((v[k] - v[k - 1]) / dt).abs())
            })
        })
        .fold(None, |m: Option<f64>, a| Some(m.map_or(a, |m| m.max(a))));
    let (fwd, bwd) = (speeds(true), speeds(false));
    let common = CalibratedRange {
        load_min_n: load.map(|r| r.0),
        load_max_n: load.map(|r| r.1),
        temperature_min_c: temperature.map(|r| r.0),
        temperature_max_c: temperature.map(|r| r.1),
        training_samples: samples().count() as u64,
        ..Default::default()
    };
    match units {
        Units::Linear => CalibratedRange {
            speed_forward_min_m_s: fwd.map(|r| r.0),
            speed_forward_max_m_s: fwd.map(|r| r.1),
            speed_backward_min_m_s: bwd.map(|r| r.0),
            speed_backward_max_m_s: bwd.map(|r| r.1),
            acceleration_max_m_s2: acceleration,
            training_rms_n: Some(train_rms),
            ..common
        },
        Units::Rotary => CalibratedRange {
            speed_forward_min_rad_s: fwd.map(|r| r.0),
            speed_forward_max_rad_s: fwd.map(|r| r.1),
            speed_backward_min_rad_s: bwd.map(|r| r.0),
            speed_backward_max_rad_s: bwd.map(|r| r.1),
            acceleration_max_rad_s2: acceleration,
            training_rms_n_m: Some(train_rms),
            ..common
        },
    }
}

/// `range` (axis units) as the fitted file holds it: a joint's (`joint`)
/// as it is; the one contact's in its m/s and N, through gain `gain`.
pub fn for_file(range: &CalibratedRange, joint: bool, gain: f64) -> CalibratedRange {
    if joint {
        range.clone()
    } else {
        range.in_contact_units(gain)
    }
}

/// The range of `outcome`'s training samples into `config` (its joint's,
/// or the one contact's through gain `gain`), and the report's section on
/// it; nothing, and an empty section, when the data give no valid range.
pub fn attach(config: &mut crate::config::Config, outcome: &FitOutcome, gain: f64) -> String {
    let range = of_training(&outcome.train, outcome.train_rms, outcome.units);
    let joint = !config.contacts.0.is_empty();
    let in_file = for_file(&range, joint, gain);
    if in_file.validate("calibrated_range", joint).is_err() {
        return String::new();
    }
    match config.contacts.0.first_mut() {
        Some(contact) => contact.calibrated_range = Some(in_file),
        None => config.calibrated_range = Some(in_file),
    }
    section(outcome, &range)
}

/// Where one held-out or validation series lies against the range.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// The series' name.
    pub name: String,
    /// Samples compared, and those outside the range.
    pub samples: usize,
    /// See `samples`.
    pub outside: usize,
    /// The furthest excursion (axis units for a speed).
    pub furthest: Option<Excursion>,
    /// RMS error inside and outside the range (None: no sample there).
    pub rms_inside: Option<f64>,
    /// See `rms_inside`.
    pub rms_outside: Option<f64>,
}

/// A sample outside the range: which input left it, by how much, and on
/// which side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Excursion {
    /// The input (`speed forward`, `load`…).
    pub input: &'static str,
    /// Its value.
    pub value: f64,
    /// The edge it left: the range's top (above) or bottom (below).
    pub edge: f64,
    /// Whether above the top.
    pub above: bool,
    /// How far: value/top above, bottom/value below (∞ at or below zero
    /// under a positive bottom, or above a zero top).
    pub factor: f64,
}

impl Excursion {
    /// `value` of `input` against its range [`lo`, `hi`], which it left.
    fn new(input: &'static str, value: f64, lo: f64, hi: f64) -> Self {
        let above = value > hi;
        let (edge, factor) = if above {
            (hi, if hi > 0.0 { value / hi } else { f64::INFINITY })
        } else {
            (
                lo,
                if value > 0.0 {
                    lo / value
                } else {
                    f64::INFINITY
                },
            )
        };
        Self {
            input,
            value,
            edge,
            above,
            factor,
        }
    }

    /// Whether it lies further out than `other`: above the top before
    /// below the bottom (a faster motion, a heavier load is what a
    /// calibration is stretched to; a time series' reversal passes every
    /// speed down to zero, below any steady curve's slowest point), then by
    /// factor.
    fn beyond(&self, other: &Self) -> bool {
        (self.above, self.factor) > (other.above, other.factor)
    }
}

/// Each series of `fits` against `range` (both in the axis's units).
pub fn place(fits: &[SeriesFit], range: &CalibratedRange) -> Vec<Placement> {
    fits.iter()
        .map(|s| {
            let se = &s.series;
            let (mut n, mut out) = (0usize, 0usize);
            let (mut ss_in, mut n_in, mut ss_out, mut n_out) = (0.0, 0usize, 0.0, 0usize);
            let mut furthest: Option<Excursion> = None;
            for k in 0..se.len() {
                let r = s.predicted[k] - se.friction[k];
                if !r.is_finite() {
                    continue;
                }
                n += 1;
                let load = se.load.as_ref().map(|l| l[k]);
                let temperature = se.temperature.as_ref().map(|t| t[k]);
                match range.side(se.velocity[k], load, temperature) {
                    RangeSide::Inside => {
                        ss_in += r * r;
                        n_in += 1;
                    }
                    RangeSide::Outside {
                        input,
                        value,
                        lo,
                        hi,
                        ..
                    } => {
                        out += 1;
                        ss_out += r * r;
                        n_out += 1;
                        let e = Excursion::new(input, value, lo, hi);
                        if furthest.is_none_or(|g| e.beyond(&g)) {
                            furthest = Some(e);
                        }
                    }
                }
            }
            let rms = |ss: f64, m: usize| (m > 0).then(|| (ss / m as f64).sqrt());
            Placement {
                name: se.name.clone(),
                samples: n,
                outside: out,
                furthest,
                rms_inside: rms(ss_in, n_in),
                rms_outside: rms(ss_out, n_out),
            }
        })
        .collect()
}

/// The range (axis units), as a sentence.
fn describe(range: &CalibratedRange, units: Units) -> String {
    let v = units.speed();
    let speed = |(lo, hi): (Option<f64>, Option<f64>)| match (lo, hi) {
        (Some(lo), Some(hi)) => {
            format!("{}–{} {v}", Num::sig(lo, 4), Num::sig(hi, 4))
        }
        _ => "never".into(),
    };
    let mut s = format!(
        "speed forward {}, backward {}",
        speed(range.speeds(true)),
        speed(range.speeds(false))
    );
    if let (Some(lo), Some(hi)) = (range.load_min_n, range.load_max_n) {
        let _ = write!(s, ", load {}–{} N", Num::sig(lo, 4), Num::sig(hi, 4));
    }
    if let (Some(lo), Some(hi)) = (range.temperature_min_c, range.temperature_max_c) {
        let _ = write!(
            s,
            ", temperature {}–{} °C",
            Num::sig(lo, 4),
            Num::sig(hi, 4)
        );
    }
    if let Some(a) = range.acceleration_max() {
        let unit = match units {
            Units::Linear => "m/s²",
            Units::Rotary => "rad/s²",
        };
        let _ = write!(s, ", acceleration up to {} {unit}", Num::sig(a, 4));
    }
    s
}

/// The report's section: the range, then where each held-out and
/// validation series lies and its error inside and outside.
pub fn section(o: &FitOutcome, range: &CalibratedRange) -> String {
    let units = o.units;
    let f = units.force();
    let mut md = format!(
        "## Where the calibration holds\n\nCalibrated on {} training samples: {}; training RMS {} {f}. The fitted file holds this range (`calibrated_range`: a joint's in the joint's units, the one contact's in m/s and N); outside it the parameters are an extrapolation.\n",
        range.training_samples,
        describe(range, units),
        Num::sig(o.train_rms, 5)
    );
    let placed: Vec<(&str, Placement)> = [("held out", &o.held_out), ("validation", &o.validate)]
        .into_iter()
        .flat_map(|(role, fits)| place(fits, range).into_iter().map(move |p| (role, p)))
        .collect();
    if placed.is_empty() {
        md.push('\n');
        return md;
    }
    let _ = write!(
        md,
        "\n| source | role | samples | outside the range | furthest | RMS inside ({f}) | RMS outside ({f}) |\n|---|---|---|---|---|---|---|\n"
    );
    let cell = |x: Option<f64>| x.map_or("—".to_string(), |v| Num::sig(v, 5).to_string());
    for (role, p) in &placed {
        let furthest = p.furthest.map_or("—".to_string(), |e| {
            let unit = match e.input {
                "load" => " N".to_string(),
                "temperature" => " °C".to_string(),
                _ => format!(" {}", units.speed()),
            };
            let (input, value) = (e.input, Num::sig(e.value, 4));
            if !e.factor.is_finite() && e.above {
                format!("{input} {value}{unit} (never trained)")
            } else if e.above {
                format!("{input} {value}{unit} ({}× its top)", Num::sig(e.factor, 3))
            } else {
                format!(
                    "{input} {value}{unit} (below its bottom, {}{unit})",
                    Num::sig(e.edge, 4)
                )
            }
        });
        let _ = writeln!(
            md,
            "| {} | {role} | {} | {} ({:.1} %) | {furthest} | {} | {} |",
            p.name,
            p.samples,
            p.outside,
            100.0 * p.outside as f64 / p.samples.max(1) as f64,
            cell(p.rms_inside),
            cell(p.rms_outside)
        );
    }
    md.push('\n');
    md
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::Series;

    fn fit(name: &str, v: &[f64], f: &[f64], predicted: &[f64]) -> SeriesFit {
        SeriesFit {
            series: std::sync::Arc::new(Series {
                name: name.into(),
                steady: false,
                t: (0..v.len()).map(|k| k as f64 * 0.1).collect(),
                velocity: v.to_vec(),
                friction: f.to_vec(),
                load: None,
                temperature: None,
                fit: vec![true; v.len()],
            }),
            predicted: predicted.to_vec(),
        }
    }

    #[test]
    fn the_range_is_the_training_speeds_by_direction_through_the_gain_and_held_out_error_splits_at_it(
    ) {
        // Training: forward 0.1..0.5, backward 0.2..0.3 rad/s (a joint).
        let train = fit(
            "train",
            &[0.1, 0.5, -0.2, -0.3],
            &[1.0, 1.0, -1.0, -1.0],
            &[1.1, 0.9, -1.0, -1.0],
        );
        let r = of_training(std::slice::from_ref(&train), 0.0707, Units::Rotary);
        // A time series passes through zero speed: its slow end is zero.
        assert_eq!(r.speed_forward_min_rad_s, Some(0.0));
        let steady = SeriesFit {
            series: std::sync::Arc::new(Series {
                steady: true,
                ..train.series.as_ref().clone()
            }),
            ..train.clone()
        };
        let curve = of_training(&[steady], 0.0707, Units::Rotary);
        assert_eq!(curve.speed_forward_min_rad_s, Some(0.1));
        assert_eq!(curve.speed_backward_min_rad_s, Some(0.2));
        assert_eq!(curve.acceleration_max(), None);
        assert_eq!(r.speed_forward_max_rad_s, Some(0.5));
        assert_eq!(r.speed_backward_max_rad_s, Some(0.3));
        assert_eq!(r.training_samples, 4);
        assert_eq!(r.training_rms_n_m, Some(0.0707));
        // acceleration: |Δω/Δt| largest between 0.5 and -0.2: 7 rad/s per s.
        approx::assert_relative_eq!(
            r.acceleration_max_rad_s2.unwrap(),
            7.0,
            max_relative = 1e-12
        );
        assert!(r.validate("contacts.axis.calibrated_range", true).is_ok());
        // The one contact's file holds it in m/s and N through the gain.
        let contact = for_file(&r, false, 0.02);
        assert_eq!(contact.speed_forward_max_m_s, Some(0.02 * 0.5));
        approx::assert_relative_eq!(contact.training_rms_n.unwrap(), 0.0707 / 0.02);
        assert!(!contact.is_rotary());
        assert!(contact.validate("calibrated_range", false).is_ok());
        // Validation: two samples inside (errors 0.1), two beyond (errors 2): one
        // at 2.5 (5× the top speed forward), one backward at 0.25 (inside).
        let val = fit(
            "val",
            &[0.3, 2.5, -0.25, -0.6],
            &[1.0, 1.0, -1.0, -1.0],
            &[1.1, 3.0, -1.1, -3.0],
        );
        let p = &place(&[val], &r)[0];
        assert_eq!((p.samples, p.outside), (4, 2));
        approx::assert_relative_eq!(p.rms_inside.unwrap(), 0.1, max_relative = 1e-9);
        approx::assert_relative_eq!(p.rms_outside.unwrap(), 2.0, max_relative = 1e-9);
        let e = p.furthest.unwrap();
        assert_eq!(e.input, "speed forward");
        assert!(e.above);
        approx::assert_relative_eq!(e.value, 2.5, max_relative = 1e-9);
        approx::assert_relative_eq!(e.factor, 5.0, max_relative = 1e-9);
        // A sample far below the slowest trained speed (a reversal of a
        // time series against a steady curve) does not outrank one above
        // the top, however large its ratio.
        let val = fit(
            "val",
            &[1e-15, 0.6, -0.25],
            &[1.0, 1.0, -1.0],
            &[1.1, 1.1, -1.1],
        );
        let curve_place = &place(&[val], &curve)[0];
        assert_eq!(curve_place.outside, 2);
        let e = curve_place.furthest.unwrap();
        assert!(e.above && e.input == "speed forward", "{e:?}");
        approx::assert_relative_eq!(e.value, 0.6, max_relative = 1e-9);
    }
}
