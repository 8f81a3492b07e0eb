//! Column expressions of calibration data (`evalexpr`): compiled once per
//! source, evaluated row by row or, when affine in the map coefficients,
//! from a base column and slopes; `ddt(COLUMN)` and `smooth(COLUMN)`
//! replaced by their windowed columns (`windowed.rs`).

use super::windowed::{Windowed, WindowedColumn};
use super::FitError;
use crate::table::Table;
use evalexpr::{
    build_operator_tree, Context, DefaultNumericTypes, EvalexprError, EvalexprResult, Node, Value,
};

/// Where a variable of an expression comes from.
#[derive(Debug, Clone, Copy)]
pub(super) enum Var {
    Column(usize),
    Derived(usize),
    Coefficient(usize),
}

/// One compiled expression and the identifiers it reads.
#[derive(Clone)]
pub(super) struct Expr {
    pub(super) text: String,
    pub(super) node: Node<DefaultNumericTypes>,
    /// The identifiers it reads, resolved once the derived columns exist.
    pub(super) vars: Vec<(String, Var)>,
    /// Its values when it reads no map coefficient (computed once).
    pub(super) fixed: Option<Vec<f64>>,
    /// When it is affine in the coefficients it reads (checked at
    /// construction): its values at the start coefficients c₀ and its slope
    /// per coefficient, so that e(c) = e(c₀) + Σ (cᵢ − c₀ᵢ) gᵢ row by row
    /// without evaluating the expression again.
    pub(super) affine: Option<Affine>,
}

/// An expression's values as an affine function of the coefficients.
#[derive(Clone)]
pub(super) struct Affine {
    pub(super) c0: Vec<f64>,
    pub(super) base: Vec<f64>,
    /// (coefficient index, slope column).
    pub(super) slopes: Vec<(usize, Vec<f64>)>,
}

impl Affine {
    pub(super) fn at(&self, coeffs: &[f64]) -> Vec<f64> {
        let mut out = self.base.clone();
        for (i, g) in &self.slopes {
            let d = coeffs.get(*i).copied().unwrap_or(f64::NAN) - self.c0[*i];
            if d != 0.0 {
                for (o, gk) in out.iter_mut().zip(g) {
                    *o += d * gk;
                }
            }
        }
        out
    }
}

impl Expr {
    pub(super) fn reads_coefficients(&self) -> bool {
        self.vars
            .iter()
            .any(|(_, v)| matches!(v, Var::Coefficient(_)))
    }
}

/// The variables of one expression at one row: a few names, looked up
/// linearly, their values overwritten row by row (no allocation per row).
struct RowContext {
    names: Vec<String>,
    values: Vec<Value<DefaultNumericTypes>>,
}

impl Context for RowContext {
    type NumericTypes = DefaultNumericTypes;

    fn get_value(&self, identifier: &str) -> Option<&Value<DefaultNumericTypes>> {
        self.names
            .iter()
            .position(|n| n == identifier)
            .map(|i| &self.values[i])
    }

    fn call_function(
        &self,
        identifier: &str,
        _argument: &Value<DefaultNumericTypes>,
    ) -> evalexpr::error::EvalexprResultValue<DefaultNumericTypes> {
        Err(EvalexprError::FunctionIdentifierNotFound(
            identifier.to_string(),
        ))
    }

    fn are_builtin_functions_disabled(&self) -> bool {
        false
    }

    fn set_builtin_functions_disabled(
        &mut self,
        disabled: bool,
    ) -> EvalexprResult<(), DefaultNumericTypes> {
        if disabled {
            Err(EvalexprError::BuiltinFunctionsCannotBeDisabled)
        } else {
            Ok(())
        }
    }
}

pub(super) fn compile(
    what: &str,
    text: &str,
    table: &Table,
    derived: &mut Vec<WindowedColumn>,
    coefficients: &[(String, f64)],
) -> Result<Expr, FitError> {
    crate::expression::check_size(text).map_err(|message| FitError::Expression {
        what: what.into(),
        text: crate::expression::shorten(text),
        message,
    })?;
    let t = windowed_as_columns(what, text, table, derived)?;
    let t = crate::expression::with_functions(&t);
    let node =
        build_operator_tree::<DefaultNumericTypes>(&t).map_err(|e| FitError::Expression {
            what: what.into(),
            text: text.into(),
            message: e.to_string(),
        })?;
    crate::expression::check_functions(&node).map_err(|message| FitError::Expression {
        what: what.into(),
        text: text.into(),
        message,
    })?;
    for id in node.iter_variable_identifiers() {
        if table.index(id).is_some() && table.column(id).is_none() {
            return Err(FitError::Expression {
                what: what.into(),
                text: text.into(),
                message: format!("column `{id}` holds text: {}", table.column_error(id)),
            });
        }
        let known = table.column(id).is_some()
            || derived.iter().any(|d| d.id == id)
            || coefficients.iter().any(|(c, _)| c == id);
        if !known {
            // A header such as `velocity (m/s)` cannot be written in an
            // expression: say how to name its columns.
            let rename = table
                .names
                .iter()
                .find(|n| !is_identifier(n))
                .map_or_else(String::new, |n| {
                    let example = identifiers_for(&table.names)
                        .map_or_else(String::new, |c| format!(", here `--columns {c}`"));
                    format!(
                        "; a column whose name is not an identifier (`{n}`) is named for expressions with --columns NAME,... (one name per column, replacing the header's){example}"
                    )
                });
            // Names are case-sensitive: `Velocity_m_s` is not `velocity_m_s`.
            let case = table
                .names
                .iter()
                .find(|n| n.eq_ignore_ascii_case(id))
                .map_or_else(String::new, |n| {
                    format!("; column names are case-sensitive: the table has `{n}`")
                });
            return Err(FitError::Expression {
                what: what.into(),
                text: text.into(),
                message: format!(
                    "`{id}` is neither a column of {} ({}) nor a map coefficient (--map NAME=VALUE){case}{rename}",
                    table.source.display(),
                    table.names.join(", ")
                ),
            });
        }
    }
    Ok(Expr {
        text: text.to_string(),
        node,
        vars: Vec::new(),
        fixed: None,
        affine: None,
    })
}

/// Whether an expression can name `name` as it is: a letter or `_`, then
/// letters, digits and `_`.
fn is_identifier(name: &str) -> bool {
    let mut c = name.chars();
    c.next()
        .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
        && c.all(|x| x.is_ascii_alphanumeric() || x == '_')
}

/// The header `names` as identifiers an expression can name, the unit
/// kept as the default columns write it (`velocity (m/s)` →
/// `velocity_m_s`, `Torque [N·m]` → `torque_nm`, `Force [N]` →
/// `force_n`), comma-separated for `--columns`; None when two would be
/// the same or one would be empty.
fn identifiers_for(names: &[String]) -> Option<String> {
    let mut out: Vec<String> = Vec::with_capacity(names.len());
    for n in names {
        let mut id = String::new();
        let chars: Vec<char> = n.trim().to_lowercase().chars().collect();
        for (i, &c) in chars.iter().enumerate() {
            // A product of units (N·m, N.m, N*m) is written together.
            let joins = matches!(c, '·' | '.' | '*' | '⋅')
                && i > 0
                && chars[i - 1].is_ascii_alphabetic()
                && chars.get(i + 1).is_some_and(|x| x.is_ascii_alphabetic());
            if c.is_ascii_alphanumeric() {
                id.push(c);
            } else if !joins && !id.ends_with('_') {
                id.push('_');
            }
        }
        let mut id = id.trim_matches('_').to_string();
        if id.starts_with(|c: char| c.is_ascii_digit()) {
            id.insert(0, '_');
        }
        if id.is_empty() || out.contains(&id) {
            return None;
        }
        out.push(id);
    }
    Some(out.join(","))
}

/// `text` with each `ddt(NAME)` and `smooth(NAME)` replaced by its
/// windowed column (`ddt__NAME`, `smooth__NAME`, added to `derived` with
/// its source column); innermost first, so that ddt(ddt(x)) (an
/// acceleration) is ddt__ddt__x, the derivative of ddt__x, smoothed the
/// same way, and smooth(smooth(f)) is f smoothed as that acceleration is.
fn windowed_as_columns(
    what: &str,
    text: &str,
    table: &Table,
    derived: &mut Vec<WindowedColumn>,
) -> Result<String, FitError> {
    let mut t = text.to_string();
    // The last call's opening: an identifier character before it would make
    // it another name's tail (`my_ddt(`), which evalexpr then rejects.
    let last_call = |t: &str| {
        Windowed::ALL
            .iter()
            .filter_map(|&(op, name)| {
                let pat = format!("{name}(");
                t.match_indices(&pat)
                    .filter(|(i, _)| {
                        !t[..*i]
                            .chars()
                            .next_back()
                            .is_some_and(|c| c.is_alphanumeric() || c == '_')
                    })
                    .map(|(i, _)| (i, op, pat.len()))
                    .last()
            })
            .max_by_key(|(i, _, _)| *i)
    };
    while let Some((i, op, open)) = last_call(&t) {
        let name = op.function();
        let rest = &t[i + open..];
        let Some(j) = rest.find(')') else {
            return Err(FitError::Expression {
                what: what.into(),
                text: text.into(),
                message: format!("`{name}(` without `)`"),
            });
        };
        let col = rest[..j].trim().to_string();
        let is_derived = derived.iter().any(|d| d.id == col);
        if !is_derived && (!is_name(&col) || table.column(&col).is_none()) {
            let why = if is_name(&col) {
                table.column_error(&col).to_string()
            } else {
                format!("{name}() takes a column name, or another of ddt() and smooth() of one")
            };
            return Err(FitError::Expression {
                what: what.into(),
                text: text.into(),
                message: format!("{name}({col}): {why}"),
            });
        }
        let id = op.column_id(&col);
        if !derived.iter().any(|d| d.id == id) {
            derived.push(WindowedColumn {
                id: id.clone(),
                source: col,
                op,
            });
        }
        t = format!("{}{}{}", &t[..i], id, &rest[j + 1..]);
    }
    Ok(t)
}

fn is_name(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_alphanumeric() || c == '_')
}

/// The columns an expression reads: a source's table and its derived
/// (`ddt`, `smooth`) columns, under the source's name (for messages).
pub(super) struct Columns<'a> {
    pub(super) name: &'a str,
    pub(super) table: &'a Table,
    pub(super) derived: &'a [(String, Vec<f64>)],
}

impl Columns<'_> {
    fn name(&self) -> &str {
        self.name
    }

    /// `e` as an affine function of its coefficients about `c0`, if it is
    /// one: slopes from unit steps, then checked at two other points (to
    /// 1e-9 of the values' scale). None for a non-affine expression, one
    /// that reads no coefficient, or one that fails to evaluate (the error
    /// then shows when the series is asked for).
    pub(super) fn affine(&self, e: &Expr, c0: &[f64]) -> Option<Affine> {
        if e.fixed.is_some() || !e.reads_coefficients() {
            return None;
        }
        let eval = |c: &[f64]| self.eval_column(e, "", c).ok();
        let base = eval(c0)?;
        let mut slopes = Vec::new();
        let used: Vec<usize> = e
            .vars
            .iter()
            .filter_map(|(_, v)| match v {
                Var::Coefficient(i) => Some(*i),
                _ => None,
            })
            .collect();
        for &i in &used {
            let h = if c0[i] != 0.0 { c0[i].abs() } else { 1.0 };
            let mut c = c0.to_vec();
            c[i] += h;
            let g: Vec<f64> = eval(&c)?
                .iter()
                .zip(&base)
                .map(|(a, b)| (a - b) / h)
                .collect();
            slopes.push((i, g));
        }
        let a = Affine {
            c0: c0.to_vec(),
            base,
            slopes,
        };
        let scale = a
            .base
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-300);
        for factor in [0.37, 2.9] {
            let c: Vec<f64> = c0
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    if used.contains(&i) {
                        v * factor + 0.13 * (1.0 + v.abs())
                    } else {
                        *v
                    }
                })
                .collect();
            let direct = eval(&c)?;
            let predicted = a.at(&c);
            let worst = direct
                .iter()
                .zip(&predicted)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            let sc = scale.max(direct.iter().fold(0.0f64, |m, v| m.max(v.abs())));
            if worst.is_nan() || worst > 1e-9 * sc {
                return None;
            }
        }
        Some(a)
    }

    /// `e` at every row, for map coefficients `coeffs`.
    pub(super) fn eval_column(
        &self,
        e: &Expr,
        what: &str,
        coeffs: &[f64],
    ) -> Result<Vec<f64>, FitError> {
        if let Some(v) = &e.fixed {
            return Ok(v.clone());
        }
        if let Some(a) = &e.affine {
            let v = a.at(coeffs);
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                return Err(FitError::Data {
                    what: self.name().to_string(),
                    message: format!("{what} `{}` is not finite at row {}", e.text, k + 1),
                });
            }
            return Ok(v);
        }
        // The time expression is compiled but not resolved (it reads
        // columns only): resolve it here.
        let vars: Vec<(String, Var)> = if e.vars.is_empty() {
            e.node
                .iter_variable_identifiers()
                .filter_map(|id| {
                    self.table
                        .names
                        .iter()
                        .position(|n| n == id)
                        .map(|i| (id.to_string(), Var::Column(i)))
                })
                .collect()
        } else {
            e.vars.clone()
        };
        let mut ctx = RowContext {
            names: vars.iter().map(|(n, _)| n.clone()).collect(),
            values: vec![Value::Float(0.0); vars.len()],
        };
        (0..self.table.rows())
            .map(|k| {
                for (slot, (_, var)) in ctx.values.iter_mut().zip(&vars) {
                    *slot = Value::Float(match *var {
                        Var::Column(i) => self.table.columns[i][k],
                        Var::Derived(i) => self.derived[i].1[k],
                        Var::Coefficient(i) => coeffs.get(i).copied().unwrap_or(f64::NAN),
                    });
                }
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
                        what: self.name().to_string(),
                        message: format!("{what} `{}` is not finite at row {}", e.text, k + 1),
                    })
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_named_in_another_case_is_pointed_at() {
        let table = Table::of_csv("Velocity_m_s,Friction_N\n0.1,1\n0.2,2\n", "c.csv");
        let Err(err) = compile("--velocity", "velocity_m_s", &table, &mut Vec::new(), &[]) else {
            panic!("a column was read under another case");
        };
        let err = err.to_string();
        assert!(
            err.contains("is neither a column of c.csv")
                && err.contains("case-sensitive: the table has `Velocity_m_s`"),
            "{err}"
        );
        assert!(compile("--velocity", "Velocity_m_s", &table, &mut Vec::new(), &[]).is_ok());
    }

    #[test]
    fn headers_with_units_in_brackets_get_a_columns_line_that_names_them_as_the_defaults() {
        let names =
            |h: &[&str]| identifiers_for(&h.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(
            names(&["velocity (m/s)", "friction (N)"]).as_deref(),
            Some("velocity_m_s,friction_n")
        );
        assert_eq!(
            names(&["Time [ms]", "Velocity [mm/s]", "Force [N]"]).as_deref(),
            Some("time_ms,velocity_mm_s,force_n")
        );
        assert_eq!(
            names(&["velocity (rad/s)", "torque (N·m)", "torque (N.mm)"]).as_deref(),
            Some("velocity_rad_s,torque_nm,torque_nmm")
        );
        assert_eq!(names(&["2nd", "x"]).as_deref(), Some("_2nd,x"));
        // Two that would be one name, or one that would be empty: none.
        assert_eq!(names(&["v (m/s)", "v [m/s]"]), None);
        assert_eq!(names(&["v", "(-)"]), None);
        let table = Table::of_csv("velocity (m/s),friction (N)\n0.1,1\n0.2,2\n", "u.csv");
        let Err(err) = compile("--velocity", "velocity_m_s", &table, &mut Vec::new(), &[]) else {
            panic!("a column was read that the table does not have");
        };
        assert!(
            err.to_string()
                .ends_with("here `--columns velocity_m_s,friction_n`"),
            "{err}"
        );
    }
}
