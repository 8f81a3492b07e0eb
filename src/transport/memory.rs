//! In-memory transport: bounded lock-free queues between threads of one
//! process. The reference backend of the conformance suite, and the node's
//! transport when it is embedded in another program.

use super::{NodePort, PeerPort, TransportError};
use crate::msgs::{Command, EstimateRecord, StatisticsRecord};
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
        MemoryNode { link: self.clone() }
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
}

impl NodePort for MemoryNode {
    fn name(&self) -> &'static str {
        "memory"
    }

    fn poll_command(&mut self) -> Result<Option<Command>, TransportError> {
        Ok(self.link.commands.pop())
    }

    fn publish_estimate(&mut self, e: &EstimateRecord) -> bool {
        self.link.estimates.push(*e).is_ok()
    }

    fn publish_statistics(&mut self, s: &StatisticsRecord) -> bool {
        self.link.statistics.force_push(*s);
        true
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

    fn is_matched(&mut self) -> bool {
        true
    }
}
