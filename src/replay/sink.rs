//! The replay's output: the `simulate` columns as CSV, or MCAP in the ROS 2
//! profile, written by a background thread to a temporary sibling and moved
//! into place only when complete.

use super::{InputMode, Oracle, PreparedReplay, ReplayError};
use crate::msgs::{self, Command, EstimateRecord};
use crate::output::{tmp_sibling, OutputError};
use crate::physics::Estimate;
use crate::record::WriteError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Output format of a replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// The `simulate` columns, then `stamp_ns`; `t_s` is the stamp relative
    /// to the first step.
    Csv,
    /// ROS 2 profile, the node's topics: the inputs and the estimates.
    Mcap,
}

impl OutputFormat {
    /// From the output path's extension (`.csv` or `.mcap`).
    pub fn from_path(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "csv" => Some(Self::Csv),
            "mcap" => Some(Self::Mcap),
            _ => None,
        }
    }

    /// The file extension of this format, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Csv => "csv",
            Self::Mcap => "mcap",
        }
    }
}

/// One contact's step: the estimate, its record and the contact's index.
type Step = (Estimate, EstimateRecord, u16);

/// One output file, written to a temporary sibling and renamed over the
/// destination only when complete.
trait Sink: Send {
    fn write(&mut self, steps: &[Step]) -> Result<(), ReplayError>;
    fn finish(self: Box<Self>, oracle: Option<&Oracle>) -> Result<PathBuf, ReplayError>;
}

struct CsvSink {
    file: crate::output::AtomicFile,
    t0: Option<u64>,
    /// Driven by joints: each contact's name, joint and gain, for the last
    /// columns (empty: one contact, no such columns).
    contacts: Vec<(String, String, f64)>,
}

impl Sink for CsvSink {
    fn write(&mut self, steps: &[Step]) -> Result<(), ReplayError> {
        for (e, rec, k) in steps {
            let t0 = *self.t0.get_or_insert(rec.stamp_ns);
            let mut e = *e;
            e.time = rec.stamp_ns.saturating_sub(t0) as f64 / 1e9;
            // What was published (0 outside the calibrated range under
            // `node.outside_envelope: zero`).
            e.friction_force = rec.friction_force_n;
            e.contact_friction_force = rec.contact_friction_force_n;
            let row = crate::offline::simulate_row_with_status(
                &e,
                msgs::status_name(rec.status),
                rec.temperature_c,
            );
            // A joint's row also holds the joint's velocity and effort, in
            // the joint's units: ω = v / gain, τ = gain · F.
            let contact = match self.contacts.get(usize::from(*k)) {
                Some((name, joint, gain)) => format!(
                    ",{name},{joint},{},{}",
                    crate::text::Num(e.velocity / gain),
                    crate::text::Num(gain * e.friction_force)
                ),
                None => String::new(),
            };
            self.file.line(format_args!(
                "{row},{},{},{}{contact}",
                rec.stamp_ns,
                msgs::command_status_name(rec.command_status),
                msgs::range_name(rec.calibrated_range)
            ))?;
        }
        Ok(())
    }

    fn finish(self: Box<Self>, _: Option<&Oracle>) -> Result<PathBuf, ReplayError> {
        Ok(self.file.commit()?)
    }
}

struct McapSink {
    /// None once finished.
    w: Option<crate::record::BagWriter>,
    path: PathBuf,
    /// The temporary sibling written (None: a device written in place).
    tmp: Option<PathBuf>,
    /// The inputs, written in stamp order between the estimates.
    commands: Vec<Command>,
    next: usize,
}

impl McapSink {
    fn writer(&mut self) -> Result<&mut crate::record::BagWriter, WriteError> {
        self.w.as_mut().ok_or(WriteError::Finished)
    }

    /// A write error of this output.
    fn error(&self, source: WriteError) -> ReplayError {
        ReplayError::Recording {
            path: self.path.clone(),
            source,
        }
    }

    fn commands_up_to(&mut self, stamp: u64) -> Result<(), WriteError> {
        while let Some(&c) = self.commands.get(self.next).filter(|c| c.stamp_ns <= stamp) {
            let item = crate::link::RecordItem::Command {
                command: c,
                received_ns: c.stamp_ns,
            };
            self.writer()?.write_item(&item)?;
            self.next += 1;
        }
        Ok(())
    }
}

impl Sink for McapSink {
    fn write(&mut self, steps: &[Step]) -> Result<(), ReplayError> {
        let mut write = || -> Result<(), WriteError> {
            for (_, rec, k) in steps {
                self.commands_up_to(rec.stamp_ns)?;
                self.writer()?
                    .write_item(&crate::link::RecordItem::Estimate {
                        record: *rec,
                        logged_ns: rec.stamp_ns,
                        contact: *k,
                    })?;
            }
            Ok(())
        };
        write().map_err(|e| self.error(e))
    }

    fn finish(mut self: Box<Self>, oracle: Option<&Oracle>) -> Result<PathBuf, ReplayError> {
        let result = (|| {
            self.commands_up_to(u64::MAX)?;
            if let Some(o) = oracle {
                let mut m = BTreeMap::new();
                m.insert("bit_identical".to_string(), o.identical.to_string());
                m.insert("compared_steps".to_string(), o.compared.to_string());
                self.writer()?
                    .write_metadata("friction_node_replay_oracle", m)?;
            }
            Ok::<(), WriteError>(())
        })();
        let w = self.w.take();
        let finished = result.and_then(|_| w.ok_or(WriteError::Finished)?.finish());
        let Some(tmp) = self.tmp.clone() else {
            // A device: written in place, nothing to move.
            finished.map_err(|e| self.error(e))?;
            return Ok(self.path.clone());
        };
        if let Err(e) = finished {
            let _ = std::fs::remove_file(&tmp);
            crate::output::forget_temporary(&tmp);
            return Err(self.error(e));
        }
        let moved = std::fs::rename(&tmp, &self.path).map_err(|e| OutputError::new(&self.path, e));
        crate::output::forget_temporary(&tmp);
        moved?;
        Ok(self.path.clone())
    }
}

impl Drop for McapSink {
    fn drop(&mut self) {
        // An unfinished output is abandoned (a finished one was renamed).
        if self.w.take().is_some() {
            if let Some(tmp) = &self.tmp {
                let _ = std::fs::remove_file(tmp);
                crate::output::forget_temporary(tmp);
            }
        }
    }
}

/// The replay's output, written by a background thread while the model
/// runs (the formatting and compression then cost no replay time on a
/// machine with a second core). Nothing replaces the destination until
/// [`OutputStream::finish`]; dropped unfinished, the temporary file is
/// removed.
pub struct OutputStream {
    tx: Option<std::sync::mpsc::SyncSender<Vec<Step>>>,
    batch: Vec<Step>,
    thread: Option<std::thread::JoinHandle<SinkOutcome>>,
    path: PathBuf,
}

const BATCH: usize = 1024;

/// The last columns of a replay driven by joints: the contact, its joint,
/// and the joint's velocity (v / gain) and effort (gain · friction), in the
/// joint's units (rad/s and N·m for a revolute joint, as `fit --rotary`
/// writes it; m/s and N for a prismatic one).
pub(super) const JOINT_COLUMNS: &str = ",contact,joint,joint_velocity,joint_effort";

/// The writer thread hands its sink back with the first write error.
type SinkOutcome = (Box<dyn Sink>, Result<(), ReplayError>);

impl CsvSink {
    /// The CSV file at `path` with its header (driven by joints: the
    /// contact, its joint, and the joint's velocity and effort).
    fn create(path: &Path, p: &PreparedReplay) -> Result<Self, ReplayError> {
        let mut file = crate::output::AtomicFile::create(path)?;
        let contacts: Vec<(String, String, f64)> = if p.config.output_plan().by_joint() {
            p.config
                .resolved_contacts()
                .into_iter()
                .map(|c| (c.name, c.joint, c.gain))
                .collect()
        } else {
            Vec::new()
        };
        file.line(format_args!(
            "{},stamp_ns,command_status,calibrated_range{}",
            crate::offline::SIMULATE_COLUMNS,
            if contacts.is_empty() {
                ""
            } else {
                JOINT_COLUMNS
            }
        ))?;
        Ok(CsvSink {
            file,
            t0: None,
            contacts,
        })
    }
}

impl McapSink {
    /// The MCAP recording of the replay of `source`, written to a temporary
    /// sibling of `path` (a device such as /dev/null is written in place,
    /// never renamed over).
    fn create(path: &Path, p: &PreparedReplay, source: &Path) -> Result<Self, ReplayError> {
        let tmp = (!crate::output::is_special(path)).then(|| tmp_sibling(path));
        let target = tmp.clone().unwrap_or_else(|| path.to_path_buf());
        let mut extra = BTreeMap::new();
        extra.insert("replay_of".to_string(), source.display().to_string());
        extra.insert("replay_input".to_string(), input_label(&p.mode));
        let names = crate::config::topics::TopicNames::from_config(&p.config);
        let w = crate::record::BagWriter::create(
            &target,
            &p.config,
            &names,
            extra,
            crate::clock::system_wall_ns(),
        )
        .map_err(|e| {
            if let Some(t) = &tmp {
                let _ = std::fs::remove_file(t);
                crate::output::forget_temporary(t);
            }
            OutputError::other(path, e.to_string())
        })?;
        Ok(McapSink {
            w: Some(w),
            path: path.to_path_buf(),
            tmp,
            commands: p.commands.clone(),
            next: 0,
        })
    }
}

/// What the replay's model was driven by, for the recording's metadata.
fn input_label(mode: &InputMode) -> String {
    match mode {
        InputMode::Topics { velocity, .. } => format!("topic {velocity}"),
        InputMode::RecordedEstimates { topic } => format!("recorded estimates {topic}"),
        InputMode::RecordedContacts { topics } => {
            format!("recorded estimates of {} contacts", topics.len())
        }
        InputMode::JointStates { topic, .. } => format!("joint states {topic}"),
    }
}

impl OutputStream {
    /// Create the temporary output next to `path` and start the writer.
    pub fn start(
        path: &Path,
        format: OutputFormat,
        p: &PreparedReplay,
        source: &Path,
    ) -> Result<Self, ReplayError> {
        let out_err = |message: String| OutputError::other(path, message);
        let sink: Box<dyn Sink> = match format {
            OutputFormat::Csv => Box::new(CsvSink::create(path, p)?),
            OutputFormat::Mcap => Box::new(McapSink::create(path, p, source)?),
        };
        let (tx, rx) = std::sync::mpsc::sync_channel::<Vec<Step>>(8);
        let thread = std::thread::Builder::new()
            .name("replay-output".into())
            .spawn(move || {
                let mut sink = sink;
                let mut result = Ok(());
                for batch in rx {
                    if result.is_ok() {
                        result = sink.write(&batch);
                    }
                }
                (sink, result)
            })
            .map_err(|e| out_err(format!("cannot start the writer thread: {e}")))?;
        Ok(Self {
            tx: Some(tx),
            batch: Vec::with_capacity(BATCH),
            thread: Some(thread),
            path: path.to_path_buf(),
        })
    }

    /// Queue one step (of contact `contact`; 0 with one contact).
    pub fn push(&mut self, e: &Estimate, rec: &EstimateRecord, contact: u16) {
        self.batch.push((*e, *rec, contact));
        if self.batch.len() >= BATCH {
            self.send();
        }
    }

    fn send(&mut self) {
        let batch = std::mem::replace(&mut self.batch, Vec::with_capacity(BATCH));
        if let Some(tx) = &self.tx {
            // A failed writer has stopped receiving; finish reports why.
            let _ = tx.send(batch);
        }
    }

    /// Write what is queued, close the file and move it into place.
    pub fn finish(mut self, oracle: Option<&Oracle>) -> Result<PathBuf, ReplayError> {
        self.send();
        self.tx = None;
        let (sink, result) = self
            .thread
            .take()
            .expect("finish once")
            .join()
            .map_err(|_| OutputError::other(&self.path, "the writer thread panicked"))?;
        if let Err(e) = result {
            // Dropping the sink removes the temporary file.
            drop(sink);
            return Err(e);
        }
        sink.finish(oracle)
    }
}

impl Drop for OutputStream {
    fn drop(&mut self) {
        self.tx = None;
        if let Some(t) = self.thread.take() {
            // The sink is dropped with the thread's result: temp removed.
            let _ = t.join();
        }
    }
}
