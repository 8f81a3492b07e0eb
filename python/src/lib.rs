//! Python bindings of friction-node (`friction_node._core`), built with
//! PyO3 and maturin. The Python package `friction_node` (python/friction_node)
//! wraps these in a friendlier API (dict configurations, numpy and pandas);
//! this module only converts and calls the Rust library.
//!
//! Errors become Python exceptions with the command line's messages:
//! `ValueError` for configuration and input, `FileNotFoundError`/`OSError`
//! for files. A panic in the library becomes PyO3's `PanicException`, never
//! a crash of the interpreter. Long calls (`Model.run`, `replay`, `fit`,
//! `stribeck`) release the GIL.
//!
//! | file | job |
//! |---|---|
//! | `lib.rs` | the module `friction_node._core` and what it exports |
//! | `model.rs` | `Model`: one contact stepped from Python, `Model.run` over arrays |
//! | `calls/` | `stribeck`, `replay` and `fit`: the command line's jobs returning arrays |
//! | `columns.rs` | estimates → named numpy columns |
//! | `errors.rs` | library errors → Python exceptions, CLI flags → keywords |
//! | `interrupts.rs` | Ctrl-C during long calls (checked between chunks) |

mod calls;
mod columns;
mod errors;
mod interrupts;
mod model;

use pyo3::prelude::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<model::Model>()?;
    m.add_class::<model::Estimate>()?;
    m.add_function(wrap_pyfunction!(calls::stribeck::stribeck, m)?)?;
    m.add_function(wrap_pyfunction!(calls::replay::replay, m)?)?;
    m.add_function(wrap_pyfunction!(calls::fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(calls::default_config_yaml, m)?)?;
    m.add("SIMULATE_COLUMNS", friction_node::offline::SIMULATE_COLUMNS)?;
    m.add(
        "LOOP_METRIC_COLUMNS",
        format!(
            "cycle,t_start_s,t_end_s,{}",
            friction_node::analysis::metrics::LOOP_METRIC_COLUMNS
        ),
    )?;
    m.add("STRIBECK_COLUMNS", friction_node::offline::STRIBECK_COLUMNS)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
