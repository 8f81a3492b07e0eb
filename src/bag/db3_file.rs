//! One rosbag2 SQLite storage file (`*.db3`, ROS 2 Humble's default).
//!
//! The tables rosbag2 (and the Python `rosbags` writer) create:
//! `topics(id, name, type, serialization_format, offered_qos_profiles, …)`,
//! `messages(id, topic_id, timestamp, data)` with `data` the serialized
//! message (CDR with its 4-byte encapsulation header, as in MCAP), and from
//! ROS 2 Iron on `message_definitions(topic_type, encoding,
//! encoded_message_definition, …)`, whose `.msg` text is used like an MCAP
//! schema. A Humble file has no definitions: its topics are then checked by
//! type name only.
//!
//! The file is opened read-only. Messages stream in `timestamp, id` order
//! (the order rosbag2 plays them) from a reader thread that owns the
//! connection, through a bounded channel: memory stays bounded whatever the
//! file's size. An SQLite error part-way is damage, like a corrupt MCAP
//! chunk: what came before stays usable.

use super::{BagError, BagScan, ChannelInfo};
use rusqlite::{Connection, OpenFlags};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, Receiver};
use std::sync::Arc;

/// Messages buffered between the reader thread and the consumer.
const BUFFERED: usize = 1024;

/// One topic of the file.
#[derive(Debug, Clone)]
struct Topic {
    id: i64,
    name: Arc<str>,
    type_name: Arc<str>,
    info: ChannelInfo,
}

/// An SQLite rosbag2 storage file.
pub struct Db3File {
    path: PathBuf,
    topics: Vec<Topic>,
    messages: u64,
}

/// One message read from the file (owned: SQLite rows are not borrowed).
#[derive(Debug, Clone)]
pub struct Db3Message {
    pub topic: Arc<str>,
    pub type_name: Arc<str>,
    pub timestamp: u64,
    pub data: Vec<u8>,
}

fn open(path: &Path) -> Result<Connection, rusqlite::Error> {
    Connection::open_with_flags(
        path,
        OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
}

/// Whether `bytes` start like an SQLite database.
pub(super) fn is_sqlite(bytes: &[u8]) -> bool {
    bytes.starts_with(b"SQLite format 3\0")
}

impl Db3File {
    /// Open the file, read its topics and count its messages.
    pub fn open(path: &Path) -> Result<Self, BagError> {
        let not_bag = |message: String| BagError::NotABag {
            path: path.to_path_buf(),
            message,
        };
        let mut head = [0u8; 16];
        {
            use std::io::Read;
            let mut f = std::fs::File::open(path).map_err(|cause| BagError::Io {
                path: path.to_path_buf(),
                cause,
            })?;
            if f.read_exact(&mut head).is_err() || !is_sqlite(&head) {
                return Err(not_bag("it is not an SQLite database".into()));
            }
        }
        let conn = open(path).map_err(|e| not_bag(format!("SQLite: {e}")))?;
        let tables = |name: &str| -> Result<bool, BagError> {
            conn.query_row(
                "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = ?1",
                [name],
                |r| r.get::<_, i64>(0),
            )
            .map(|n| n > 0)
            .map_err(|e| not_bag(format!("SQLite cannot read its tables ({e})")))
        };
        for t in ["topics", "messages"] {
            if !tables(t)? {
                return Err(not_bag(format!(
                    "an SQLite file without the rosbag2 table `{t}`"
                )));
            }
        }
        let definitions = if tables("message_definitions")? {
            read_definitions(&conn).map_err(|e| not_bag(format!("message_definitions: {e}")))?
        } else {
            Vec::new()
        };
        let mut topics = read_topics(&conn, &definitions)
            .map_err(|e| not_bag(format!("the topics table: {e}")))?;
        let counts =
            count_messages(&conn).map_err(|e| not_bag(format!("the messages table: {e}")))?;
        let mut messages = 0;
        for (id, n) in counts {
            messages += n;
            if let Some(t) = topics.iter_mut().find(|t| t.id == id) {
                t.info.messages = n;
            }
        }
        Ok(Self {
            path: path.to_path_buf(),
            topics,
            messages,
        })
    }

    /// The file opened.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Channels and counts (an SQLite file has no recorded configuration).
    pub fn scan(&self) -> BagScan {
        BagScan {
            channels: self.topics.iter().map(|t| t.info.clone()).collect(),
            messages: self.messages,
            ..Default::default()
        }
    }

    /// Stream the messages in `timestamp, id` order.
    pub fn stream(&self) -> Db3Stream {
        let (tx, rx) = sync_channel(BUFFERED);
        let path = self.path.clone();
        let topics: Vec<(i64, Arc<str>, Arc<str>)> = self
            .topics
            .iter()
            .map(|t| (t.id, t.name.clone(), t.type_name.clone()))
            .collect();
        std::thread::spawn(move || {
            let run = || -> Result<(), String> {
                let conn = open(&path).map_err(|e| e.to_string())?;
                let mut st = conn
                    .prepare(
                        "SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp, id",
                    )
                    .map_err(|e| e.to_string())?;
                let mut rows = st.query([]).map_err(|e| e.to_string())?;
                while let Some(r) = rows.next().map_err(|e| e.to_string())? {
                    let id: i64 = r.get(0).map_err(|e| e.to_string())?;
                    let ts: i64 = r.get(1).map_err(|e| e.to_string())?;
                    let data: Vec<u8> = r.get(2).map_err(|e| e.to_string())?;
                    let Some((_, name, ty)) = topics.iter().find(|(k, _, _)| *k == id) else {
                        return Err(format!(
                            "a message of topic id {id}, which is not in the topics table"
                        ));
                    };
                    let timestamp =
                        u64::try_from(ts).map_err(|_| format!("a negative timestamp {ts}"))?;
                    let m = Db3Message {
                        topic: name.clone(),
                        type_name: ty.clone(),
                        timestamp,
                        data,
                    };
                    if tx.send(Ok(m)).is_err() {
                        return Ok(()); // the consumer stopped reading
                    }
                }
                Ok(())
            };
            if let Err(e) = run() {
                let _ = tx.send(Err(format!("SQLite: {e}")));
            }
        });
        Db3Stream { rx }
    }
}

/// The message stream of a [`Db3File`].
pub struct Db3Stream {
    rx: Receiver<Result<Db3Message, String>>,
}

impl Iterator for Db3Stream {
    type Item = Result<Db3Message, String>;
    fn next(&mut self) -> Option<Self::Item> {
        self.rx.recv().ok()
    }
}

/// (type, encoding, text) of every message definition.
fn read_definitions(conn: &Connection) -> rusqlite::Result<Vec<(String, String, String)>> {
    let mut st = conn.prepare(
        "SELECT topic_type, encoding, encoded_message_definition FROM message_definitions",
    )?;
    let rows = st.query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))?;
    rows.collect()
}

fn read_topics(
    conn: &Connection,
    definitions: &[(String, String, String)],
) -> rusqlite::Result<Vec<Topic>> {
    let mut st =
        conn.prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")?;
    let rows = st.query_map([], |r| {
        let id: i64 = r.get(0)?;
        let name: String = r.get(1)?;
        let type_name: String = r.get(2)?;
        let format: String = r.get(3)?;
        let (schema_encoding, schema_text) = definitions
            .iter()
            .find(|(t, _, text)| *t == type_name && !text.is_empty())
            .map_or((String::new(), String::new()), |(_, e, text)| {
                (e.clone(), text.clone())
            });
        Ok(Topic {
            id,
            name: name.as_str().into(),
            type_name: type_name.as_str().into(),
            info: ChannelInfo {
                topic: name,
                schema_name: type_name,
                schema_encoding,
                schema_text,
                message_encoding: format,
                messages: 0,
            },
        })
    })?;
    rows.collect()
}

fn count_messages(conn: &Connection) -> rusqlite::Result<Vec<(i64, u64)>> {
    let mut st = conn.prepare("SELECT topic_id, count(*) FROM messages GROUP BY topic_id")?;
    let rows = st.query_map([], |r| {
        Ok((
            r.get::<_, i64>(0)?,
            u64::try_from(r.get::<_, i64>(1)?).unwrap_or(0),
        ))
    })?;
    rows.collect()
}
