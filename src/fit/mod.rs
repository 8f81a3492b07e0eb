//! Calibration: fit the model's unknowns (any numeric configuration key,
//! and the coefficients of the input maps) to recorded friction, and fit
//! the classic models (Coulomb + viscous, Stribeck, LuGre) to the same data
//! with the same optimiser, so that the comparison is honest.
//!
//! The method is bounded nonlinear least squares on the friction residual
//! r_k = F_model(t_k; p) − F_measured(t_k):
//!
//! | step | how |
//! |---|---|
//! | scaling | each parameter on its log scale (positive bounds) or linear scale, mapped to an unbounded variable by the sine transform s = lo + (hi − lo)(1 + sin u)/2 |
//! | global phase | a seeded Latin-hypercube set of starts over the scaled bounds, each scored by one simulation |
//! | local phase | Levenberg–Marquardt (MINPACK, `levenberg-marquardt` on nalgebra) from the given start, then the best distinct global starts side by side, each stopped inside the first optimum's 95 % confidence region or, with `--later-runs valley` (the default), as soon as a straight line from it falls all the way to that optimum (the valley test); Jacobian by forward differences of whole simulations run in parallel, kept up to date between them by Broyden's secant update and polished on differences at the end |
//! | statistics | standard errors s²(JᵀJ)⁻¹ and correlations from the Jacobian in scaled coordinates at the optimum; flags at bounds and for |corr| > 0.95 |
//!
//! Transient data are simulated from the steady state of the first sample
//! (as `simulate` does), on the solver's fixed step, with the inputs
//! interpolated linearly between samples and the friction read at the sample
//! times; steady curves are solved point by point with the steady solver.
//!
//! | file | content |
//! |---|---|
//! | `auto.rs` | `--fit auto`: the terms chosen by blocked cross-validation |
//! | `series.rs` | a table and its mapping → the model's inputs |
//! | `expr.rs` | column expressions: compiling, affine fast path, `ddt` |
//! | `bag_input.rs` | topics of a bag → a table |
//! | `params.rs` | fitted parameters: bounds, scales, configuration keys |
//! | `physics_model.rs` | our model as a predictor (transient and steady) |
//! | `baselines.rs` | Coulomb + viscous, Stribeck, LuGre |
//! | `problem.rs` | the problem: model, data, map coefficients, residuals, predictions |
//! | `options.rs` | how a fit searches: starts, global points, budget, progress, stop |
//! | `local_run.rs` | one Levenberg–Marquardt run: secant or difference Jacobians, the stop inside an earlier optimum's confidence region or valley, what was still moving |
//! | `driver.rs` | the whole fit: global phase, local runs, statistics, predictions |
//! | `prepare.rs` | data → our model: scales, keys, maps, a rotary joint's lever, `--fit auto`'s base set |
//! | `request.rs` | a calibration as data (the command line's and Python's) and its steps |
//! | `search.rs` | the global phase and the distinct optima |
//! | `stats.rs` | standard errors, correlations, flags; one-step blocked cross-validation |
//! | `report.rs` | the summary, the tables, plots, the fitted YAML |
//! | `by_direction.rs` | the residual by direction of motion: level and offset errors |
//! | `synthetic.rs` | synthetic data: the model along a motion, with noise |
//! | `rotary.rs` | a rotary joint (rad/s, N·m): the lever arm and load chosen from the data |
//! | `reversals.rs` | velocity reversals in the data and the stiffness through them (pre-sliding starts) |

pub mod auto;
#[cfg(feature = "mcap")]
pub mod bag_input;
pub mod baselines;
pub mod by_direction;
pub mod driver;
mod expr;
pub mod local_run;
pub mod options;
pub mod params;
pub mod physics_model;
pub mod prepare;
pub mod problem;
pub mod report;
pub mod request;
pub mod reversals;
pub mod rotary;
pub mod search;
pub mod series;
pub mod stats;
pub mod synthetic;

pub use crate::table::{Delimiter, Table, TableError};
pub use baselines::{Baseline, BaselineKind, LoadForm};
pub use driver::FitOutcome;
pub use options::Options;
pub use params::{FittedParameter, ParamSpec};
pub use physics_model::PhysicsModel;
pub use problem::{Data, Model};
pub use series::{Mapping, Series, Source};

use std::path::PathBuf;

/// The units of a fit's data: a linear axis (velocity m/s, friction N) or
/// a rotary joint (rad/s, N·m; `fit --rotary`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Units {
    /// m/s and N.
    #[default]
    Linear,
    /// rad/s and N·m.
    Rotary,
}

impl Units {
    /// The friction's unit.
    pub fn force(self) -> &'static str {
        match self {
            Self::Linear => "N",
            Self::Rotary => "N·m",
        }
    }

    /// The velocity's unit.
    pub fn speed(self) -> &'static str {
        match self {
            Self::Linear => "m/s",
            Self::Rotary => "rad/s",
        }
    }

    /// The friction's unit in a column name (`measured_n`, `measured_n_m`).
    pub fn force_column(self) -> &'static str {
        match self {
            Self::Linear => "n",
            Self::Rotary => "n_m",
        }
    }

    /// The velocity's unit in a column name.
    pub fn speed_column(self) -> &'static str {
        match self {
            Self::Linear => "m_s",
            Self::Rotary => "rad_s",
        }
    }
}

/// Errors of calibration: inputs, keys, bounds and data. A fit that does
/// not converge is not an error (it is an outcome with a status).
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// A data file could not be read.
    #[error("cannot read {}: {cause}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// A table's line does not parse.
    #[error("{}:{line}: {message}", path.display())]
    Table {
        /// The file.
        path: PathBuf,
        /// The line, 1-based.
        line: usize,
        /// What is wrong with it.
        message: String,
    },
    /// A column expression or map does not parse or evaluate.
    #[error("{what} `{text}`: {message}")]
    Expression {
        /// Which expression (the flag).
        what: String,
        /// Its text.
        text: String,
        /// What is wrong with it.
        message: String,
    },
    /// The data cannot be fitted (too few samples, non-finite values, …).
    #[error("{what}: {message}")]
    Data {
        /// The source or column.
        what: String,
        /// What is wrong.
        message: String,
    },
    /// A `--fit` key that cannot be fitted.
    #[error("--fit {key}: {message}")]
    Key {
        /// The key.
        key: String,
        /// Why.
        message: String,
    },
    /// `--bounds` that cannot hold.
    #[error("--bounds {key}: {message}")]
    Bounds {
        /// The key.
        key: String,
        /// Why.
        message: String,
    },
    /// The base configuration is not valid.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    /// A stop was requested.
    #[error(transparent)]
    Interrupted(#[from] crate::interrupt::Interrupted),
    /// A bag could not be read.
    #[cfg(feature = "mcap")]
    #[error(transparent)]
    Bag(#[from] crate::bag::BagError),
}

impl From<TableError> for FitError {
    fn from(e: TableError) -> Self {
        match e {
            TableError::Io { path, cause } => FitError::Io { path, cause },
            TableError::Cell {
                path,
                line,
                message,
            } => FitError::Table {
                path,
                line,
                message,
            },
        }
    }
}
