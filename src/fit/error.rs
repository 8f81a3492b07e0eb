//! What can go wrong in calibration: [`FitError`] for the inputs, keys,
//! bounds and data (setup; a fit that does not converge is an outcome, not
//! an error), and [`PredictError`] for why a model gives no prediction at
//! some parameter values (the optimiser steps away from those).

use crate::table::TableError;
use std::path::PathBuf;

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
    /// An output could not be written.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
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

/// Why a model gives no prediction at some parameter values: an outcome of
/// the search (it steps away from such points), reported when it happens
/// at the optimum or on held-out data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PredictError {
    /// The values make no valid configuration.
    #[error("{0}")]
    Parameters(String),
    /// The solver cannot be built for them.
    #[error("the solver cannot be built: {0}")]
    Solver(String),
    /// A temperature outside the viscosity law's range.
    #[error("{0}")]
    Viscosity(String),
    /// A time step ended without an estimate.
    #[error("the step at t = {t_s:.4} s ended {status} ({iterations} iterations)")]
    Step {
        /// The step's time, s.
        t_s: f64,
        /// How it ended.
        status: &'static str,
        /// Newton iterations.
        iterations: u32,
    },
    /// Step after step at the iteration bound: the inputs are out of reach.
    #[error("{steps} steps in a row up to t = {t_s:.4} s hit the iteration bound: these parameters cannot follow the inputs (e.g. a load the contact cannot carry)")]
    Stuck {
        /// Steps in a row.
        steps: u32,
        /// The last one's time, s.
        t_s: f64,
    },
    /// A steady state that did not converge.
    #[error("the steady state at v = {velocity_m_s} m/s did not converge ({status})")]
    Steady {
        /// The point's velocity (the model's input).
        velocity_m_s: f64,
        /// How it ended.
        status: &'static str,
    },
    /// A classic model outside its domain (LuGre's g(v) ≤ 0).
    #[error("{0}")]
    Domain(String),
    /// Map coefficients that make the data's inputs invalid (a load ≤ 0).
    #[error("{0}")]
    Inputs(String),
}

/// `what` = `value` is out of `range`.
pub(super) fn range_error(what: &str, value: String, range: &str) -> FitError {
    FitError::Data {
        what: what.to_string(),
        message: format!("{value} is out of range: must be {range}"),
    }
}
