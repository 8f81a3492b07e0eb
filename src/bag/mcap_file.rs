//! One memory-mapped MCAP file.

use super::structure::readable_prefix;
use super::{BagError, BagScan, ChannelInfo, Damage};
use std::path::{Path, PathBuf};

/// The bytes of a file: mapped, or in memory (fuzzing, tests).
enum Data {
    Mapped(memmap2::Mmap),
    Owned(Vec<u8>),
}

impl std::ops::Deref for Data {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match self {
            Data::Mapped(m) => m,
            Data::Owned(v) => v,
        }
    }
}

/// A memory-mapped MCAP file.
pub struct McapFile {
    path: PathBuf,
    map: Data,
    /// Bytes that are structurally sound (the whole file when undamaged).
    readable: usize,
    /// Why the rest is not (see [`super::structure`]).
    structural_damage: Option<String>,
}

/// Run a call into the `mcap` reader, turning a panic on damaged data into
/// an error (a backstop: [`super::structure`] rejects what is known to make
/// it panic before it runs).
pub(super) fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).map_err(|p| {
        let what = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown".into());
        format!("the MCAP reader failed on damaged data ({what})")
    })
}

fn channel_info(c: &mcap::Channel<'_>, messages: u64) -> ChannelInfo {
    let schema = c.schema.as_ref();
    ChannelInfo {
        topic: c.topic.clone(),
        schema_name: schema.map_or(String::new(), |s| s.name.clone()),
        schema_encoding: schema.map_or(String::new(), |s| s.encoding.clone()),
        schema_text: schema.map_or(String::new(), |s| {
            String::from_utf8_lossy(&s.data).into_owned()
        }),
        message_encoding: c.message_encoding.clone(),
        messages,
    }
}

impl McapFile {
    /// Open (map) the file; nothing is read yet.
    pub fn open(path: &Path) -> Result<Self, BagError> {
        let io = |cause| BagError::Io {
            path: path.to_path_buf(),
            cause,
        };
        let file = std::fs::File::open(path).map_err(io)?;
        if !file.metadata().map_err(io)?.is_file() {
            return Err(BagError::NotABag {
                path: path.to_path_buf(),
                message: "not a regular file".into(),
            });
        }
        // SAFETY: the bag is opened read-only; a concurrent writer could
        // change it under us, which the mcap reader reports as damage.
        let map = unsafe { memmap2::Mmap::map(&file) }.map_err(io)?;
        Self::from_data(path, Data::Mapped(map))
    }

    /// An MCAP file held in memory; `path` names it in messages.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, BagError> {
        Self::from_data(path, Data::Owned(bytes))
    }

    fn from_data(path: &Path, map: Data) -> Result<Self, BagError> {
        if map.len() < 8 || &map[..8] != b"\x89MCAP0\r\n" {
            let hint = if map.starts_with(b"SQLite format 3\0") {
                " (an SQLite file: open it as a `.db3` bag)"
            } else {
                ""
            };
            return Err(BagError::NotABag {
                path: path.to_path_buf(),
                message: format!("it does not start with the MCAP magic{hint}"),
            });
        }
        let (readable, structural_damage) = readable_prefix(&map);
        Ok(Self {
            path: path.to_path_buf(),
            map,
            readable,
            structural_damage,
        })
    }

    /// The file opened.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.map
    }

    /// Why the file is only readable up to a point, if it is.
    pub fn structural_damage(&self) -> Option<&str> {
        self.structural_damage.as_deref()
    }

    /// The structurally sound prefix.
    fn readable(&self) -> &[u8] {
        &self.map[..self.readable]
    }

    /// The message stream (chunk CRCs checked; a missing end magic is
    /// tolerated: a recording that was never finalised).
    pub fn stream(&self) -> Result<mcap::MessageStream<'_>, BagError> {
        mcap::MessageStream::new_with_options(
            self.readable(),
            mcap::read::Options::IgnoreEndMagic | mcap::read::Options::ValidateChunkCrcs,
        )
        .map_err(|e| BagError::NotABag {
            path: self.path.clone(),
            message: e.to_string(),
        })
    }

    /// Channels, counts and the recorded config: from the summary section
    /// when the file has a complete one (damage inside chunks then shows in
    /// the decoding pass), else by reading every message (a recording that
    /// was never finalised), noting where the file stops being readable.
    pub fn scan(&self) -> Result<BagScan, BagError> {
        let summary = if self.structural_damage.is_none() {
            guarded(|| self.scan_summary()).ok().flatten()
        } else {
            None
        };
        let mut scan = match summary {
            Some(s) => s,
            None => self.scan_messages()?,
        };
        if scan.damage.is_none() {
            if let Some(why) = &self.structural_damage {
                scan.damage = Some(Damage {
                    after_messages: scan.messages,
                    last_log_time_ns: None,
                    file: self.path.clone(),
                    error: why.clone(),
                });
            }
        }
        scan.recorded_config = guarded(|| self.recorded_config()).ok().flatten();
        Ok(scan)
    }

    fn scan_summary(&self) -> Option<BagScan> {
        let summary = mcap::Summary::read(&self.map).ok()??;
        let stats = summary.stats.as_ref()?;
        let mut ids: Vec<&u16> = summary.channels.keys().collect();
        ids.sort();
        let channels = ids
            .into_iter()
            .map(|id| {
                let n = stats.channel_message_counts.get(id).copied().unwrap_or(0);
                channel_info(&summary.channels[id], n)
            })
            .collect();
        Some(BagScan {
            channels,
            messages: stats.message_count,
            ..Default::default()
        })
    }

    fn scan_messages(&self) -> Result<BagScan, BagError> {
        let mut scan = BagScan::default();
        let mut last = None;
        let mut stream = self.stream()?;
        loop {
            let m = match guarded(|| stream.next()) {
                Ok(None) => break,
                Ok(Some(m)) => m.map_err(|e| e.to_string()),
                Err(e) => Err(e),
            };
            match m {
                Ok(m) => {
                    scan.messages += 1;
                    last = Some(m.log_time);
                    let c = &m.channel;
                    match scan.channels.iter_mut().find(|k| {
                        k.topic == c.topic
                            && Some(&k.schema_name) == c.schema.as_ref().map(|s| &s.name)
                    }) {
                        Some(k) => k.messages += 1,
                        None => scan.channels.push(channel_info(c, 1)),
                    }
                }
                Err(error) => {
                    scan.damage = Some(Damage {
                        after_messages: scan.messages,
                        last_log_time_ns: last,
                        file: self.path.clone(),
                        error,
                    });
                    break;
                }
            }
        }
        Ok(scan)
    }

    /// `config_yaml` of the `friction_node` metadata record. Metadata
    /// records sit outside the chunks: a walk over the records (chunks are
    /// skipped, not decompressed) finds them even without a summary.
    fn recorded_config(&self) -> Option<String> {
        self.metadata("friction_node")
            .and_then(|m| m.get("config_yaml").cloned())
    }

    /// The first metadata record called `name`.
    pub fn metadata(&self, name: &str) -> Option<std::collections::BTreeMap<String, String>> {
        let reader = mcap::read::LinearReader::new_with_options(
            self.readable(),
            mcap::read::Options::IgnoreEndMagic.into(),
        )
        .ok()?;
        for r in reader {
            match r {
                Ok(mcap::records::Record::Metadata(m)) if m.name == name => {
                    return Some(m.metadata);
                }
                Ok(_) => {}
                Err(_) => break,
            }
        }
        None
    }
}
