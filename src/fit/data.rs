//! The data of a fit: its training sources, the parts of the training
//! files held out of them, the validation sources, by role, with the input
//! maps' coefficients and the units; which training samples a fold of
//! cross-validation leaves out of the cost.

use super::series::{Series, Source};

/// The data of a fit: training sources, the parts of the given training
/// files held out of them (`--holdout`), and validation sources
/// (`--validate`), with the input maps' coefficients.
///
/// The held-out parts are sources of their own, cut from the files before
/// anything else reads them: every choice a fit makes (the scale, the
/// terms, the starts, the bounds) sees `train` only, so nothing held out
/// can reach one. They are predicted after the fit, as validation files
/// are (from their own first sample).
pub struct Data {
    /// Training sources.
    pub train: Vec<Source>,
    /// The held-out parts of the training files (not fitted).
    pub held_out: Vec<Source>,
    /// Validation sources (not fitted).
    pub validate: Vec<Source>,
    /// Which samples of each training source are left out of the cost (a
    /// fold of cross-validation; [`HoldOut::None`] in a plain fit).
    pub holdout: HoldOut,
    /// Map coefficient names and their values (fixed or starts).
    pub map_names: Vec<String>,
    /// Their values.
    pub map_values: Vec<f64>,
    /// The units of velocity and friction.
    pub units: super::Units,
}

/// The role of a source in a fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Role {
    /// Fitted.
    Train,
    /// A held-out part of a training file (`--holdout`).
    HeldOut,
    /// A `--validate` file.
    Validate,
}

impl Role {
    /// Its name in `fit.csv` and the tables.
    pub fn name(self) -> &'static str {
        match self {
            Self::Train => "fit",
            Self::HeldOut => "held_out",
            Self::Validate => "validate",
        }
    }
}

impl Data {
    /// The sources of `role`.
    pub fn sources(&self, role: Role) -> &[Source] {
        match role {
            Role::Train => &self.train,
            Role::HeldOut => &self.held_out,
            Role::Validate => &self.validate,
        }
    }

    /// The same data without what is not fitted: the training sources
    /// alone (what the term selection sees).
    pub fn training_only(&self) -> Self {
        Self {
            train: self.train.clone(),
            held_out: Vec::new(),
            validate: Vec::new(),
            holdout: HoldOut::None,
            map_names: self.map_names.clone(),
            map_values: self.map_values.clone(),
            units: self.units,
        }
    }
}

/// How the training data are cut into folds for cross-validation: by what
/// a calibration is asked to predict.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Folds {
    /// Each training file is a fold: predicted from the others (several
    /// files, loads or temperatures).
    Files(usize),
    /// Each source cut into this many folds by its kind: a time series
    /// into contiguous time blocks, a steady curve into contiguous speed
    /// ranges (its points ranked by |v|: the slowest and the fastest are
    /// predicted from the rest).
    Within(usize),
    /// Time series: this many contiguous time blocks, and one more fold,
    /// the samples faster than [`FASTEST_FROM`] of the record's top speed
    /// (predicted from the slower ones: a faster motion, as a steady
    /// curve's fastest speed range). A steady source among them is cut as
    /// by [`Folds::Within`] into as many speed ranges as there are folds.
    Motion(usize),
}

/// The fastest fold of a time series ([`Folds::Motion`]): the samples whose
/// speed exceeds this fraction of the record's top speed, predicted from
/// the slower ones at up to 1.25× the speeds they were fitted on, about
/// the reach of a steady curve's fastest quarter.
pub const FASTEST_FROM: f64 = 0.8;

/// The least share of a record's samples its fastest fold holds: where
/// the record spends less of its time above [`FASTEST_FROM`] of its top
/// speed (a brief peak), the fold starts lower, at this quantile of the
/// speeds, so that its error is a mean over many samples, not one peak's.
pub const FASTEST_SHARE: f64 = 0.05;

/// The speed above which a time series' samples are its fastest fold
/// ([`Folds::Motion`]): [`FASTEST_FROM`] of its top speed, or lower, at
/// the speed that [`FASTEST_SHARE`] of its samples exceed.
pub fn fastest_from(velocity: &[f64]) -> f64 {
    let mut speed: Vec<f64> = velocity.iter().map(|v| v.abs()).collect();
    speed.sort_by(f64::total_cmp);
    let Some(&top) = speed.last() else {
        return 0.0;
    };
    let k = ((speed.len() as f64) * (1.0 - FASTEST_SHARE)).floor() as usize;
    let quantile = speed[k.min(speed.len() - 1)];
    (FASTEST_FROM * top).min(quantile)
}

/// Whether the time series `s` can be cut into [`Folds::Motion`]`(blocks)`:
/// its fastest fold leaves the slower samples the majority, and each time
/// block keeps at least [`FASTEST_SHARE`] of the samples. A record at one
/// speed (or mostly at its top) has no faster motion to predict from a
/// slower one: every sample would be in the fastest fold, and the blocks
/// and the refit without it would be empty.
pub fn motion_cuts(s: &Series, blocks: usize) -> bool {
    let n = s.len();
    if n == 0 || blocks == 0 {
        return false;
    }
    let mut count = vec![0usize; blocks + 1];
    for f in Folds::Motion(blocks).of(0, s) {
        count[f] += 1;
    }
    let least = ((FASTEST_SHARE * n as f64).ceil() as usize).max(1);
    2 * count[blocks] <= n && count[..blocks].iter().all(|c| *c >= least)
}

impl Folds {
    /// How many folds there are.
    pub fn count(self) -> usize {
        match self {
            Self::Files(n) | Self::Within(n) => n,
            Self::Motion(n) => n + 1,
        }
    }

    /// The fold of every sample of `s`, the training source `source`.
    pub fn of(self, source: usize, s: &Series) -> Vec<usize> {
        let n = s.len();
        match self {
            Self::Files(_) => vec![source; n],
            Self::Motion(blocks) if s.steady => Self::Within(blocks + 1).of(source, s),
            Self::Motion(blocks) => {
                let from = fastest_from(&s.velocity);
                (0..n)
                    .map(|k| {
                        if s.velocity[k].abs() > from {
                            blocks
                        } else {
                            k * blocks / n.max(1)
                        }
                    })
                    .collect()
            }
            Self::Within(count) if s.steady => {
                let mut order: Vec<usize> = (0..n).collect();
                order.sort_by(|&a, &b| s.velocity[a].abs().total_cmp(&s.velocity[b].abs()));
                let mut fold = vec![0; n];
                for (rank, &k) in order.iter().enumerate() {
                    fold[k] = rank * count / n.max(1);
                }
                fold
            }
            Self::Within(count) => (0..n).map(|k| k * count / n.max(1)).collect(),
        }
    }
}

/// Which samples of each training source are left out of the cost
/// (scored, not fitted): a fold of cross-validation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum HoldOut {
    /// Nothing.
    #[default]
    None,
    /// Fold `index` of `folds`.
    Fold {
        /// Which fold, from 0.
        index: usize,
        /// How the data are cut.
        folds: Folds,
    },
}

impl HoldOut {
    /// Mark the held-out samples of `s`, the training source `source`.
    pub fn apply(self, s: &mut Series, source: usize) {
        match self {
            Self::None => {}
            Self::Fold { index, folds } => {
                let fold = folds.of(source, s);
                for (f, b) in s.fit.iter_mut().zip(fold) {
                    *f = b != index;
                }
            }
        }
    }
}
