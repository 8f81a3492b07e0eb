//! The configuration layer's error, and where a configuration came from.

use std::path::PathBuf;

/// Errors of the configuration layer.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The parameter file could not be read.
    #[error("cannot read config file {}: {cause}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// The text is not YAML.
    #[error("config {origin} is not valid YAML: {message}")]
    Syntax {
        /// Where the text came from.
        origin: String,
        /// The parser's message.
        message: String,
    },
    /// The YAML is not a parameter file's shape.
    #[error("config {origin}: {message}")]
    Layout {
        /// Where the text came from.
        origin: String,
        /// What is wrong with its shape.
        message: String,
    },
    /// A key the configuration does not have.
    #[error("unknown config key `{key}` ({message})")]
    UnknownKey {
        /// The dotted key.
        key: String,
        /// The keys it could have meant.
        message: String,
    },
    /// A value of the wrong type or form.
    #[error("config key `{key}`: {message}")]
    InvalidValue {
        /// The dotted key.
        key: String,
        /// What was expected.
        message: String,
    },
    /// A value outside its physical range.
    #[error("config key `{key}` = {value} is out of range: allowed {range}")]
    OutOfRange {
        /// The dotted key.
        key: String,
        /// The value given.
        value: String,
        /// The allowed range.
        range: String,
    },
    /// A `--set KEY=VALUE` that cannot be applied.
    #[error("override `{arg}`: {message}")]
    BadOverride {
        /// The argument.
        arg: String,
        /// Why.
        message: String,
    },
    /// A `--ros-args` section rcl would refuse.
    #[error("--ros-args {arg}: {message}")]
    RosArgs {
        /// The argument.
        arg: String,
        /// Why.
        message: String,
    },
}

/// Where a configuration came from (for messages).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    /// The built-in `launch-config/default.yaml`.
    Embedded,
    /// A parameter file.
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
