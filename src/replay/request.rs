//! A replay as data: what `replay`'s command line and Python's
//! `friction_node.replay()` both build, and the steps from it to the
//! written outputs (bag → prepared input → the model's run → the output
//! file and the report). Nothing here prints: the caller reports what it
//! likes between [`ReplayRequest::prepare`] (nothing written yet) and
//! [`ReadyReplay::run`].

use super::{prepare, run, write_report, OutputFormat, OutputStream, PreparedReplay};
use super::{ReplayError, ReplayOptions, ReplayResult};
use crate::bag::Bag;
use crate::interrupt::Interrupted;
use crate::msgs::CommandKind;
use std::path::PathBuf;
use std::time::Instant;

/// Everything one replay needs.
#[derive(Debug, Clone, Default)]
pub struct ReplayRequest {
    /// An MCAP file or a rosbag2 directory.
    pub bag: PathBuf,
    /// Topics, configuration, overrides and maps.
    pub options: ReplayOptions,
    /// Where the replayed estimates go, and as what (none: kept in memory).
    pub out: Option<(PathBuf, OutputFormat)>,
    /// A directory for `summary.md`, `cycles.csv` and the figures.
    pub report: Option<PathBuf>,
}

/// A request whose input has been read and validated; nothing is written
/// yet.
#[derive(Debug)]
pub struct ReadyReplay<'r> {
    request: &'r ReplayRequest,
    /// The configuration, the mode and the decoded commands.
    pub prepared: PreparedReplay,
    started: Instant,
}

/// What a replay produced.
#[derive(Debug)]
pub struct ReplayOutcome {
    /// The validated input.
    pub prepared: PreparedReplay,
    /// The replayed estimates and verdicts.
    pub result: ReplayResult,
    /// The output file, in place (when the request asked for one).
    pub written: Option<PathBuf>,
    /// The report's files (when the request asked for a report).
    pub report_files: Vec<PathBuf>,
    /// Reading, model and writing, s.
    pub wall_s: f64,
    /// The model's run alone, s.
    pub model_wall_s: f64,
}

impl ReplayRequest {
    /// Open the bag and validate and decode its input (errors name what was
    /// wrong; nothing is written).
    pub fn prepare(&self) -> Result<ReadyReplay<'_>, ReplayError> {
        let started = Instant::now();
        let bag = Bag::open(&self.bag)?;
        let prepared = prepare(&bag, &self.options)?;
        Ok(ReadyReplay {
            request: self,
            prepared,
            started,
        })
    }
}

impl ReadyReplay<'_> {
    /// The model steps the replay will take (one per velocity command, or
    /// per set of joint velocities).
    pub fn steps(&self) -> usize {
        self.prepared
            .commands
            .iter()
            .filter(|c| {
                matches!(
                    c.kind,
                    CommandKind::Velocity | CommandKind::JointVelocity { last: true, .. }
                )
            })
            .count()
    }

    /// Run the model (`progress(done, total)` now and then; its error stops
    /// the run), write the output (moved into place only when complete) and
    /// the report.
    pub fn run(
        self,
        progress: &mut dyn FnMut(usize, usize) -> Result<(), Interrupted>,
    ) -> Result<ReplayOutcome, ReplayError> {
        let ReadyReplay {
            request,
            prepared,
            started,
        } = self;
        if let Some(r) = &request.report {
            crate::output::prepare_dir(r)?;
        }
        let mut stream = match &request.out {
            Some((path, format)) => {
                Some(OutputStream::start(path, *format, &prepared, &request.bag)?)
            }
            None => None,
        };
        let model_started = Instant::now();
        let result = run(&prepared, progress, &mut |e, rec, k| {
            if let Some(s) = stream.as_mut() {
                s.push(e, rec, k);
            }
        })?;
        let model_wall_s = model_started.elapsed().as_secs_f64();
        let written = match stream {
            Some(s) => Some(s.finish(result.oracle.as_ref())?),
            None => None,
        };
        let wall_s = started.elapsed().as_secs_f64();
        let report_files = match &request.report {
            Some(r) => write_report(r, &request.bag, &prepared, &result, wall_s)?,
            None => Vec::new(),
        };
        Ok(ReplayOutcome {
            prepared,
            result,
            written,
            report_files,
            wall_s,
            model_wall_s,
        })
    }
}

impl ReplayOutcome {
    /// Bag time from the first replayed step to the last, s.
    pub fn span_s(&self) -> f64 {
        let e = &self.result.estimates;
        match (e.first(), e.last()) {
            (Some(a), Some(b)) => b.1.stamp_ns.saturating_sub(a.1.stamp_ns) as f64 / 1e9,
            _ => 0.0,
        }
    }
}
