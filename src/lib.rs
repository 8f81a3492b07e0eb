//! friction-node: a physics-based, real-time estimate of sliding friction.
//!
//! The [`physics`] module is the model core (no I/O, no clock, no logging);
//! everything else carries it to and from the world. Layers, lowest first,
//! each importing only from the layers below it (no file imports upward,
//! and no two files import each other but a `mod.rs` and its children):
//! the core; the messages (wire structs mirroring `msg/*.msg`, the wire
//! choices); configuration, inputs and tables; the links and transports;
//! the loop (node, contacts) and recording; offline work (simulate, replay,
//! fit, studies, benches) on top.
//!
//! | module | job |
//! |---|---|
//! | [`physics`] | the model and its solvers: Reynolds + cavitation + GW + load balance |
//! | [`config`] | the YAML parameter files: schema, defaults, overrides, validation, input envelope |
//! | [`range_watch`] | where a step's input lies against a contact's calibrated range; what is published outside it |
//! | [`signal`] | velocity, load and temperature inputs of offline runs |
//! | [`table`] | numeric tables from text (the csv crate): delimiters, columns, line numbers |
//! | [`expression`] | size and depth limits on the column expressions people write |
//! | [`clock`] | monotonic and wall time, system or simulated |
//! | [`stats`] | fixed-memory statistics windows and histograms |
//! | [`text`] | text formatting shared by the output layers |
//! | [`output`] | atomic, checked output files; free-space checks |
//! | [`interrupt`] | SIGINT/SIGTERM as a stop request for long offline work |
//! | [`analysis`] | hysteresis-loop metrics of a run |
//! | [`msgs`] | wire structs mirroring `msg/*.msg`, the loop's records, CDR |
//! | [`link`] | what the loop shares with its threads: loop settings, the parameter hand-over, the film-profile slot, record items, the recorder's counters, the live status |
//! | [`transport`] | in-memory, iceoryx2 and ROS 2 backends behind small traits |
//! | [`contacts`] | several contacts stepped together, the worker pool |
//! | [`node`] | the fixed-step real-time loop, its runner and live parameters |
//! | [`record`] | MCAP recording: one file, split directories, snapshots |
//! | [`bag`] | reading bags: MCAP, rosbag2 SQLite and directories |
//! | [`replay`] | the model over a recorded motion, the determinism oracle, reports |
//! | [`offline`] | `simulate`, `stribeck` and `profile` to CSV |
//! | [`fit`] | calibration: least squares on any key, classic baselines, reports |
//! | [`studies`] | the paper's parametric studies and their claims |
//! | [`plot`] | SVG figures shared by studies, replay and fit |
//! | [`mod@bench`] | step, latency, recorder, accuracy and fit benchmarks |

#![warn(missing_docs)]
#![warn(unreachable_pub)]

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
pub mod link;
pub mod msgs;
pub mod node;
pub mod offline;
pub mod output;
pub mod physics;
#[cfg(feature = "plots")]
pub mod plot;
pub mod range_watch;
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
