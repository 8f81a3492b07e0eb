//! rosbag2 directories: `metadata.yaml` (what `ros2 bag record` writes, and
//! the node's split recordings) and the storage files it lists (`mcap` or
//! `sqlite3` storage).
//!
//! Reading accepts every field rosbag2 writes (unknown ones are ignored);
//! writing produces version 5 of the format with storage identifier `mcap`.

use super::BagError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `metadata.yaml`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MetadataFile {
    /// The bag's description.
    pub rosbag2_bagfile_information: Metadata,
}

/// Nanoseconds, as rosbag2 writes durations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Nanoseconds {
    /// A duration, ns.
    pub nanoseconds: u64,
}

/// Nanoseconds since the Unix epoch, as rosbag2 writes times.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Since {
    /// A time, ns since the Unix epoch.
    pub nanoseconds_since_epoch: u64,
}

/// One topic and its message count.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct TopicWithCount {
    /// The topic.
    pub topic_metadata: TopicMetadata,
    /// Messages on it.
    pub message_count: u64,
}

/// A topic's name, type, serialization and offered QoS (a YAML string).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct TopicMetadata {
    /// The topic's name.
    pub name: String,
    #[serde(rename = "type")]
    /// Its type.
    pub type_name: String,
    /// `cdr`.
    pub serialization_format: String,
    /// rosbag2 writes a YAML string; version 9 writers (e.g. `rosbags`) may
    /// write a YAML list: either is read, kept as YAML text.
    #[serde(deserialize_with = "yaml_text")]
    pub offered_qos_profiles: String,
}

/// A string, or any other YAML value as its YAML text (`null` → empty).
fn yaml_text<'de, D: serde::Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let v = serde_norway::Value::deserialize(d)?;
    Ok(match v {
        serde_norway::Value::String(s) => s,
        serde_norway::Value::Null => String::new(),
        other => serde_norway::to_string(&other)
            .map_err(serde::de::Error::custom)?
            .trim_end()
            .to_string(),
    })
}

/// One storage file of the bag.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct FileInfo {
    /// The file, relative to the directory.
    pub path: String,
    /// Its first message's time.
    pub starting_time: Since,
    /// Its span.
    pub duration: Nanoseconds,
    /// Its messages.
    pub message_count: u64,
}

/// `rosbag2_bagfile_information`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Metadata {
    /// The metadata format's version.
    pub version: u32,
    /// `mcap` or `sqlite3`.
    pub storage_identifier: String,
    /// The whole bag's span.
    pub duration: Nanoseconds,
    /// Its first message's time.
    pub starting_time: Since,
    /// Its messages.
    pub message_count: u64,
    /// Its topics with their counts.
    pub topics_with_message_count: Vec<TopicWithCount>,
    /// File compression (empty: none).
    pub compression_format: String,
    /// File or message compression (empty: none).
    pub compression_mode: String,
    /// The files, in order.
    pub relative_file_paths: Vec<String>,
    /// The files with their spans and counts.
    pub files: Vec<FileInfo>,
    /// The ROS 2 distribution that wrote it.
    pub ros_distro: String,
}

impl Default for Metadata {
    fn default() -> Self {
        Self {
            version: 5,
            storage_identifier: "mcap".into(),
            duration: Nanoseconds::default(),
            starting_time: Since::default(),
            message_count: 0,
            topics_with_message_count: Vec::new(),
            compression_format: String::new(),
            compression_mode: String::new(),
            relative_file_paths: Vec::new(),
            files: Vec::new(),
            ros_distro: String::new(),
        }
    }
}

impl Metadata {
    /// The YAML text of `metadata.yaml`.
    pub fn to_yaml(&self) -> String {
        serde_norway::to_string(&MetadataFile {
            rosbag2_bagfile_information: self.clone(),
        })
        .expect("metadata serializes")
    }
}

/// Read a directory's `metadata.yaml` and return it with the storage files
/// in order (each must exist).
pub fn open_directory(dir: &Path) -> Result<(Metadata, Vec<PathBuf>), BagError> {
    let not_bag = |message: String| BagError::NotABag {
        path: dir.to_path_buf(),
        message,
    };
    let meta_path = dir.join("metadata.yaml");
    let text = std::fs::read_to_string(&meta_path).map_err(|e| {
        not_bag(format!(
            "a bag directory needs a rosbag2 metadata.yaml ({}: {e})",
            meta_path.display()
        ))
    })?;
    let file: MetadataFile = serde_norway::from_str(&text)
        .map_err(|e| not_bag(format!("metadata.yaml is not rosbag2 metadata: {e}")))?;
    let m = file.rosbag2_bagfile_information;
    if !matches!(m.storage_identifier.as_str(), "mcap" | "sqlite3") {
        return Err(not_bag(format!(
            "storage `{}` is not supported here (mcap or sqlite3)",
            m.storage_identifier
        )));
    }
    let names: Vec<String> = if m.relative_file_paths.is_empty() {
        m.files.iter().map(|f| f.path.clone()).collect()
    } else {
        m.relative_file_paths.clone()
    };
    if names.is_empty() {
        return Err(not_bag("metadata.yaml lists no files".into()));
    }
    let mut files = Vec::with_capacity(names.len());
    for n in &names {
        // rosbag2 writes paths relative to the directory (older versions
        // prefix the directory's own name).
        let direct = dir.join(n);
        let p = if direct.exists() {
            direct
        } else {
            match Path::new(n).file_name() {
                Some(base) if dir.join(base).exists() => dir.join(base),
                _ => {
                    return Err(not_bag(format!(
                        "metadata.yaml lists `{n}`, which is not in the directory"
                    )))
                }
            }
        };
        files.push(p);
    }
    Ok((m, files))
}
