//! Solver-setup errors: the only `Result` errors of the physics core.
//! Numerical outcomes of a step are statuses (see [`super::Status`]), never errors.

use core::fmt;

/// A parameter handed to the solver violates an invariant of the model.
#[derive(Debug, Clone, PartialEq)]
pub enum SetupError {
    /// `field` has `value`, which is not allowed: `reason`.
    InvalidParameter {
        /// The parameter, as its configuration key or field names it.
        field: &'static str,
        /// The value given.
        value: f64,
        /// What the model requires instead.
        reason: &'static str,
    },
    /// `field`'s choice is not supported with the rest of the settings.
    Unsupported {
        /// The setting.
        field: &'static str,
        /// Why it cannot be combined with the others.
        reason: &'static str,
    },
}

impl SetupError {
    pub(crate) fn invalid(field: &'static str, value: f64, reason: &'static str) -> Self {
        SetupError::InvalidParameter {
            field,
            value,
            reason,
        }
    }
}

impl fmt::Display for SetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SetupError::InvalidParameter {
                field,
                value,
                reason,
            } => write!(f, "invalid solver parameter `{field}` = {value}: {reason}"),
            SetupError::Unsupported { field, reason } => {
                write!(f, "unsupported solver setting `{field}`: {reason}")
            }
        }
    }
}

impl std::error::Error for SetupError {}
