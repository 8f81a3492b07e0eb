//! The replay report: `summary.md`, loop metrics per cycle (`cycles.csv`)
//! and figures.

use super::{Oracle, PreparedReplay, ReplayResult};
use crate::bag::Silence;
use crate::msgs;
use crate::output::OutputError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The first step's stamp, ns.
fn t0_ns(p: &PreparedReplay) -> u64 {
    p.commands.first().map_or(0, |c| c.stamp_ns)
}

/// "1.200 s (0.5 s long), …" relative to `t0_ns`, at most five.
pub fn gap_list(gaps: &[Silence], t0_ns: u64) -> String {
    let mut s: Vec<String> = gaps
        .iter()
        .take(5)
        .map(|g| {
            format!(
                "at {:.3} s ({:.3} s long)",
                g.from_ns.saturating_sub(t0_ns) as f64 / 1e9,
                g.length_s
            )
        })
        .collect();
    if gaps.len() > 5 {
        s.push(format!("and {} more", gaps.len() - 5));
    }
    s.join(", ")
}

/// Hysteresis of the cycle detection, as a fraction of the velocity's
/// half-range: a swing must reach this far past the mean on both sides to
/// count as a cycle, so chatter about a reversal (noise, a controller's
/// limit cycle at standstill) is not one.
pub(super) const CYCLE_HYSTERESIS: f64 = 0.25;

/// Where the cycles of `velocity` start: at its last upward crossing of
/// the mean before it rises [`CYCLE_HYSTERESIS`] of its half-range above
/// the mean, having been as far below it since the last start (a Schmitt
/// trigger placed on the mean crossing); and at a last upward crossing the
/// record ends after.
pub(super) fn cycle_starts(velocity: &[f64]) -> Vec<usize> {
    let n = velocity.len();
    if n < 2 {
        return Vec::new();
    }
    let (lo, hi) = velocity
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(*v), b.max(*v))
        });
    let mean = velocity.iter().sum::<f64>() / n as f64;
    let band = CYCLE_HYSTERESIS * 0.5 * (hi - lo);
    if band.is_nan() || band <= 0.0 {
        return Vec::new();
    }
    let mut starts = Vec::new();
    // A record that starts below the mean starts a cycle where it rises
    // through it, as one that ends just after an upward crossing closes one.
    let (mut armed, mut last_up) = (velocity[0] < mean, None);
    for k in 1..n {
        let (a, b) = (velocity[k - 1], velocity[k]);
        if armed && a < mean && b >= mean {
            last_up = Some(k);
        }
        if armed && b >= mean + band {
            starts.push(last_up.unwrap_or(k));
            armed = false;
        } else if b < mean - band {
            armed = true;
            last_up = None;
        }
    }
    // A record that ends just after its last upward crossing (a whole
    // number of periods) closes its last cycle there.
    if let (true, Some(k)) = (armed, last_up) {
        starts.push(k);
    }
    starts
}

/// Cycles of a replay: segments between the starts `cycle_starts`
/// finds, and their loop metrics.
pub fn cycles(r: &ReplayResult, mass: f64) -> Vec<crate::analysis::LoopMetrics> {
    use crate::analysis::{metrics::one_cycle, LoopSample};
    let e = &r.estimates;
    if e.len() < 8 {
        return Vec::new();
    }
    let t0 = e[0].1.stamp_ns;
    let samples: Vec<LoopSample> = e
        .iter()
        .map(|(est, rec)| {
            let mut s = LoopSample::from(est);
            s.t = rec.stamp_ns.saturating_sub(t0) as f64 / 1e9;
            s
        })
        .collect();
    let velocity: Vec<f64> = samples.iter().map(|s| s.velocity).collect();
    cycle_starts(&velocity)
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[1] - w[0] >= 8)
        .map(|(k, w)| {
            one_cycle(
                k,
                samples[w[0]].t,
                samples[w[1]].t,
                &samples[w[0]..w[1]],
                mass,
                6,
            )
        })
        .collect()
}

/// `cycles.csv`: every cycle's loop metrics.
fn write_cycles_csv(
    dir: &Path,
    cyc: &[crate::analysis::LoopMetrics],
) -> Result<PathBuf, OutputError> {
    use crate::text::Num;
    let mut f = crate::output::AtomicFile::create(&dir.join("cycles.csv"))?;
    f.line(format_args!(
        "cycle,t_start_s,t_end_s,{}",
        crate::analysis::metrics::LOOP_METRIC_COLUMNS
    ))?;
    for m in cyc {
        f.line(format_args!(
            "{},{},{},{}",
            m.cycle + 1,
            Num(m.t_start),
            Num(m.t_end),
            m.csv_fields()
        ))?;
    }
    f.commit()
}

/// The summary's table: input, configuration, steps, gaps, damage,
/// statuses, regimes and the determinism verdict.
fn summary_table(bag: &Path, p: &PreparedReplay, r: &ReplayResult, wall_s: f64) -> String {
    let e = &r.estimates;
    let span = match (e.first(), e.last()) {
        (Some(a), Some(b)) => (b.1.stamp_ns.saturating_sub(a.1.stamp_ns)) as f64 / 1e9,
        _ => 0.0,
    };
    let mut status = BTreeMap::new();
    let mut regime = [0usize; 3];
    for (_, rec) in e {
        *status
            .entry(msgs::status_name(rec.status))
            .or_insert(0usize) += 1;
        regime[(rec.regime as usize).min(2)] += 1;
    }
    let mut md = String::new();
    md.push_str(&format!("# Replay of `{}`\n\n", bag.display()));
    md.push_str("| | |\n|---|---|\n");
    md.push_str(&format!("| input | {} |\n", p.mode.describe()));
    if p.scan.files.len() > 1 {
        md.push_str(&format!(
            "| bag | a rosbag2 directory of {} split files, replayed in order as one run |\n",
            p.scan.files.len()
        ));
    }
    md.push_str(&format!("| configuration | {} |\n", p.config_source));
    md.push_str(&format!(
        "| steps | {} over {:.3} s of bag time, replayed in {:.3} s ({:.0}× real time) |\n",
        e.len(),
        span,
        wall_s,
        if wall_s > 0.0 {
            span / wall_s
        } else {
            f64::NAN
        }
    ));
    md.push_str(&format!(
        "| commands rejected | {} |\n",
        r.commands_rejected
    ));
    md.push_str(&format!(
        "| contact steps outside the calibrated range | {} |\n",
        r.steps_outside_calibrated_range
    ));
    if !p.gaps.is_empty() {
        md.push_str(&format!(
            "| velocity gaps | {} longer than the command timeout ({} s; the node's timeout rule applied): {} |\n",
            p.gaps.len(),
            p.config.node.command_timeout_s,
            gap_list(&p.gaps, t0_ns(p))
        ));
    }
    if let Some(d) = &p.scan.damage {
        md.push_str(&format!(
            "| **damaged bag** | replayed everything before the damage, {d} |\n"
        ));
    }
    md.push_str(&format!(
        "| statuses | {} |\n",
        status
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    let n = e.len().max(1) as f64;
    md.push_str(&format!(
        "| regime (share of steps) | boundary {:.1} %, mixed {:.1} %, hydrodynamic {:.1} % |\n",
        100.0 * regime[0] as f64 / n,
        100.0 * regime[1] as f64 / n,
        100.0 * regime[2] as f64 / n
    ));
    if let Some(o) = &r.oracle {
        md.push_str(&format!("| determinism | {} |\n", verdict(o)));
    }
    md
}

/// The determinism oracle's verdict in one line.
fn verdict(o: &Oracle) -> String {
    if o.identical {
        return format!(
            "re-simulation **bit-identical** to the recording ({} steps)",
            o.compared
        );
    }
    format!(
        "**differs** from the recording: {}{}",
        o.deviations
            .iter()
            .map(|(f, d, k)| format!("{f} by up to {d:.3e} (step {k})"))
            .collect::<Vec<_>>()
            .join("; "),
        o.count_mismatch.map_or(String::new(), |(a, b)| format!(
            "; {a} steps recorded, {b} replayed"
        ))
    )
}

/// The summary's loop-metrics section (the first 20 cycles).
fn loop_metrics_section(cyc: &[crate::analysis::LoopMetrics]) -> String {
    if cyc.is_empty() {
        return "\nNo periodic cycles were detected (the velocity does not cross its mean repeatedly).\n".into();
    }
    let mut md = format!(
        "\n## Loop metrics ({} cycles; `cycles.csv` has all columns)\n\n",
        cyc.len()
    );
    md.push_str("| cycle | t (s) | friction loop area (N·m/s) | COF loop area (m/s) | peak COF at v | mean COF | h0 range (µm) | asperity share | M raw / smooth |\n|---|---|---|---|---|---|---|---|---|\n");
    for m in cyc.iter().take(20) {
        md.push_str(&format!(
            "| {} | {:.3}–{:.3} | {:.2} | {:.5} | {:.4} at {:+.3} m/s | {:.4} | {:.3}–{:.3} | {:.1} % | {:.1e} / {:.1e} |\n",
            m.cycle + 1,
            m.t_start,
            m.t_end,
            m.friction_loop_area,
            m.cof_loop_area,
            m.peak_cof,
            m.peak_cof_velocity,
            m.mean_cof,
            m.h0_min * 1e6,
            m.h0_max * 1e6,
            100.0 * m.mean_asperity_share,
            m.inertia_share,
            m.inertia_share_smooth
        ));
    }
    if cyc.len() > 20 {
        md.push_str(&format!(
            "| … | {} more in `cycles.csv` | | | | | | | |\n",
            cyc.len() - 20
        ));
    }
    md
}

/// Write the report: `summary.md`, `cycles.csv` and (feature `plots`) SVG
/// figures into `dir`.
pub fn write_report(
    dir: &Path,
    bag: &Path,
    p: &PreparedReplay,
    r: &ReplayResult,
    wall_s: f64,
) -> Result<Vec<PathBuf>, OutputError> {
    std::fs::create_dir_all(dir).map_err(|e| OutputError::new(dir, e))?;
    let cyc = cycles(r, p.config.contact.mass_kg);
    let mut files = vec![write_cycles_csv(dir, &cyc)?];
    #[cfg(feature = "plots")]
    let figures = plots::write(dir, r)?;
    #[cfg(not(feature = "plots"))]
    let figures: Vec<PathBuf> = Vec::new();
    let mut md = summary_table(bag, p, r, wall_s);
    md.push_str(&loop_metrics_section(&cyc));
    if !figures.is_empty() {
        md.push_str("\n## Figures\n\n");
        for f in &figures {
            if let Some(name) = f.file_name() {
                md.push_str(&format!("![{0}]({0})\n\n", name.to_string_lossy()));
            }
        }
    }
    files.extend(figures);
    let mut f = crate::output::AtomicFile::create(&dir.join("summary.md"))?;
    f.line(format_args!("{}", md.trim_end()))?;
    files.push(f.commit()?);
    Ok(files)
}

#[cfg(feature = "plots")]
mod plots {
    use super::*;
    use crate::msgs::EstimateRecord;
    use crate::plot::{figure, Axes, Line, Panel, COLORS};
    use plotters::prelude::SeriesLabelPosition;

    type Steps = [(crate::physics::Estimate, EstimateRecord)];

    fn line(label: &str, k: usize, points: Vec<(f64, f64)>) -> Line {
        Line {
            label: Some(label.to_string()),
            points,
            color: COLORS[k % COLORS.len()],
            dashed: false,
        }
    }

    fn axes(x: &'static str) -> Axes<'static> {
        Axes {
            x,
            y: "",
            log_x: false,
            log_y: false,
            legend: SeriesLabelPosition::UpperRight,
            legend_everywhere: true,
        }
    }

    /// Seconds since the first step.
    fn seconds(e: &Steps) -> impl Fn(&EstimateRecord) -> f64 {
        let t0 = e.first().map_or(0, |x| x.1.stamp_ns);
        move |rec| rec.stamp_ns.saturating_sub(t0) as f64 / 1e9
    }

    fn friction_velocity(dir: &Path, e: &Steps) -> Result<PathBuf, OutputError> {
        figure(
            &dir.join("friction_velocity.svg"),
            "friction against velocity",
            &[
                Panel {
                    title: "friction force".into(),
                    lines: vec![line(
                        "F_f",
                        0,
                        e.iter()
                            .map(|(_, r)| (r.velocity_m_s, r.friction_force_n))
                            .collect(),
                    )],
                },
                Panel {
                    title: "coefficient of friction".into(),
                    lines: vec![line(
                        "COF",
                        1,
                        e.iter().map(|(_, r)| (r.velocity_m_s, r.cof)).collect(),
                    )],
                },
            ],
            &axes("velocity (m/s)"),
        )
    }

    fn time_series(dir: &Path, e: &Steps) -> Result<PathBuf, OutputError> {
        let t = seconds(e);
        figure(
            &dir.join("time_series.svg"),
            "velocity, friction and film thickness against time",
            &[
                Panel {
                    title: "velocity (m/s)".into(),
                    lines: vec![line(
                        "v",
                        0,
                        e.iter().map(|(_, r)| (t(r), r.velocity_m_s)).collect(),
                    )],
                },
                Panel {
                    title: "friction force (N)".into(),
                    lines: vec![line(
                        "F_f",
                        1,
                        e.iter().map(|(_, r)| (t(r), r.friction_force_n)).collect(),
                    )],
                },
                Panel {
                    title: "h0 (µm)".into(),
                    lines: vec![line(
                        "h0",
                        2,
                        e.iter().map(|(_, r)| (t(r), r.h0_m * 1e6)).collect(),
                    )],
                },
            ],
            &axes("time (s)"),
        )
    }

    fn regime_share(dir: &Path, e: &Steps) -> Result<PathBuf, OutputError> {
        let t = seconds(e);
        figure(
            &dir.join("regime_share.svg"),
            "lubrication regime and load share against time",
            &[
                Panel {
                    title: "load share".into(),
                    lines: vec![
                        line(
                            "asperities",
                            0,
                            e.iter()
                                .map(|(_, r)| (t(r), r.asperity_load_share))
                                .collect(),
                        ),
                        line(
                            "fluid",
                            1,
                            e.iter()
                                .map(|(_, r)| (t(r), r.hydrodynamic_force_n / r.load_n))
                                .collect(),
                        ),
                    ],
                },
                Panel {
                    title: "regime: 0 boundary, 1 mixed, 2 hydrodynamic".into(),
                    lines: vec![line(
                        "regime",
                        3,
                        e.iter().map(|(_, r)| (t(r), r.regime as f64)).collect(),
                    )],
                },
            ],
            &axes("time (s)"),
        )
    }

    pub(super) fn write(dir: &Path, r: &ReplayResult) -> Result<Vec<PathBuf>, OutputError> {
        let e = &r.estimates;
        Ok(vec![
            friction_velocity(dir, e)?,
            time_series(dir, e)?,
            regime_share(dir, e)?,
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chatter_at_reversals_is_not_counted_as_cycles() {
        // 5 cycles of a 1 Hz motion at 1 kHz, with a 25 Hz chatter of 20 %
        // of the amplitude while the motion passes through zero.
        let v: Vec<f64> = (0..5000)
            .map(|k| {
                let t = k as f64 * 1e-3;
                let s = (2.0 * std::f64::consts::PI * t).sin();
                let chatter = if s.abs() < 0.2 {
                    0.2 * (2.0 * std::f64::consts::PI * 25.0 * t).sin()
                } else {
                    0.0
                };
                s + chatter
            })
            .collect();
        let starts = cycle_starts(&v);
        // Starts at t = 1, 2, 3, 4 s (the record starts at the mean, not
        // below it, and ends just before t = 5 s, below it).
        assert_eq!(starts.len(), 4, "{starts:?}");
        for (i, k) in starts.iter().enumerate() {
            let t = *k as f64 * 1e-3;
            assert!((t - (i + 1) as f64).abs() < 0.02, "start {i} at {t} s");
        }
    }
}
