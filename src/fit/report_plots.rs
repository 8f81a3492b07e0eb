//! A report's plots: the fit and its residuals per series, and the
//! residual of every model against velocity (SVG, with the `plots`
//! feature, which this file is compiled with); the binned residual they
//! draw.

use super::driver::FitOutcome;
use super::problem::SeriesFit;
use crate::output::OutputError;
use crate::plot::{figure, Axes, Line, Panel, COLORS};
use plotters::prelude::SeriesLabelPosition;
use std::path::{Path, PathBuf};

/// The mean residual (model − measured, N) in `bins` equal bins of
/// velocity over the samples of `fit`: (bin centre, mean) for bins that
/// hold samples.
pub fn binned_residual(fit: &SeriesFit, bins: usize) -> Vec<(f64, f64)> {
    let v = &fit.series.velocity;
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Vec::new();
    }
    let w = (hi - lo) / bins as f64;
    let mut sum = vec![(0.0, 0usize); bins];
    for (k, vk) in v.iter().enumerate() {
        let r = fit.predicted[k] - fit.series.friction[k];
        if r.is_finite() {
            let b = (((vk - lo) / w) as usize).min(bins - 1);
            sum[b].0 += r;
            sum[b].1 += 1;
        }
    }
    sum.iter()
        .enumerate()
        .filter(|(_, (_, n))| *n > 0)
        .map(|(b, (s, n))| (lo + (b as f64 + 0.5) * w, s / *n as f64))
        .collect()
}

fn line(label: &str, c: usize, points: Vec<(f64, f64)>, dashed: bool) -> Line {
    Line {
        label: Some(label.into()),
        points,
        color: COLORS[c % COLORS.len()],
        dashed,
    }
}

fn panels(
    fits: &[SeriesFit],
    role: &str,
    x: impl Fn(&SeriesFit, usize) -> f64,
    resid: bool,
) -> Vec<Panel> {
    fits.iter()
        .map(|f| {
            let n = f.series.len();
            let pts = |y: &dyn Fn(usize) -> f64| (0..n).map(|k| (x(f, k), y(k))).collect();
            let name = Path::new(&f.series.name)
                .file_name()
                .map_or(f.series.name.clone(), |s| s.to_string_lossy().into_owned());
            let lines = if resid {
                vec![line(
                    "residual",
                    2,
                    pts(&|k| f.predicted[k] - f.series.friction[k]),
                    false,
                )]
            } else {
                vec![
                    line("measured", 0, pts(&|k| f.series.friction[k]), false),
                    line("model", 1, pts(&|k| f.predicted[k]), true),
                ]
            };
            Panel {
                title: format!("{name} ({role})"),
                lines,
            }
        })
        .collect()
}

/// One panel per held-out source (validation data, else the training
/// data), one line per model: its residual against velocity, averaged
/// in 40 bins of velocity.
pub(super) fn residual_by_velocity(
    dir: &Path,
    models: &[&FitOutcome],
) -> Result<Vec<PathBuf>, OutputError> {
    // The data not fitted: --validate files, else the held-out parts,
    // else (nothing held out) the training data.
    fn pick(o: &FitOutcome) -> (&[SeriesFit], &'static str) {
        if !o.validate.is_empty() {
            (&o.validate, "validation")
        } else if !o.held_out.is_empty() {
            (&o.held_out, "held out")
        } else {
            (&o.train, "training")
        }
    }
    let (sources, role) = pick(models[0]);
    let panels: Vec<Panel> = (0..sources.len())
        .map(|j| {
            let name = Path::new(&sources[j].series.name)
                .file_name()
                .map_or(sources[j].series.name.clone(), |s| {
                    s.to_string_lossy().into_owned()
                });
            Panel {
                title: format!("{name} ({role})"),
                lines: models
                    .iter()
                    .enumerate()
                    .filter_map(|(m, o)| {
                        pick(o)
                            .0
                            .get(j)
                            .map(|f| line(&o.label, m, binned_residual(f, 40), m > 0))
                    })
                    .collect(),
            }
        })
        .collect();
    if panels.is_empty() {
        return Ok(Vec::new());
    }
    let u = models[0].units;
    let (x, y) = (
        format!("velocity ({})", u.speed()),
        format!("mean residual, model − measured ({})", u.force()),
    );
    let ax = Axes {
        x: &x,
        y: &y,
        log_x: false,
        log_y: false,
        legend: SeriesLabelPosition::UpperLeft,
        legend_everywhere: false,
    };
    Ok(vec![figure(
        &dir.join("residual_velocity.svg"),
        "residual against velocity, every model",
        &panels,
        &ax,
    )?])
}

pub(super) fn write(dir: &Path, o: &FitOutcome) -> Result<Vec<PathBuf>, OutputError> {
    let (f, v) = (o.units.force(), o.units.speed());
    let (friction, velocity, residual) = (
        format!("friction ({f})"),
        format!("velocity ({v})"),
        format!("residual ({f})"),
    );
    fn ax<'a>(x: &'a str, y: &'a str) -> Axes<'a> {
        Axes {
            x,
            y,
            log_x: false,
            log_y: false,
            legend: SeriesLabelPosition::UpperRight,
            legend_everywhere: true,
        }
    }
    let roles = [
        (&o.train, "training"),
        (&o.held_out, "held out"),
        (&o.validate, "validation"),
    ];
    let every = |x: &dyn Fn(&SeriesFit, usize) -> f64, resid: bool| -> Vec<Panel> {
        roles
            .iter()
            .flat_map(|(fits, role)| panels(fits, role, x, resid))
            .collect()
    };
    let all = every(&|f, k| f.series.t[k], false);
    let vel = every(&|f, k| f.series.velocity[k], false);
    let res = every(&|f, k| f.series.t[k], true);
    let steady = o.train.iter().all(|f| f.series.steady);
    let tx = if steady { "point" } else { "time (s)" };
    Ok(vec![
        figure(
            &dir.join("friction_time.svg"),
            &format!("{}: measured and fitted friction", o.label),
            &all,
            &ax(tx, &friction),
        )?,
        figure(
            &dir.join("friction_velocity.svg"),
            &format!("{}: friction against velocity", o.label),
            &vel,
            &ax(&velocity, &friction),
        )?,
        figure(
            &dir.join("residual.svg"),
            &format!("{}: residual (model − measured)", o.label),
            &res,
            &ax(tx, &residual),
        )?,
    ])
}
