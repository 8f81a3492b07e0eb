//! Measurement tables: CSV (with a header, or headerless with `--columns`),
//! comma, semicolon, tab or whitespace separated; read with the `csv` crate.
//! Every value must be a finite number; a bad cell is named by file, line
//! and column.

use super::FitError;
use std::path::{Path, PathBuf};

/// Column separator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Delimiter {
    /// Comma, semicolon or tab, whichever the first line uses; runs of
    /// spaces when the first line has none of them.
    #[default]
    Auto,
    Comma,
    Semicolon,
    Tab,
    /// Runs of spaces and tabs.
    Whitespace,
}

/// A table of named numeric columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    pub source: PathBuf,
    pub names: Vec<String>,
    /// Column-major values.
    pub columns: Vec<Vec<f64>>,
}

impl Table {
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|k| self.columns[k].as_slice())
    }

    /// Read `path`; `names` replaces (or supplies, when headerless) the
    /// column names; `skip` drops that many data rows first.
    pub fn read(
        path: &Path,
        delimiter: Delimiter,
        names: Option<&[String]>,
        skip: usize,
    ) -> Result<Table, FitError> {
        let text = std::fs::read_to_string(path).map_err(|source| FitError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::parse(&text, path, delimiter, names, skip)
    }

    /// Parse table text (see [`Table::read`]).
    pub fn parse(
        text: &str,
        path: &Path,
        delimiter: Delimiter,
        names: Option<&[String]>,
        skip: usize,
    ) -> Result<Table, FitError> {
        let bad = |line: usize, message: String| FitError::Table {
            path: path.to_path_buf(),
            line,
            message,
        };
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
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
        // Records as (line number, fields).
        let mut records: Vec<(usize, Vec<String>)> = Vec::new();
        match delim {
            Some(d) => {
                let mut r = csv::ReaderBuilder::new()
                    .delimiter(d)
                    .has_headers(false)
                    .flexible(true)
                    .comment(Some(b'#'))
                    .trim(csv::Trim::All)
                    .from_reader(text.as_bytes());
                for rec in r.records() {
                    let rec = rec.map_err(|e| {
                        let line = e.position().map_or(0, |p| p.line() as usize);
                        bad(line, e.to_string())
                    })?;
                    let line = rec.position().map_or(0, |p| p.line() as usize);
                    if rec.iter().all(|f| f.is_empty()) {
                        continue;
                    }
                    records.push((line, rec.iter().map(str::to_string).collect()));
                }
            }
            None => {
                for (k, l) in text.lines().enumerate() {
                    let l = l.split('#').next().unwrap_or("");
                    if l.trim().is_empty() {
                        continue;
                    }
                    records.push((k + 1, l.split_whitespace().map(str::to_string).collect()));
                }
            }
        }
        if records.is_empty() {
            return Err(bad(0, "no rows".into()));
        }
        let header_row = records[0].1.iter().any(|f| f.parse::<f64>().is_err());
        let mut column_names: Vec<String> = if header_row {
            records.remove(0).1
        } else {
            (1..=records[0].1.len()).map(|k| format!("c{k}")).collect()
        };
        if let Some(n) = names {
            if n.len() != column_names.len() {
                return Err(bad(
                    records.first().map_or(0, |r| r.0),
                    format!(
                        "--columns names {} columns, the table has {}",
                        n.len(),
                        column_names.len()
                    ),
                ));
            }
            column_names = n.to_vec();
        }
        let width = column_names.len();
        let mut columns = vec![Vec::with_capacity(records.len()); width];
        for (line, fields) in records.into_iter().skip(skip) {
            if fields.len() != width {
                return Err(bad(
                    line,
                    format!("{} columns, the header has {width}", fields.len()),
                ));
            }
            for (k, f) in fields.iter().enumerate() {
                let v: f64 = f.parse().map_err(|_| {
                    bad(
                        line,
                        format!("`{f}` in column `{}` is not a number", column_names[k]),
                    )
                })?;
                if !v.is_finite() {
                    return Err(bad(
                        line,
                        format!("`{f}` in column `{}` is not finite", column_names[k]),
                    ));
                }
                columns[k].push(v);
            }
        }
        if columns.first().is_none_or(|c| c.is_empty()) {
            return Err(bad(0, "no data rows".into()));
        }
        Ok(Table {
            source: path.to_path_buf(),
            names: column_names,
            columns,
        })
    }
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
    }

    #[test]
    fn a_bad_cell_is_named_by_line_and_column() {
        let p = Path::new("bad.csv");
        let e = Table::parse("t_s,v\n0,1\n1,x\n", p, Delimiter::Auto, None, 0).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("bad.csv, line 3") && m.contains("`x`") && m.contains("`v`"),
            "{m}"
        );
        let e = Table::parse("t_s,v\n0,nan\n", p, Delimiter::Auto, None, 0).unwrap_err();
        assert!(e.to_string().contains("not finite"));
        let e = Table::parse("t_s,v\n0,1,2\n", p, Delimiter::Auto, None, 0).unwrap_err();
        assert!(e.to_string().contains("3 columns"));
    }
}
