//! Messages. `msg/msg/*.msg` (the ROS 2 package `friction_msgs`) is the
//! source of truth for message layout; the wire structs mirror it field by
//! field (a test checks names, order and types against the `.msg` text) and
//! convert to and from the loop's heap-free records. The standard ROS types
//! the node reads or writes are mirrored too.
//!
//! Units are SI and part of each field's name; stamps are ROS time
//! (`builtin_interfaces/Time`), nanoseconds in the records (`stamp_ns`).
//!
//! | file | content |
//! |---|---|
//! | `wire.rs` | the ROS 2 wire structs (serde, `.msg` field order) |
//! | `types.rs` | [`MsgType`]: package, name, definition, `ros2msg` schema |
//! | `records.rs` | heap-free records of the loop and their conversions |
//! | `cdr.rs` | CDR with its encapsulation header |
//! | `command_codec.rs` | a command as its message and back (Float64, TwistStamped, Temperature, JointState), the stamp rule |
//! | `ros_interfaces.rs` | standard interfaces: parameters, `/rosout`, diagnostics, `/clock`, Trigger |
//! | `tests.rs` | round trips of every message through CDR and the records |
//! | `legacy/` | `.msg` definitions of layouts older bags were recorded in (`FrictionEstimateV1`, `V2`, read by `types.rs`) |

mod cdr;
pub mod command_codec;
mod records;
pub mod ros_interfaces;
mod types;
mod wire;

pub use cdr::{from_cdr, to_cdr, CdrError};
pub use records::*;
pub use types::*;
pub use wire::*;

#[cfg(test)]
mod tests;
