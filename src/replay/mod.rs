//! Replay: run the model over the velocity recorded in any ROS 2 bag (an
//! MCAP file or a rosbag2 directory, read through [`crate::bag`]).
//!
//! The commanded velocity is read from a channel of type
//! `std_msgs/msg/Float64`, `geometry_msgs/msg/TwistStamped` (`linear.x`) or
//! `sensor_msgs/msg/JointState` (the `velocity` of one joint), detected from
//! its schema; a `std_msgs/msg/Float64` load channel is optional. The model
//! runs in lockstep on the step grid (the node's own loop, fed one command at
//! a time), so a replay is exactly what the node would have done.
//!
//! For a bag recorded by friction-node, replay uses the recorded
//! configuration by default and is driven by the recorded estimates' own
//! velocity and load (what each step of the node actually applied, in timer
//! and lockstep mode alike); it then reports whether the re-simulation is
//! bit-identical to the recording, and the largest deviation per field if not
//! (the determinism oracle).
//!
//! A truncated or corrupt bag replays everything before the damage and says
//! where it stopped. Nothing is written before the input is validated.
//!
//! | file | content |
//! |---|---|
//! | `mod.rs` | the error, the step limit, what the layer exports |
//! | `request.rs` | one replay as data, for the command line and Python: prepare, run, write |
//! | `mode.rs` | what drives the replay (`InputMode`) |
//! | `prepare.rs` | options, choosing the configuration and topics, validating the input |
//! | `inputs.rs` | decoding the inputs: the bag's topics or recorded estimates, maps, checks |
//! | `commands.rs` | the decoded samples as the node's commands on the step grid |
//! | `run.rs` | running the node's loop over the commands |
//! | `oracle.rs` | the determinism check |
//! | `sink.rs` | CSV and MCAP outputs, written off the model's thread |
//! | `report.rs` | `summary.md`, `cycles.csv`, figures |

mod commands;
mod inputs;
mod mode;
mod oracle;
mod prepare;
mod report;
mod request;
mod run;
mod sink;

pub use mode::InputMode;
pub use oracle::Oracle;
pub use prepare::{prepare, ParameterChange, PreparedReplay, ReplayOptions};
pub use report::{cycles, gap_list, write_report};
pub use request::{ReadyReplay, ReplayOutcome, ReplayRequest};
pub use run::{run, ContactReplay, ReplayResult};
pub use sink::{OutputFormat, OutputStream};

use crate::bag::decode::VELOCITY_TYPES;
use crate::bag::{self, BagError, Damage};
use crate::config::ConfigError;
use crate::node::NodeError;
use std::path::PathBuf;

/// Errors of the replay layer.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The bag could not be read.
    #[error(transparent)]
    Bag(#[from] BagError),
    /// A stop was requested.
    #[error(transparent)]
    Interrupted(#[from] crate::interrupt::Interrupted),
    /// No topic of a velocity type.
    #[error("no usable velocity topic ({VELOCITY_TYPES}); the bag has:\n{}", bag::listing(.available))]
    NoVelocityTopic {
        /// The bag's topics: (name, type, messages).
        available: Vec<(String, String, u64)>,
    },
    /// More than one topic could be the velocity.
    #[error("several topics could be the velocity; choose one with --topic:\n{}", bag::listing(.candidates))]
    AmbiguousVelocity {
        /// The candidates: (name, type, messages).
        candidates: Vec<(String, String, u64)>,
    },
    /// The input topic has no message.
    #[error("topic `{topic}` has no messages before {}", damage_note(.damage))]
    Empty {
        /// The topic.
        topic: String,
        /// Where the bag is damaged, if that is why.
        damage: Option<Damage>,
    },
    /// An output file could not be written.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// The MCAP output could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Recording {
        /// The output.
        path: PathBuf,
        /// Why.
        source: crate::record::WriteError,
    },
    /// The input spans more steps than [`MAX_REPLAY_STEPS`].
    #[error("topic `{topic}`: its stamps span {span_s:.3e} s, more than {MAX_REPLAY_STEPS} steps of {dt_s} s (a stamp is probably wrong; or replay a shorter part)")]
    TooLong {
        /// The velocity topic.
        topic: String,
        /// Its stamps' span, s.
        span_s: f64,
        /// The step, s.
        dt_s: f64,
    },
    /// A `--velocity-map` or `--load-map` expression failed.
    #[error("{flag} `{expr}`: {message}")]
    Map {
        /// The flag.
        flag: &'static str,
        /// The expression.
        expr: String,
        /// What went wrong, and at which message.
        message: String,
    },
    /// The configuration recorded in the bag is not valid here.
    #[error("the recorded configuration in the bag: {0}")]
    RecordedConfig(ConfigError),
    /// A recorded parameter change was refused.
    #[error("the parameter change recorded at {stamp_ns} ns cannot be applied: {message}")]
    Parameters {
        /// The change's stamp, ns.
        stamp_ns: u64,
        /// Why it was refused.
        message: String,
    },
    /// The model could not be set up.
    #[error(transparent)]
    Setup(#[from] crate::physics::SetupError),
    /// The configuration (`--config`, `--set`) is not valid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The node's loop could not be built.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// Several configured contacts (count, and why this bag cannot drive them).
    #[error(
        "the configuration lists {0} contacts (`contacts`): a bag is replayed for several \
         contacts from a friction-node recording of them (its `~/contacts/NAME/friction` \
         topics); {1}. Replay a foreign bag with a configuration without `contacts`, once \
         per joint (--joint)"
    )]
    SeveralContacts(usize, String),
}

impl ReplayError {
    /// Whether the message already names the bag (it could not be opened).
    pub fn names_the_bag(&self) -> bool {
        matches!(
            self,
            ReplayError::Bag(BagError::Io { .. } | BagError::NotABag { .. })
        )
    }

    /// Whether the error is the configuration's (a file or the overrides),
    /// not the bag's: a message about it does not begin with the bag.
    pub fn is_configuration(&self) -> bool {
        matches!(self, ReplayError::Config(_))
    }
}

fn damage_note(d: &Option<Damage>) -> String {
    match d {
        Some(d) => format!("the damage ({d})"),
        None => "the end of the bag".into(),
    }
}

/// The most steps one replay runs (its inputs are held in memory: about
/// 24 bytes per step; 14 h at 1 kHz).
pub const MAX_REPLAY_STEPS: u64 = 50_000_000;
