//! Analysis of runs: hysteresis-loop metrics. Pure computation (no I/O).
//!
//! | file | job |
//! |---|---|
//! | `metrics.rs` | hysteresis-loop metrics per motion cycle (docs/model.md §9) |

pub mod metrics;

pub use metrics::{cycle_metrics, CycleCollector, LoopMetrics, LoopSample};
