//! Input signals for offline runs: velocity (m/s) or load (N) against time (s).
//!
//! | spec | meaning |
//! |---|---|
//! | `const:V` | constant V |
//! | `sine:V0,V1,F` | V0 + V1 sin(2π F t) |
//! | `sine:V0,V1,F,PHASE` | V0 + V1 sin(2π F t + PHASE), PHASE in rad |
//! | `csv:FILE` | time in the first column (s), value in the second; linear interpolation, held constant outside the table |
//! | `csv:FILE@NAME` | the same, value from the column whose header is NAME |
//!
//! A table is read as [`crate::table::Table`] reads one: comma, semicolon,
//! tab or whitespace separated, an optional header line, `#` comments;
//! times must increase strictly. A malformed line is reported with its
//! line number.

use crate::table::{Delimiter, Table, TableError};
use crate::text::Num;
use std::path::{Path, PathBuf};

/// A scalar function of time.
#[derive(Debug, Clone, PartialEq)]
pub enum Signal {
    /// `const:V`.
    Const(f64),
    /// `sine:V0,V1,F[,PHASE]`: V0 + V1 sin(2π F t + PHASE).
    Sine {
        /// V0.
        offset: f64,
        /// V1.
        amplitude: f64,
        /// F, Hz.
        frequency_hz: f64,
        /// PHASE, rad.
        phase_rad: f64,
    },
    /// `csv:FILE[@COLUMN]`: linear interpolation between the rows.
    Table {
        /// The file.
        source: PathBuf,
        /// Times, s, increasing.
        t: Vec<f64>,
        /// Values.
        y: Vec<f64>,
    },
}

/// Errors reading a signal spec.
#[derive(Debug, thiserror::Error)]
pub enum SignalError {
    /// A spec that does not parse.
    #[error("{what} spec `{spec}`: {message} (expected const:V, sine:V0,V1,F[,PHASE] or csv:FILE[@COLUMN])")]
    Syntax {
        /// Which input (velocity, load, temperature).
        what: String,
        /// The spec given.
        spec: String,
        /// What is wrong with it.
        message: String,
    },
    /// A table that cannot be read.
    #[error("cannot read {what} table {}: {cause}", path.display())]
    Io {
        /// Which input.
        what: String,
        /// The table.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// A table that does not cover the run.
    #[error("{what} table {}: {message}", path.display())]
    Coverage {
        /// Which input.
        what: String,
        /// The table.
        path: PathBuf,
        /// What it does not cover.
        message: String,
    },
    /// A table line that does not parse.
    #[error("{}:{line}: {message}", path.display())]
    Csv {
        /// The table.
        path: PathBuf,
        /// The line, 1-based.
        line: usize,
        /// What is wrong with it.
        message: String,
    },
}

impl Signal {
    /// Parse a spec; `what` ("velocity", "load") is used in messages.
    pub fn parse(spec: &str, what: &str) -> Result<Signal, SignalError> {
        let syntax = |message: String| SignalError::Syntax {
            what: what.to_string(),
            spec: spec.to_string(),
            message,
        };
        let (kind, rest) = spec
            .split_once(':')
            .ok_or_else(|| syntax("missing `kind:`".into()))?;
        let numbers = |rest: &str| -> Result<Vec<f64>, SignalError> {
            rest.split(',')
                .map(|x| {
                    let v: f64 = x
                        .trim()
                        .parse()
                        .map_err(|_| syntax(format!("`{}` is not a number", x.trim())))?;
                    if v.is_finite() {
                        Ok(v)
                    } else {
                        Err(syntax(format!("`{}` is not finite", x.trim())))
                    }
                })
                .collect()
        };
        match kind {
            "const" => {
                let v = numbers(rest)?;
                match v[..] {
                    [c] => Ok(Signal::Const(c)),
                    _ => Err(syntax(format!("const takes 1 number, got {}", v.len()))),
                }
            }
            "sine" => {
                let v = numbers(rest)?;
                let (offset, amplitude, frequency_hz, phase_rad) = match v[..] {
                    [a, b, c] => (a, b, c, 0.0),
                    [a, b, c, d] => (a, b, c, d),
                    _ => {
                        return Err(syntax(format!(
                            "sine takes 3 or 4 numbers, got {}",
                            v.len()
                        )))
                    }
                };
                if frequency_hz < 0.0 {
                    return Err(syntax(format!("frequency {frequency_hz} Hz is negative")));
                }
                Ok(Signal::Sine {
                    offset,
                    amplitude,
                    frequency_hz,
                    phase_rad,
                })
            }
            "csv" => {
                let (file, column) = match rest.rsplit_once('@') {
                    Some((f, c)) if !c.is_empty() && !c.contains('/') => (f, Some(c)),
                    _ => (rest, None),
                };
                if file.is_empty() {
                    return Err(syntax("missing file name".into()));
                }
                read_table(Path::new(file), column, what)
            }
            other => Err(syntax(format!("unknown kind `{other}`"))),
        }
    }

    /// Value at time t.
    pub fn at(&self, t: f64) -> f64 {
        match self {
            Signal::Const(c) => *c,
            Signal::Sine {
                offset,
                amplitude,
                frequency_hz,
                phase_rad,
            } => {
                offset
                    + amplitude * (2.0 * std::f64::consts::PI * frequency_hz * t + phase_rad).sin()
            }
            Signal::Table { t: ts, y, .. } => {
                if t <= ts[0] {
                    return y[0];
                }
                let last = ts.len() - 1;
                if t >= ts[last] {
                    return y[last];
                }
                let j = ts.partition_point(|&x| x <= t);
                let (t0, t1) = (ts[j - 1], ts[j]);
                y[j - 1] + (y[j] - y[j - 1]) * (t - t0) / (t1 - t0)
            }
        }
    }

    /// How a `csv:` table covers a run over [0, `duration_s`] s (other
    /// signals cover any run): `Ok(None)` when its times span the run;
    /// a warning when part of the run lies outside them, where the table's
    /// first or last value is held; an error when no part of the run lies
    /// within them (the whole run would be a held value).
    pub fn check_coverage(
        &self,
        what: &str,
        duration_s: f64,
    ) -> Result<Option<String>, SignalError> {
        let Signal::Table { source, t, .. } = self else {
            return Ok(None);
        };
        if t.len() == 1 {
            // One row: a constant, whatever its time.
            return Ok(None);
        }
        let (first, last) = (t[0], t[t.len() - 1]);
        let spans = format!(
            "its times span [{}, {}] s and the run [0, {}] s",
            Num(first),
            Num(last),
            Num(duration_s)
        );
        if last < 0.0 || first > duration_s {
            return Err(SignalError::Coverage {
                what: what.into(),
                path: source.clone(),
                message: format!(
                    "{spans}: the table does not cover the run at all (the whole run would hold its {} value)",
                    if last <= 0.0 { "last" } else { "first" }
                ),
            });
        }
        let mut held = Vec::new();
        if first > 0.0 {
            held.push(format!("its first value before {} s", Num(first)));
        }
        if last < duration_s {
            held.push(format!("its last value after {} s", Num(last)));
        }
        Ok((!held.is_empty()).then(|| {
            format!(
                "{what} table {}: {spans}; held at {}",
                source.display(),
                held.join(" and ")
            )
        }))
    }

    /// The period of a periodic signal (a sine with non-zero amplitude and frequency).
    pub fn period(&self) -> Option<f64> {
        match self {
            Signal::Sine {
                amplitude,
                frequency_hz,
                ..
            } if *amplitude != 0.0 && *frequency_hz > 0.0 => Some(1.0 / frequency_hz),
            _ => None,
        }
    }

    /// Smallest and largest value over all time.
    pub fn range(&self) -> (f64, f64) {
        match self {
            Signal::Const(c) => (*c, *c),
            Signal::Sine {
                offset, amplitude, ..
            } => (offset - amplitude.abs(), offset + amplitude.abs()),
            Signal::Table { y, .. } => y
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                    (a.min(*v), b.max(*v))
                }),
        }
    }

    /// Largest |value| (for sanity checks and plots).
    pub fn max_abs(&self) -> f64 {
        match self {
            Signal::Const(c) => c.abs(),
            Signal::Sine {
                offset, amplitude, ..
            } => offset.abs() + amplitude.abs(),
            Signal::Table { y, .. } => y.iter().fold(0.0, |m, v| m.max(v.abs())),
        }
    }
}

impl std::fmt::Display for Signal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Signal::Const(c) => write!(f, "const:{}", Num(*c)),
            Signal::Sine {
                offset,
                amplitude,
                frequency_hz,
                phase_rad,
            } => {
                write!(
                    f,
                    "sine:{},{},{}",
                    Num(*offset),
                    Num(*amplitude),
                    Num(*frequency_hz)
                )?;
                if *phase_rad != 0.0 {
                    write!(f, ",{}", Num(*phase_rad))?;
                }
                Ok(())
            }
            Signal::Table { source, t, .. } => {
                write!(f, "csv:{} ({} points)", source.display(), t.len())
            }
        }
    }
}

fn read_table(path: &Path, column: Option<&str>, what: &str) -> Result<Signal, SignalError> {
    let text = std::fs::read_to_string(path).map_err(|cause| SignalError::Io {
        what: what.to_string(),
        path: path.to_path_buf(),
        cause,
    })?;
    parse_table(&text, path, column, what)
}

impl From<TableError> for SignalError {
    fn from(e: TableError) -> Self {
        match e {
            TableError::Io { path, cause } => SignalError::Io {
                what: "signal".into(),
                path,
                cause,
            },
            TableError::Cell {
                path,
                line,
                message,
            } => SignalError::Csv {
                path,
                line,
                message,
            },
        }
    }
}

/// Parse the text of a `csv:` table (see the module documentation; read
/// as [`crate::table::Table`] reads it: any separator, a header or none);
/// `path` names it in messages.
pub fn parse_table(
    text: &str,
    path: &Path,
    column: Option<&str>,
    what: &str,
) -> Result<Signal, SignalError> {
    let _ = what;
    let err = |line: usize, message: String| SignalError::Csv {
        path: path.to_path_buf(),
        line,
        message,
    };
    let table = Table::parse(text, path, Delimiter::Auto, None, 0)?;
    if table.names.len() < 2 {
        return Err(err(
            table.lines[0],
            format!(
                "expected at least 2 columns (time, value), found {}",
                table.names.len()
            ),
        ));
    }
    let col = match column {
        None => 1,
        Some(name) if !table.has_header => {
            return Err(err(
                table.lines[0],
                format!("a column name (@{name}) needs a header line"),
            ))
        }
        Some(name) => match table.index(name) {
            Some(0) => return Err(err(1, format!("column `{name}` is the time column"))),
            Some(k) => k,
            None => return Err(table.column_error(name).into()),
        },
    };
    let numeric = |k: usize| -> Result<Vec<f64>, SignalError> {
        match table.text[k] {
            None => Ok(table.columns[k].clone()),
            Some(_) => Err(table.column_error(&table.names[k]).into()),
        }
    };
    let (ts, ys) = (numeric(0)?, numeric(col)?);
    if let Some(k) = (1..ts.len()).find(|&k| ts[k] <= ts[k - 1]) {
        return Err(err(
            table.lines[k],
            format!(
                "time {} s does not increase (previous {} s)",
                ts[k],
                ts[k - 1]
            ),
        ));
    }
    Ok(Signal::Table {
        source: path.to_path_buf(),
        t: ts,
        y: ys,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A file named `name` holding `text`, in a directory of its own that
    /// goes when the file's guard drops.
    struct Tmp {
        _dir: tempfile::TempDir,
        path: PathBuf,
    }

    impl std::ops::Deref for Tmp {
        type Target = std::path::Path;
        fn deref(&self) -> &std::path::Path {
            &self.path
        }
    }

    fn tmp(name: &str, text: &str) -> Tmp {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        Tmp { _dir: dir, path }
    }

    #[test]
    fn const_and_sine_specs_evaluate() {
        assert_eq!(
            Signal::parse("const:0.25", "velocity").unwrap().at(3.0),
            0.25
        );
        let s = Signal::parse("sine:0.5,0.25,2", "velocity").unwrap();
        assert_relative_eq!(s.at(0.125), 0.75, epsilon = 1e-12);
        assert_eq!(s.period(), Some(0.5));
        assert_eq!(
            Signal::parse("sine:1,0,2", "velocity").unwrap().period(),
            None
        );
    }

    #[test]
    fn bad_specs_say_what_is_wrong() {
        for (spec, needle) in [
            ("fast", "missing `kind:`"),
            ("const:abc", "`abc` is not a number"),
            ("sine:1,2", "sine takes 3 or 4 numbers"),
            ("ramp:1", "unknown kind `ramp`"),
            ("const:nan", "not finite"),
            ("sine:0,1,-2", "negative"),
        ] {
            let e = Signal::parse(spec, "velocity").unwrap_err().to_string();
            assert!(e.contains(needle), "{spec}: {e}");
        }
    }

    #[test]
    fn csv_table_interpolates_and_holds_its_ends() {
        let p = tmp("ok.csv", "t_s,velocity_m_s\n0,0\n1,2 # comment\n\n3,0\n");
        let s = Signal::parse(&format!("csv:{}", p.display()), "velocity").unwrap();
        assert_eq!(s.at(-1.0), 0.0);
        assert_relative_eq!(s.at(0.5), 1.0);
        assert_relative_eq!(s.at(2.0), 1.0);
        assert_eq!(s.at(10.0), 0.0);
        // Any separator a spreadsheet writes, as `fit` reads it.
        for (name, text) in [
            ("semi.csv", "t_s;v\n0;0\n1;2\n"),
            ("tab.csv", "t_s\tv\n0\t0\n1\t2\n"),
            ("space.csv", "t_s v\n0 0\n1 2\n"),
        ] {
            let p = tmp(name, text);
            let s = Signal::parse(&format!("csv:{}", p.display()), "velocity").unwrap();
            assert_relative_eq!(s.at(0.5), 1.0);
        }
        let p = tmp("cols.csv", "t_s,velocity_m_s,load_n\n0,1,100\n1,1,300\n");
        let s = Signal::parse(&format!("csv:{}@load_n", p.display()), "load").unwrap();
        assert_relative_eq!(s.at(0.5), 200.0);
    }

    #[test]
    fn a_table_outside_the_run_is_an_error_and_a_partial_one_a_warning() {
        let p = tmp("late.csv", "t_s,v\n5,0.1\n6,0.1\n");
        let s = Signal::parse(&format!("csv:{}", p.display()), "velocity").unwrap();
        let e = s.check_coverage("velocity", 1.0).unwrap_err().to_string();
        assert!(
            e.contains("late.csv")
                && e.contains("[5, 6] s")
                && e.contains("does not cover the run at all"),
            "{e}"
        );
        let w = s.check_coverage("velocity", 10.0).unwrap().unwrap();
        assert!(
            w.contains("first value before 5 s") && w.contains("last value after 6 s"),
            "{w}"
        );
        let p = tmp("full.csv", "t_s,v\n0,0.1\n2,0.1\n");
        let s = Signal::parse(&format!("csv:{}", p.display()), "velocity").unwrap();
        assert_eq!(s.check_coverage("velocity", 2.0).unwrap(), None);
        assert_eq!(
            Signal::Const(1.0).check_coverage("load", 1e6).unwrap(),
            None
        );
    }

    #[test]
    fn malformed_csv_lines_are_reported_with_their_line_number() {
        let p = tmp("bad.csv", "t_s,v\n0,0\n0.1,abc\n");
        let e = Signal::parse(&format!("csv:{}", p.display()), "velocity")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.csv:3") && e.contains("`abc`"), "{e}");
        let p = tmp("order.csv", "0,0\n1,1\n1,2\n");
        let e = Signal::parse(&format!("csv:{}", p.display()), "velocity")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("order.csv:3") && e.contains("does not increase"),
            "{e}"
        );
        let p = tmp("short.csv", "0,0\n1\n");
        let e = Signal::parse(&format!("csv:{}", p.display()), "velocity")
            .unwrap_err()
            .to_string();
        assert!(e.contains("short.csv:2"), "{e}");
        let e = Signal::parse("csv:/nonexistent/v.csv", "velocity")
            .unwrap_err()
            .to_string();
        assert!(e.contains("/nonexistent/v.csv"), "{e}");
        let p = tmp("named.csv", "t,v\n0,1\n");
        let e = Signal::parse(&format!("csv:{}@load_n", p.display()), "load")
            .unwrap_err()
            .to_string();
        assert!(e.contains("no column named `load_n`"), "{e}");
    }
}
