//! From recorded columns to the model's inputs: time, velocity, friction,
//! load and temperature, each an expression of the columns (`evalexpr`),
//! with map coefficients that can themselves be fitted, `ddt(COLUMN)` for a
//! smoothed time derivative (a position to a velocity) and `smooth(COLUMN)`
//! for a column smoothed as that derivative is (a force beside a derived
//! acceleration: `windowed.rs`).
//!
//! ```text
//! --time 't_ms / 1000' --velocity 'ddt(position_mm) / 1000'
//! --friction 'force_n - 51.87 * p_bar - c0' --load 'k * p_bar + f0' --map k=50 --map f0=10
//! ```
//!
//! A table without a time column (and no `--time`) is a steady curve: each
//! row a steady operating point.

use super::expr::{compile, Affine, Columns, Expr, Var};
use super::windowed::WindowedColumn;
use super::FitError;
use crate::table::Table;

/// A sample interval up to this factor over a model's integration step
/// counts as one step: a log's clock jitter neither doubles LuGre's steps
/// (`baselines.rs`) nor makes a series' start read as a slow log's
/// (`film_run.rs`).
pub(super) const STEP_SLACK: f64 = 1.01;

/// How the model's inputs come from a table's columns.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapping {
    /// None: `t_s` if the table has it, else a steady curve.
    pub time: Option<String>,
    /// The velocity column expression, m/s.
    pub velocity: String,
    /// The friction column expression, N.
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
    /// The source's name.
    pub name: String,
    /// A steady curve (no time, each point a steady state).
    pub steady: bool,
    /// Time, s (steady: the row index).
    pub t: Vec<f64>,
    /// Velocity, m/s.
    pub velocity: Vec<f64>,
    /// Measured friction, N.
    pub friction: Vec<f64>,
    /// Normal load, N (None: the configuration's).
    pub load: Option<Vec<f64>>,
    /// Temperature, °C (None: the reference temperature).
    pub temperature: Option<Vec<f64>>,
    /// Whether each sample is used in the fit (the rest is held out).
    pub fit: Vec<bool>,
}

/// One step of the fingerprints' hash: FNV-1a's multiply on a 64-bit word,
/// then an xor-shift that folds the high bits into the low ones. Both are
/// bijections of the state, so two inputs of equal length that differ in a
/// single word never collide; fast on long columns.
pub(super) fn mix(h: u64, w: u64) -> u64 {
    let h = (h ^ w).wrapping_mul(0x0000_0100_0000_01b3);
    h ^ (h >> 29)
}

impl Series {
    /// A fingerprint of the series' model inputs: time, velocity, load,
    /// temperature and whether it is steady (the film traces' and the
    /// problem's kept predictions' key; `mix` over every value).
    pub fn inputs_fingerprint(&self) -> u64 {
        let mut h = mix(0xcbf2_9ce4_8422_2325, u64::from(self.steady));
        let mut column = |v: &[f64]| {
            h = mix(h, v.len() as u64);
            for x in v {
                h = mix(h, x.to_bits());
            }
        };
        column(&self.t);
        column(&self.velocity);
        column(self.load.as_deref().unwrap_or(&[]));
        column(self.temperature.as_deref().unwrap_or(&[]));
        h
    }

    /// Samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether it has no sample.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The load at sample `k`, N (`default` without a load column).
    pub fn load_at(&self, k: usize, default: f64) -> f64 {
        self.load.as_ref().map_or(default, |l| l[k])
    }
}

/// A table with its mapping, ready to give series for any coefficients.
#[derive(Clone)]
pub struct Source {
    pub(super) table: Table,
    pub(super) name: String,
    pub(super) steady: bool,
    time: Option<Expr>,
    velocity: Expr,
    friction: Expr,
    load: Option<Expr>,
    temperature: Option<Expr>,
    /// Windowed columns `ddt__NAME`, `smooth__NAME`.
    pub(super) derived: Vec<(String, Vec<f64>)>,
    coefficients: Vec<String>,
    /// The times (they cannot depend on coefficients).
    times: Vec<f64>,
    /// The first row that is scored: a time series' held-out part is
    /// simulated from the start of its file, so that it starts in the
    /// state the motion before it left, and scored from here (0: every row).
    pub(super) scored_from: usize,
}

impl Source {
    /// Compile `mapping` against `table`; the time column is evaluated now
    /// (it cannot depend on coefficients) and checked.
    pub fn new(table: Table, mapping: &Mapping) -> Result<Self, FitError> {
        let coeffs = &mapping.coefficients;
        let mut derived_cols: Vec<WindowedColumn> = Vec::new();
        let mut expr = |what: &str, text: Option<String>, default: &str, c: &[(String, f64)]| {
            text.or_else(|| table.column(default).map(|_| default.to_string()))
                .as_deref()
                .map(|t| compile(what, t, &table, &mut derived_cols, c))
                .transpose()
        };
        let time = expr("--time", mapping.time.clone(), "t_s", &[])?;
        let velocity = expr("--velocity", Some(mapping.velocity.clone()), "", coeffs)?
            .expect("the velocity is always given");
        let friction = expr("--friction", Some(mapping.friction.clone()), "", coeffs)?
            .expect("the friction is always given");
        let load = expr("--load", mapping.load.clone(), "load_n", coeffs)?;
        let temperature = expr(
            "--temperature",
            mapping.temperature.clone(),
            "temperature_c",
            coeffs,
        )?;
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
            times: Vec::new(),
            scored_from: 0,
        };
        let t = s.compute_times()?;
        s.derive_columns(derived_cols, &t, mapping.smooth_s)?;
        s.times = t;
        s.resolve_variables();
        let c0: Vec<f64> = coeffs.iter().map(|(_, v)| *v).collect();
        s.precompute(&c0)?;
        Ok(s)
    }

    /// The windowed columns (`ddt`, `smooth`) the expressions read, in
    /// order (a nested one reads a column made before it), over the times `t`.
    fn derive_columns(
        &mut self,
        derived_cols: Vec<WindowedColumn>,
        t: &[f64],
        smooth_s: f64,
    ) -> Result<(), FitError> {
        let Some(first) = derived_cols.first() else {
            return Ok(());
        };
        let name = format!("{}()", first.op.function());
        if self.steady {
            return Err(FitError::Expression {
                what: name,
                text: first.source.clone(),
                message: "a steady curve has no time to differentiate or smooth over".into(),
            });
        }
        let span = t.last().copied().unwrap_or(0.0) - t[0];
        if t.len() < 5 || span < 2.0 * smooth_s {
            return Err(FitError::Data {
                what: self.name.clone(),
                message: format!(
                    "{name} needs at least 5 samples over twice the smoothing window ({} s); the data has {} over {span} s",
                    2.0 * smooth_s,
                    t.len()
                ),
            });
        }
        for d in derived_cols {
            let y = match self.table.column(&d.source) {
                Some(y) => y.to_vec(),
                None => self
                    .derived
                    .iter()
                    .find(|(id, _)| *id == d.source)
                    .map(|(_, y)| y.clone())
                    .expect("checked when compiled"),
            };
            self.derived.push((d.id, d.op.apply(t, &y, smooth_s)));
        }
        Ok(())
    }

    /// Every expression's variables resolved to a column, a derived column
    /// or a map coefficient.
    fn resolve_variables(&mut self) {
        let resolve = |e: &Expr| -> Vec<(String, Var)> {
            e.node
                .iter_variable_identifiers()
                .map(|id| {
                    let var = if let Some(i) = self.table.names.iter().position(|n| n == id) {
                        Var::Column(i)
                    } else if let Some(i) = self.derived.iter().position(|(n, _)| n == id) {
                        Var::Derived(i)
                    } else {
                        Var::Coefficient(
                            self.coefficients
                                .iter()
                                .position(|c| c == id)
                                .expect("checked when compiled"),
                        )
                    };
                    (id.to_string(), var)
                })
                .collect()
        };
        let velocity = resolve(&self.velocity);
        let friction = resolve(&self.friction);
        let load = self.load.as_ref().map(resolve);
        let temperature = self.temperature.as_ref().map(resolve);
        self.velocity.vars = velocity;
        self.friction.vars = friction;
        if let (Some(e), Some(v)) = (self.load.as_mut(), load) {
            e.vars = v;
        }
        if let (Some(e), Some(v)) = (self.temperature.as_mut(), temperature) {
            e.vars = v;
        }
    }

    /// Expressions that read no map coefficient evaluated once, and each
    /// expression's affine fast path at the starting coefficients `c0`.
    fn precompute(&mut self, c0: &[f64]) -> Result<(), FitError> {
        let fixed = |s: &Source, e: &Expr, what: &str| -> Result<Option<Vec<f64>>, FitError> {
            if e.reads_coefficients() {
                Ok(None)
            } else {
                s.eval_column(e, what, &[]).map(Some)
            }
        };
        let velocity = (
            fixed(self, &self.velocity, "--velocity")?,
            self.affine(&self.velocity, c0),
        );
        let friction = (
            fixed(self, &self.friction, "--friction")?,
            self.affine(&self.friction, c0),
        );
        let load = match &self.load {
            Some(e) => Some((fixed(self, e, "--load")?, self.affine(e, c0))),
            None => None,
        };
        let temperature = match &self.temperature {
            Some(e) => Some((fixed(self, e, "--temperature")?, self.affine(e, c0))),
            None => None,
        };
        (self.velocity.fixed, self.velocity.affine) = velocity;
        (self.friction.fixed, self.friction.affine) = friction;
        if let (Some(e), Some((f, a))) = (self.load.as_mut(), load) {
            (e.fixed, e.affine) = (f, a);
        }
        if let (Some(e), Some((f, a))) = (self.temperature.as_mut(), temperature) {
            (e.fixed, e.affine) = (f, a);
        }
        Ok(())
    }

    /// The source's name (its file).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The columns its expressions read.
    fn columns(&self) -> Columns<'_> {
        Columns {
            name: &self.name,
            table: &self.table,
            derived: &self.derived,
        }
    }

    /// `e` as an affine function of the coefficients about `c0`, if it is one.
    fn affine(&self, e: &Expr, c0: &[f64]) -> Option<Affine> {
        self.columns().affine(e, c0)
    }

    /// `e` at every row, for map coefficients `coeffs`.
    fn eval_column(&self, e: &Expr, what: &str, coeffs: &[f64]) -> Result<Vec<f64>, FitError> {
        self.columns().eval_column(e, what, coeffs)
    }

    /// Whether map coefficient `i` moves the measured friction alone, and
    /// that affinely: the friction expression is affine in it (checked at
    /// construction) and no input expression reads it. A fitted such
    /// coefficient changes every residual by a slope that no parameter
    /// changes.
    pub fn moves_only_the_friction_affinely(&self, i: usize) -> bool {
        self.friction.affine.is_some() && !self.inputs_read(i)
    }

    /// Whether an input expression (velocity, load, temperature) reads map
    /// coefficient `i`: the model's inputs then depend on it.
    pub fn inputs_read(&self, i: usize) -> bool {
        let reads = |e: &Expr| {
            e.vars
                .iter()
                .any(|(_, v)| matches!(v, Var::Coefficient(k) if *k == i))
        };
        [
            Some(&self.velocity),
            self.load.as_ref(),
            self.temperature.as_ref(),
        ]
        .into_iter()
        .flatten()
        .any(reads)
    }

    /// Whether it is a steady curve.
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

    fn compute_times(&self) -> Result<Vec<f64>, FitError> {
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
        let t = self.times.clone();
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

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> Table {
        Table::of_csv(text, "m.csv")
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
    fn a_nested_ddt_is_the_second_derivative_an_acceleration() {
        // x = 3 t² mm: ẍ = 6 mm/s² everywhere (a local linear fit of a
        // linear velocity is exact away from the ends).
        let mut text = String::from("t_s,x_mm,force\n");
        for k in 0..300 {
            let t = k as f64 * 0.01;
            text += &format!("{t},{},{}\n", 3.0 * t * t, 1.0);
        }
        let m = Mapping {
            velocity: "ddt(x_mm) / 1000".into(),
            friction: "force - m * ddt(ddt(x_mm)) / 1000".into(),
            coefficients: vec![("m".into(), 2.0)],
            ..Default::default()
        };
        let s = Source::new(table(&text), &m).unwrap();
        let se = s.series(&[2.0]).unwrap();
        for k in 20..280 {
            approx::assert_relative_eq!(se.friction[k], 1.0 - 2.0 * 6e-3, epsilon = 1e-9);
            approx::assert_relative_eq!(se.velocity[k], 6.0 * se.t[k] / 1000.0, epsilon = 1e-9);
        }
        // Anything but a column (or a ddt of one) is refused by name.
        let e = Source::new(
            table(&text),
            &Mapping {
                velocity: "ddt(x_mm * 2)".into(),
                friction: "force".into(),
                ..Default::default()
            },
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("ddt() takes a column name"), "{e}");
    }

    #[test]
    fn a_force_read_as_smooth_smooth_is_filtered_as_the_acceleration_beside_it() {
        // F = M ẍ, the force stepping from 0 to 4 N at 1 s, M = 2 kg: the
        // friction `F − m ẍ` is zero but for the derivation. With the force
        // as measured the step leaves half of it (2 N); smoothed twice, as
        // ddt(ddt(x)) smooths the acceleration, under 3 % of it.
        let mut text = String::from("t_s,x_m,force_n\n");
        for k in 0..2000 {
            let t = k as f64 * 1e-3;
            let (x, f) = if t >= 1.0 {
                ((t - 1.0).powi(2), 4.0)
            } else {
                (0.0, 0.0)
            };
            text += &format!("{t},{x},{f}\n");
        }
        let worst = |friction: &str| {
            let m = Mapping {
                velocity: "ddt(x_m)".into(),
                friction: friction.into(),
                coefficients: vec![("m".into(), 2.0)],
                smooth_s: 0.01,
                ..Default::default()
            };
            let se = Source::new(table(&text), &m)
                .unwrap()
                .series(&[2.0])
                .unwrap();
            se.friction[100..1900]
                .iter()
                .fold(0.0f64, |w, f| w.max(f.abs()))
        };
        approx::assert_abs_diff_eq!(worst("force_n - m * ddt(ddt(x_m))"), 2.0, epsilon = 1e-6);
        let filtered = worst("smooth(smooth(force_n)) - m * ddt(ddt(x_m))");
        assert!(filtered < 0.03 * 4.0, "{filtered}");
        // smooth() of anything but a column (or a windowed column) is refused.
        let e = Source::new(
            table(&text),
            &Mapping {
                velocity: "ddt(x_m)".into(),
                friction: "smooth(force_n * 2)".into(),
                ..Default::default()
            },
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("smooth() takes a column name"), "{e}");
    }

    #[test]
    fn an_absurdly_long_or_deep_expression_is_refused_before_it_is_parsed() {
        let t = table("t_s,v,f\n0,1,2\n1,1,2\n");
        let m = |v: String| Mapping {
            velocity: v,
            friction: "f".into(),
            ..Default::default()
        };
        let e = Source::new(t.clone(), &m(format!("{}v", "-".repeat(100_000))))
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("100001 characters") && e.contains("at most 1000"),
            "{e}"
        );
        let e = Source::new(t.clone(), &m(format!("{}v", "-".repeat(40))))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("nested 40 deep"), "{e}");
        let e = Source::new(
            t.clone(),
            &m(format!("{}v{}", "(".repeat(33), ")".repeat(33))),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("nested 33 deep"), "{e}");
        assert!(Source::new(t, &m("-(-v) - -1e-3 * 2".into())).is_ok());
    }

    #[test]
    fn affine_maps_take_the_fast_path_and_give_the_directly_evaluated_values() {
        let mut text = String::from("t_s,p_bar,force\n");
        for k in 0..50 {
            text += &format!(
                "{},{},{}\n",
                k as f64 * 0.01,
                1.0 + 0.1 * k as f64,
                20.0 + k as f64
            );
        }
        let m = Mapping {
            velocity: "0.01 + 0 * p_bar".into(),
            friction: "force - p_bar * 1e5 * a - off".into(),
            load: Some("k * k * p_bar + f0".into()),
            coefficients: vec![
                ("a".into(), 5e-4),
                ("off".into(), 0.0),
                ("k".into(), 3.0),
                ("f0".into(), 10.0),
            ],
            ..Default::default()
        };
        let s = Source::new(table(&text), &m).unwrap();
        assert!(s.friction.affine.is_some(), "force - p A - off is affine");
        assert!(s.load.as_ref().unwrap().affine.is_none(), "k² p is not");
        let c = [5.2e-4, 1.5, 2.0, 30.0];
        let se = s.series(&c).unwrap();
        for k in 0..50 {
            let p = 1.0 + 0.1 * k as f64;
            let f = 20.0 + k as f64 - p * 1e5 * c[0] - c[1];
            approx::assert_relative_eq!(se.friction[k], f, max_relative = 1e-12, epsilon = 1e-9);
            approx::assert_relative_eq!(
                se.load.as_ref().unwrap()[k],
                4.0 * p + 30.0,
                max_relative = 1e-12
            );
        }
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
