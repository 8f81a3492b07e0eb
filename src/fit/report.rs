//! What a fit tells its user: the parameter table (standard errors, 95 %
//! intervals, flags), correlations, the distinct optima, the residuals;
//! `summary.md`, `fit.csv` and plots (`report_plots.rs`) in a report
//! directory, with the models table (`models_table.rs`); the fitted
//! parameter file.

use super::data::Role;
use super::driver::FitOutcome;
use super::models_table::on_joint;
use super::stats::CORRELATION_FLAG;
use crate::config::Config;
use crate::output::{AtomicFile, OutputError};
use crate::text::Num;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Parameters: value, SE, 95 % interval, bounds, flags (and, on a rotary
/// joint, each value as it acts on the joint).
pub fn parameter_table(o: &FitOutcome) -> String {
    let joint = o.contact_scale.is_some();
    let mut s = String::from("| parameter | value | std. error | 95 % interval | bounds | flag |");
    if joint {
        s.push_str(if o.units == super::Units::Rotary {
            " on the joint |"
        } else {
            " on the axis |"
        });
    }
    s.push_str("\n|---|---|---|---|---|---|");
    s.push_str(if joint { "---|\n" } else { "\n" });
    for (j, p) in o.params.iter().enumerate() {
        let st = &o.statistics;
        let flag = parameter_flag(st.at_bound[j], o.best[j], st.standard_error[j]);
        let _ = write!(
            s,
            "| `{}` | {} | {} | [{}, {}] | [{}, {}]{} | {flag} |",
            p.name,
            Num(o.best[j]).sci(4),
            Num(st.standard_error[j]).sci(4),
            Num(st.interval95[j].0).sci(4),
            Num(st.interval95[j].1).sci(4),
            Num(p.lo).sci(4),
            Num(p.hi).sci(4),
            if p.log { " log" } else { "" },
        );
        if joint {
            let _ = write!(s, " {} |", on_joint(o, &p.name, o.best[j]));
        }
        s.push('\n');
    }
    if o.statistics.batches > 0 {
        let _ = write!(
            s,
            "\nStandard errors and intervals from {} batches of the residuals (each time series cut into {} contiguous ones, each steady point one): a time series' consecutive samples are not independent news. Never below those of independent residuals.\n",
            o.statistics.batches,
            super::stats::BATCHES
        );
    }
    s
}

/// The gain our model ran through: gain, load and how they were found
/// (empty when the data are the contact's own).
pub fn joint_lines(o: &FitOutcome) -> String {
    o.contact_scale.as_ref().map_or(String::new(), |j| {
        if o.units == super::Units::Rotary {
            format!(
                "\n## The joint\n\nThe data are a rotary joint's (rad/s, N·m). The model's contact slides at r ω and puts r F on the joint: lever arm r = {} m (the fitted file's `gain`), contact load F_N = {} N; {}. Every table below is in the joint's units; the parameter table also gives each term as it acts on the joint.\n",
                Num::sig(j.gain, 5),
                Num::sig(j.load_n, 5),
                j.how
            )
        } else {
            format!(
                "\n## The contact's scale\n\nThe model's contact slides at g v and puts g F on the axis: gain g = {} (the fitted file's `gain`: the axis is written as a joint, driven by its JointState), contact load F_N = {} N; {}. The tables are in the data's units; the parameter table also gives each term as it acts on the axis.\n",
                Num::sig(j.gain, 5),
                Num::sig(j.load_n, 5),
                j.how
            )
        }
    })
}

/// What a parameter's row warns of: at a bound; not identifiable (no
/// finite standard error); or poorly identified, a standard error as large
/// as the value itself (the 95 % interval then spans zero, or the whole
/// bounds: the data hardly constrain it).
fn parameter_flag(at_bound: bool, value: f64, standard_error: f64) -> &'static str {
    if at_bound {
        "at a bound"
    } else if !standard_error.is_finite() {
        "not identifiable"
    } else if standard_error > 0.0 && standard_error >= value.abs() {
        "poorly identified (std. error ≥ |value|)"
    } else {
        ""
    }
}

/// The correlation matrix with pairs above the flag named.
pub fn correlation_table(o: &FitOutcome) -> String {
    let names: Vec<&str> = o.params.iter().map(|p| p.name.as_str()).collect();
    let mut s = format!(
        "| | {} |\n|---|{}\n",
        names.join(" | "),
        "---|".repeat(names.len())
    );
    for (i, row) in o.statistics.correlation.iter().enumerate() {
        let cells: Vec<String> = row.iter().map(|r| format!("{r:+.3}")).collect();
        let _ = writeln!(s, "| {} | {} |", names[i], cells.join(" | "));
    }
    let pairs = o.statistics.correlated_pairs();
    if !pairs.is_empty() {
        s.push('\n');
        for (i, j, r) in pairs {
            let _ = writeln!(
                s,
                "- `{}` and `{}` are correlated ({r:+.3}, |ρ| > {CORRELATION_FLAG}): these data do not separate them",
                names[i], names[j]
            );
        }
    }
    if o.statistics.rank_deficient {
        s.push_str("- JᵀJ is singular: some parameters do not change the residual at all\n");
    }
    s
}

/// The distinct optima, best first.
pub fn optima_table(o: &FitOutcome) -> String {
    let u = match o.units {
        super::Units::Linear => "N²".to_string(),
        super::Units::Rotary => format!("({})²", o.units.force()),
    };
    let mut s = format!(
        "| # | cost ½Σr² ({u}) | {} | outcome |\n|---|---|{}---|\n",
        o.params
            .iter()
            .map(|p| format!("`{}`", p.name))
            .collect::<Vec<_>>()
            .join(" | "),
        "---|".repeat(o.params.len())
    );
    for (k, r) in o.optima.iter().take(3).enumerate() {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} |",
            k + 1,
            Num(r.cost).sci(4),
            r.x.iter()
                .map(|v| Num(*v).sci(4))
                .collect::<Vec<_>>()
                .join(" | "),
            r.termination
        );
    }
    s
}

/// Residual summary lines.
pub fn residual_lines(o: &FitOutcome) -> String {
    let u = o.units.force();
    let mut s = format!(
        "training RMS {} {u}, max |residual| {} {u} (σ = {} {u})\n",
        Num::sig(o.train_rms, 5),
        Num::sig(o.train_max, 5),
        Num::sig(o.statistics.sigma, 5)
    );
    if let Some(h) = o.holdout_rms {
        let _ = writeln!(
            s,
            "held-out RMS {} {u} (the held-out parts of the training files: --holdout)",
            Num::sig(h, 5)
        );
    }
    if let Some(v) = o.validate_rms {
        let _ = writeln!(s, "validation RMS {} {u} (--validate data)", Num::sig(v, 5));
    }
    if let Some(why) = &o.validate_failure {
        let _ = writeln!(s, "no prediction on the --validate data: {why}");
    }
    let _ = writeln!(
        s,
        "{} simulations{}, {:.1} ms each on average, {:.1} s in all",
        o.simulations,
        o.film_solves.map_or(String::new(), |f| format!(
            " ({f} solved the film, the others recomposed its friction)"
        )),
        1e3 * o.simulation_mean_s,
        o.wall_s
    );
    s
}

/// The fitted parameter file: the complete configuration, a header naming
/// the fit, and the map coefficients (which are not configuration keys) as
/// comments.
pub fn fitted_yaml(
    config: &Config,
    o: &FitOutcome,
    sources: &[String],
    map: &[(String, f64)],
) -> String {
    let mut s = format!(
        "# Fitted by friction-node fit on {}\n# {} — training RMS {} {u}{}\n",
        sources.join(", "),
        if o.converged {
            "converged"
        } else {
            "NOT CONVERGED: the best point found"
        },
        Num::sig(o.train_rms, 5),
        o.held_out_rms().map_or(String::new(), |h| format!(
            ", held-out RMS {} {}",
            Num::sig(h, 5),
            o.units.force()
        )),
        u = o.units.force(),
    );
    for (j, p) in o.params.iter().enumerate() {
        let _ = writeln!(
            s,
            "# {} = {} ± {}",
            p.name,
            Num(o.best[j]),
            Num(o.statistics.standard_error[j]).sci(4)
        );
    }
    if !map.is_empty() {
        s.push_str("# input map coefficients (not configuration keys):");
        for (n, v) in map {
            let _ = write!(s, " {n}={}", Num(*v));
        }
        s.push('\n');
    }
    s + &config.to_yaml()
}

/// `fit.csv`: every sample of every source with the prediction.
fn write_samples(path: &Path, o: &FitOutcome) -> Result<PathBuf, OutputError> {
    let units = o.units;
    let mut f = AtomicFile::create(path)?;
    let (v, n) = (units.speed_column(), units.force_column());
    f.line(format_args!(
        "source,role,t_s,velocity_{v},load_n,measured_{n},predicted_{n},residual_{n}"
    ))?;
    for (fits, role) in [
        (&o.train, Role::Train),
        (&o.held_out, Role::HeldOut),
        (&o.validate, Role::Validate),
    ] {
        for sf in fits {
            let s = &sf.series;
            for k in 0..s.len() {
                let role = super::by_direction::sample_role(role, s.fit[k]);
                f.line(format_args!(
                    "{},{role},{},{},{},{},{},{}",
                    s.name.replace(',', ";"),
                    Num(s.t[k]),
                    Num(s.velocity[k]),
                    s.load
                        .as_ref()
                        .map_or(String::new(), |l| Num(l[k]).to_string()),
                    Num(s.friction[k]),
                    Num(sf.predicted[k]),
                    Num(sf.predicted[k] - s.friction[k]),
                ))?;
            }
        }
    }
    f.commit()
}

/// The whole markdown summary of one fit.
pub fn summary(o: &FitOutcome, verdict: &str, extra: &str) -> String {
    format!(
        "# Fit of {}: {}\n\n{}{}{}\n## Parameters\n\n{}\n## Correlations\n\n{}\n## Distinct optima (best first)\n\n{}\n## Residual by direction of motion\n\n{}\n{}",
        o.label,
        if o.converged { "converged" } else { "NOT converged (best point found)" },
        if verdict.is_empty() {
            String::new()
        } else {
            format!("{verdict}\n\n")
        },
        residual_lines(o),
        joint_lines(o),
        parameter_table(o),
        correlation_table(o),
        optima_table(o),
        super::by_direction::direction_table(o),
        extra
    )
}

/// Write `summary.md`, `fit.csv` and the plots into `dir` (which exists).
pub fn write_report(
    dir: &Path,
    o: &FitOutcome,
    verdict: &str,
    extra: &str,
) -> Result<Vec<PathBuf>, OutputError> {
    let files = vec![
        crate::output::write_file(
            &dir.join("summary.md"),
            summary(o, verdict, extra).as_bytes(),
        )?,
        write_samples(&dir.join("fit.csv"), o)?,
    ];
    #[cfg(feature = "plots")]
    let files = [files, super::report_plots::write(dir, o)?].concat();
    Ok(files)
}

/// The report of a fit and of the classic models fitted beside it: ours
/// in `dir` (with `extra` appended to its summary), each classic model in
/// a folder named for it, and, with classic models, the residual of every
/// model against velocity on the held-out data in one figure. Returns the
/// files written.
pub fn write_models_report(
    dir: &Path,
    ours: &FitOutcome,
    classic: &[FitOutcome],
    verdict: &str,
    extra: &str,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut files = Vec::new();
    for b in classic {
        let sub = dir.join(slug(&b.label));
        crate::output::prepare_dir(&sub)?;
        files.extend(write_report(&sub, b, "", "")?);
    }
    files.extend(write_report(dir, ours, verdict, extra)?);
    #[cfg(feature = "plots")]
    if !classic.is_empty() {
        let all: Vec<&FitOutcome> = std::iter::once(ours).chain(classic).collect();
        files.extend(super::report_plots::residual_by_velocity(dir, &all)?);
    }
    Ok(files)
}

/// A model's label as a directory name (`Coulomb + viscous` → `coulomb-viscous`).
pub fn slug(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .split('-')
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_standard_error_that_dwarfs_its_value_is_flagged() {
        // The case: σ = 2.7e-5 ± 6.5e-2 had an empty flag column.
        assert!(parameter_flag(false, 2.7e-5, 6.5e-2).starts_with("poorly identified"));
        assert_eq!(parameter_flag(false, 0.3, 0.001), "");
        assert_eq!(
            parameter_flag(false, 0.3, f64::INFINITY),
            "not identifiable"
        );
        assert_eq!(parameter_flag(true, 0.3, 1.0), "at a bound");
        assert_eq!(parameter_flag(false, 0.0, 0.0), "");
    }
}
