//! Library errors → Python exceptions (the command line's messages).

use friction_node::bag::BagError;
use friction_node::config::ConfigError;
use friction_node::fit::FitError;
use friction_node::replay::ReplayError;
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::PyErr;

fn io(e: &std::io::Error, message: String) -> PyErr {
    if e.kind() == std::io::ErrorKind::NotFound {
        PyFileNotFoundError::new_err(message)
    } else {
        PyOSError::new_err(message)
    }
}

pub fn config(e: ConfigError) -> PyErr {
    match &e {
        ConfigError::Io { source, .. } => io(source, e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub fn bag(e: BagError) -> PyErr {
    match &e {
        BagError::Io { source, .. } => io(source, e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub fn replay(e: ReplayError) -> PyErr {
    match e {
        ReplayError::Bag(b) => bag(b),
        ReplayError::Config(c) => config(c),
        ReplayError::Output { .. } => PyOSError::new_err(e.to_string()),
        other => PyValueError::new_err(other.to_string()),
    }
}

pub fn fit(e: FitError) -> PyErr {
    match e {
        FitError::Io { ref source, .. } => io(source, e.to_string()),
        FitError::Bag(b) => bag(b),
        FitError::Config(c) => config(c),
        other => PyValueError::new_err(other.to_string()),
    }
}

pub fn value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

pub fn os(message: impl Into<String>) -> PyErr {
    PyOSError::new_err(message.into())
}
