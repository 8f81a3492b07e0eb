//! In-memory transport: bounded lock-free queues between threads of one
//! process. The reference backend of the conformance suite, and the node's
//! transport when it is embedded in another program.
//!
//! With several contacts ([`MemoryQueues::for_plan`]) the peer's
//! JointStates are resolved by joint name into per-contact commands, and
//! the node's outputs are per-contact estimates and joint efforts.

use super::{
    joint_commands, record_input, JointEfforts, JointStateCommand, NodePort, PeerPort,
    PortCounters, RecordQueue, SharedCounters, TransportError,
};
use crate::clock::system_wall_ns;
use crate::config::OutputPlan;
use crate::link::RecordItem;
use crate::msgs::{Command, EstimateRecord, StatisticsRecord};
use crossbeam_queue::ArrayQueue;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The bounded queues of both directions between a node and its peers in
/// one process (clone it to hand it to threads; not `crate::link`, which
/// holds what the loop shares with every backend).
#[derive(Clone)]
pub struct MemoryQueues {
    commands: Arc<ArrayQueue<Command>>,
    estimates: Arc<ArrayQueue<EstimateRecord>>,
    statistics: Arc<ArrayQueue<StatisticsRecord>>,
    /// One contact, or joints (their configured order).
    plan: OutputPlan,
    contact_estimates: Arc<ArrayQueue<(usize, EstimateRecord)>>,
    efforts: Arc<ArrayQueue<JointEfforts>>,
}

impl MemoryQueues {
    /// A link whose queues hold `capacity` items each.
    pub fn new(capacity: usize) -> Self {
        Self {
            commands: Arc::new(ArrayQueue::new(capacity)),
            estimates: Arc::new(ArrayQueue::new(capacity)),
            statistics: Arc::new(ArrayQueue::new(capacity.min(64))),
            plan: OutputPlan::OneContact,
            contact_estimates: Arc::new(ArrayQueue::new(1)),
            efforts: Arc::new(ArrayQueue::new(1)),
        }
    }

    /// The queues of `plan`: for joints, per-contact estimates (`capacity`
    /// each contact) and efforts; for one contact, unchanged.
    pub fn for_plan(mut self, plan: &OutputPlan) -> Self {
        let OutputPlan::Joints(joints) = plan else {
            return self;
        };
        let capacity = self.estimates.capacity();
        self.plan = plan.clone();
        self.contact_estimates = Arc::new(ArrayQueue::new(
            capacity.saturating_mul(joints.len().max(1)),
        ));
        self.efforts = Arc::new(ArrayQueue::new(capacity));
        self
    }

    /// The node's side.
    pub fn node(&self) -> MemoryNode {
        self.node_recording(None)
    }

    /// The loop's side, handing every command it delivers to `record`.
    pub fn node_recording(&self, record: RecordQueue) -> MemoryNode {
        MemoryNode {
            link: self.clone(),
            record,
            counters: SharedCounters::default(),
            clock: None,
        }
    }

    /// The peer's side.
    pub fn peer(&self) -> MemoryPeer {
        MemoryPeer { link: self.clone() }
    }

    /// Statistics published so far (drains them).
    pub fn take_statistics(&self) -> Vec<StatisticsRecord> {
        std::iter::from_fn(|| self.statistics.pop()).collect()
    }
}

/// The loop's side.
pub struct MemoryNode {
    link: MemoryQueues,
    record: RecordQueue,
    counters: SharedCounters,
    /// Stamps received commands for the recorder (default: the system's).
    clock: Option<std::sync::Arc<dyn crate::clock::Clock>>,
}

impl MemoryNode {
    /// Stamp received commands with this clock's wall time (tests on
    /// simulated time).
    pub fn with_clock(mut self, clock: std::sync::Arc<dyn crate::clock::Clock>) -> Self {
        self.clock = Some(clock);
        self
    }
}

impl NodePort for MemoryNode {
    fn name(&self) -> &'static str {
        "memory"
    }

    fn poll_command(&mut self) -> Result<Option<Command>, TransportError> {
        let c = self.link.commands.pop();
        if let Some(command) = c {
            SharedCounters::bump(&self.counters.received);
            if self.record.is_some() {
                let received_ns = self
                    .clock
                    .as_ref()
                    .map_or_else(system_wall_ns, |c| c.wall_ns());
                let item = RecordItem::Command {
                    command,
                    received_ns,
                };
                record_input(&self.record, item, &self.counters);
            }
        }
        Ok(c)
    }

    fn publish_estimate(&mut self, contact: usize, e: &EstimateRecord) -> bool {
        // A full queue is a drop, which the loop counts.
        if !self.link.plan.by_joint() {
            self.link.estimates.push(*e).is_ok()
        } else {
            self.link.contact_estimates.push((contact, *e)).is_ok()
        }
    }

    fn publish_efforts(&mut self, stamp_ns: u64, efforts: &[f64]) -> bool {
        self.link
            .efforts
            .push(JointEfforts::new(stamp_ns, efforts))
            .is_ok()
    }

    fn publish_statistics(&mut self, s: &StatisticsRecord) -> bool {
        // The newest statistics replace the oldest when nobody reads them.
        if self.link.statistics.force_push(*s).is_some() {
            SharedCounters::bump(&self.counters.statistics_failures);
        }
        true
    }

    fn counters(&self) -> PortCounters {
        self.counters.snapshot()
    }

    fn wait_for_command(&mut self, timeout: Duration) -> Result<(), TransportError> {
        let start = Instant::now();
        let mut spins = 0u32;
        while self.link.commands.is_empty() && start.elapsed() < timeout {
            spins += 1;
            if spins > 1000 {
                std::thread::sleep(Duration::from_micros(20));
            } else {
                std::hint::spin_loop();
            }
        }
        Ok(())
    }
}

/// The peer's side.
pub struct MemoryPeer {
    link: MemoryQueues,
}

impl MemoryPeer {
    /// Ok when the link was opened for joints (a configuration with
    /// `contacts`), else the error of `operation`.
    fn joints(&self, operation: &'static str) -> Result<(), TransportError> {
        if !self.link.plan.by_joint() {
            return Err(TransportError::NotJoints {
                backend: "memory",
                operation,
            });
        }
        Ok(())
    }
}

impl PeerPort for MemoryPeer {
    fn name(&self) -> &'static str {
        "memory"
    }

    fn send(&mut self, c: &Command) -> Result<(), TransportError> {
        self.link
            .commands
            .push(*c)
            .map_err(|_| TransportError::Full {
                backend: "memory",
                operation: "send a command",
            })
    }

    fn try_recv(&mut self) -> Result<Option<EstimateRecord>, TransportError> {
        Ok(self.link.estimates.pop())
    }

    fn try_recv_statistics(&mut self) -> Result<Option<StatisticsRecord>, TransportError> {
        Ok(self.link.statistics.pop())
    }

    fn send_joint_state(&mut self, js: &JointStateCommand) -> Result<(), TransportError> {
        self.joints("send a JointState")?;
        let mut full = false;
        let names = js.name.iter().map(String::as_str);
        joint_commands(
            self.link.plan.joints(),
            js.stamp_ns,
            names,
            &js.velocity,
            |c, _| {
                full |= self.link.commands.push(c).is_err();
            },
        );
        if full {
            return Err(TransportError::Full {
                backend: "memory",
                operation: "send a JointState",
            });
        }
        Ok(())
    }

    fn try_recv_efforts(&mut self) -> Result<Option<JointEfforts>, TransportError> {
        self.joints("receive joint efforts")?;
        Ok(self.link.efforts.pop())
    }

    fn try_recv_contact(&mut self) -> Result<Option<(usize, EstimateRecord)>, TransportError> {
        self.joints("receive a contact estimate")?;
        Ok(self.link.contact_estimates.pop())
    }

    fn is_matched(&mut self) -> bool {
        true
    }
}
