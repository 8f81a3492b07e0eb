//! Tables of numbers from text files: what `fit` reads as measurements and
//! `csv:` signals read as inputs. Read with the `csv` crate: comma,
//! semicolon or tab separated (detected from the first line), or runs of
//! whitespace; an optional header line (a first line with a field that is
//! not a number); `#` starts a comment, at the start of a line or after the
//! fields; a byte-order mark is ignored.
//!
//! A column may hold text (the `status` and `regime` columns `simulate`
//! writes): it is kept by name and refused only when something reads it,
//! with the first text cell named by file and line. Every other cell must
//! be a finite number; a bad one is named by file, line and column.

use std::path::{Path, PathBuf};

/// Column separator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Delimiter {
    /// Comma, semicolon or tab, whichever the first line uses; runs of
    /// spaces when the first line has none of them.
    #[default]
    Auto,
    /// `,`.
    Comma,
    /// `;`.
    Semicolon,
    /// Tab.
    Tab,
    /// Runs of spaces and tabs.
    Whitespace,
}

/// A table that could not be read.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// The file could not be read.
    #[error("cannot read {}: {cause}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// A cell or line that does not parse; `line` 0: the file as a whole
    /// (shown without a line).
    #[error("{}{}: {message}", path.display(), at_line(*line))]
    Cell {
        /// The file.
        path: PathBuf,
        /// The line, 1-based.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// `:LINE`, or nothing for line 0 (the file as a whole).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

/// The first cell of a column that is not a number.
#[derive(Debug, Clone, PartialEq)]
pub struct TextCell {
    /// Its line, 1-based.
    pub line: usize,
    /// Its text.
    pub text: String,
}

/// A table of named columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The file it was read from.
    pub source: PathBuf,
    /// Column names.
    pub names: Vec<String>,
    /// Column-major values (NaN in a text column).
    pub columns: Vec<Vec<f64>>,
    /// Per column: its first text cell, if it holds text.
    pub text: Vec<Option<TextCell>>,
    /// The line of each data row.
    pub lines: Vec<usize>,
    /// Whether the first line was a header.
    pub has_header: bool,
}

/// A hint when `cell` reads as a number written with a decimal comma
/// (`0,01`, `-1,5e-3`), which this reader does not take; else nothing.
fn decimal_comma_hint(cell: &str) -> &'static str {
    let t = cell.trim();
    let looks = t.matches(',').count() == 1
        && !t.contains('.')
        && t.replacen(',', ".", 1).parse::<f64>().is_ok();
    if looks {
        " (a decimal comma? numbers are read with a decimal point: convert the file's decimal commas to points, e.g. `sed 's/,/./g'` on a semicolon- or tab-separated file)"
    } else {
        ""
    }
}

impl Table {
    /// Data rows.
    pub fn rows(&self) -> usize {
        self.lines.len()
    }

    /// A table of numeric columns (as long as each other) from elsewhere
    /// (a bag's topics); its rows are numbered from 1.
    pub fn from_columns(source: &Path, names: Vec<String>, columns: Vec<Vec<f64>>) -> Self {
        let rows = columns.first().map_or(0, Vec::len);
        Self {
            source: source.to_path_buf(),
            text: vec![None; names.len()],
            names,
            columns,
            lines: (1..=rows).collect(),
            has_header: true,
        }
    }

    /// The rows where `keep` holds, in order (`keep` has one entry per row).
    pub fn select_rows(&self, keep: &[bool]) -> Self {
        let pick = |c: &Vec<f64>| -> Vec<f64> {
            c.iter()
                .zip(keep)
                .filter(|(_, k)| **k)
                .map(|(v, _)| *v)
                .collect()
        };
        Self {
            source: self.source.clone(),
            names: self.names.clone(),
            columns: self.columns.iter().map(pick).collect(),
            text: self.text.clone(),
            lines: self
                .lines
                .iter()
                .zip(keep)
                .filter(|(_, k)| **k)
                .map(|(l, _)| *l)
                .collect(),
            has_header: self.has_header,
        }
    }

    /// A numeric column by name (None: no such column, or it holds text).
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.index(name)
            .filter(|&k| self.text[k].is_none())
            .map(|k| self.columns[k].as_slice())
    }

    /// The index of column `name`.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// A hint for text on the first data row under a header, which is
    /// often a row of units (`s, rad/s, N·m`): `--skip 1` drops it.
    fn units_row_hint(&self, line: usize) -> &'static str {
        if self.has_header && self.lines.first() == Some(&line) {
            " (a row of units under the header? --skip 1 drops the first data row)"
        } else {
            ""
        }
    }

    /// Why column `name` cannot be read as numbers: missing (with the
    /// columns there are) or holding text (with its first text cell).
    pub fn column_error(&self, name: &str) -> TableError {
        let message = match self.index(name).and_then(|k| self.text[k].as_ref()) {
            Some(cell) => {
                return TableError::Cell {
                    path: self.source.clone(),
                    line: cell.line,
                    message: if cell.text.trim().is_empty() {
                        format!(
                            "the cell in column `{name}` is empty: every row needs a number in each column read (drop the row, or fill it)"
                        )
                    } else {
                        format!(
                            "`{}` in column `{name}` is not a number{}{}",
                            cell.text,
                            decimal_comma_hint(&cell.text),
                            self.units_row_hint(cell.line)
                        )
                    },
                }
            }
            None => format!(
                "no column named `{name}` (columns: {})",
                self.names.join(", ")
            ),
        };
        TableError::Cell {
            path: self.source.clone(),
            line: 0,
            message,
        }
    }

    /// Read `path`; `names` replaces (or supplies, when headerless) the
    /// column names; `skip` drops that many data rows first.
    pub fn read(
        path: &Path,
        delimiter: Delimiter,
        names: Option<&[String]>,
        skip: usize,
    ) -> Result<Table, TableError> {
        let text = std::fs::read_to_string(path).map_err(|cause| TableError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        Self::parse(&text, path, delimiter, names, skip)
    }

    /// A table parsed from CSV `text` as the file `name` (delimiter
    /// detected, no rows skipped), for tests.
    #[cfg(test)]
    pub fn of_csv(text: &str, name: &str) -> Table {
        Table::parse(text, std::path::Path::new(name), Delimiter::Auto, None, 0)
            .expect("a test table parses")
    }

    /// Parse table text (see [`Table::read`]).
    pub fn parse(
        text: &str,
        path: &Path,
        delimiter: Delimiter,
        names: Option<&[String]>,
        skip: usize,
    ) -> Result<Table, TableError> {
        let bad = |line: usize, message: String| TableError::Cell {
            path: path.to_path_buf(),
            line,
            message,
        };
        let (text, delim) = normalise(text, delimiter);
        let records = records(&text, delim).map_err(|(line, m)| bad(line, m))?;
        let Some((head_line, head_width, has_header)) = records
            .first()
            .map(|(l, f)| (*l, f.len(), f.iter().any(|f| f.parse::<f64>().is_err())))
        else {
            return Err(bad(0, "no data rows".into()));
        };
        let mut rows = records.into_iter();
        let mut column_names: Vec<String> = if has_header {
            rows.next().expect("a first record").1
        } else {
            (1..=head_width).map(|k| format!("c{k}")).collect()
        };
        if let Some(n) = names {
            if n.len() != column_names.len() {
                return Err(bad(
                    head_line,
                    format!(
                        "--columns names {} columns, the table has {}",
                        n.len(),
                        column_names.len()
                    ),
                ));
            }
            column_names = n.to_vec();
        }
        let DataRows {
            columns,
            text: cells_text,
            lines,
        } = numeric_columns(rows.skip(skip), &column_names, has_header, &bad)?;
        if lines.is_empty() {
            return Err(bad(0, "no data rows".into()));
        }
        Ok(Table {
            source: path.to_path_buf(),
            names: column_names,
            columns,
            text: cells_text,
            lines,
            has_header,
        })
    }
}

/// The text as the record reader takes it, with the field separator
/// (None: whitespace): without a byte-order mark, comments cut at `#`, the
/// separator detected from the first non-blank line when `Auto`, and blank
/// lines kept as (skipped) empty records so that line numbers stay true.
fn normalise(text: &str, delimiter: Delimiter) -> (String, Option<u8>) {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    // Comments end every line at `#` (line numbers are kept).
    let text: String = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
    let delim = match delimiter {
        Delimiter::Comma => Some(b','),
        Delimiter::Semicolon => Some(b';'),
        Delimiter::Tab => Some(b'\t'),
        Delimiter::Whitespace => None,
        Delimiter::Auto => [b',', b';', b'\t']
            .into_iter()
            .find(|d| first.as_bytes().contains(d)),
    };
    // The csv reader does not count blank lines: a lone separator keeps
    // them.
    let text = match delim {
        Some(d) => text
            .lines()
            .map(|l| {
                if l.trim().is_empty() {
                    (d as char).to_string()
                } else {
                    l.to_string()
                }
            })
            .collect::<Vec<_>>()
            .join("\n"),
        None => text,
    };
    (text, delim)
}

/// What [`numeric_columns`] read.
struct DataRows {
    columns: Vec<Vec<f64>>,
    text: Vec<Option<TextCell>>,
    lines: Vec<usize>,
}

/// The data rows as numeric columns (NaN in a text cell, whose first
/// occurrence per column is kept), with each row's line. Every row must be
/// as wide as the header; a non-finite number is refused.
fn numeric_columns(
    rows: impl Iterator<Item = Record>,
    names: &[String],
    has_header: bool,
    bad: &dyn Fn(usize, String) -> TableError,
) -> Result<DataRows, TableError> {
    let width = names.len();
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); width];
    let mut cells_text: Vec<Option<TextCell>> = vec![None; width];
    let mut lines = Vec::new();
    for (line, fields) in rows {
        if fields.len() != width {
            return Err(bad(
                line,
                format!(
                    "{} columns, {} {width}",
                    fields.len(),
                    if has_header {
                        "the header has"
                    } else {
                        "the first row has"
                    }
                ),
            ));
        }
        for (k, f) in fields.iter().enumerate() {
            let v = match f.parse::<f64>() {
                Ok(v) if v.is_finite() => v,
                Ok(_) => {
                    return Err(bad(
                        line,
                        format!("`{f}` in column `{}` is not finite", names[k]),
                    ))
                }
                Err(_) => {
                    if cells_text[k].is_none() {
                        cells_text[k] = Some(TextCell {
                            line,
                            text: f.clone(),
                        });
                    }
                    f64::NAN
                }
            };
            columns[k].push(v);
        }
        lines.push(line);
    }
    Ok(DataRows {
        columns,
        text: cells_text,
        lines,
    })
}

/// A record: its line number and fields.
type Record = (usize, Vec<String>);

/// The non-empty records of `text`, or (line, message) of the first that
/// cannot be read.
fn records(text: &str, delim: Option<u8>) -> Result<Vec<Record>, (usize, String)> {
    let mut out = Vec::new();
    match delim {
        Some(d) => {
            let mut r = csv::ReaderBuilder::new()
                .delimiter(d)
                .has_headers(false)
                .flexible(true)
                .trim(csv::Trim::All)
                .from_reader(text.as_bytes());
            for rec in r.records() {
                let rec = rec.map_err(|e| {
                    let line = e.position().map_or(0, |p| p.line() as usize);
                    (line, e.to_string())
                })?;
                let line = rec.position().map_or(0, |p| p.line() as usize);
                if rec.iter().all(|f| f.is_empty()) {
                    continue;
                }
                out.push((line, rec.iter().map(str::to_string).collect()));
            }
        }
        None => {
            for (k, l) in text.lines().enumerate() {
                if l.trim().is_empty() {
                    continue;
                }
                out.push((k + 1, l.split_whitespace().map(str::to_string).collect()));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_with_headers_or_named_columns_and_any_separator_are_read() {
        let p = Path::new("t.csv");
        let t = Table::parse("t_s,v\n0,1\n1,2\n", p, Delimiter::Auto, None, 0).unwrap();
        assert_eq!(t.column("v"), Some(&[1.0, 2.0][..]));
        let names: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let t = Table::parse(
            "0.0\t4.4\t1\n10\t4.6  2\n",
            p,
            Delimiter::Whitespace,
            Some(&names),
            0,
        )
        .unwrap();
        assert_eq!(t.column("c"), Some(&[1.0, 2.0][..]));
        let t = Table::parse("1;2\n3;4\n5;6\n", p, Delimiter::Auto, None, 1).unwrap();
        assert_eq!(t.column("c1"), Some(&[3.0, 5.0][..]));
        let t = Table::parse(
            "t_s;v\n0;0.1 # a comment\n\n# a line\n1;0.2\n",
            p,
            Delimiter::Auto,
            None,
            0,
        )
        .unwrap();
        assert_eq!(t.column("v"), Some(&[0.1, 0.2][..]));
        assert_eq!(t.lines, vec![2, 5]);
    }

    #[test]
    fn a_bad_cell_is_named_by_line_and_column() {
        let p = Path::new("bad.csv");
        let t = Table::parse("t_s,v\n0,1\n1,x\n", p, Delimiter::Auto, None, 0).unwrap();
        assert_eq!(t.column("v"), None, "a text column is not numeric");
        let m = t.column_error("v").to_string();
        assert!(
            m.contains("bad.csv:3") && m.contains("`x`") && m.contains("`v`"),
            "{m}"
        );
        let m = t.column_error("w").to_string();
        assert!(
            m.starts_with("bad.csv: no column named `w`") && m.contains("t_s, v"),
            "{m}"
        );
        let e = Table::parse("t_s,v\n0,nan\n", p, Delimiter::Auto, None, 0).unwrap_err();
        assert!(e.to_string().contains("not finite"));
        let e = Table::parse("t_s,v\n0,1,2\n", p, Delimiter::Auto, None, 0).unwrap_err();
        assert!(e.to_string().contains("3 columns"));
        let e = Table::parse("", p, Delimiter::Auto, None, 0).unwrap_err();
        assert!(e.to_string().contains("no data rows"));
    }

    #[test]
    fn a_number_written_with_a_decimal_comma_is_named_as_such() {
        let p = Path::new("euro.csv");
        let t = Table::parse("v;f\n0,01;1,5\n", p, Delimiter::Auto, None, 0).unwrap();
        let m = t.column_error("v").to_string();
        assert!(m.contains("`0,01`") && m.contains("decimal comma"), "{m}");
        // Text that is not a comma-decimal number gets no such hint.
        let t = Table::parse("v;f\n1,2,3;x\n", p, Delimiter::Auto, None, 0).unwrap();
        assert!(!t.column_error("v").to_string().contains("decimal comma"));
        assert!(!t.column_error("f").to_string().contains("decimal comma"));
    }

    #[test]
    fn an_empty_cell_is_named_as_empty_with_its_line() {
        let p = Path::new("gap.csv");
        let t = Table::parse("v,f\n1,2\n2,\n3,4\n", p, Delimiter::Auto, None, 0).unwrap();
        let m = t.column_error("f").to_string();
        assert!(
            m.contains("gap.csv:3") && m.contains("the cell in column `f` is empty"),
            "{m}"
        );
        assert!(!m.contains("``"), "{m}");
    }

    #[test]
    fn text_on_the_first_row_under_a_header_is_named_as_a_possible_row_of_units() {
        let p = Path::new("units.csv");
        let t = Table::parse("v,f\nrad/s,Nm\n1,2\n2,3\n", p, Delimiter::Auto, None, 0).unwrap();
        let m = t.column_error("v").to_string();
        assert!(m.contains("units.csv:2") && m.contains("--skip 1"), "{m}");
        let t = Table::parse("v,f\nrad/s,Nm\n1,2\n2,3\n", p, Delimiter::Auto, None, 1).unwrap();
        assert_eq!(t.column("v"), Some(&[1.0, 2.0][..]));
        // Text further down is no row of units.
        let t = Table::parse("v,f\n1,2\nx,3\n", p, Delimiter::Auto, None, 0).unwrap();
        assert!(!t.column_error("v").to_string().contains("--skip"));
    }

    #[test]
    fn the_text_columns_of_a_simulate_run_are_kept_but_not_read() {
        let p = Path::new("run.csv");
        let t = Table::parse(
            "t_s,velocity_m_s,friction_n,status\n0,0.1,5,converged\n0.001,0.2,6,converged\n",
            p,
            Delimiter::Auto,
            None,
            0,
        )
        .unwrap();
        assert_eq!(t.column("friction_n"), Some(&[5.0, 6.0][..]));
        assert_eq!(t.column("status"), None);
        assert!(t.column_error("status").to_string().contains("run.csv:2"));
    }
}
