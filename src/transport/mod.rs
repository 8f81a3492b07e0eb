//! Transports: how commands reach the loop and estimates leave it.
//!
//! A backend has two sides behind small traits: [`NodePort`] (the loop's
//! side; every method but [`NodePort::wait_for_command`] is non-blocking) and
//! [`PeerPort`] (drivers, tests and benchmarks: they send commands and read
//! estimates). One conformance suite (`tests/transport_conformance.rs`) runs
//! against every backend: in-memory (here), iceoryx2 and ROS 2.
//!
//! Backends are opened from a [`BackendSpec`] on the thread that uses them
//! (iceoryx2 ports are not `Send`).
//!
//! | file | job |
//! |---|---|
//! | `mod.rs` | the backend-neutral traits and the loop's ports (the film-profile slot they publish from is `crate::link`'s) |
//! | `memory.rs` | in-memory: bounded lock-free queues between threads of one process |
//! | `iceoryx/` | iceoryx2: zero-copy shared memory on one host |
//! | `ros2/` | ROS 2 through ros2-client (pure-Rust DDS) |

pub mod memory;

#[cfg(feature = "iceoryx2")]
pub mod iceoryx;
#[cfg(feature = "ros2")]
pub mod ros2;

use crate::link::FilmProfileSlot;
use crate::link::RecordItem;
use crate::msgs::{Command, EstimateRecord, StatisticsRecord};
use crossbeam_queue::ArrayQueue;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Errors of the transport layer, by the operation that failed. The
/// middleware's errors arrive formatted: the backends' error types stay out
/// of this crate's API.
#[derive(Debug, thiserror::Error)]
pub enum TransportError {
    /// Opening a side failed: a node, context, topic, service, publisher,
    /// subscriber, poll or thread.
    #[error("{backend}: cannot {operation}: {message}")]
    Open {
        /// `memory`, `ros2` or `iceoryx2`.
        backend: &'static str,
        /// What was being opened, as a phrase ("create topic `x`").
        operation: String,
        /// The middleware's error.
        message: String,
    },
    /// Sending failed: a command, a joint state, an event, a notification.
    #[error("{backend}: cannot {operation}: {message}")]
    Send {
        /// `memory`, `ros2` or `iceoryx2`.
        backend: &'static str,
        /// What was being sent, as a phrase.
        operation: String,
        /// The middleware's error.
        message: String,
    },
    /// Receiving failed: an estimate, statistics, efforts, a command event.
    #[error("{backend}: cannot {operation}: {message}")]
    Receive {
        /// `memory`, `ros2` or `iceoryx2`.
        backend: &'static str,
        /// What was being received, as a phrase.
        operation: String,
        /// The middleware's error.
        message: String,
    },
    /// A bounded queue had no room: the other side does not keep up.
    #[error("{backend}: cannot {operation}: the queue is full")]
    Full {
        /// `memory`, `ros2` or `iceoryx2`.
        backend: &'static str,
        /// What was being sent.
        operation: &'static str,
    },
    /// A message the wire cannot carry (a name longer than its slot, more
    /// joints than a sample holds).
    #[error("{backend}: cannot {operation}: {reason}")]
    TooLarge {
        /// `memory`, `ros2` or `iceoryx2`.
        backend: &'static str,
        /// What was being sent.
        operation: &'static str,
        /// What does not fit.
        reason: String,
    },
    /// A joint operation on a side opened for one contact.
    #[error("{backend}: cannot {operation}: this side was opened for one contact (a configuration with `contacts` opens the joints)")]
    NotJoints {
        /// `memory`, `ros2` or `iceoryx2`.
        backend: &'static str,
        /// What was asked.
        operation: &'static str,
    },
    /// The transport's feature was not compiled in.
    #[error("the {0} transport is not built in (rebuild with the `{0}` feature)")]
    NotBuiltIn(&'static str),
    /// A publisher or subscriber found no counterpart in time.
    #[error("{backend}: {what} not matched within {waited:?}")]
    NotMatched {
        /// `ros2` or `iceoryx2`.
        backend: &'static str,
        /// The topic or service.
        what: &'static str,
        /// How long it waited.
        waited: Duration,
    },
}

/// The kind of operation a middleware error came from (each backend's
/// helpers build [`TransportError`] from it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(dead_code)] // a backend may not use every kind
pub(crate) enum Operation {
    Open,
    Send,
    Receive,
}

impl TransportError {
    /// The error of a middleware operation of `kind`.
    #[allow(dead_code)] // the in-memory backend has no middleware
    pub(crate) fn middleware(
        backend: &'static str,
        kind: Operation,
        operation: impl Into<String>,
        error: impl std::fmt::Debug,
    ) -> Self {
        let (operation, message) = (operation.into(), format!("{error:?}"));
        match kind {
            Operation::Open => TransportError::Open {
                backend,
                operation,
                message,
            },
            Operation::Send => TransportError::Send {
                backend,
                operation,
                message,
            },
            Operation::Receive => TransportError::Receive {
                backend,
                operation,
                message,
            },
        }
    }
}

/// What a port counted itself (the loop adds its own counts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PortCounters {
    /// Commands the transport delivered (taken from DDS, shared memory, …).
    pub received: u64,
    /// Delivered commands discarded by a full receive queue (or lost in a
    /// full shared-memory buffer) before the loop took them.
    pub overwritten: u64,
    /// Outputs the transport's I/O failed to send.
    pub publish_failures: u64,
    /// LoopStatistics the transport failed to send.
    pub statistics_failures: u64,
    /// Received samples the recorder queue had no room for.
    pub recorder_drops: u64,
}

impl PortCounters {
    /// Add `o`'s counts.
    pub fn add(&mut self, o: &PortCounters) {
        self.received += o.received;
        self.overwritten += o.overwritten;
        self.publish_failures += o.publish_failures;
        self.statistics_failures += o.statistics_failures;
        self.recorder_drops += o.recorder_drops;
    }
}

/// [`PortCounters`] shared between a port's threads.
#[derive(Debug, Default)]
pub struct SharedCounters {
    /// Commands delivered.
    pub received: AtomicU64,
    /// Commands discarded by a full receive queue or buffer.
    pub overwritten: AtomicU64,
    /// Outputs the I/O failed to send.
    pub publish_failures: AtomicU64,
    /// LoopStatistics not sent.
    pub statistics_failures: AtomicU64,
    /// Received samples the recorder queue had no room for.
    pub recorder_drops: AtomicU64,
}

impl SharedCounters {
    /// The counts now.
    pub fn snapshot(&self) -> PortCounters {
        let l = |a: &AtomicU64| a.load(Ordering::Relaxed);
        PortCounters {
            received: l(&self.received),
            overwritten: l(&self.overwritten),
            publish_failures: l(&self.publish_failures),
            statistics_failures: l(&self.statistics_failures),
            recorder_drops: l(&self.recorder_drops),
        }
    }

    /// Count one.
    pub fn bump(a: &AtomicU64) {
        a.fetch_add(1, Ordering::Relaxed);
    }
}

/// Where a port puts what it received, for the recorder (None: not recording).
pub type RecordQueue = Option<Arc<ArrayQueue<RecordItem>>>;

/// What a node port is given besides its spec.
#[derive(Clone, Default)]
pub struct PortIo {
    /// The slot the loop writes film profiles into (backends that publish
    /// film profiles read it).
    pub film_profile: Option<Arc<FilmProfileSlot>>,
    /// The recorder's queue: the port puts every command it receives into
    /// it, as received.
    pub record: RecordQueue,
    /// Set when a peer asks for a snapshot (ROS 2 `~/snapshot`).
    pub snapshot: Option<Arc<std::sync::atomic::AtomicBool>>,
    /// Parameters while running (ROS 2 serves them; others ignore it).
    pub parameters: Option<crate::link::ParameterIo>,
    /// `use_sim_time`: the clock that ROS 2 `/clock` drives.
    pub sim_time: Option<Arc<crate::clock::ExternalClock>>,
}

/// Hand a received sample to the recorder, counting a full queue.
pub fn record_input(queue: &RecordQueue, item: RecordItem, counters: &SharedCounters) {
    if let Some(q) = queue {
        if q.push(item).is_err() {
            SharedCounters::bump(&counters.recorder_drops);
        }
    }
}

pub use crate::config::MAX_CONTACTS;

/// Every contact's effort on its joint after one step, in the configured
/// joint order (Copy: the loop hands it over without allocating).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointEfforts {
    /// The step's stamp, ns.
    pub stamp_ns: u64,
    /// Efforts used.
    pub len: usize,
    /// N (linear joint) or N·m (rotary), `gain · F_f`; `len` used.
    pub effort: [f64; MAX_CONTACTS],
}

impl JointEfforts {
    /// The efforts of a step (at most MAX_CONTACTS).
    pub fn new(stamp_ns: u64, efforts: &[f64]) -> Self {
        let len = efforts.len().min(MAX_CONTACTS);
        let mut effort = [0.0; MAX_CONTACTS];
        effort[..len].copy_from_slice(&efforts[..len]);
        Self {
            stamp_ns,
            len,
            effort,
        }
    }

    /// The efforts used.
    pub fn as_slice(&self) -> &[f64] {
        &self.effort[..self.len.min(MAX_CONTACTS)]
    }
}

/// A `sensor_msgs/JointState` as a peer sends it (velocities by joint
/// name; the peer side may allocate).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointStateCommand {
    /// The message's stamp, ns.
    pub stamp_ns: u64,
    /// Joint names.
    pub name: Vec<String>,
    /// Velocities, one per name (m/s or rad/s).
    pub velocity: Vec<f64>,
}

/// The commands a JointState carries for the configured `joints`, in
/// message order, handed to `f` with the joint's name: one per configured
/// joint it names (other joints are not this node's and are skipped); a
/// joint whose velocity is missing (arrays of different lengths) gets a
/// NaN, which the loop rejects for that contact only. The last command
/// is marked `last` (lockstep steps on it). Allocates nothing.
pub fn joint_commands<'a>(
    joints: &[String],
    stamp_ns: u64,
    names: impl Iterator<Item = &'a str>,
    velocity: &[f64],
    mut f: impl FnMut(Command, &'a str),
) {
    let mut pending: Option<(u16, f64, &'a str)> = None;
    for (i, name) in names.enumerate() {
        let Some(k) = joints.iter().position(|j| j == name) else {
            continue;
        };
        let v = velocity.get(i).copied().unwrap_or(f64::NAN);
        if let Some((contact, value, n)) = pending.take() {
            let kind = crate::msgs::CommandKind::JointVelocity {
                contact,
                last: false,
                joint: true,
            };
            f(
                Command {
                    kind,
                    value,
                    stamp_ns,
                },
                n,
            );
        }
        pending = Some((u16::try_from(k).unwrap_or(u16::MAX), v, name));
    }
    if let Some((contact, value, n)) = pending {
        let kind = crate::msgs::CommandKind::JointVelocity {
            contact,
            last: true,
            joint: true,
        };
        f(
            Command {
                kind,
                value,
                stamp_ns,
            },
            n,
        );
    }
}

/// The loop's side of a transport.
pub trait NodePort {
    /// The backend's name.
    fn name(&self) -> &'static str;
    /// Next pending command, if any (non-blocking).
    fn poll_command(&mut self) -> Result<Option<Command>, TransportError>;
    /// Publish contact `contact`'s estimate (non-blocking); false when it
    /// was dropped. With one contact (no `contacts`), contact 0 on the
    /// node's estimate topic; with several, on the per-contact output.
    fn publish_estimate(&mut self, contact: usize, e: &EstimateRecord) -> bool;
    /// Publish every contact's effort in the configured joint order (only
    /// with several contacts; non-blocking); false when dropped.
    fn publish_efforts(&mut self, stamp_ns: u64, efforts: &[f64]) -> bool;
    /// Publish loop statistics (non-blocking); false when dropped.
    fn publish_statistics(&mut self, s: &StatisticsRecord) -> bool;
    /// Block until a command may be pending or `timeout` passes.
    fn wait_for_command(&mut self, timeout: Duration) -> Result<(), TransportError>;
    /// What the port counted (commands delivered and lost, send failures).
    fn counters(&self) -> PortCounters;
}

/// The other side: sends commands, reads estimates.
pub trait PeerPort {
    /// The backend's name.
    fn name(&self) -> &'static str;
    /// Send one command.
    fn send(&mut self, c: &Command) -> Result<(), TransportError>;
    /// Next estimate, if any (non-blocking).
    fn try_recv(&mut self) -> Result<Option<EstimateRecord>, TransportError>;
    /// Next loop statistics, if any (non-blocking).
    fn try_recv_statistics(&mut self) -> Result<Option<StatisticsRecord>, TransportError>;
    /// Send a JointState (several contacts: velocities by joint name).
    fn send_joint_state(&mut self, js: &JointStateCommand) -> Result<(), TransportError>;
    /// Next joint efforts (several contacts), if any (non-blocking).
    fn try_recv_efforts(&mut self) -> Result<Option<JointEfforts>, TransportError>;
    /// Next per-contact estimate (several contacts): (contact index, estimate).
    fn try_recv_contact(&mut self) -> Result<Option<(usize, EstimateRecord)>, TransportError>;
    /// Whether the node's endpoints are matched (discovery done).
    fn is_matched(&mut self) -> bool;
}

/// Poll `peer` until it is matched (discovery) or `timeout` passes.
pub fn wait_matched(peer: &mut dyn PeerPort, timeout: Duration) -> Result<(), TransportError> {
    let start = Instant::now();
    while !peer.is_matched() {
        if start.elapsed() > timeout {
            return Err(TransportError::NotMatched {
                backend: peer.name(),
                what: "the node",
                waited: timeout,
            });
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(())
}

/// Receive the next estimate, polling until `timeout`.
pub fn recv_timeout(
    peer: &mut dyn PeerPort,
    timeout: Duration,
) -> Result<Option<EstimateRecord>, TransportError> {
    let start = Instant::now();
    let mut spins = 0u32;
    loop {
        if let Some(e) = peer.try_recv()? {
            return Ok(Some(e));
        }
        if start.elapsed() > timeout {
            return Ok(None);
        }
        // Spin briefly (sub-µs latency for shared memory), then back off.
        spins += 1;
        if spins > 2000 {
            std::thread::sleep(Duration::from_micros(50));
        } else {
            std::hint::spin_loop();
        }
    }
}

/// How to open a backend (Send; opened on the thread that uses it).
// Built once per transport at setup: the ROS 2 spec's size (its topic
// names) costs nothing there, and boxing it would only add a step to read.
#[allow(clippy::large_enum_variant)]
#[derive(Clone)]
pub enum BackendSpec {
    /// In-process queues (tests, replay).
    Memory(memory::MemoryQueues),
    #[cfg(feature = "iceoryx2")]
    /// iceoryx2 services.
    Iceoryx2(iceoryx::IceoryxSpec),
    #[cfg(feature = "ros2")]
    /// ROS 2 topics and services.
    Ros2(ros2::Ros2Spec),
}

impl BackendSpec {
    /// Whether this backend serves the node's parameters (ROS 2 does).
    pub fn serves_parameters(&self) -> bool {
        match self {
            #[cfg(feature = "ros2")]
            BackendSpec::Ros2(_) => true,
            _ => false,
        }
    }

    /// The backend's name.
    pub fn name(&self) -> &'static str {
        match self {
            BackendSpec::Memory(_) => "memory",
            #[cfg(feature = "iceoryx2")]
            BackendSpec::Iceoryx2(_) => "iceoryx2",
            #[cfg(feature = "ros2")]
            BackendSpec::Ros2(_) => "ros2",
        }
    }

    /// Open the node's side.
    pub fn open_node(&self, io: PortIo) -> Result<Box<dyn NodePort>, TransportError> {
        match self {
            BackendSpec::Memory(l) => Ok(Box::new(l.node_recording(io.record))),
            #[cfg(feature = "iceoryx2")]
            BackendSpec::Iceoryx2(s) => Ok(Box::new(iceoryx::IceoryxNode::open(s, io.record)?)),
            #[cfg(feature = "ros2")]
            BackendSpec::Ros2(s) => Ok(Box::new(ros2::Ros2Node::open(s, io)?)),
        }
    }

    /// Open a peer's side.
    pub fn open_peer(&self) -> Result<Box<dyn PeerPort>, TransportError> {
        match self {
            BackendSpec::Memory(l) => Ok(Box::new(l.peer())),
            #[cfg(feature = "iceoryx2")]
            BackendSpec::Iceoryx2(s) => Ok(Box::new(iceoryx::IceoryxPeer::open(s)?)),
            #[cfg(feature = "ros2")]
            BackendSpec::Ros2(s) => Ok(Box::new(ros2::Ros2Peer::open(s)?)),
        }
    }
}
