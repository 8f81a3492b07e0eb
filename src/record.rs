//! MCAP recording in the ROS 2 profile (what rosbag2, Foxglove and
//! PlotJuggler read).
//!
//! - header profile `ros2`; channels encoded `cdr` (4-byte encapsulation
//!   header, little endian); schemas `ros2msg` built from `msg/*.msg` and the
//!   standard definitions, each dependency after a line of 80 `=`;
//! - every channel carries `offered_qos_profiles` (rosbag2's YAML);
//! - the commands the node received (inputs) and everything it published
//!   (outputs), on the node's resolved ROS topic names; `log_time` is the wall
//!   clock when recorded, `publish_time` the message's stamp;
//! - the full resolved configuration as the metadata record `friction_node`
//!   (key `config_yaml`).
//!
//! The recorder runs on its own thread, fed by a bounded lock-free queue: the
//! loop never waits for the disk. Chunks are closed at least every second, so
//! a crash loses at most the open chunk. A write error (disk full, …) stops
//! the recording, never the loop, and is reported.

use crate::config::{CommandType, Compression, Config, QosConfig, Reliability};
use crate::msgs::{
    self, Command, CommandKind, Float64, Header, MsgType, RecordItem, Time, TwistStamped,
};
use crate::transport::names::TopicNames;
use crate::transport::ProfileSlot;
use crossbeam_queue::ArrayQueue;
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Errors of the recorder layer.
#[derive(Debug, thiserror::Error)]
pub enum RecorderError {
    #[error("cannot create recording {}: {source}", path.display())]
    Create {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("recording {}: {message}", path.display())]
    Mcap { path: PathBuf, message: String },
}

/// What a finished recording reports.
#[derive(Debug, Clone, Default)]
pub struct RecorderReport {
    pub path: PathBuf,
    pub messages: u64,
    pub bytes: u64,
    /// Set when writing failed (the loop went on; later outputs were lost).
    pub error: Option<String>,
}

/// rosbag2's `offered_qos_profiles` metadata for one publisher.
pub fn offered_qos_yaml(q: &QosConfig) -> String {
    // rosbag2 enums: history 1 keep_last; reliability 1 reliable, 2 best
    // effort; durability 1 transient local, 2 volatile; liveliness 1
    // automatic.
    let reliability = match q.reliability {
        Reliability::Reliable => 1,
        Reliability::BestEffort => 2,
    };
    let durability = match q.durability {
        crate::config::Durability::TransientLocal => 1,
        crate::config::Durability::Volatile => 2,
    };
    let inf = "    sec: 2147483647\n    nsec: 4294967295\n";
    format!(
        "- history: 1\n  depth: {}\n  reliability: {reliability}\n  durability: {durability}\n  deadline:\n{inf}  lifespan:\n{inf}  liveliness: 1\n  liveliness_lease_duration:\n{inf}  avoid_ros_namespace_conventions: false\n",
        q.depth
    )
}

struct Channels {
    velocity: u16,
    load: u16,
    friction: u16,
    friction_force: u16,
    film_profile: u16,
    statistics: u16,
}

type McapWriter = mcap::Writer<BufWriter<std::fs::File>>;

/// A running recorder.
pub struct Recorder {
    queue: Arc<ArrayQueue<RecordItem>>,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<RecorderReport>>,
    error: Arc<Mutex<Option<String>>>,
    messages: Arc<AtomicU64>,
    path: PathBuf,
}

impl Recorder {
    /// Create the file (errors here mean nothing was recorded) and start the
    /// writer thread.
    pub fn start(
        path: &Path,
        config: &Config,
        names: &TopicNames,
        profile: Option<Arc<ProfileSlot>>,
    ) -> Result<Self, RecorderError> {
        let bag = BagWriter::create(path, config, names, BTreeMap::new())?;
        let queue = Arc::new(ArrayQueue::new(config.node.queue_capacity));
        let stop = Arc::new(AtomicBool::new(false));
        let error = Arc::new(Mutex::new(None));
        let messages = Arc::new(AtomicU64::new(0));
        let ctx = WriterCtx {
            bag: Some(bag),
            path: path.to_path_buf(),
            error: error.clone(),
            messages: messages.clone(),
        };
        let (q, s) = (queue.clone(), stop.clone());
        let thread = std::thread::Builder::new()
            .name("mcap-recorder".into())
            .spawn(move || writer_thread(ctx, q, s, profile))
            .map_err(|source| RecorderError::Create {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(Self {
            queue,
            stop,
            thread: Some(thread),
            error,
            messages,
            path: path.to_path_buf(),
        })
    }

    /// The queue the loop pushes into.
    pub fn queue(&self) -> Arc<ArrayQueue<RecordItem>> {
        self.queue.clone()
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.messages.load(Ordering::Relaxed)
    }

    /// A write error, if one happened.
    pub fn error(&self) -> Option<String> {
        self.error.lock().ok().and_then(|e| e.clone())
    }

    /// Write what is queued, finalise the file (summary, footer) and report.
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

fn add_channels(
    w: &mut McapWriter,
    config: &Config,
    names: &TopicNames,
) -> mcap::McapResult<Channels> {
    let mut schema =
        |t: &MsgType| w.add_schema(&t.full_name(), "ros2msg", t.ros2msg_schema().as_bytes());
    let velocity_type = match config.ros.command_type {
        CommandType::Float64 => &msgs::FLOAT64,
        CommandType::TwistStamped => &msgs::TWIST_STAMPED,
    };
    let s_vel = schema(velocity_type)?;
    let s_f64 = schema(&msgs::FLOAT64)?;
    let s_est = schema(&msgs::FRICTION_ESTIMATE)?;
    let s_prof = schema(&msgs::FILM_PROFILE)?;
    let s_stat = schema(&msgs::LOOP_STATISTICS)?;
    let meta = |q: &QosConfig| {
        let mut m = BTreeMap::new();
        m.insert("offered_qos_profiles".to_string(), offered_qos_yaml(q));
        m
    };
    let (cq, eq) = (
        meta(&config.ros.qos.commands),
        meta(&config.ros.qos.estimates),
    );
    Ok(Channels {
        velocity: w.add_channel(s_vel, &names.cmd_velocity, "cdr", &cq)?,
        load: w.add_channel(s_f64, &names.normal_load, "cdr", &cq)?,
        friction: w.add_channel(s_est, &names.friction, "cdr", &eq)?,
        friction_force: w.add_channel(s_f64, &names.friction_force, "cdr", &eq)?,
        film_profile: w.add_channel(s_prof, &names.film_profile, "cdr", &eq)?,
        statistics: w.add_channel(s_stat, &names.loop_statistics, "cdr", &eq)?,
    })
}

/// A synchronous MCAP writer in the ROS 2 profile for the node's topics
/// (the recorder's thread and `replay` both use it).
pub struct BagWriter {
    w: McapWriter,
    channels: Channels,
    frame_id: String,
    command_type: CommandType,
    sequence: u32,
    messages: u64,
    path: PathBuf,
}

impl BagWriter {
    /// Create `path` with the schemas, channels and the `friction_node`
    /// metadata record (resolved config, plus `extra` keys).
    pub fn create(
        path: &Path,
        config: &Config,
        names: &TopicNames,
        extra: BTreeMap<String, String>,
    ) -> Result<Self, RecorderError> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|source| RecorderError::Create {
                path: path.to_path_buf(),
                source,
            })?;
        }
        let file = std::fs::File::create(path).map_err(|source| RecorderError::Create {
            path: path.to_path_buf(),
            source,
        })?;
        let mcap_err = |e: mcap::McapError| RecorderError::Mcap {
            path: path.to_path_buf(),
            message: e.to_string(),
        };
        let compression = match config.recording.compression {
            Compression::None => None,
            Compression::Zstd => Some(mcap::Compression::Zstd),
            Compression::Lz4 => Some(mcap::Compression::Lz4),
        };
        let mut w = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("friction-node ", env!("CARGO_PKG_VERSION")))
            .compression(compression)
            .chunk_size(Some(config.recording.chunk_size_bytes))
            .create(BufWriter::new(file))
            .map_err(mcap_err)?;
        let channels = add_channels(&mut w, config, names).map_err(mcap_err)?;
        let mut meta = extra;
        meta.insert("config_yaml".to_string(), config.to_yaml());
        meta.insert("version".to_string(), env!("CARGO_PKG_VERSION").to_string());
        meta.insert(
            "step_mode".to_string(),
            format!("{:?}", config.node.step_mode).to_lowercase(),
        );
        meta.insert("started_ns".to_string(), crate::node::wall_ns().to_string());
        w.write_metadata(&mcap::records::Metadata {
            name: "friction_node".into(),
            metadata: meta,
        })
        .map_err(mcap_err)?;
        Ok(Self {
            w,
            channels,
            frame_id: config.node.frame_id.clone(),
            command_type: config.ros.command_type,
            sequence: 0,
            messages: 0,
            path: path.to_path_buf(),
        })
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.messages
    }

    /// Write a metadata record.
    pub fn write_metadata(
        &mut self,
        name: &str,
        metadata: BTreeMap<String, String>,
    ) -> Result<(), String> {
        self.w
            .write_metadata(&mcap::records::Metadata {
                name: name.into(),
                metadata,
            })
            .map_err(|e| e.to_string())
    }

    fn write<T: serde::Serialize>(
        &mut self,
        channel: u16,
        log_ns: u64,
        publish_ns: u64,
        msg: &T,
    ) -> Result<(), String> {
        let data = msgs::to_cdr(msg)?;
        self.sequence = self.sequence.wrapping_add(1);
        self.w
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: channel,
                    sequence: self.sequence,
                    log_time: log_ns,
                    publish_time: publish_ns,
                },
                &data,
            )
            .map_err(|e| e.to_string())?;
        self.messages += 1;
        Ok(())
    }

    /// Write one item the loop produced, logged at `log_ns`.
    pub fn write_item(&mut self, item: &RecordItem, log_ns: u64) -> Result<(), String> {
        match *item {
            RecordItem::Command {
                command,
                received_ns,
            } => self.command(&command, received_ns),
            RecordItem::Estimate(e) => {
                self.write(
                    self.channels.friction,
                    log_ns,
                    e.stamp_ns,
                    &e.to_wire(&self.frame_id),
                )?;
                self.write(
                    self.channels.friction_force,
                    log_ns,
                    e.stamp_ns,
                    &Float64 {
                        data: e.friction_force_n,
                    },
                )
            }
            RecordItem::Statistics(s) => self.write(
                self.channels.statistics,
                log_ns,
                s.stamp_ns,
                &s.to_wire(&self.frame_id),
            ),
        }
    }

    fn command(&mut self, c: &Command, received_ns: u64) -> Result<(), String> {
        match (c.kind, self.command_type) {
            (CommandKind::Load, _) => self.write(
                self.channels.load,
                received_ns,
                c.stamp_ns,
                &Float64 { data: c.value },
            ),
            (CommandKind::Velocity, CommandType::Float64) => self.write(
                self.channels.velocity,
                received_ns,
                c.stamp_ns,
                &Float64 { data: c.value },
            ),
            (CommandKind::Velocity, CommandType::TwistStamped) => {
                let mut m = TwistStamped {
                    header: Header {
                        stamp: Time::from_ns(c.stamp_ns),
                        frame_id: self.frame_id.clone(),
                    },
                    ..Default::default()
                };
                m.twist.linear.x = c.value;
                self.write(self.channels.velocity, received_ns, c.stamp_ns, &m)
            }
        }
    }

    /// Write a film profile.
    pub fn write_profile(
        &mut self,
        p: crate::transport::ProfileData,
        log_ns: u64,
    ) -> Result<(), String> {
        let m = msgs::FilmProfile {
            header: Header {
                stamp: Time::from_ns(p.stamp_ns),
                frame_id: self.frame_id.clone(),
            },
            dx_m: p.dx_m,
            h_m: p.h_m,
            p_pa: p.p_pa,
        };
        let stamp = p.stamp_ns;
        self.write(self.channels.film_profile, log_ns, stamp, &m)
    }

    /// Close the open chunk (what is on disk is then readable after a crash).
    pub fn flush(&mut self) -> Result<(), String> {
        self.w.flush().map_err(|e| e.to_string())
    }

    /// Write the summary and footer.
    pub fn finish(mut self) -> Result<u64, String> {
        self.w.finish().map_err(|e| e.to_string())?;
        drop(self.w);
        Ok(std::fs::metadata(&self.path).map_or(0, |m| m.len()))
    }
}

/// The recorder thread's state: the writer (gone after a failure) and what
/// it reports.
struct WriterCtx {
    bag: Option<BagWriter>,
    path: PathBuf,
    error: Arc<Mutex<Option<String>>>,
    messages: Arc<AtomicU64>,
}

impl WriterCtx {
    /// Stop recording after an error; the loop is unaffected.
    fn fail(&mut self, message: String) {
        tracing::error!(
            "recording {} failed: {message}; the node goes on without recording",
            self.path.display()
        );
        if let Ok(mut slot) = self.error.lock() {
            slot.get_or_insert(message);
        }
        // Keep what is on disk readable up to the last complete chunk; the
        // writer's drop then tries (and may fail) to write the footer.
        if let Some(mut b) = self.bag.take() {
            let _ = b.flush();
        }
    }

    fn with(&mut self, f: impl FnOnce(&mut BagWriter) -> Result<(), String>) {
        let Some(b) = self.bag.as_mut() else { return };
        match f(b) {
            Ok(()) => self.messages.store(b.messages(), Ordering::Relaxed),
            Err(e) => self.fail(e),
        }
    }
}

fn writer_thread(
    mut ctx: WriterCtx,
    queue: Arc<ArrayQueue<RecordItem>>,
    stop: Arc<AtomicBool>,
    profile: Option<Arc<ProfileSlot>>,
) -> RecorderReport {
    let mut seen = 0u64;
    let mut last_flush = Instant::now();
    loop {
        let stopping = stop.load(Ordering::Acquire);
        let mut idle = true;
        while let Some(item) = queue.pop() {
            idle = false;
            let now = crate::node::wall_ns();
            ctx.with(|b| b.write_item(&item, now));
        }
        if let Some(slot) = &profile {
            if let Some(p) = slot.read_if_newer(&mut seen) {
                let now = crate::node::wall_ns();
                ctx.with(|b| b.write_profile(p, now));
            }
        }
        if last_flush.elapsed() > Duration::from_secs(1) {
            // Close the open chunk: a crash loses at most a second.
            ctx.with(|b| b.flush());
            last_flush = Instant::now();
        }
        if stopping && queue.is_empty() {
            break;
        }
        if idle {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    let mut report = RecorderReport {
        path: ctx.path.clone(),
        messages: ctx.messages.load(Ordering::Relaxed),
        ..Default::default()
    };
    if let Some(b) = ctx.bag.take() {
        match b.finish() {
            Ok(bytes) => report.bytes = bytes,
            Err(e) => ctx.fail(e),
        }
    }
    if report.bytes == 0 {
        report.bytes = std::fs::metadata(&ctx.path).map_or(0, |m| m.len());
    }
    report.error = ctx.error.lock().ok().and_then(|e| e.clone());
    report
}
