//! In-memory transport: bounded lock-free queues between threads of one
//! process. The reference backend of the conformance suite, and the node's
//! transport when it is embedded in another program.

use super::{
    record_input, NodePort, PeerPort, PortCounters, RecordQueue, SharedCounters, TransportError,
};
use crate::clock::system_wall_ns;
use crate::msgs::{Command, EstimateRecord, RecordItem, StatisticsRecord};
use crossbeam_queue::ArrayQueue;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Both directions of an in-memory link (clone it to hand it to threads).
#[derive(Clone)]
pub struct MemoryLink {
    commands: Arc<ArrayQueue<Command>>,
    estimates: Arc<ArrayQueue<EstimateRecord>>,
    statistics: Arc<ArrayQueue<StatisticsRecord>>,
}

impl MemoryLink {
    pub fn new(capacity: usize) -> Self {
        Self {
            commands: Arc::new(ArrayQueue::new(capacity)),
            estimates: Arc::new(ArrayQueue::new(capacity)),
            statistics: Arc::new(ArrayQueue::new(capacity.min(64))),
        }
    }

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
    link: MemoryLink,
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

    fn publish_estimate(&mut self, e: &EstimateRecord) -> bool {
        // A full queue is a drop, which the loop counts.
        self.link.estimates.push(*e).is_ok()
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
    link: MemoryLink,
}

impl PeerPort for MemoryPeer {
    fn name(&self) -> &'static str {
        "memory"
    }

    fn send(&mut self, c: &Command) -> Result<(), TransportError> {
        self.link.commands.push(*c).map_err(|_| {
            TransportError::backend("memory", "send a command", "the command queue is full")
        })
    }

    fn try_recv(&mut self) -> Result<Option<EstimateRecord>, TransportError> {
        Ok(self.link.estimates.pop())
    }

    fn try_recv_statistics(&mut self) -> Result<Option<StatisticsRecord>, TransportError> {
        Ok(self.link.statistics.pop())
    }

    fn is_matched(&mut self) -> bool {
        true
    }
}
