//! From recorded columns to the model's inputs: time, velocity, friction,
//! load and temperature, each an expression of the columns (`evalexpr`),
//! with map coefficients that can themselves be fitted and `ddt(COLUMN)`
//! for a smoothed time derivative (a position to a velocity).
//!
//! ```text
//! --time 't_ms / 1000' --velocity 'ddt(position_mm) / 1000'
//! --friction 'force_n - 51.87 * p_bar - c0' --load 'k * p_bar + f0' --map k=50 --map f0=10
//! ```
//!
//! A table without a time column (and no `--time`) is a steady curve: each
//! row a steady operating point.

use super::table::Table;
use super::FitError;
use evalexpr::{
    build_operator_tree, ContextWithMutableVariables, DefaultNumericTypes, HashMapContext, Node,
    Value,
};
use std::path::PathBuf;

/// How the model's inputs come from a table's columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapping {
    /// None: `t_s` if the table has it, else a steady curve.
    pub time: Option<String>,
    pub velocity: String,
    pub friction: String,
    /// None: `load_n` if present, else `contact.load_n`.
    pub load: Option<String>,
    /// None: `temperature_c` if present, else the reference temperature.
    pub temperature: Option<String>,
    /// Half-width of the window of `ddt(...)`, s.
    pub smooth_s: f64,
    /// Map coefficients and their starting values.
    pub coefficients: Vec<(String, f64)>,
}

impl Default for Mapping {
    fn default() -> Self {
        Self {
            time: None,
            velocity: "velocity_m_s".into(),
            friction: "friction_n".into(),
            load: None,
            temperature: None,
            smooth_s: 0.05,
            coefficients: Vec::new(),
        }
    }
}

/// One series of samples, as the model sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    /// A steady curve (no time, each point a steady state).
    pub steady: bool,
    /// Time, s (steady: the row index).
    pub t: Vec<f64>,
    pub velocity: Vec<f64>,
    pub friction: Vec<f64>,
    /// Normal load, N (None: the configuration's).
    pub load: Option<Vec<f64>>,
    /// Temperature, °C (None: the reference temperature).
    pub temperature: Option<Vec<f64>>,
    /// Whether each sample is used in the fit (the rest is held out).
    pub fit: Vec<bool>,
}

impl Series {
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    pub fn load_at(&self, k: usize, default: f64) -> f64 {
        self.load.as_ref().map_or(default, |l| l[k])
    }

    /// Hold out the last `fraction` of a time series, or every k-th point of
    /// a steady curve (interleaved, so both ends stay in the fit).
    pub fn hold_out(&mut self, fraction: f64) {
        if fraction <= 0.0 {
            return;
        }
        let n = self.len();
        if self.steady {
            let every = (1.0 / fraction).round().max(2.0) as usize;
            for (k, f) in self.fit.iter_mut().enumerate() {
                *f = k % every != every / 2;
            }
        } else {
            let cut = ((1.0 - fraction) * n as f64).round() as usize;
            for (k, f) in self.fit.iter_mut().enumerate() {
                *f = k < cut;
            }
        }
    }
}

/// One compiled expression and the identifiers it reads.
struct Expr {
    text: String,
    node: Node<DefaultNumericTypes>,
}

/// A table with its mapping, ready to give series for any coefficients.
pub struct Source {
    table: Table,
    name: String,
    steady: bool,
    time: Option<Expr>,
    velocity: Expr,
    friction: Expr,
    load: Option<Expr>,
    temperature: Option<Expr>,
    /// Derived columns `ddt__NAME`.
    derived: Vec<(String, Vec<f64>)>,
    coefficients: Vec<String>,
}

fn compile(
    what: &str,
    text: &str,
    table: &Table,
    derived: &mut Vec<(String, String)>,
    coefficients: &[(String, f64)],
) -> Result<Expr, FitError> {
    // ddt(NAME) → ddt__NAME, a derived column.
    let mut t = text.to_string();
    while let Some(i) = t.find("ddt(") {
        let rest = &t[i + 4..];
        let Some(j) = rest.find(')') else {
            return Err(FitError::Expression {
                what: what.into(),
                text: text.into(),
                message: "`ddt(` without `)`".into(),
            });
        };
        let col = rest[..j].trim().to_string();
        if table.column(&col).is_none() {
            return Err(FitError::Expression {
                what: what.into(),
                text: text.into(),
                message: format!(
                    "ddt({col}): no column `{col}` (columns: {})",
                    table.names.join(", ")
                ),
            });
        }
        let id = format!("ddt__{col}");
        if !derived.iter().any(|(d, _)| *d == id) {
            derived.push((id.clone(), col));
        }
        t = format!("{}{}{}", &t[..i], id, &rest[j + 1..]);
    }
    let node =
        build_operator_tree::<DefaultNumericTypes>(&t).map_err(|e| FitError::Expression {
            what: what.into(),
            text: text.into(),
            message: e.to_string(),
        })?;
    for id in node.iter_variable_identifiers() {
        let known = table.column(id).is_some()
            || derived.iter().any(|(d, _)| d == id)
            || coefficients.iter().any(|(c, _)| c == id);
        if !known {
            return Err(FitError::Expression {
                what: what.into(),
                text: text.into(),
                message: format!(
                    "`{id}` is neither a column ({}) nor a map coefficient (--map NAME=VALUE)",
                    table.names.join(", ")
                ),
            });
        }
    }
    Ok(Expr {
        text: text.to_string(),
        node,
    })
}

/// d/dt of `y` by a local linear fit over ±`half` s (at least ±1 sample).
fn derivative(t: &[f64], y: &[f64], half: f64) -> Vec<f64> {
    let n = t.len();
    let (mut lo, mut hi) = (0usize, 0usize);
    (0..n)
        .map(|k| {
            while t[k] - t[lo] > half && lo + 1 < k {
                lo += 1;
            }
            while hi + 1 < n && (t[hi + 1] - t[k] <= half || hi < k + 1) {
                hi += 1;
            }
            let a = lo.min(k.saturating_sub(1));
            let b = hi.max((k + 1).min(n - 1));
            let m = (b - a + 1) as f64;
            let (st, sy) = (t[a..=b].iter().sum::<f64>(), y[a..=b].iter().sum::<f64>());
            let (mt, my) = (st / m, sy / m);
            let (mut num, mut den) = (0.0, 0.0);
            for j in a..=b {
                num += (t[j] - mt) * (y[j] - my);
                den += (t[j] - mt) * (t[j] - mt);
            }
            if den > 0.0 {
                num / den
            } else {
                0.0
            }
        })
        .collect()
}

impl Source {
    /// Compile `mapping` against `table`; the time column is evaluated now
    /// (it cannot depend on coefficients) and checked.
    pub fn new(table: Table, mapping: &Mapping) -> Result<Self, FitError> {
        let coeffs = &mapping.coefficients;
        let mut derived_cols: Vec<(String, String)> = Vec::new();
        let time_text = mapping
            .time
            .clone()
            .or_else(|| table.column("t_s").map(|_| "t_s".to_string()));
        let time = time_text
            .as_deref()
            .map(|t| compile("--time", t, &table, &mut derived_cols, &[]))
            .transpose()?;
        let velocity = compile(
            "--velocity",
            &mapping.velocity,
            &table,
            &mut derived_cols,
            coeffs,
        )?;
        let friction = compile(
            "--friction",
            &mapping.friction,
            &table,
            &mut derived_cols,
            coeffs,
        )?;
        let load_text = mapping
            .load
            .clone()
            .or_else(|| table.column("load_n").map(|_| "load_n".to_string()));
        let load = load_text
            .as_deref()
            .map(|t| compile("--load", t, &table, &mut derived_cols, coeffs))
            .transpose()?;
        let temp_text = mapping.temperature.clone().or_else(|| {
            table
                .column("temperature_c")
                .map(|_| "temperature_c".to_string())
        });
        let temperature = temp_text
            .as_deref()
            .map(|t| compile("--temperature", t, &table, &mut derived_cols, coeffs))
            .transpose()?;
        let name = table.source.display().to_string();
        let mut s = Source {
            steady: time.is_none(),
            table,
            name,
            time,
            velocity,
            friction,
            load,
            temperature,
            derived: Vec::new(),
            coefficients: coeffs.iter().map(|(c, _)| c.clone()).collect(),
        };
        let t = s.times()?;
        if !derived_cols.is_empty() {
            if s.steady {
                return Err(FitError::Expression {
                    what: "ddt()".into(),
                    text: derived_cols[0].1.clone(),
                    message: "a steady curve has no time to differentiate over".into(),
                });
            }
            let span = t.last().copied().unwrap_or(0.0) - t[0];
            if t.len() < 5 || span < 2.0 * mapping.smooth_s {
                return Err(FitError::Data {
                    what: s.name.clone(),
                    message: format!(
                        "ddt() needs at least 5 samples over twice the smoothing window ({} s); the data has {} over {span} s",
                        2.0 * mapping.smooth_s,
                        t.len()
                    ),
                });
            }
            for (id, col) in derived_cols {
                let y = s.table.column(&col).expect("checked").to_vec();
                s.derived.push((id, derivative(&t, &y, mapping.smooth_s)));
            }
        }
        Ok(s)
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    pub fn is_steady(&self) -> bool {
        self.steady
    }

    /// Map coefficients that appear in the load expression and nowhere
    /// else (a load-linear classic model absorbs them).
    pub fn load_only_coefficients(&self) -> Vec<String> {
        let ids = |e: &Expr| -> Vec<String> {
            e.node
                .iter_variable_identifiers()
                .map(str::to_string)
                .collect()
        };
        let Some(load) = &self.load else {
            return Vec::new();
        };
        let elsewhere: Vec<String> = [
            Some(&self.velocity),
            Some(&self.friction),
            self.temperature.as_ref(),
        ]
        .into_iter()
        .flatten()
        .flat_map(ids)
        .collect();
        ids(load)
            .into_iter()
            .filter(|c| self.coefficients.contains(c) && !elsewhere.contains(c))
            .collect()
    }

    fn context_row(&self, ctx: &mut HashMapContext<DefaultNumericTypes>, k: usize) {
        for (name, col) in self.table.names.iter().zip(&self.table.columns) {
            let _ = ctx.set_value(name.clone(), Value::Float(col[k]));
        }
        for (name, col) in &self.derived {
            let _ = ctx.set_value(name.clone(), Value::Float(col[k]));
        }
    }

    fn eval_column(&self, e: &Expr, what: &str, coeffs: &[f64]) -> Result<Vec<f64>, FitError> {
        let mut ctx = HashMapContext::<DefaultNumericTypes>::new();
        for (name, v) in self.coefficients.iter().zip(coeffs) {
            let _ = ctx.set_value(name.clone(), Value::Float(*v));
        }
        (0..self.table.rows())
            .map(|k| {
                self.context_row(&mut ctx, k);
                let v =
                    e.node
                        .eval_number_with_context(&ctx)
                        .map_err(|x| FitError::Expression {
                            what: what.into(),
                            text: e.text.clone(),
                            message: format!("row {}: {x}", k + 1),
                        })?;
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(FitError::Data {
                        what: self.name.clone(),
                        message: format!("{what} `{}` is not finite at row {}", e.text, k + 1),
                    })
                }
            })
            .collect()
    }

    fn times(&self) -> Result<Vec<f64>, FitError> {
        let t = match &self.time {
            Some(e) => self.eval_column(e, "--time", &[])?,
            None => (0..self.table.rows()).map(|k| k as f64).collect(),
        };
        if t.len() < 2 {
            return Err(FitError::Data {
                what: self.name.clone(),
                message: format!("{} sample(s): a fit needs at least two", t.len()),
            });
        }
        if let Some(k) = t.windows(2).position(|w| w[1] <= w[0]) {
            return Err(FitError::Data {
                what: self.name.clone(),
                message: format!(
                    "time does not increase at row {} ({} s after {} s)",
                    k + 2,
                    t[k + 1],
                    t[k]
                ),
            });
        }
        Ok(t)
    }

    /// The series for map coefficients `coeffs` (in the mapping's order).
    pub fn series(&self, coeffs: &[f64]) -> Result<Series, FitError> {
        let t = self.times()?;
        let velocity = self.eval_column(&self.velocity, "--velocity", coeffs)?;
        let friction = self.eval_column(&self.friction, "--friction", coeffs)?;
        let load = self
            .load
            .as_ref()
            .map(|e| self.eval_column(e, "--load", coeffs))
            .transpose()?;
        if let Some(l) = &load {
            if let Some(k) = l.iter().position(|x| *x <= 0.0) {
                return Err(FitError::Data {
                    what: self.name.clone(),
                    message: format!(
                        "the load `{}` is {} N at row {}: a load must be positive",
                        self.load.as_ref().expect("some").text,
                        l[k],
                        k + 1
                    ),
                });
            }
        }
        let temperature = self
            .temperature
            .as_ref()
            .map(|e| self.eval_column(e, "--temperature", coeffs))
            .transpose()?;
        let n = t.len();
        Ok(Series {
            name: self.name.clone(),
            steady: self.steady,
            t,
            velocity,
            friction,
            load,
            temperature,
            fit: vec![true; n],
        })
    }
}

/// The sources a path stands for (one table).
pub fn source_path(p: &std::path::Path) -> PathBuf {
    p.to_path_buf()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::table::Delimiter;
    use std::path::Path;

    fn table(text: &str) -> Table {
        Table::parse(text, Path::new("m.csv"), Delimiter::Auto, None, 0).unwrap()
    }

    #[test]
    fn expressions_map_columns_and_coefficients_and_ddt_differentiates() {
        let mut text = String::from("t_ms,pos_mm,force,p_bar\n");
        for k in 0..200 {
            let t = k as f64 * 10.0;
            text += &format!("{t},{},{},{}\n", 0.02 * t, 10.0 + k as f64, 2.0);
        }
        let m = Mapping {
            time: Some("t_ms / 1000".into()),
            velocity: "ddt(pos_mm) / 1000".into(),
            friction: "force - c0".into(),
            load: Some("k * p_bar".into()),
            coefficients: vec![("k".into(), 50.0), ("c0".into(), 1.0)],
            ..Default::default()
        };
        let s = Source::new(table(&text), &m).unwrap();
        let se = s.series(&[50.0, 1.0]).unwrap();
        assert!(!se.steady);
        assert!((se.t[10] - 0.1).abs() < 1e-12);
        // pos 0.02 mm/ms = 20 mm/s = 0.02 m/s.
        assert!(
            se.velocity.iter().all(|v| (v - 0.02).abs() < 1e-9),
            "{:?}",
            &se.velocity[..3]
        );
        assert_eq!(se.friction[0], 9.0);
        assert_eq!(se.load.as_ref().unwrap()[0], 100.0);
        let se = s.series(&[-1.0, 1.0]);
        assert!(se.unwrap_err().to_string().contains("must be positive"));
    }

    #[test]
    fn bad_mappings_and_data_are_named() {
        let t = table("t_s,v,f\n0,1,2\n1,1,2\n");
        let m = |v: &str| Mapping {
            velocity: v.into(),
            friction: "f".into(),
            ..Default::default()
        };
        let e = Source::new(t.clone(), &m("speed"))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("`speed`") && e.contains("t_s, v, f"), "{e}");
        let e = Source::new(t.clone(), &m("(v")).err().unwrap().to_string();
        assert!(e.contains("--velocity"), "{e}");
        let e = Source::new(t.clone(), &m("ddt(v)"))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("at least 5 samples"), "{e}");
        let back = table("t_s,v,f\n0,1,2\n1,1,2\n0.5,1,2\n");
        let e = Source::new(back, &m("v")).err().unwrap().to_string();
        assert!(e.contains("does not increase at row 3"), "{e}");
        let one = table("t_s,v,f\n0,1,2\n");
        let e = Source::new(one, &m("v")).err().unwrap().to_string();
        assert!(e.contains("at least two"), "{e}");
        // No time column: a steady curve.
        let steady = table("v,f\n0.1,2\n0.2,3\n");
        assert!(Source::new(steady, &m("v")).unwrap().is_steady());
    }
}
