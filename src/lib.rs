//! friction-node: a physics-based, real-time estimate of sliding friction.
//!
//! The [`physics`] module is the model core (no I/O, no clock, no logging).
//! [`analysis`] computes loop metrics from runs. The other modules are the
//! layers around them.

pub mod analysis;
pub mod physics;
