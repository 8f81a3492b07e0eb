//! Where a fit's error sits: the residual of every source split by
//! direction of motion, and the two numbers that tell a wrong friction
//! level from an offset no friction model can carry.
//!
//! For the samples of one source (and one role: fitted, held out of the
//! training data, or `--validate` data), sliding forward (v ≥ f·v_top),
//! sliding backward (v ≤ −f·v_top) and passing through reversal (the rest),
//! with f = [`SLIDING_FRACTION`] and v_top the source's top speed:
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | b₊, b₋ | bias, the mean of (model − measured) sliding forward / backward | N |
//! | e_level | (b₊ − b₋) / 2: > 0 when the model's friction is too large in magnitude | N |
//! | e_offset | (b₊ + b₋) / 2: the same shift in both directions | N |
//!
//! Friction opposes motion, so a friction level that is wrong by δ gives
//! b₊ = +δ and b₋ = −δ (e_level = δ, e_offset = 0), while a force that does
//! not change sign with the motion — a sensor offset, a wrong effective
//! piston area, a level that differs by direction — gives b₊ = b₋
//! (e_offset ≠ 0). When every model shares one e_offset on held-out data,
//! that part of the error is in the data's mapping, not in any model's
//! friction.

use super::data::Role;
use super::driver::FitOutcome;
use super::problem::SeriesFit;
use std::fmt::Write as _;

/// Samples slower than this fraction of their source's top speed count as
/// passing through reversal, not as sliding.
pub const SLIDING_FRACTION: f64 = 0.1;

/// The fewest samples sliding in each direction for a level and an offset
/// error: fewer say "too few samples" (a mean of one sample is noise).
pub const MIN_DIRECTION_SAMPLES: usize = 10;

/// Sums over the samples of one group, for means and an RMS.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct GroupResidual {
    /// Samples in the group.
    pub samples: usize,
    speed_sum: f64,
    measured_sum: f64,
    predicted_sum: f64,
    squared_sum: f64,
}

impl GroupResidual {
    fn add(&mut self, speed: f64, measured: f64, predicted: f64) {
        self.samples += 1;
        self.speed_sum += speed;
        self.measured_sum += measured;
        self.predicted_sum += predicted;
        self.squared_sum += (predicted - measured).powi(2);
    }

    fn mean(&self, sum: f64) -> Option<f64> {
        (self.samples > 0).then(|| sum / self.samples as f64)
    }

    /// Mean speed |v|, m/s.
    pub fn mean_speed_m_s(&self) -> Option<f64> {
        self.mean(self.speed_sum)
    }

    /// Mean measured friction, N.
    pub fn measured_mean_n(&self) -> Option<f64> {
        self.mean(self.measured_sum)
    }

    /// Mean model friction, N.
    pub fn predicted_mean_n(&self) -> Option<f64> {
        self.mean(self.predicted_sum)
    }

    /// Mean residual (model − measured), N.
    pub fn bias_n(&self) -> Option<f64> {
        self.mean(self.predicted_sum - self.measured_sum)
    }

    /// RMS residual, N.
    pub fn rms_n(&self) -> Option<f64> {
        self.mean(self.squared_sum).map(f64::sqrt)
    }
}

/// One source's residual in one role, by direction of motion.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceResidual {
    /// The source's name.
    pub source: String,
    /// `fit`, `held_out` or `validate` (as in `fit.csv`).
    pub role: &'static str,
    /// Sliding with v ≥ [`SLIDING_FRACTION`] × the top speed.
    pub forward: GroupResidual,
    /// Sliding with v ≤ −[`SLIDING_FRACTION`] × the top speed.
    pub backward: GroupResidual,
    /// The slower samples, around reversals and rest.
    pub reversal: GroupResidual,
    /// Whether the source is a steady curve: its slower samples are then
    /// its slowest steady points, not a passage through reversal.
    pub steady: bool,
}

impl SourceResidual {
    /// Whether both directions hold [`MIN_DIRECTION_SAMPLES`] or more.
    pub fn enough_samples(&self) -> bool {
        self.forward.samples >= MIN_DIRECTION_SAMPLES
            && self.backward.samples >= MIN_DIRECTION_SAMPLES
    }

    /// e_level = (b₊ − b₋)/2, N: > 0 when the model's friction is too large
    /// in magnitude (None without [`MIN_DIRECTION_SAMPLES`] in each
    /// direction).
    pub fn level_error_n(&self) -> Option<f64> {
        self.enough_samples()
            .then(|| Some((self.forward.bias_n()? - self.backward.bias_n()?) / 2.0))?
    }

    /// e_offset = (b₊ + b₋)/2, N: the shift common to both directions.
    pub fn offset_error_n(&self) -> Option<f64> {
        self.enough_samples()
            .then(|| Some((self.forward.bias_n()? + self.backward.bias_n()?) / 2.0))?
    }
}

/// The role of a sample of a source of `role`: `fit`, `held_out` (the
/// held-out part of a training file, or a training sample left out of the
/// cost) or `validate`.
pub fn sample_role(role: Role, fitted: bool) -> &'static str {
    match (role, fitted) {
        (Role::Train, false) => Role::HeldOut.name(),
        (r, _) => r.name(),
    }
}

/// Every source's residual by direction: training sources first, then
/// the held-out parts, then `--validate` sources.
pub fn source_residuals(
    train: &[SeriesFit],
    held_out: &[SeriesFit],
    validate: &[SeriesFit],
) -> Vec<SourceResidual> {
    let mut out = Vec::new();
    for (fits, training) in [
        (train, Role::Train),
        (held_out, Role::HeldOut),
        (validate, Role::Validate),
    ] {
        for sf in fits {
            let s = &sf.series;
            let top = s.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let threshold = SLIDING_FRACTION * top;
            let first = out.len();
            for k in 0..s.len() {
                let (v, measured, predicted) = (s.velocity[k], s.friction[k], sf.predicted[k]);
                if !(v.is_finite() && measured.is_finite() && predicted.is_finite()) {
                    continue;
                }
                let role = sample_role(training, s.fit[k]);
                let i = match out[first..]
                    .iter()
                    .position(|r: &SourceResidual| r.role == role)
                {
                    Some(i) => first + i,
                    None => {
                        out.push(SourceResidual {
                            source: s.name.clone(),
                            role,
                            forward: GroupResidual::default(),
                            backward: GroupResidual::default(),
                            reversal: GroupResidual::default(),
                            steady: s.steady,
                        });
                        out.len() - 1
                    }
                };
                let r = &mut out[i];
                let group = if top > 0.0 && v >= threshold {
                    &mut r.forward
                } else if top > 0.0 && v <= -threshold {
                    &mut r.backward
                } else {
                    &mut r.reversal
                };
                group.add(v.abs(), measured, predicted);
            }
        }
    }
    out
}

/// A force in significant digits (any scale: N, N·m, mN).
fn force_cell(v: Option<f64>) -> String {
    v.map_or("–".into(), |x| crate::text::Num::sig(x, 5).to_string())
}

fn cell(v: Option<f64>, scale: f64, digits: usize) -> String {
    v.map_or("–".into(), |x| format!("{:.*}", digits, x * scale))
}

/// The file name of a source, for tables (its full path is in `fit.csv`).
fn short(source: &str) -> &str {
    source.rsplit(['/', '\\']).next().unwrap_or(source)
}

/// One model's residual by source and direction (markdown), in the
/// data's units (a joint's rad/s and N·m with `--rotary`).
pub fn direction_table(o: &FitOutcome) -> String {
    let f = o.units.force();
    let (speed_unit, speed_scale, digits) = match o.units {
        super::Units::Linear => ("mm/s", 1e3, 2),
        super::Units::Rotary => ("rad/s", 1.0, 4),
    };
    let mut s = format!(
        "| source | role | motion | samples | mean speed ({speed_unit}) | measured mean ({f}) | model mean ({f}) | bias ({f}) | RMS ({f}) |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in source_residuals(&o.train, &o.held_out, &o.validate) {
        let slow = if r.steady { "slow" } else { "reversal" };
        for (motion, g) in [
            ("forward", &r.forward),
            ("backward", &r.backward),
            (slow, &r.reversal),
        ] {
            if g.samples == 0 {
                continue;
            }
            let _ = writeln!(
                s,
                "| {} | {} | {motion} | {} | {} | {} | {} | {} | {} |",
                short(&r.source),
                r.role,
                g.samples,
                cell(g.mean_speed_m_s(), speed_scale, digits),
                force_cell(g.measured_mean_n()),
                force_cell(g.predicted_mean_n()),
                force_cell(g.bias_n()),
                force_cell(g.rms_n()),
            );
        }
    }
    let _ = writeln!(
        s,
        "\nforward / backward: sliding faster than {:.0} % of the source's top speed; reversal: the rest \
         (slow on a steady curve, which passes through no reversal). \
         Bias = mean(model − measured).",
        100.0 * SLIDING_FRACTION
    );
    s
}

/// Every model's level and offset error on the same sources (markdown):
/// held-out and `--validate` sources when there are any, else the fitted
/// ones.
pub fn models_direction_table(models: &[&FitOutcome]) -> String {
    if models.is_empty() {
        return String::new();
    }
    let rows: Vec<Vec<SourceResidual>> = models
        .iter()
        .map(|o| source_residuals(&o.train, &o.held_out, &o.validate))
        .collect();
    let held_out = rows[0].iter().any(|r| r.role != "fit");
    let f = models[0].units.force();
    let mut s = format!("| source | role | measured +/− ({f})¹ |");
    for o in models {
        let _ = write!(s, " {}: level / offset error ({f}) |", o.label);
    }
    s.push_str("\n|---|---|---|");
    s.push_str(&"---|".repeat(models.len()));
    s.push('\n');
    for (i, r) in rows[0].iter().enumerate() {
        if held_out && r.role == "fit" {
            continue;
        }
        let _ = write!(
            s,
            "| {} | {} | {} / {} |",
            short(&r.source),
            r.role,
            force_cell(r.forward.measured_mean_n()),
            force_cell(r.backward.measured_mean_n())
        );
        for m in &rows {
            match m.get(i) {
                Some(x) if !x.enough_samples() => {
                    let _ = write!(
                        s,
                        " too few samples (n₊ = {}, n₋ = {}) |",
                        x.forward.samples, x.backward.samples
                    );
                }
                x => {
                    let (level, offset) =
                        x.map_or((None, None), |x| (x.level_error_n(), x.offset_error_n()));
                    let _ = write!(s, " {} / {} |", force_cell(level), force_cell(offset));
                }
            }
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "\nWhile sliding (faster than {:.0} % of the source's top speed; at least {MIN_DIRECTION_SAMPLES} samples each way): level error (b₊ − b₋)/2 > 0 where the \
         model's friction is too large in magnitude; offset error (b₊ + b₋)/2, the same shift in both \
         directions (an offset, an effective area, a level that differs by direction), which no friction \
         level carries. b = mean(model − measured), each model against the data through its own input maps; \
         ¹ the mean measured friction sliding forward / backward, through the first model's maps.",
        100.0 * SLIDING_FRACTION
    );
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::series::Series;
    use approx::assert_relative_eq;

    /// A reciprocating source: ±10 mm/s strokes with reversals between,
    /// measured friction 5 sgn(v) + `offset`, model 5 (1 + `level`) sgn(v).
    fn source(level: f64, offset: f64) -> SeriesFit {
        let n = 400;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
        let velocity: Vec<f64> = t
            .iter()
            .map(|t| 0.01 * (2.0 * std::f64::consts::PI * t / 2.0).sin())
            .collect();
        let sgn = |v: f64| (v / 1e-3).tanh();
        let friction: Vec<f64> = velocity.iter().map(|v| 5.0 * sgn(*v) + offset).collect();
        let predicted: Vec<f64> = velocity
            .iter()
            .map(|v| 5.0 * (1.0 + level) * sgn(*v))
            .collect();
        SeriesFit {
            series: std::sync::Arc::new(Series {
                name: "data/stroke.csv".into(),
                steady: false,
                t,
                fit: vec![true; n],
                velocity,
                friction,
                load: None,
                temperature: None,
            }),
            predicted,
        }
    }

    #[test]
    fn a_force_that_does_not_change_sign_is_an_offset_error_not_a_level_error() {
        let r = source_residuals(&[source(0.0, 0.8)], &[], &[]);
        assert_eq!(r.len(), 1);
        assert_relative_eq!(r[0].offset_error_n().unwrap(), -0.8, epsilon = 1e-12);
        assert_relative_eq!(r[0].level_error_n().unwrap(), 0.0, epsilon = 1e-12);
    }

    #[test]
    fn a_friction_level_too_large_is_a_level_error_not_an_offset_error() {
        let r = source_residuals(&[source(0.1, 0.0)], &[], &[]);
        let level = r[0].level_error_n().unwrap();
        // 10 % of 5 N, a little less where tanh has not saturated.
        assert!(level > 0.45 && level <= 0.5, "level error {level}");
        assert_relative_eq!(r[0].offset_error_n().unwrap(), 0.0, epsilon = 1e-9);
    }

    #[test]
    fn a_direction_with_too_few_samples_gives_no_level_or_offset_error() {
        let mut one_back = source(0.0, 0.8);
        // Every backward sample but one becomes a reversal sample.
        let mut kept = false;
        for v in std::sync::Arc::make_mut(&mut one_back.series)
            .velocity
            .iter_mut()
        {
            if *v < -0.001 {
                if kept {
                    *v = 0.0;
                }
                kept = true;
            }
        }
        let r = source_residuals(&[one_back.clone()], &[], &[]);
        assert_eq!(r[0].backward.samples, 1);
        assert!(!r[0].enough_samples());
        assert_eq!(r[0].level_error_n(), None);
        assert_eq!(r[0].offset_error_n(), None);
        let o = crate::fit::driver::tests_outcome(vec![one_back]);
        let table = models_direction_table(&[&o]);
        assert!(table.contains("too few samples (n₊ = "), "{table}");
    }

    #[test]
    fn slow_samples_count_as_reversal_and_roles_split_sources() {
        let r = source_residuals(
            &[source(0.0, 0.0)],
            &[source(0.0, 0.0)],
            &[source(0.0, 0.0)],
        );
        let roles: Vec<&str> = r.iter().map(|x| x.role).collect();
        assert_eq!(roles, ["fit", "held_out", "validate"]);
        // |sin| < 0.1 on about 6.4 % of a period.
        let v = &r[2];
        let total = v.forward.samples + v.backward.samples + v.reversal.samples;
        assert_eq!(total, 400);
        assert!(
            (20..=32).contains(&v.reversal.samples),
            "{} reversal samples",
            v.reversal.samples
        );
        assert!(v.forward.mean_speed_m_s().unwrap() > 0.005);
    }

    #[test]
    fn a_steady_curves_slowest_points_are_called_slow_not_a_reversal() {
        let mut curve = source(0.0, 0.0);
        let mut series = (*curve.series).clone();
        series.steady = true;
        curve.series = std::sync::Arc::new(series);
        let table = direction_table(&crate::fit::driver::tests_outcome(vec![curve]));
        assert!(table.contains("| fit | slow |"), "{table}");
        assert!(!table.contains("| reversal |"), "{table}");
        let series = direction_table(&crate::fit::driver::tests_outcome(vec![source(0.0, 0.0)]));
        assert!(series.contains("| fit | reversal |"), "{series}");
    }
}
