//! Helpers shared by the integration tests: the loop's (`tests/node.rs`,
//! `tests/recording/`) and running the binary (`cli`). Each test file
//! uses some of them.
#![allow(dead_code)]

pub mod cli;
pub mod motion;
pub mod records;

use friction_node::config::{Config, StepMode};
use friction_node::msgs::EstimateRecord;
use friction_node::transport::PeerPort;

/// Timer mode on a small grid, statistics at 10 Hz, a 50 ms command timeout.
pub fn timer_config() -> Config {
    let mut c = Config::default();
    c.solver.cells = 32;
    c.node.step_mode = StepMode::Timer;
    c.node.statistics_rate_hz = 10.0;
    c.node.command_timeout_s = 0.05;
    c
}

/// Every estimate waiting at `peer`.
pub fn drain(peer: &mut dyn PeerPort) -> Vec<EstimateRecord> {
    std::iter::from_fn(|| peer.try_recv().unwrap()).collect()
}
