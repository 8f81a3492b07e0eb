//! The node's log lines for `/rosout`: a `tracing` layer that keeps events
//! at info and above in a bounded lock-free queue, from which the ROS 2
//! transport's I/O thread publishes them as `rcl_interfaces/msg/Log`.
//!
//! Each call site is rate-limited to [`PER_SITE_INTERVAL_NS`]: a warning
//! that fires every step (a deadline miss, a rejected command) reaches
//! `/rosout` at most once a second, and the next line it sends says how many
//! were suppressed. The terminal gets every line (the `fmt` layer is
//! separate). Nothing here blocks or allocates on a full queue: the line is
//! dropped and counted.

use crossbeam_queue::ArrayQueue;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use tracing::field::{Field, Visit};
use tracing::{Event, Level, Subscriber};
use tracing_subscriber::layer::Context;
use tracing_subscriber::Layer;

/// At most one line per call site in this interval.
pub const PER_SITE_INTERVAL_NS: u64 = 1_000_000_000;

/// Lines waiting for the I/O thread.
const QUEUE: usize = 256;

/// rcl's severities (`rcl_interfaces/msg/Log`).
pub mod severity {
    /// Debug.
    pub const DEBUG: u8 = 10;
    /// Information.
    pub const INFO: u8 = 20;
    /// Warning.
    pub const WARN: u8 = 30;
    /// Error.
    pub const ERROR: u8 = 40;
    /// Fatal.
    pub const FATAL: u8 = 50;
}

/// One log line.
#[derive(Debug, Clone, PartialEq)]
pub struct LogLine {
    /// When it was logged, ns.
    pub stamp_ns: u64,
    /// Severity (`severity`).
    pub level: u8,
    /// The module that logged it (`friction_node::node::timer`).
    pub target: String,
    /// The message.
    pub message: String,
    /// The source file.
    pub file: String,
    /// The source line.
    pub line: u32,
}

struct Shared {
    queue: ArrayQueue<LogLine>,
    enabled: AtomicBool,
    dropped: AtomicU64,
    /// Per call site: (last sent, suppressed since).
    sites: Mutex<HashMap<usize, (u64, u64)>>,
}

fn shared() -> &'static Shared {
    static S: OnceLock<Shared> = OnceLock::new();
    S.get_or_init(|| Shared {
        queue: ArrayQueue::new(QUEUE),
        enabled: AtomicBool::new(true),
        dropped: AtomicU64::new(0),
        sites: Mutex::new(HashMap::new()),
    })
}

/// The layer; `enabled` false (`--disable-rosout-logs`) keeps nothing.
pub fn layer(enabled: bool) -> RosoutLayer {
    shared().enabled.store(enabled, Ordering::Relaxed);
    RosoutLayer
}

/// Take the lines waiting (for the I/O thread).
pub fn drain(mut f: impl FnMut(LogLine)) {
    while let Some(l) = shared().queue.pop() {
        f(l);
    }
}

/// Lines dropped because the queue was full.
pub fn dropped() -> u64 {
    shared().dropped.load(Ordering::Relaxed)
}

/// See [`layer`].
pub struct RosoutLayer;

struct MessageVisitor(String);

impl Visit for MessageVisitor {
    fn record_debug(&mut self, field: &Field, value: &dyn std::fmt::Debug) {
        if field.name() == "message" {
            self.0 = format!("{value:?}");
        } else {
            self.0 += &format!(" {}={value:?}", field.name());
        }
    }
    fn record_str(&mut self, field: &Field, value: &str) {
        if field.name() == "message" {
            self.0 = value.to_string();
        } else {
            self.0 += &format!(" {}={value}", field.name());
        }
    }
}

fn level_of(l: &Level) -> u8 {
    match *l {
        Level::ERROR => severity::ERROR,
        Level::WARN => severity::WARN,
        Level::INFO => severity::INFO,
        _ => severity::DEBUG,
    }
}

impl<S: Subscriber> Layer<S> for RosoutLayer {
    fn on_event(&self, event: &Event<'_>, _ctx: Context<'_, S>) {
        let sh = shared();
        let meta = event.metadata();
        if !sh.enabled.load(Ordering::Relaxed) || *meta.level() > Level::INFO {
            return;
        }
        // Chatter of the DDS stack is not the node's.
        if meta.target().starts_with("rustdds") || meta.target().starts_with("ros2_client") {
            return;
        }
        let now = crate::clock::system_wall_ns();
        let site = meta as *const _ as usize;
        let suppressed = {
            let mut sites = sh.sites.lock().unwrap_or_else(|p| p.into_inner());
            let e = sites.entry(site).or_insert((0, 0));
            if e.0 != 0 && now.saturating_sub(e.0) < PER_SITE_INTERVAL_NS {
                e.1 += 1;
                return;
            }
            let s = e.1;
            *e = (now, 0);
            s
        };
        let mut v = MessageVisitor(String::new());
        event.record(&mut v);
        if suppressed > 0 {
            v.0 += &format!(" ({suppressed} more suppressed in the last second)");
        }
        let line = LogLine {
            stamp_ns: now,
            level: level_of(meta.level()),
            target: meta.target().to_string(),
            message: v.0,
            file: meta.file().unwrap_or("").to_string(),
            line: meta.line().unwrap_or(0),
        };
        if sh.queue.push(line).is_err() {
            sh.dropped.fetch_add(1, Ordering::Relaxed);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracing_subscriber::layer::SubscriberExt;

    #[test]
    fn info_and_above_reach_the_queue_once_a_second_per_site_with_a_suppressed_count() {
        let sub = tracing_subscriber::registry().with(layer(true));
        tracing::subscriber::with_default(sub, || {
            drain(|_| {});
            tracing::debug!("not for rosout");
            for k in 0..5 {
                tracing::warn!(step = k, "deadline missed");
            }
            tracing::info!("started");
            let mut lines = Vec::new();
            drain(|l| lines.push(l));
            assert_eq!(lines.len(), 2, "{lines:?}");
            assert_eq!(lines[0].level, severity::WARN);
            assert!(lines[0].message.starts_with("deadline missed step=0"));
            assert_eq!(lines[1].level, severity::INFO);
            assert_eq!(lines[1].message, "started");
            assert!(lines[0].target.contains("rosout"));
        });
    }
}
