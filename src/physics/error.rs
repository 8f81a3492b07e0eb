//! Solver-setup errors: the only `Result` errors of the physics core.
//! Numerical outcomes of a step are statuses (see [`super::Status`]), never errors.

use core::fmt;

/// A parameter handed to the solver violates an invariant of the model.
#[derive(Debug, Clone, PartialEq)]
pub enum SetupError {
    /// `field` has `value`, which is not allowed: `reason`.
    InvalidParameter {
        field: &'static str,
        value: f64,
        reason: &'static str,
    },
    /// `field`'s choice is not supported with the rest of the settings.
    Unsupported {
        field: &'static str,
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
