//! Reading ROS 2 bags: MCAP files, rosbag2 SQLite files (`.db3`) and
//! rosbag2 directories (a `metadata.yaml` with its split `*.mcap` or `*.db3`
//! files, read in order as one run).
//!
//! This module knows nothing of replay or calibration: it opens a bag, lists
//! its channels ([`Bag::scan`]), streams its messages in file order
//! ([`Bag::messages`]), decodes the message types the project reads
//! ([`decode`]) and puts sampled inputs onto a fixed step grid
//! ([`mod@resample`]). A truncated or corrupt file stops the stream where the
//! damage starts; what came before stays usable, and [`Damage`] says where.
//!
//! | file | content |
//! |---|---|
//! | `mod.rs` | [`Bag`], [`BagScan`], [`ChannelInfo`], [`Damage`], [`BagError`] |
//! | `mcap_file.rs` | one memory-mapped MCAP file: summary, metadata, message stream |
//! | `db3_file.rs` | one rosbag2 SQLite file: topics, definitions, message stream |
//! | `rosbag2.rs` | rosbag2 directories: `metadata.yaml` and its files |
//! | `decode.rs` | schema checks and the known message types as samples |
//! | `resample.rs` | sampled inputs onto the model's step grid, silences |
//! | `structure.rs` | a structural check of an MCAP file before the `mcap` reader sees it |

mod db3_file;
pub mod decode;
mod mcap_file;
pub mod resample;
pub mod rosbag2;
pub mod structure;

pub use db3_file::Db3File;
pub use decode::{check_schema, decode_cdr, read_topics, SampleKind, TopicDecoder, TopicSamples};
pub use mcap_file::McapFile;
pub use resample::{resample, Hold, Silence};

use std::path::{Path, PathBuf};

/// Errors of the bag layer.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    /// The bag could not be read.
    #[error("cannot read bag {}: {cause}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// Why.
        cause: std::io::Error,
    },
    /// Neither MCAP, SQLite nor a rosbag2 directory.
    #[error("{} is not a bag: {message}", path.display())]
    NotABag {
        /// The path.
        path: PathBuf,
        /// What was found instead.
        message: String,
    },
    /// A topic asked for is not in the bag.
    #[error("topic `{topic}` is not in the bag; it has:\n{}", listing(.available))]
    TopicNotFound {
        /// The topic.
        topic: String,
        /// The bag's topics: (name, type, messages).
        available: Vec<(String, String, u64)>,
    },
    /// A topic of a type this reader does not decode.
    #[error(
        "topic `{topic}` has type `{type_name}`, which cannot be read here (expected {expected})"
    )]
    UnsupportedType {
        /// The topic.
        topic: String,
        /// Its type.
        type_name: String,
        /// The types that would do.
        expected: String,
    },
    /// A schema whose fields are not its type's.
    #[error(
        "topic `{topic}`: the schema does not match its declared type `{type_name}`: {message}"
    )]
    SchemaMismatch {
        /// The topic.
        topic: String,
        /// Its declared type.
        type_name: String,
        /// The difference.
        message: String,
    },
    /// A JointState topic read without naming the joint.
    #[error("topic `{topic}` is JointState: choose a joint with --joint (joints: {})", .joints.join(", "))]
    JointRequired {
        /// The topic.
        topic: String,
        /// The joints it carries.
        joints: Vec<String>,
    },
    /// The joint asked for is not in the messages.
    #[error("topic `{topic}` has no joint `{joint}` (joints: {})", .joints.join(", "))]
    JointMissing {
        /// The topic.
        topic: String,
        /// The joint asked for.
        joint: String,
        /// The joints it carries.
        joints: Vec<String>,
    },
    /// A message that does not decode as its type.
    #[error("topic `{topic}`, message {index}: cannot decode as {type_name}: {message}")]
    Decode {
        /// The topic.
        topic: String,
        /// Its type.
        type_name: String,
        /// The message's index on the topic, 1-based.
        index: u64,
        /// The decoder's error.
        message: String,
    },
}

/// At most this many channels are listed in a message.
const LISTED: usize = 40;

/// "  topic  \[type\]  n messages" lines (at most `LISTED`, then a count).
pub fn listing(v: &[(String, String, u64)]) -> String {
    if v.is_empty() {
        return "  (no channels)".into();
    }
    let mut lines: Vec<String> = v
        .iter()
        .take(LISTED)
        .map(|(t, ty, n)| format!("  {t}  [{ty}]  {n} messages"))
        .collect();
    if v.len() > LISTED {
        lines.push(format!("  … and {} more channels", v.len() - LISTED));
    }
    lines.join("\n")
}

/// Where a damaged bag stopped being readable.
#[derive(Debug, Clone, PartialEq)]
pub struct Damage {
    /// Messages read before the damage.
    pub after_messages: u64,
    /// Log time of the last good message, ns.
    pub last_log_time_ns: Option<u64>,
    /// The file in which the damage is (a directory bag has several).
    pub file: PathBuf,
    /// What was wrong.
    pub error: String,
}

impl std::fmt::Display for Damage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "after {} messages", self.after_messages)?;
        if let Some(t) = self.last_log_time_ns {
            write!(f, " (last good log time {:.6} s)", t as f64 / 1e9)?;
        }
        write!(f, " in {}: {}", self.file.display(), self.error)
    }
}

/// One channel (topic and type) of the bag; a directory bag's files each
/// have their own channel records, merged here by topic and type.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelInfo {
    /// The topic.
    pub topic: String,
    /// Its type (`std_msgs/msg/Float64`).
    pub schema_name: String,
    /// The schema's encoding (`ros2msg`).
    pub schema_encoding: String,
    /// The schema's text.
    pub schema_text: String,
    /// The messages' encoding (`cdr`).
    pub message_encoding: String,
    /// Messages on it.
    pub messages: u64,
}

/// What a first pass over the bag found.
#[derive(Debug, Clone, Default)]
pub struct BagScan {
    /// In order of first appearance.
    pub channels: Vec<ChannelInfo>,
    /// Messages in the bag.
    pub messages: u64,
    /// `config_yaml` of the `friction_node` metadata record, if any.
    pub recorded_config: Option<String>,
    /// Where the bag is damaged, if it is.
    pub damage: Option<Damage>,
    /// The files read, in order.
    pub files: Vec<PathBuf>,
}

impl BagScan {
    /// (topic, type, messages) of every channel.
    pub fn listing(&self) -> Vec<(String, String, u64)> {
        self.channels
            .iter()
            .map(|c| (c.topic.clone(), c.schema_name.clone(), c.messages))
            .collect()
    }

    /// The channel of `topic`.
    pub fn channel(&self, topic: &str) -> Option<&ChannelInfo> {
        self.channels.iter().find(|c| c.topic == topic)
    }

    /// The channel of `topic`, or an error listing the bag's topics.
    pub fn require(&self, topic: &str) -> Result<&ChannelInfo, BagError> {
        self.channel(topic).ok_or_else(|| BagError::TopicNotFound {
            topic: topic.to_string(),
            available: self.listing(),
        })
    }

    fn merge(&mut self, c: ChannelInfo) {
        match self
            .channels
            .iter_mut()
            .find(|k| k.topic == c.topic && k.schema_name == c.schema_name)
        {
            Some(k) => k.messages += c.messages,
            None => self.channels.push(c),
        }
    }
}

/// One message of the stream.
#[derive(Debug, Clone)]
pub struct BagMessage<'a> {
    /// The topic.
    pub topic: &'a str,
    /// Its type.
    pub schema_name: &'a str,
    /// When it was recorded, ns.
    pub log_time: u64,
    /// When it was published, ns.
    pub publish_time: u64,
    /// The serialized message (CDR).
    pub data: &'a [u8],
}

/// One storage file of a bag.
pub enum BagFile {
    /// An MCAP file.
    Mcap(McapFile),
    /// A rosbag2 SQLite file (.db3).
    Sqlite(Db3File),
}

impl BagFile {
    /// Open an MCAP or SQLite storage file, told apart by its first bytes.
    pub fn open(path: &Path) -> Result<Self, BagError> {
        let mut head = [0u8; 16];
        let n = {
            use std::io::Read;
            let mut f = std::fs::File::open(path).map_err(|cause| BagError::Io {
                path: path.to_path_buf(),
                cause,
            })?;
            f.read(&mut head).unwrap_or(0)
        };
        if db3_file::is_sqlite(&head[..n]) {
            Ok(Self::Sqlite(Db3File::open(path)?))
        } else {
            Ok(Self::Mcap(McapFile::open(path)?))
        }
    }

    /// The file or directory opened.
    pub fn path(&self) -> &Path {
        match self {
            Self::Mcap(f) => f.path(),
            Self::Sqlite(f) => f.path(),
        }
    }

    fn scan(&self) -> Result<BagScan, BagError> {
        match self {
            Self::Mcap(f) => f.scan(),
            Self::Sqlite(f) => Ok(f.scan()),
        }
    }
}

/// An opened bag: one storage file or a rosbag2 directory of them.
pub struct Bag {
    path: PathBuf,
    files: Vec<BagFile>,
    /// The directory's `metadata.yaml` (when the bag is a directory).
    pub directory: Option<rosbag2::Metadata>,
}

impl Bag {
    /// Open an MCAP file, an SQLite (`.db3`) file or a rosbag2 directory;
    /// nothing is decoded yet.
    pub fn open(path: &Path) -> Result<Self, BagError> {
        let io = |cause| BagError::Io {
            path: path.to_path_buf(),
            cause,
        };
        let meta = std::fs::metadata(path).map_err(io)?;
        if meta.is_dir() {
            let (metadata, files) = rosbag2::open_directory(path)?;
            let files = files
                .iter()
                .map(|f| BagFile::open(f))
                .collect::<Result<Vec<_>, _>>()?;
            return Ok(Self {
                path: path.to_path_buf(),
                files,
                directory: Some(metadata),
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            files: vec![BagFile::open(path)?],
            directory: None,
        })
    }

    /// One MCAP file held in memory (fuzzing, tests); `path` names it.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, BagError> {
        Ok(Self {
            path: path.to_path_buf(),
            files: vec![BagFile::Mcap(McapFile::from_bytes(path, bytes)?)],
            directory: None,
        })
    }

    /// The file or directory opened.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The storage files, in order.
    pub fn files(&self) -> &[BagFile] {
        &self.files
    }

    /// Channels, counts and the recorded config of every file (see
    /// [`McapFile::scan`]); the first damaged file ends the scan.
    pub fn scan(&self) -> Result<BagScan, BagError> {
        let mut scan = BagScan::default();
        for f in &self.files {
            let s = f.scan()?;
            scan.messages += s.messages;
            scan.files.push(f.path().to_path_buf());
            for c in s.channels {
                scan.merge(c);
            }
            if scan.recorded_config.is_none() {
                scan.recorded_config = s.recorded_config;
            }
            if let Some(mut d) = s.damage {
                d.after_messages = scan.messages;
                scan.damage = Some(d);
                break;
            }
        }
        Ok(scan)
    }

    /// Every message in file order; the first damage ends the stream with
    /// `Err(Damage)` (messages before it were yielded).
    pub fn messages(&self) -> Result<Messages<'_>, BagError> {
        Ok(Messages {
            files: &self.files,
            current: None,
            next_file: 0,
            count: 0,
            last_log: None,
            done: false,
        })
    }
}

/// The stream of one storage file.
enum FileStream<'a> {
    Mcap(Box<mcap::MessageStream<'a>>),
    Sqlite(db3_file::Db3Stream),
}

/// Iterator over a bag's messages (see [`Bag::messages`]).
pub struct Messages<'a> {
    files: &'a [BagFile],
    current: Option<(usize, FileStream<'a>)>,
    next_file: usize,
    count: u64,
    last_log: Option<u64>,
    done: bool,
}

/// A message with its channel kept alive: borrowed from an MCAP file (the
/// stream hands out `Arc`s) or owned, read from an SQLite file.
pub enum OwnedChannelMessage<'a> {
    /// From an MCAP file.
    Mcap(mcap::Message<'a>),
    /// From an SQLite file.
    Sqlite(db3_file::Db3Message),
}

impl OwnedChannelMessage<'_> {
    /// The message, borrowed.
    pub fn view(&self) -> BagMessage<'_> {
        match self {
            Self::Mcap(m) => BagMessage {
                topic: &m.channel.topic,
                schema_name: m.channel.schema.as_ref().map_or("", |s| s.name.as_str()),
                log_time: m.log_time,
                publish_time: m.publish_time,
                data: &m.data,
            },
            Self::Sqlite(m) => BagMessage {
                topic: &m.topic,
                schema_name: &m.type_name,
                log_time: m.timestamp,
                publish_time: m.timestamp,
                data: &m.data,
            },
        }
    }
}

impl<'a> Iterator for Messages<'a> {
    type Item = Result<OwnedChannelMessage<'a>, Damage>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if self.done {
                return None;
            }
            if self.current.is_none() {
                let k = self.next_file;
                let f = self.files.get(k)?;
                self.next_file += 1;
                match f {
                    BagFile::Mcap(f) => match f.stream() {
                        Ok(s) => self.current = Some((k, FileStream::Mcap(Box::new(s)))),
                        Err(e) => {
                            self.done = true;
                            return Some(Err(self.damage(k, e.to_string())));
                        }
                    },
                    BagFile::Sqlite(f) => self.current = Some((k, FileStream::Sqlite(f.stream()))),
                }
            }
            let (k, stream) = self.current.as_mut().expect("set above");
            let k = *k;
            let next = match stream {
                FileStream::Mcap(stream) => match mcap_file::guarded(|| stream.next()) {
                    Ok(None) => None,
                    Ok(Some(Ok(m))) => Some(Ok(OwnedChannelMessage::Mcap(m))),
                    Ok(Some(Err(e))) => Some(Err(e.to_string())),
                    Err(e) => Some(Err(e)),
                },
                FileStream::Sqlite(stream) => {
                    stream.next().map(|m| m.map(OwnedChannelMessage::Sqlite))
                }
            };
            match next {
                None => {
                    self.current = None;
                    // A structurally damaged file ends where the damage is.
                    if let BagFile::Mcap(f) = &self.files[k] {
                        if let Some(why) = f.structural_damage() {
                            self.done = true;
                            let why = why.to_string();
                            return Some(Err(self.damage(k, why)));
                        }
                    }
                }
                Some(Ok(m)) => {
                    self.count += 1;
                    self.last_log = Some(m.view().log_time);
                    return Some(Ok(m));
                }
                Some(Err(e)) => {
                    self.done = true;
                    return Some(Err(self.damage(k, e)));
                }
            }
        }
    }
}

impl Messages<'_> {
    fn damage(&self, file: usize, error: String) -> Damage {
        Damage {
            after_messages: self.count,
            last_log_time_ns: self.last_log,
            file: self.files[file].path().to_path_buf(),
            error,
        }
    }
}
