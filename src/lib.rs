//! friction-node: a physics-based, real-time estimate of sliding friction.
//!
//! The [`physics`] module is the model core (no I/O). The other modules are
//! the layers around it.

pub mod physics;
