//! Offline runs: `simulate`, `stribeck` and `profile`, writing CSV.
//!
//! Output files are written through [`crate::output::AtomicFile`]: an
//! existing file is never half-overwritten, and an unwritable destination is
//! reported before any computation.
//!
//! | file | job |
//! |---|---|
//! | `simulate.rs` | `simulate`: a transient run over velocity, load and temperature signals, its rows, timing and report |
//! | `stribeck.rs` | `stribeck`: steady states over a velocity sweep |
//! | `profile.rs` | `profile`: the steady film, pressure and shear fields at one velocity |

mod profile;
mod simulate;
mod stribeck;

pub use profile::*;
pub use simulate::*;
pub use stribeck::*;

use crate::config::ConfigError;
use crate::output::OutputError;
use crate::physics::SetupError;
use crate::signal::SignalError;

/// A simulation (offline run, study case, benchmark) could not be set up,
/// was given a bad argument, or could not write its output.
#[derive(Debug, thiserror::Error)]
pub enum SimulationError {
    /// The configuration is not valid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The model could not be set up.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// An input signal is not usable.
    #[error(transparent)]
    Signal(#[from] SignalError),
    /// The output could not be written.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// A stop was requested.
    #[error(transparent)]
    Interrupted(#[from] crate::interrupt::Interrupted),
    /// An argument outside what the command accepts.
    #[error("invalid argument `{name}` = {value}: {message}")]
    Argument {
        /// The argument.
        name: &'static str,
        /// Its value.
        value: String,
        /// Why it is refused.
        message: String,
    },
}

pub(crate) fn arg_err(
    name: &'static str,
    value: impl ToString,
    message: impl Into<String>,
) -> SimulationError {
    SimulationError::Argument {
        name,
        value: value.to_string(),
        message: message.into(),
    }
}
