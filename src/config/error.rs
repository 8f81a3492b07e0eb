//! The configuration layer's error, and where a configuration came from.

use std::path::PathBuf;

/// Errors of the configuration layer.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read config file {}: {cause}", path.display())]
    Io {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error("config {origin} is not valid YAML: {message}")]
    Syntax { origin: String, message: String },
    #[error("config {origin}: {message}")]
    Layout { origin: String, message: String },
    #[error("unknown config key `{key}` ({message})")]
    UnknownKey { key: String, message: String },
    #[error("config key `{key}`: {message}")]
    InvalidValue { key: String, message: String },
    #[error("config key `{key}` = {value} is out of range: allowed {range}")]
    OutOfRange {
        key: String,
        value: String,
        range: String,
    },
    #[error("override `{arg}`: {message}")]
    BadOverride { arg: String, message: String },
    #[error("--ros-args {arg}: {message}")]
    RosArgs { arg: String, message: String },
}

/// Where a configuration came from (for messages).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    /// The built-in `launch-config/default.yaml`.
    Embedded,
    File(PathBuf),
    /// Text handed over by a caller, described (e.g. "passed to
    /// fn_model_new_from_yaml", "recorded in the bag").
    Text(&'static str),
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::Embedded => write!(f, "(built-in launch-config/default.yaml)"),
            Origin::File(p) => write!(f, "{}", p.display()),
            Origin::Text(what) => write!(f, "(YAML text {what})"),
        }
    }
}
