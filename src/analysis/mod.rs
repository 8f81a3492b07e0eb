//! Analysis of runs: hysteresis-loop metrics. Pure computation (no I/O).

pub mod metrics;

pub use metrics::{cycle_metrics, CycleCollector, LoopMetrics, LoopSample};
