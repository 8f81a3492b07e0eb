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
        ConfigError::Io { cause, .. } => io(cause, e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub fn bag(e: BagError) -> PyErr {
    match &e {
        BagError::Io { cause, .. } => io(cause, e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

pub fn replay(e: ReplayError) -> PyErr {
    match e {
        ReplayError::Bag(b) => bag(b),
        ReplayError::Config(c) => config(c),
        ReplayError::Output(_) | ReplayError::Recording { .. } => PyOSError::new_err(e.to_string()),
        other => PyValueError::new_err(keywords(&other.to_string())),
    }
}

pub fn fit(e: FitError) -> PyErr {
    match e {
        FitError::Io { ref cause, .. } => io(cause, e.to_string()),
        FitError::Bag(b) => bag(b),
        FitError::Config(c) => config(c),
        FitError::Output(_) => PyOSError::new_err(e.to_string()),
        other => PyValueError::new_err(keywords(&other.to_string())),
    }
}

/// The command line's flags, as the Python functions name the same
/// arguments (keyword arguments of `fit` and `replay`).
const FLAGS_AS_KEYWORDS: [(&str, &str); 24] = [
    ("--max-evaluations", "max_evaluations"),
    ("--global-points", "global_points"),
    ("--velocity-topic", "velocity_topic"),
    ("--friction-topic", "friction_topic"),
    ("--temperature-topic", "temperature_topic"),
    ("--load-topic", "load_topic"),
    ("--velocity-map", "velocity_map"),
    ("--load-map", "load_map"),
    ("--temperature", "temperature"),
    ("--delimiter", "delimiter"),
    ("--validate", "validate"),
    ("--velocity", "velocity"),
    ("--friction", "friction"),
    ("--holdout", "holdout"),
    ("--columns", "columns"),
    ("--bounds", "bounds"),
    ("--smooth", "smooth"),
    ("--starts", "starts"),
    ("--start", "start"),
    ("--topic", "topic"),
    ("--joint", "joint"),
    ("--load", "load"),
    ("--time", "time"),
    ("--fit", "fit"),
];

/// `message` with every command-line flag it names (`--holdout`) replaced
/// by the keyword argument of the Python function (`holdout`), so that a
/// Python user reads the names they typed. `--map` is `map`; `--skip` is
/// `skip` (the same words).
pub fn keywords(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    'scan: while let Some(i) = rest.find("--") {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        for (flag, kw) in FLAGS_AS_KEYWORDS
            .iter()
            .chain(&[("--map", "map"), ("--skip", "skip")])
        {
            let boundary = tail[flag.len().min(tail.len())..]
                .chars()
                .next()
                .is_none_or(|c| !(c.is_alphanumeric() || c == '-' || c == '_'));
            if tail.starts_with(flag) && boundary {
                out.push_str(kw);
                rest = &tail[flag.len()..];
                continue 'scan;
            }
        }
        out.push_str("--");
        rest = &tail[2..];
    }
    out.push_str(rest);
    out
}

pub fn value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

#[cfg(test)]
mod tests {
    #[test]
    fn flags_in_messages_become_the_python_keywords() {
        assert_eq!(
            super::keywords(
                "--holdout: 1.5 is out of range; --global-points 3, --start x, --starts 2"
            ),
            "holdout: 1.5 is out of range; global_points 3, start x, starts 2"
        );
        assert_eq!(
            super::keywords("--fit a.b: unknown key (--map c=1)"),
            "fit a.b: unknown key (map c=1)"
        );
        assert_eq!(
            super::keywords("a -- b --unknown-flag"),
            "a -- b --unknown-flag"
        );
    }
}
