//! Where the recording goes: one MCAP file, or a rosbag2-style directory
//! of split files (`DIR/DIR_0.mcap`, `DIR/DIR_1.mcap`, … and
//! `metadata.yaml`, rewritten atomically at every split so that a crash
//! leaves a readable directory).
//!
//! A split never loses or duplicates a message: each entry goes to exactly
//! one file. The finished file is finalised (summary, footer) on a thread of
//! its own, so the recorder goes on with the next file at once; memory held
//! per file (the writer's chunk indexes) is released with it. With a disk
//! budget the oldest files are deleted (and leave `metadata.yaml`) when the
//! total exceeds it. A write error (a full disk) closes the current file;
//! in a directory the recording resumes in a new file once a file can be
//! created again.

use super::bag_writer::{BagWriter, TopicTable};
use super::entry::Entry;
use super::{RecorderError, WriteError};
use crate::bag::rosbag2::{FileInfo, Metadata, Nanoseconds, Since, TopicMetadata, TopicWithCount};
use crate::config::topics::TopicNames;
use crate::config::Config;
use crate::link::RecorderCounters;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

/// A finished split file, as `metadata.yaml` lists it.
#[derive(Debug, Clone)]
struct Done {
    name: String,
    path: PathBuf,
    info: FileInfo,
    counts: Vec<u64>,
}

/// The split directory being written.
pub struct SplitDir {
    dir: PathBuf,
    base: String,
    config: Config,
    names: TopicNames,
    index: u64,
    current: Option<BagWriter>,
    done: Vec<Done>,
    max_bytes: u64,
    max_duration_ns: u64,
    budget: u64,
    /// The last time the current file's size was looked at (entries).
    since_size_check: u64,
    finalisers: Vec<std::thread::JoinHandle<Result<u64, WriteError>>>,
    /// Entries written since the last failure was seen.
    pub failed: Option<String>,
}

fn ns_to_since(ns: u64) -> Since {
    Since {
        nanoseconds_since_epoch: ns,
    }
}

impl SplitDir {
    /// Check the directory (absent or empty, writable) and open file 0.
    pub fn create(
        dir: &Path,
        config: &Config,
        names: &TopicNames,
        started_ns: u64,
    ) -> Result<Self, RecorderError> {
        let err = |message: String| RecorderError::Directory {
            path: dir.to_path_buf(),
            message,
        };
        if dir.exists() {
            if !dir.is_dir() {
                return Err(err("exists and is not a directory".into()));
            }
            let entries = std::fs::read_dir(dir).map_err(|e| err(e.to_string()))?;
            if entries.count() > 0 {
                return Err(err(
                    "exists and is not empty (a split recording needs a new or empty directory)"
                        .into(),
                ));
            }
        }
        std::fs::create_dir_all(dir).map_err(|e| err(e.to_string()))?;
        let base = dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .filter(|n| !n.is_empty())
            .unwrap_or_else(|| "recording".into());
        let r = &config.recording;
        let mut s = Self {
            dir: dir.to_path_buf(),
            base,
            config: config.clone(),
            names: names.clone(),
            index: 0,
            current: None,
            done: Vec::new(),
            max_bytes: r.split.max_bytes,
            max_duration_ns: r.split.max_duration_s.saturating_mul(1_000_000_000),
            budget: r.budget_bytes,
            since_size_check: 0,
            finalisers: Vec::new(),
            failed: None,
        };
        s.open(started_ns)?;
        s.write_metadata().map_err(|e| err(e.to_string()))?;
        Ok(s)
    }

    fn file_name(&self, k: u64) -> String {
        format!("{}_{k}.mcap", self.base)
    }

    fn open(&mut self, now_ns: u64) -> Result<(), RecorderError> {
        let name = self.file_name(self.index);
        let mut extra = BTreeMap::new();
        extra.insert("split_index".to_string(), self.index.to_string());
        let w = BagWriter::create(
            &self.dir.join(&name),
            &self.config,
            &self.names,
            extra,
            now_ns,
        )?;
        self.current = Some(w);
        self.index += 1;
        self.since_size_check = 0;
        Ok(())
    }

    /// Whether the current file is due to be split before `e`.
    fn due(&mut self, e: &Entry) -> bool {
        let Some(w) = &self.current else {
            return false;
        };
        if self.max_duration_ns > 0 {
            if let Some(first) = w.first_log_ns {
                if e.log_ns.saturating_sub(first) >= self.max_duration_ns {
                    return true;
                }
            }
        }
        if self.max_bytes > 0 {
            self.since_size_check += 1;
            if self.since_size_check >= 256 {
                self.since_size_check = 0;
                let on_disk = std::fs::metadata(w.path()).map_or(0, |m| m.len());
                // What is on disk plus at most one open chunk.
                if on_disk + self.config.recording.chunk_size_bytes >= self.max_bytes {
                    return true;
                }
            }
        }
        false
    }

    /// Finish the current file off this thread, start the next.
    fn rotate(&mut self, now_ns: u64, counters: &RecorderCounters) -> Result<(), WriteError> {
        if let Some(w) = self.current.take() {
            let name = w
                .path()
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let first = w.first_log_ns.unwrap_or(now_ns);
            self.done.push(Done {
                name,
                path: w.path().to_path_buf(),
                info: FileInfo {
                    path: String::new(),
                    starting_time: ns_to_since(first),
                    duration: Nanoseconds {
                        nanoseconds: w.last_log_ns.saturating_sub(first),
                    },
                    message_count: w.messages(),
                },
                counts: w.counts.clone(),
            });
            self.finalisers.push(std::thread::spawn(move || w.finish()));
        }
        self.reap();
        self.open(now_ns)
            .map_err(|e| WriteError::Open(Box::new(e)))?;
        counters.files.fetch_add(1, Ordering::Relaxed);
        self.enforce_budget(counters);
        self.write_metadata()
    }

    /// Join the finalisers that are done (their errors are reported).
    fn reap(&mut self) {
        let (finished, running): (Vec<_>, Vec<_>) =
            self.finalisers.drain(..).partition(|h| h.is_finished());
        self.finalisers = running;
        for h in finished {
            if let Ok(Err(e)) = h.join() {
                tracing::error!("finalising a split file failed: {e}");
            }
        }
    }

    fn enforce_budget(&mut self, counters: &RecorderCounters) {
        if self.budget == 0 {
            return;
        }
        let size = |p: &Path| std::fs::metadata(p).map_or(0, |m| m.len());
        let current = self.current.as_ref().map_or(0, |w| size(w.path()));
        let mut total: u64 = current + self.done.iter().map(|d| size(&d.path)).sum::<u64>();
        while total > self.budget && !self.done.is_empty() {
            let old = self.done.remove(0);
            let n = size(&old.path);
            match std::fs::remove_file(&old.path) {
                Ok(()) => {
                    counters.files_deleted.fetch_add(1, Ordering::Relaxed);
                    tracing::info!(
                        "recording budget {} bytes: deleted {} ({n} bytes)",
                        self.budget,
                        old.path.display()
                    );
                }
                Err(e) => tracing::error!("cannot delete {}: {e}", old.path.display()),
            }
            total = total.saturating_sub(n);
        }
    }

    /// `metadata.yaml` for the files present (written atomically).
    fn write_metadata(&self) -> Result<(), WriteError> {
        let table = TopicTable::new(&self.config, &self.names);
        let mut counts = vec![0u64; table.slots()];
        let mut files = Vec::new();
        for d in &self.done {
            for (c, n) in counts.iter_mut().zip(&d.counts) {
                *c += n;
            }
            files.push(FileInfo {
                path: d.name.clone(),
                ..d.info.clone()
            });
        }
        if let Some(w) = &self.current {
            for (c, n) in counts.iter_mut().zip(&w.counts) {
                *c += n;
            }
            let first = w.first_log_ns.unwrap_or(0);
            files.push(FileInfo {
                path: w
                    .path()
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                starting_time: ns_to_since(first),
                duration: Nanoseconds {
                    nanoseconds: w.last_log_ns.saturating_sub(first),
                },
                message_count: w.messages(),
            });
        }
        let start = files
            .iter()
            .filter(|f| f.message_count > 0)
            .map(|f| f.starting_time.nanoseconds_since_epoch)
            .min()
            .unwrap_or(0);
        let end = files
            .iter()
            .map(|f| f.starting_time.nanoseconds_since_epoch + f.duration.nanoseconds)
            .max()
            .unwrap_or(0);
        let m = Metadata {
            storage_identifier: "mcap".into(),
            duration: Nanoseconds {
                nanoseconds: end.saturating_sub(start),
            },
            starting_time: ns_to_since(start),
            message_count: files.iter().map(|f| f.message_count).sum(),
            topics_with_message_count: table
                .topics
                .iter()
                .map(|(id, name, ty, qos)| TopicWithCount {
                    topic_metadata: TopicMetadata {
                        name: name.clone(),
                        type_name: ty.full_name(),
                        serialization_format: "cdr".into(),
                        offered_qos_profiles: qos.clone(),
                    },
                    message_count: counts[id.index()],
                })
                .collect(),
            relative_file_paths: files.iter().map(|f| f.path.clone()).collect(),
            files,
            ..Default::default()
        };
        crate::output::write_file(&self.dir.join("metadata.yaml"), m.to_yaml().as_bytes())?;
        Ok(())
    }

    /// Write one entry, splitting first when due. After a failure, entries
    /// are counted lost until a new file can be opened.
    pub fn write(&mut self, e: &Entry, counters: &RecorderCounters) {
        if self.current.is_none() {
            // Failed earlier: try a new file (space may have returned).
            match self.open(e.log_ns) {
                Ok(()) => {
                    counters.files.fetch_add(1, Ordering::Relaxed);
                    tracing::warn!("recording resumed in a new file");
                    self.failed = None;
                    let _ = self.write_metadata();
                }
                Err(_) => {
                    counters.lost.fetch_add(1, Ordering::Relaxed);
                    return;
                }
            }
        }
        if self.due(e) {
            if let Err(m) = self.rotate(e.log_ns, counters) {
                self.fail(m);
                counters.lost.fetch_add(1, Ordering::Relaxed);
                return;
            }
        }
        let w = self.current.as_mut().expect("opened above");
        match w.write_entry(e) {
            Ok(()) => {
                counters.messages.fetch_add(1, Ordering::Relaxed);
            }
            Err(m) => {
                counters.lost.fetch_add(1, Ordering::Relaxed);
                self.fail(m);
            }
        }
    }

    fn fail(&mut self, error: WriteError) {
        let message = error.to_string();
        tracing::error!(
            "recording into {} failed: {message}; retrying in a new file",
            self.dir.display()
        );
        if let Some(mut w) = self.current.take() {
            let _ = w.flush();
            self.done.push(Done {
                name: w
                    .path()
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                path: w.path().to_path_buf(),
                info: FileInfo {
                    path: String::new(),
                    starting_time: ns_to_since(w.first_log_ns.unwrap_or(0)),
                    duration: Nanoseconds {
                        nanoseconds: w.last_log_ns.saturating_sub(w.first_log_ns.unwrap_or(0)),
                    },
                    message_count: w.messages(),
                },
                counts: w.counts.clone(),
            });
        }
        self.failed.get_or_insert(message);
    }

    /// Close the open chunk of the current file; reap finished files.
    pub fn flush(&mut self) {
        if let Some(w) = self.current.as_mut() {
            if let Err(m) = w.flush() {
                self.fail(m);
            }
        }
        self.reap();
    }

    /// Finish the last file, wait for every finaliser, write the metadata.
    pub fn finish(mut self) -> Result<(PathBuf, u64), WriteError> {
        let mut result = Ok(());
        if let Some(w) = self.current.take() {
            let first = w.first_log_ns.unwrap_or(0);
            let done = Done {
                name: w
                    .path()
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                path: w.path().to_path_buf(),
                info: FileInfo {
                    path: String::new(),
                    starting_time: ns_to_since(first),
                    duration: Nanoseconds {
                        nanoseconds: w.last_log_ns.saturating_sub(first),
                    },
                    message_count: w.messages(),
                },
                counts: w.counts.clone(),
            };
            if let Err(e) = w.finish() {
                result = Err(e);
            }
            self.done.push(done);
        }
        for h in self.finalisers.drain(..) {
            if let Ok(Err(e)) = h.join() {
                result = Err(e);
            }
        }
        self.write_metadata()?;
        result?;
        let bytes = self
            .done
            .iter()
            .map(|d| std::fs::metadata(&d.path).map_or(0, |m| m.len()))
            .sum();
        Ok((self.dir.clone(), bytes))
    }
}
