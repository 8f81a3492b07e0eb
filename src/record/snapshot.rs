//! The snapshot ring: the last `recording.snapshot_s` seconds of every
//! recorded topic, in memory, written as one MCAP file on request.
//!
//! Entries older than the window (by log time) leave the ring as new ones
//! arrive; a byte bound (`recording.snapshot_max_bytes`) caps it whatever
//! the rates. A snapshot copies the ring and is written on a thread of its
//! own; the recorder goes on.

use super::bag_writer::BagWriter;
use super::entry::Entry;
use super::WriteError;
use crate::config::topics::TopicNames;
use crate::config::Config;
use std::collections::{BTreeMap, VecDeque};
use std::path::PathBuf;

/// The ring.
pub struct Ring {
    window_ns: u64,
    max_bytes: usize,
    entries: VecDeque<Entry>,
    bytes: usize,
}

impl Ring {
    /// A ring of the last `window_s` seconds, at most `max_bytes` in memory.
    pub fn new(window_s: u64, max_bytes: u64) -> Self {
        Self {
            window_ns: window_s.saturating_mul(1_000_000_000),
            max_bytes: usize::try_from(max_bytes).unwrap_or(usize::MAX),
            entries: VecDeque::new(),
            bytes: 0,
        }
    }

    /// Add an entry; the oldest leave when the window or the bound is exceeded.
    pub fn push(&mut self, e: Entry) {
        let newest = e.log_ns;
        self.bytes += e.footprint();
        self.entries.push_back(e);
        while let Some(front) = self.entries.front() {
            let old = newest.saturating_sub(front.log_ns) > self.window_ns;
            if old || self.bytes > self.max_bytes {
                self.bytes -= front.footprint();
                self.entries.pop_front();
            } else {
                break;
            }
        }
    }

    /// Bytes held now.
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// The time span held, ns.
    pub fn span_ns(&self) -> u64 {
        match (self.entries.front(), self.entries.back()) {
            (Some(a), Some(b)) => b.log_ns.saturating_sub(a.log_ns),
            _ => 0,
        }
    }

    /// A copy of the contents, in order.
    pub fn contents(&self) -> Vec<Entry> {
        self.entries.iter().cloned().collect()
    }
}

/// Write `entries` as one MCAP file at `path` (sorted by log time).
pub fn write(
    path: PathBuf,
    config: &Config,
    names: &TopicNames,
    mut entries: Vec<Entry>,
    now_ns: u64,
) -> Result<(PathBuf, u64, u64), WriteError> {
    entries.sort_by_key(|e| e.log_ns);
    let span = match (entries.first(), entries.last()) {
        (Some(a), Some(b)) => b.log_ns - a.log_ns,
        _ => 0,
    };
    let mut extra = BTreeMap::new();
    extra.insert("snapshot_span_ns".to_string(), span.to_string());
    let tmp = crate::output::tmp_sibling(&path);
    let mut w = BagWriter::create(&tmp, config, names, extra, now_ns)
        .map_err(|e| WriteError::Open(Box::new(e)))?;
    let result = entries
        .iter()
        .try_for_each(|e| w.write_entry(e))
        .and_then(|_| w.finish());
    match result {
        Ok(bytes) => {
            let moved = std::fs::rename(&tmp, &path);
            crate::output::forget_temporary(&tmp);
            moved?;
            Ok((path, span, bytes))
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            crate::output::forget_temporary(&tmp);
            Err(e)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::entry::TopicId;

    fn entry(t_ms: u64) -> Entry {
        Entry {
            topic: TopicId::Friction,
            log_ns: t_ms * 1_000_000,
            publish_ns: t_ms * 1_000_000,
            data: vec![0; 100],
        }
    }

    #[test]
    fn the_ring_keeps_the_last_window_and_respects_its_byte_bound() {
        let mut r = Ring::new(2, 1 << 30);
        for t in 0..10_000 {
            r.push(entry(t));
        }
        assert_eq!(r.span_ns(), 2_000_000_000);
        assert_eq!(r.contents().len(), 2001);
        let mut small = Ring::new(3600, 10 * entry(0).footprint() as u64);
        for t in 0..100 {
            small.push(entry(t));
        }
        assert_eq!(small.contents().len(), 10);
        assert!(small.bytes() <= 10 * entry(0).footprint());
    }
}
