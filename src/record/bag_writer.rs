//! One MCAP file in the ROS 2 profile for the node's topics: schemas and
//! channels (every file carries all of them, so each is readable alone),
//! the `friction_node` metadata record, messages, per-topic counts.

use super::entry::{Encoder, Entry, TopicId};
use super::{RecorderError, WriteError};
use crate::config::topics::TopicNames;
use crate::config::{CommandType, Compression, Config, QosConfig, Reliability};
use crate::link::RecordItem;
use crate::msgs::{self, MsgType};
use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

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

/// What each recorded topic is: its name, type and offered QoS.
#[derive(Debug, Clone)]
pub(super) struct TopicTable {
    pub topics: Vec<(TopicId, String, &'static MsgType, String)>,
}

impl TopicTable {
    pub(super) fn new(config: &Config, names: &TopicNames) -> Self {
        let velocity_type = match config.ros.command_type {
            CommandType::Float64 => &msgs::FLOAT64,
            CommandType::TwistStamped => &msgs::TWIST_STAMPED,
        };
        let cq = offered_qos_yaml(&config.ros.qos.commands);
        let eq = offered_qos_yaml(&config.ros.qos.estimates);
        let pq = offered_qos_yaml(&crate::config::QosConfig {
            reliability: Reliability::Reliable,
            depth: 1000,
            durability: crate::config::Durability::Volatile,
        });
        let row = |id, name: &String, ty, qos: &String| (id, name.clone(), ty, qos.clone());
        let n = names;
        let mut table = Self {
            topics: vec![
                row(TopicId::Velocity, &n.cmd_velocity, velocity_type, &cq),
                row(TopicId::Load, &n.normal_load, &msgs::FLOAT64, &cq),
                row(
                    TopicId::Friction,
                    &n.friction,
                    &msgs::FRICTION_ESTIMATE,
                    &eq,
                ),
                row(
                    TopicId::FrictionForce,
                    &n.friction_force,
                    &msgs::FLOAT64,
                    &eq,
                ),
                row(
                    TopicId::FilmProfile,
                    &n.film_profile,
                    &msgs::FILM_PROFILE,
                    &eq,
                ),
                row(
                    TopicId::Statistics,
                    &n.loop_statistics,
                    &msgs::LOOP_STATISTICS,
                    &eq,
                ),
                row(
                    TopicId::Temperature,
                    &n.temperature,
                    &msgs::TEMPERATURE,
                    &cq,
                ),
                row(
                    TopicId::ParameterEvents,
                    &n.parameter_events,
                    &msgs::ros_interfaces::PARAMETER_EVENT,
                    &pq,
                ),
            ],
        };
        if config.output_plan().by_joint() {
            // Several contacts: the JointState input and each contact's
            // estimate on its own topic (the node's published names).
            table.topics.push((
                TopicId::JointCommands,
                names.joint_commands.clone(),
                &msgs::JOINT_STATE,
                offered_qos_yaml(&config.ros.qos.commands),
            ));
            for (k, name) in names.contact_friction.iter().enumerate() {
                let k = u16::try_from(k).expect("at most MAX_CONTACTS contacts");
                table.topics.push((
                    TopicId::ContactFriction(k),
                    name.clone(),
                    &msgs::FRICTION_ESTIMATE,
                    offered_qos_yaml(&config.ros.qos.estimates),
                ));
            }
        }
        table
    }

    /// Indices [`TopicId::index`] spans for this table.
    pub(super) fn slots(&self) -> usize {
        self.topics
            .iter()
            .map(|(id, ..)| id.index() + 1)
            .max()
            .unwrap_or(0)
    }
}

type McapWriter = mcap::Writer<BufWriter<std::fs::File>>;

/// One MCAP file being written.
pub struct BagWriter {
    w: McapWriter,
    /// Channel id of each [`TopicId`] (by index; None: not in this file).
    channels: Vec<Option<u16>>,
    encoder: Encoder,
    sequence: u32,
    messages: u64,
    /// Messages per topic.
    pub counts: Vec<u64>,
    /// Log time of the first and last message, ns.
    pub first_log_ns: Option<u64>,
    /// Log time of the last message, ns.
    pub last_log_ns: u64,
    /// Bytes handed to the writer (serialized messages; the file is smaller
    /// when compressed).
    pub payload_bytes: u64,
    path: PathBuf,
    scratch: Vec<Entry>,
}

impl BagWriter {
    /// Create `path` with the schemas, channels and the `friction_node`
    /// metadata record (resolved config, plus `extra` keys).
    pub fn create(
        path: &Path,
        config: &Config,
        names: &TopicNames,
        extra: BTreeMap<String, String>,
        started_ns: u64,
    ) -> Result<Self, RecorderError> {
        let create = |cause| RecorderError::Create {
            path: path.to_path_buf(),
            cause,
        };
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(create)?;
        }
        let file = std::fs::File::create(path).map_err(create)?;
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
        let table = TopicTable::new(config, names);
        let slots = table.slots();
        let channels = add_channels(&mut w, table).map_err(mcap_err)?;
        let mut meta = extra;
        meta.insert("config_yaml".to_string(), config.to_yaml());
        meta.insert("version".to_string(), env!("CARGO_PKG_VERSION").to_string());
        meta.insert(
            "step_mode".to_string(),
            format!("{:?}", config.node.step_mode).to_lowercase(),
        );
        meta.insert("started_ns".to_string(), started_ns.to_string());
        w.write_metadata(&mcap::records::Metadata {
            name: "friction_node".into(),
            metadata: meta,
        })
        .map_err(mcap_err)?;
        Ok(Self {
            w,
            channels,
            encoder: Encoder::new(config),
            sequence: 0,
            messages: 0,
            counts: vec![0; slots],
            first_log_ns: None,
            last_log_ns: 0,
            payload_bytes: 0,
            path: path.to_path_buf(),
            scratch: Vec::new(),
        })
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
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
    ) -> Result<(), WriteError> {
        Ok(self.w.write_metadata(&mcap::records::Metadata {
            name: name.into(),
            metadata,
        })?)
    }

    /// Write one serialized message.
    pub fn write_entry(&mut self, e: &Entry) -> Result<(), WriteError> {
        let Some(channel_id) = self.channels.get(e.topic.index()).copied().flatten() else {
            return Err(WriteError::UnknownTopic(e.topic));
        };
        self.sequence = self.sequence.wrapping_add(1);
        self.w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: e.log_ns,
                publish_time: e.publish_ns,
            },
            &e.data,
        )?;
        self.messages += 1;
        self.counts[e.topic.index()] += 1;
        self.first_log_ns.get_or_insert(e.log_ns);
        self.last_log_ns = self.last_log_ns.max(e.log_ns);
        self.payload_bytes += e.data.len() as u64 + 31;
        Ok(())
    }

    /// Write one item the loop or a transport produced.
    pub fn write_item(&mut self, item: &RecordItem) -> Result<(), WriteError> {
        let mut out = std::mem::take(&mut self.scratch);
        out.clear();
        let r = self
            .encoder
            .encode(item, &mut out)
            .and_then(|_| out.iter().try_for_each(|e| self.write_entry(e)));
        self.scratch = out;
        r
    }

    /// Close the open chunk (what is on disk is then readable after a crash).
    pub fn flush(&mut self) -> Result<(), WriteError> {
        Ok(self.w.flush()?)
    }

    /// Write the summary and footer; returns the file's size.
    pub fn finish(mut self) -> Result<u64, WriteError> {
        self.w.finish()?;
        drop(self.w);
        Ok(std::fs::metadata(&self.path).map_or(0, |m| m.len()))
    }
}

/// One schema per message type and one channel per topic of `table`, with
/// its QoS as `offered_qos_profiles`: the channel ids by topic slot.
fn add_channels(
    w: &mut McapWriter,
    table: TopicTable,
) -> Result<Vec<Option<u16>>, mcap::McapError> {
    let mut channels = vec![None; table.slots()];
    let mut schemas: BTreeMap<String, u16> = BTreeMap::new();
    for (id, topic, ty, qos) in table.topics {
        let name = ty.full_name();
        let schema = match schemas.get(&name) {
            Some(s) => *s,
            None => {
                let s = w.add_schema(&name, "ros2msg", ty.ros2msg_schema().as_bytes())?;
                schemas.insert(name, s);
                s
            }
        };
        let mut meta = BTreeMap::new();
        meta.insert("offered_qos_profiles".to_string(), qos);
        channels[id.index()] = Some(w.add_channel(schema, &topic, "cdr", &meta)?);
    }
    Ok(channels)
}
