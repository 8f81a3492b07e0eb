//! friction-node: a physics-based, real-time estimate of sliding friction.
//!
//! The [`physics`] module is the model core (no I/O, no clock, no logging).
//! [`analysis`] computes loop metrics from runs. [`config`] reads the ROS 2
//! parameter files; [`signal`] the velocity and load inputs.

pub mod analysis;
#[cfg(feature = "mcap")]
pub mod bag;
pub mod bench;
pub mod clock;
pub mod config;
pub mod contacts;
pub mod expression;
pub mod fit;
pub mod interrupt;
pub mod msgs;
pub mod node;
pub mod offline;
pub mod output;
pub mod physics;
#[cfg(feature = "plots")]
pub mod plot;
#[cfg(feature = "mcap")]
pub mod record;
#[cfg(feature = "mcap")]
pub mod replay;
pub mod signal;
pub mod stats;
pub mod studies;
pub mod table;
pub mod text;
pub mod transport;
