//! `stribeck`, `replay` and `fit`: the command line's offline jobs, returning
//! Python data instead of files (and writing the same files when asked).
//!
//! | file | job |
//! |---|---|
//! | `stribeck.rs` | `stribeck`: steady states at given velocities |
//! | `replay.rs` | `replay`: the model over a bag, its estimates, cycles and summary |
//! | `fit.rs` | `fit`: calibration, its outcome dict, the report and fitted file |

pub mod fit;
pub mod replay;
pub mod stribeck;

use pyo3::prelude::*;

/// The built-in default parameter file.
#[pyfunction]
pub fn default_config_yaml() -> &'static str {
    friction_node::config::DEFAULT_YAML
}
