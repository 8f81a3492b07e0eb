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
//! A CSV may start with a header line; `#` starts a comment; times must
//! increase strictly. A malformed line is reported with its line number.

use crate::text::Num;
use std::path::{Path, PathBuf};

/// A scalar function of time.
#[derive(Debug, Clone, PartialEq)]
pub enum Signal {
    Const(f64),
    Sine {
        offset: f64,
        amplitude: f64,
        frequency_hz: f64,
        phase_rad: f64,
    },
    Table {
        source: PathBuf,
        t: Vec<f64>,
        y: Vec<f64>,
    },
}

/// Errors reading a signal spec.
#[derive(Debug, thiserror::Error)]
pub enum SignalError {
    #[error("{what} spec `{spec}`: {message} (expected const:V, sine:V0,V1,F[,PHASE] or csv:FILE[@COLUMN])")]
    Syntax {
        what: String,
        spec: String,
        message: String,
    },
    #[error("cannot read {what} table {}", path.display())]
    Io {
        what: String,
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}:{line}: {message}", path.display())]
    Csv {
        path: PathBuf,
        line: usize,
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
    let text = std::fs::read_to_string(path).map_err(|source| SignalError::Io {
        what: what.to_string(),
        path: path.to_path_buf(),
        source,
    })?;
    parse_table(&text, path, column, what)
}

/// Parse the text of a `csv:` table (see the module documentation); `path`
/// names it in messages.
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
    let mut col = 1usize;
    let mut saw_data = false;
    let mut header_seen = false;
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    // A byte-order mark (spreadsheet exports) is not part of the first line.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    for (k, raw) in text.lines().enumerate() {
        let lineno = k + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let first_is_number = fields[0].parse::<f64>().is_ok();
        if !saw_data && !first_is_number {
            // Header line.
            header_seen = true;
            if let Some(name) = column {
                col = fields.iter().position(|f| *f == name).ok_or_else(|| {
                    err(
                        lineno,
                        format!("no column named `{name}` in header {fields:?}"),
                    )
                })?;
                if col == 0 {
                    return Err(err(lineno, format!("column `{name}` is the time column")));
                }
            }
            continue;
        }
        if let (Some(name), false) = (column, header_seen) {
            return Err(err(
                lineno,
                format!("a column name (@{name}) needs a header line"),
            ));
        }
        saw_data = true;
        if fields.len() <= col {
            return Err(err(
                lineno,
                format!(
                    "expected at least {} columns, found {}",
                    col + 1,
                    fields.len()
                ),
            ));
        }
        let t: f64 = fields[0]
            .parse()
            .map_err(|_| err(lineno, format!("time `{}` is not a number", fields[0])))?;
        let y: f64 = fields[col]
            .parse()
            .map_err(|_| err(lineno, format!("value `{}` is not a number", fields[col])))?;
        if !t.is_finite() || !y.is_finite() {
            return Err(err(lineno, "time and value must be finite".into()));
        }
        if let Some(&prev) = ts.last() {
            if t <= prev {
                return Err(err(
                    lineno,
                    format!("time {t} s does not increase (previous {prev} s)"),
                ));
            }
        }
        ts.push(t);
        ys.push(y);
    }
    if ts.is_empty() {
        return Err(err(0, "no data rows".into()));
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

    fn tmp(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("fn-signal-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
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
        let p = tmp("cols.csv", "t_s,velocity_m_s,load_n\n0,1,100\n1,1,300\n");
        let s = Signal::parse(&format!("csv:{}@load_n", p.display()), "load").unwrap();
        assert_relative_eq!(s.at(0.5), 200.0);
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
