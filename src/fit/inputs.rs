//! What a calibration reads: the data files (CSV tables, bags), the files
//! held out or given for validation, how their columns map to the model's
//! inputs, and whether they are a rotary joint's. Reading one file into a
//! table is here too; what the tables become is `prepare.rs`'s.

use super::error::range_error;
use super::{Delimiter, FitError, Mapping, Table};
use std::path::{Path, PathBuf};

/// Topics of bag data (velocity and friction are needed when a data path is
/// a bag).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TopicChoice {
    /// The velocity topic.
    pub velocity: Option<String>,
    /// The friction topic.
    pub friction: Option<String>,
    /// JointState topics: which joint.
    pub joint: Option<String>,
    /// The load topic.
    pub load: Option<String>,
    /// The temperature topic.
    pub temperature: Option<String>,
}

/// The data of a calibration and how to read them.
#[derive(Debug, Clone, PartialEq)]
pub struct DataRequest {
    /// Training data: CSV files, MCAP files, rosbag2 directories.
    pub files: Vec<PathBuf>,
    /// Validation data (not fitted; the error is reported on it).
    pub validate: Vec<PathBuf>,
    /// Fraction of each training file held out (cut off before anything
    /// reads it), in [0, 0.9].
    pub holdout: f64,
    /// Column expressions and map coefficients.
    pub mapping: Mapping,
    /// Column names of headerless CSV data.
    pub columns: Option<Vec<String>>,
    /// Rows skipped at the top of each table.
    pub skip: usize,
    /// The column separator.
    pub delimiter: Delimiter,
    /// Bag reading.
    pub topics: TopicChoice,
    /// The data are a rotary joint's: velocity in rad/s, friction in N·m
    /// (the lever arm and the contact's load are chosen from the data, see
    /// `rotary.rs`, unless the configuration's one contact has a gain).
    pub rotary: bool,
    /// A map coefficient subtracted from the friction as read: the
    /// friction column or expression, once a joint's or a unit's column is
    /// resolved, is read as (FRICTION) − NAME (`--fit auto`'s rule 12,
    /// `offset_try.rs`; NAME must be among the mapping's coefficients).
    pub friction_offset: Option<String>,
}

impl Default for DataRequest {
    /// The command line's defaults.
    fn default() -> Self {
        Self {
            files: Vec::new(),
            validate: Vec::new(),
            holdout: 0.0,
            mapping: Mapping::default(),
            columns: None,
            skip: 0,
            delimiter: Delimiter::Auto,
            topics: TopicChoice::default(),
            rotary: false,
            friction_offset: None,
        }
    }
}

impl DataRequest {
    /// The ranges the command line enforces.
    pub fn check(&self) -> Result<(), FitError> {
        if self.files.is_empty() {
            return Err(FitError::Data {
                what: "data".into(),
                message: "no data files given".into(),
            });
        }
        if !(self.holdout.is_finite() && (0.0..=0.9).contains(&self.holdout)) {
            return Err(range_error(
                "--holdout",
                self.holdout.to_string(),
                "a fraction in [0, 0.9]",
            ));
        }
        let s = self.mapping.smooth_s;
        if !(s.is_finite() && (1e-9..=1e3).contains(&s)) {
            return Err(range_error(
                "--smooth",
                s.to_string(),
                "a number of seconds in (0, 1e3]",
            ));
        }
        Ok(())
    }

    /// The units of the data.
    pub fn units(&self) -> super::Units {
        if self.rotary {
            super::Units::Rotary
        } else {
            super::Units::Linear
        }
    }

    /// One data file as a table; a bag also returns which topics were used.
    pub fn table(&self, path: &Path) -> Result<(Table, Option<String>), FitError> {
        if is_bag(path) {
            return self.bag_table(path);
        }
        Ok((
            Table::read(path, self.delimiter, self.columns.as_deref(), self.skip)?,
            None,
        ))
    }

    #[cfg(feature = "mcap")]
    fn bag_table(&self, path: &Path) -> Result<(Table, Option<String>), FitError> {
        let (Some(velocity), Some(friction)) = (&self.topics.velocity, &self.topics.friction)
        else {
            // Name the topics there are to choose from (a bag that cannot
            // be scanned fails again, with its own error, once they are
            // given).
            let has = crate::bag::Bag::open(path)
                .and_then(|b| b.scan())
                .map_or_else(
                    |_| String::new(),
                    |scan| format!("; the bag has:\n{}", crate::bag::listing(&scan.listing())),
                );
            return Err(FitError::Data {
                what: path.display().to_string(),
                message: format!("bag data needs --velocity-topic and --friction-topic{has}"),
            });
        };
        let topics = super::bag_input::BagTopics {
            velocity: velocity.clone(),
            friction: friction.clone(),
            joint: self.topics.joint.clone(),
            load: self.topics.load.clone(),
            temperature: self.topics.temperature.clone(),
            rotary: self.rotary,
        };
        let (table, note, used) = super::bag_input::read(path, &topics)?;
        let mut line = format!(
            "{}: velocity `{}`, friction `{}`, load {}, temperature {}",
            path.display(),
            used.velocity,
            used.friction,
            used.load.as_deref().map_or(
                "from the configuration (contact.load_n)".into(),
                |t| format!("`{t}`")
            ),
            used.temperature
                .as_deref()
                .map_or("none".into(), |t| format!("`{t}`")),
        );
        if let Some(n) = note {
            line.push_str(&format!("\nwarning: {n}"));
        }
        Ok((table, Some(line)))
    }

    #[cfg(not(feature = "mcap"))]
    fn bag_table(&self, path: &Path) -> Result<(Table, Option<String>), FitError> {
        Err(FitError::Data {
            what: path.display().to_string(),
            message: "reading bags needs the `mcap` feature".into(),
        })
    }
}

/// A data path that is read as a bag.
pub fn is_bag(p: &Path) -> bool {
    p.is_dir() || matches!(p.extension().and_then(|e| e.to_str()), Some("mcap" | "db3"))
}
