//! MCAP recording in the ROS 2 profile (what rosbag2, Foxglove and
//! PlotJuggler read), for months of uptime.
//!
//! - header profile `ros2`; channels encoded `cdr` (4-byte encapsulation
//!   header, little endian); schemas `ros2msg` built from `msg/*.msg` and the
//!   standard definitions, each dependency after a line of 80 `=`;
//! - every channel carries `offered_qos_profiles` (rosbag2's YAML);
//! - the commands the node received (inputs), each ROS 2 sample byte for
//!   byte as it came off the wire (other transports' commands encoded as the
//!   configured command type), and everything it published (outputs), on the
//!   node's resolved ROS topic names; `log_time` is the wall clock when
//!   received or recorded, `publish_time` the publisher's stamp;
//! - the full resolved configuration as the metadata record `friction_node`
//!   (key `config_yaml`) in every file.
//!
//! Output: one file, or with `recording.split.*` a rosbag2 directory of
//! split files with `metadata.yaml` and an optional disk budget
//! (`split.rs`); memory is bounded by the split size, not the recorded time.
//! With `recording.snapshot_s` the last seconds of every topic stay in a
//! bounded ring and are written as one file on request (`snapshot.rs`).
//!
//! The recorder runs on its own thread, fed by a bounded lock-free queue: the
//! loop never waits for the disk. Chunks are closed at least every second, so
//! a crash loses at most the open chunk. A write error (disk full, …) stops
//! the recording, never the loop, and is reported; a split recording resumes
//! in a new file when a file can be created again.
//!
//! | file | content |
//! |---|---|
//! | `mod.rs` | [`Recorder`]: the thread, its queue, what it reports |
//! | `entry.rs` | items to serialized messages on the node's topics |
//! | `bag_writer.rs` | one MCAP file |
//! | `split.rs` | a directory of split files, `metadata.yaml`, the budget |
//! | `snapshot.rs` | the snapshot ring |

mod bag_writer;
pub mod entry;
pub mod snapshot;
mod split;

pub use bag_writer::{offered_qos_yaml, BagWriter};
pub use split::SplitDir;

use crate::clock::Clock;
use crate::config::topics::TopicNames;
use crate::config::Config;
use crate::link::FilmProfileSlot;
use crate::link::RecordItem;
use crate::link::RecorderCounters;
use crate::msgs::Note;
use crossbeam_queue::ArrayQueue;
use entry::{Encoder, Entry, TopicId};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Errors of the recorder layer.
#[derive(Debug, thiserror::Error)]
pub enum RecorderError {
    /// The file could not be created.
    #[error("cannot create recording {}: {cause}", path.display())]
    Create {
        /// The recording.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// The MCAP writer refused to start.
    #[error("recording {}: {message}", path.display())]
    Mcap {
        /// The recording.
        path: PathBuf,
        /// The MCAP writer's error.
        message: String,
    },
    /// A split recording's directory is not usable.
    #[error("recording directory {}: {message}", path.display())]
    Directory {
        /// The directory.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A recording's name that is neither an `.mcap` file nor a split
    /// recording's directory: nothing is written (an existing file of that
    /// name, a CSV say, is never overwritten with MCAP bytes).
    #[error("recording {}: a recording is an .mcap file (or, with recording.split.*, a directory of split files); name it NAME.mcap", path.display())]
    Name {
        /// The name given.
        path: PathBuf,
    },
}

/// Whether `path` can hold one recording file: a name ending in `.mcap`
/// (any case), or a device such as `/dev/null`.
pub fn is_recording_name(path: &Path) -> bool {
    crate::output::is_special(path)
        || path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// A write into a recording failed (the recording stops; what is on disk
/// stays readable up to the last chunk).
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The MCAP writer (an I/O error underneath, or a full disk).
    #[error(transparent)]
    Mcap(#[from] mcap::McapError),
    /// An I/O error beside the writer (renaming a finished file).
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A message did not serialize as CDR.
    #[error("cannot encode {topic:?} as CDR: {error}")]
    Encode {
        /// The topic the message was for.
        topic: TopicId,
        /// The codec's error.
        #[source]
        error: crate::msgs::CdrError,
    },
    /// An item for a contact the recording does not have.
    #[error("{what} of contact {contact}, but the recording has {contacts} contacts")]
    NoSuchContact {
        /// What the item was.
        what: &'static str,
        /// The contact it named.
        contact: u16,
        /// Contacts in the recording.
        contacts: usize,
    },
    /// An entry on a topic this recording did not declare.
    #[error("{0:?} is not a topic of this recording")]
    UnknownTopic(TopicId),
    /// A file beside the messages (`metadata.yaml`) could not be written.
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
    /// The next file of a split recording (or a snapshot) could not be
    /// created.
    #[error(transparent)]
    Open(Box<RecorderError>),
    /// The recording was already closed.
    #[error("the recording is already finished")]
    Finished,
}

/// What a finished recording reports.
#[derive(Debug, Clone, Default)]
pub struct RecorderReport {
    /// The file or directory (None: snapshots only).
    pub path: Option<PathBuf>,
    /// Messages written.
    pub messages: u64,
    /// Bytes on disk.
    pub bytes: u64,
    /// Files written (1 without splitting).
    pub files: u64,
    /// Files deleted to keep to the budget.
    pub files_deleted: u64,
    /// Messages lost after a write error.
    pub lost: u64,
    /// Snapshot files written.
    pub snapshots: Vec<PathBuf>,
    /// Set when writing failed (the loop went on; later outputs were lost).
    pub error: Option<String>,
}

/// Where entries go.
enum Output {
    None,
    /// One file (None once writing failed).
    Single(Option<Box<BagWriter>>, PathBuf),
    Split(Box<SplitDir>),
}

/// What to record and where.
#[derive(Debug, Clone, Default)]
pub struct RecordPlan {
    /// File, or directory when `recording.split.*` is set; None: snapshots only.
    pub path: Option<PathBuf>,
    /// Where snapshot files go.
    pub snapshot_dir: PathBuf,
}

/// A running recorder.
pub struct Recorder {
    queue: Arc<ArrayQueue<RecordItem>>,
    stop: Arc<AtomicBool>,
    snapshot: Arc<AtomicBool>,
    counters: Arc<RecorderCounters>,
    thread: Option<std::thread::JoinHandle<RecorderReport>>,
    path: Option<PathBuf>,
}

/// A snapshot being written: (file, span ns, bytes) or an error.
type SnapshotThread = std::thread::JoinHandle<Result<(PathBuf, u64, u64), WriteError>>;

/// The recorder thread's state.
struct Writer {
    out: Output,
    encoder: Encoder,
    ring: Option<snapshot::Ring>,
    config: Config,
    names: TopicNames,
    plan: RecordPlan,
    counters: Arc<RecorderCounters>,
    clock: Arc<dyn Clock>,
    error: Option<String>,
    snapshots: Vec<PathBuf>,
    snapshot_threads: Vec<SnapshotThread>,
    scratch: Vec<Entry>,
}

impl Recorder {
    /// Create the file or directory (errors here mean nothing was
    /// recorded; the node reports them before its loop starts) and start
    /// the writer thread.
    pub fn start(
        plan: RecordPlan,
        config: &Config,
        names: &TopicNames,
        film_profile: Option<Arc<FilmProfileSlot>>,
        clock: Arc<dyn Clock>,
    ) -> Result<Self, RecorderError> {
        let now = clock.wall_ns();
        if let Some(p) = &plan.path {
            if !config.recording.splits() && !is_recording_name(p) {
                return Err(RecorderError::Name { path: p.clone() });
            }
        }
        let out = match &plan.path {
            None => Output::None,
            Some(p) if config.recording.splits() => {
                Output::Split(Box::new(SplitDir::create(p, config, names, now)?))
            }
            Some(p) => Output::Single(
                Some(Box::new(BagWriter::create(
                    p,
                    config,
                    names,
                    BTreeMap::new(),
                    now,
                )?)),
                p.clone(),
            ),
        };
        let counters = Arc::new(RecorderCounters::default());
        if plan.path.is_some() {
            counters.files.store(1, Ordering::Relaxed);
        }
        let queue = Arc::new(ArrayQueue::new(config.node.queue_capacity));
        let stop = Arc::new(AtomicBool::new(false));
        let snapshot = Arc::new(AtomicBool::new(false));
        let r = &config.recording;
        let w = Writer {
            out,
            encoder: Encoder::new(config),
            ring: (r.snapshot_s > 0)
                .then(|| snapshot::Ring::new(r.snapshot_s, r.snapshot_max_bytes)),
            config: config.clone(),
            names: names.clone(),
            plan: plan.clone(),
            counters: counters.clone(),
            clock,
            error: None,
            snapshots: Vec::new(),
            snapshot_threads: Vec::new(),
            scratch: Vec::new(),
        };
        let (q, s, snap) = (queue.clone(), stop.clone(), snapshot.clone());
        let thread = std::thread::Builder::new()
            .name("mcap-recorder".into())
            .spawn(move || w.run(q, s, snap, film_profile))
            .map_err(|cause| RecorderError::Create {
                path: plan.path.clone().unwrap_or_default(),
                cause,
            })?;
        Ok(Self {
            queue,
            stop,
            snapshot,
            counters,
            thread: Some(thread),
            path: plan.path,
        })
    }

    /// The queue the loop and the transports push into.
    pub fn queue(&self) -> Arc<ArrayQueue<RecordItem>> {
        self.queue.clone()
    }

    /// The counters the loop reports in its statistics.
    pub fn counters(&self) -> Arc<RecorderCounters> {
        self.counters.clone()
    }

    /// Set to ask for a snapshot (SIGUSR1, `~/snapshot`).
    pub fn snapshot_request(&self) -> Arc<AtomicBool> {
        self.snapshot.clone()
    }

    /// The file or directory recorded into (None: snapshots only).
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.counters.messages.load(Ordering::Relaxed)
    }

    /// Write what is queued, finalise the files and report.
    pub fn finish(mut self) -> RecorderReport {
        self.stop.store(true, Ordering::Release);
        let report = self.thread.take().and_then(|t| t.join().ok());
        report.unwrap_or_else(|| RecorderReport {
            path: self.path.clone(),
            error: Some("the recorder thread panicked".into()),
            ..Default::default()
        })
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Writer {
    fn fail(&mut self, error: WriteError) {
        let message = error.to_string();
        if let Output::Single(w @ Some(_), path) = &mut self.out {
            tracing::error!(
                "recording {} failed: {message}; the node goes on without recording",
                path.display()
            );
            // Keep what is on disk readable up to the last complete chunk.
            if let Some(mut b) = w.take() {
                let _ = b.flush();
            }
            self.error.get_or_insert(message);
        }
    }

    fn write(&mut self, e: Entry) {
        match &mut self.out {
            Output::None => {}
            Output::Single(Some(w), _) => match w.write_entry(&e) {
                Ok(()) => {
                    self.counters.messages.fetch_add(1, Ordering::Relaxed);
                }
                Err(m) => {
                    self.counters.lost.fetch_add(1, Ordering::Relaxed);
                    self.fail(m);
                }
            },
            Output::Single(None, _) => {
                self.counters.lost.fetch_add(1, Ordering::Relaxed);
            }
            Output::Split(d) => {
                d.write(&e, &self.counters);
                if let Some(m) = d.failed.clone() {
                    self.error.get_or_insert(m);
                }
            }
        }
        if let Some(r) = self.ring.as_mut() {
            r.push(e);
        }
    }

    fn item(&mut self, item: &RecordItem) {
        let mut out = std::mem::take(&mut self.scratch);
        out.clear();
        match self.encoder.encode(item, &mut out) {
            Ok(()) => {
                for e in out.drain(..) {
                    self.write(e);
                }
            }
            Err(m) => tracing::error!("recording: cannot encode a message: {m}"),
        }
        self.scratch = out;
    }

    fn flush(&mut self) {
        match &mut self.out {
            Output::Single(Some(w), _) => {
                if let Err(m) = w.flush() {
                    self.fail(m);
                }
            }
            Output::Split(d) => d.flush(),
            _ => {}
        }
    }

    /// Start writing a snapshot of the ring on a thread of its own.
    fn snapshot(&mut self) {
        let Some(ring) = &self.ring else {
            tracing::warn!("a snapshot was asked for but recording.snapshot_s is 0");
            return;
        };
        let now = self.clock.wall_ns();
        let path = self.plan.snapshot_dir.join(format!(
            "friction_node_snapshot_{}.mcap",
            crate::clock::utc_stamp(now)
        ));
        let (config, names, entries) = (self.config.clone(), self.names.clone(), ring.contents());
        self.snapshot_threads.push(std::thread::spawn(move || {
            if let Some(d) = path.parent() {
                std::fs::create_dir_all(d)?;
            }
            snapshot::write(path, &config, &names, entries, now)
        }));
    }

    fn reap_snapshots(&mut self, wait: bool) {
        let (done, running): (Vec<_>, Vec<_>) = self
            .snapshot_threads
            .drain(..)
            .partition(|h| wait || h.is_finished());
        self.snapshot_threads = running;
        for h in done {
            match h.join() {
                Ok(Ok((path, span, bytes))) => {
                    let span_s = span as f64 / 1e9;
                    tracing::warn!(
                        "snapshot {}: {span_s:.3} s of every topic, {bytes} bytes",
                        path.display()
                    );
                    self.counters.snapshots.fetch_add(1, Ordering::Relaxed);
                    if let Ok(mut slot) = self.counters.last_snapshot.lock() {
                        *slot = (Note::new(&path.display().to_string()), span_s);
                    }
                    self.snapshots.push(path);
                }
                Ok(Err(e)) => tracing::error!("snapshot failed: {e}"),
                Err(_) => tracing::error!("the snapshot thread panicked"),
            }
        }
    }

    fn run(
        mut self,
        queue: Arc<ArrayQueue<RecordItem>>,
        stop: Arc<AtomicBool>,
        snapshot: Arc<AtomicBool>,
        film_profile: Option<Arc<FilmProfileSlot>>,
    ) -> RecorderReport {
        let mut seen = 0u64;
        let mut last_flush = Instant::now();
        loop {
            let stopping = stop.load(Ordering::Acquire);
            let mut idle = true;
            while let Some(item) = queue.pop() {
                idle = false;
                self.item(&item);
            }
            if let Some(slot) = &film_profile {
                if let Some(p) = slot.read_if_newer(&mut seen) {
                    // Logged at its step's stamp, like the step's estimate.
                    let at = p.stamp_ns;
                    match self.encoder.film_profile(p, at) {
                        Ok(e) => self.write(e),
                        Err(m) => tracing::error!("recording: cannot encode a film profile: {m}"),
                    }
                }
            }
            if snapshot.swap(false, Ordering::AcqRel) {
                self.snapshot();
            }
            self.reap_snapshots(false);
            if last_flush.elapsed() > Duration::from_secs(1) {
                // Close the open chunk: a crash loses at most a second.
                self.flush();
                last_flush = Instant::now();
            }
            if stopping && queue.is_empty() {
                break;
            }
            if idle {
                std::thread::sleep(Duration::from_millis(2));
            }
        }
        self.reap_snapshots(true);
        self.finish()
    }

    fn finish(mut self) -> RecorderReport {
        let mut report = RecorderReport {
            path: self.plan.path.clone(),
            ..Default::default()
        };
        match std::mem::replace(&mut self.out, Output::None) {
            Output::None => {}
            Output::Single(Some(w), path) => match w.finish() {
                Ok(bytes) => report.bytes = bytes,
                Err(e) => {
                    self.error.get_or_insert(e.to_string());
                    report.bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
                }
            },
            Output::Single(None, path) => {
                report.bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
            }
            Output::Split(d) => match d.finish() {
                Ok((_, bytes)) => report.bytes = bytes,
                Err(e) => {
                    self.error.get_or_insert(e.to_string());
                }
            },
        }
        let c = &self.counters;
        report.messages = c.messages.load(Ordering::Relaxed);
        report.files = c.files.load(Ordering::Relaxed);
        report.files_deleted = c.files_deleted.load(Ordering::Relaxed);
        report.lost = c.lost.load(Ordering::Relaxed);
        report.snapshots = self.snapshots;
        report.error = self.error;
        report
    }
}
