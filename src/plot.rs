//! SVG figures (plotters, pure Rust, no system fonts), shared by the study
//! reports and the replay report.

use crate::output::{write_file, OutputError};
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// The figures' line colours, in order.
pub const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// A line of a panel.
pub struct Line {
    /// Its legend (None: not in the legend).
    pub label: Option<String>,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
    /// Its colour.
    pub color: RGBColor,
    /// Dashed instead of solid.
    pub dashed: bool,
}

/// One panel of a figure.
pub struct Panel {
    /// Its title.
    pub title: String,
    /// Its lines.
    pub lines: Vec<Line>,
}

/// Axis labels and scales of every panel.
pub struct Axes<'a> {
    /// x label with unit.
    pub x: &'a str,
    /// y label with unit.
    pub y: &'a str,
    /// Logarithmic x.
    pub log_x: bool,
    /// Logarithmic y.
    pub log_y: bool,
    /// Where the legend goes.
    pub legend: SeriesLabelPosition,
    /// Legend in every panel (series differ between panels) or only in
    /// the first (the same series everywhere).
    pub legend_everywhere: bool,
}

/// Tick label: plain for ordinary values, short exponent form for tiny
/// or huge ones.
fn tick(v: f64, span: f64, log: bool) -> String {
    let a = v.abs();
    if a == 0.0 || (!log && a < 1e-9 * span) {
        return "0".into();
    }
    let plain = if log {
        (1e-3..1e4).contains(&a)
    } else {
        (1e-3..1e5).contains(&span)
    };
    if !plain {
        return format!("{v:.1e}").replace(".0e", "e");
    }
    let digits = if log {
        (-(a.log10().floor()) + 1.0).clamp(0.0, 6.0) as usize
    } else {
        (-(span / 5.0).log10().floor()).clamp(0.0, 6.0) as usize
    };
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A plotting error as an output error on `path`.
pub fn plot_err(path: &Path, e: impl std::fmt::Display) -> OutputError {
    OutputError::other(path, e)
}

/// At most `max` points, evenly spaced (keeps the last point).
fn decimate(points: Vec<(f64, f64)>, max: usize) -> Vec<(f64, f64)> {
    if points.len() <= max {
        return points;
    }
    let step = points.len().div_ceil(max);
    let last = *points.last().expect("non-empty");
    let mut out: Vec<(f64, f64)> = points.into_iter().step_by(step).collect();
    if out.last() != Some(&last) {
        out.push(last);
    }
    out
}

/// Points per plotted line (the CSVs keep every sample).
const MAX_POINTS: usize = 1200;

fn bounds(panel: &Panel, log_x: bool, log_y: bool) -> ((f64, f64), (f64, f64)) {
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for l in &panel.lines {
        for &(x, y) in &l.points {
            if !(x.is_finite() && y.is_finite()) || (log_x && x <= 0.0) || (log_y && y <= 0.0) {
                continue;
            }
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if !x0.is_finite() {
        return ((0.0, 1.0), (0.0, 1.0));
    }
    let pad = |a: f64, b: f64, log: bool| -> (f64, f64) {
        if log {
            (a / 1.3, b * 1.3)
        } else {
            let d = if b > a {
                0.05 * (b - a)
            } else {
                0.05 * a.abs().max(1e-12)
            };
            (a - d, b + d)
        }
    };
    (pad(x0, x1, log_x), pad(y0, y1, log_y))
}

/// A line's points that its axes can show (finite; positive on a log
/// axis), decimated to [`MAX_POINTS`].
fn plottable(l: &Line, ax: &Axes<'_>) -> Vec<(f64, f64)> {
    decimate(
        l.points
            .iter()
            .copied()
            .filter(|&(x, y)| {
                x.is_finite() && y.is_finite() && (!ax.log_x || x > 0.0) && (!ax.log_y || y > 0.0)
            })
            .collect(),
        MAX_POINTS,
    )
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    p: &Panel,
    ax: &Axes<'_>,
    legend: bool,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let ((x0, x1), (y0, y1)) = bounds(p, ax.log_x, ax.log_y);
    let mut b = ChartBuilder::on(area);
    b.caption(&p.title, ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(38)
        .y_label_area_size(62);
    let spans = (x1 - x0, y1 - y0);
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    match (ax.log_x, ax.log_y) {
        (false, false) => {
            let chart = b.build_cartesian_2d(x0..x1, y0..y1).map_err(e)?;
            draw_chart(chart, p, ax, legend, spans)
        }
        (true, false) => {
            let chart = b
                .build_cartesian_2d((x0..x1).log_scale(), y0..y1)
                .map_err(e)?;
            draw_chart(chart, p, ax, legend, spans)
        }
        (false, true) => {
            let chart = b
                .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
                .map_err(e)?;
            draw_chart(chart, p, ax, legend, spans)
        }
        (true, true) => {
            let chart = b
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(e)?;
            draw_chart(chart, p, ax, legend, spans)
        }
    }
}

/// A panel's mesh, lines and legend on a chart of any axis scales; `spans`
/// are the axes' ranges (for the ticks' digits).
fn draw_chart<'a, DB, X, Y>(
    mut chart: ChartContext<'a, DB, Cartesian2d<X, Y>>,
    p: &Panel,
    ax: &Axes<'_>,
    legend: bool,
    (xs, ys): (f64, f64),
) -> Result<(), String>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    chart
        .configure_mesh()
        .x_desc(ax.x)
        .y_desc(ax.y)
        .x_label_formatter(&|v| tick(*v, xs, ax.log_x))
        .y_label_formatter(&|v| tick(*v, ys, ax.log_y))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(|e| e.to_string())?;
    let mut labelled = false;
    for l in &p.lines {
        let pts = plottable(l, ax);
        let style = ShapeStyle::from(&l.color).stroke_width(if l.dashed { 1 } else { 2 });
        let s = if l.dashed {
            chart.draw_series(DashedLineSeries::new(pts, 6, 4, style))
        } else {
            chart.draw_series(LineSeries::new(pts, style))
        }
        .map_err(|e| e.to_string())?;
        if let Some(label) = &l.label {
            let (c, dashed) = (l.color, l.dashed);
            s.label(label.clone()).legend(move |(x, y)| {
                // A dashed line's key is dashed too.
                let (a, b) = if dashed { (7, 11) } else { (18, 18) };
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (a, 0)], c.stroke_width(2))
                    + PathElement::new(vec![(b, 0), (18, 0)], c.stroke_width(2))
            });
            labelled = true;
        }
    }
    if labelled && legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(180, 180, 180))
            .label_font(("sans-serif", 12))
            .position(ax.legend.clone())
            .draw()
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Draw `panels` on a grid under `title` into the SVG `path` (written atomically).
pub fn figure(
    path: &Path,
    title: &str,
    panels: &[Panel],
    ax: &Axes<'_>,
) -> Result<PathBuf, OutputError> {
    let cols = panels.len().clamp(1, 3);
    let rows = panels.len().div_ceil(cols).max(1);
    let (w, h) = (460 * cols as u32, 40 + 380 * rows as u32);
    // Rendered in memory, then written atomically (a failed write is an
    // error, never a half-written figure).
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let (top, rest) = root.split_vertically(40);
        top.titled(title, ("sans-serif", 20))
            .map_err(|e| plot_err(path, e))?;
        // Colours mean the same in every panel: one legend, in the first.
        for (k, (area, p)) in rest
            .split_evenly((rows, cols))
            .iter()
            .zip(panels)
            .enumerate()
        {
            draw_panel(area, p, ax, k == 0 || ax.legend_everywhere)
                .map_err(|e| plot_err(path, e))?;
        }
        root.present().map_err(|e| plot_err(path, e))?;
    }
    write_file(path, svg.as_bytes())
}
