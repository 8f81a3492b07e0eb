//! How a fit searches: the number of starts and global points, the
//! evaluation budget, progress lines and the stop request.

/// Where progress lines go.
pub type Progress = Box<dyn Fn(&str) + Sync>;

/// Progress lines with the label of what they are about (the model being
/// fitted, or `fit` for the calibration's own steps).
pub type LabelledProgress = std::sync::Arc<dyn Fn(&str, &str) + Send + Sync>;

/// How a fit searches.
pub struct Options {
    /// Local (LM) runs: the start and the best distinct points of the
    /// global phase.
    pub starts: usize,
    /// Points of the global phase (0: none).
    pub global_points: usize,
    /// Seed of the global phase's points.
    pub seed: u64,
    /// Residual evaluations per LM run (the Jacobian's are extra).
    pub max_evaluations: usize,
    /// Progress lines (the command prints them).
    pub progress: Option<Progress>,
    /// Requested from outside (SIGINT, Ctrl-C): the search ends at its next
    /// evaluation and the fit is [`super::FitError::Interrupted`].
    pub stop: crate::interrupt::Stop,
    /// More starts, each a whole point (the model's parameters, then the
    /// fitted map coefficients), run besides the given start and the global
    /// points: e.g. a nested model's optimum.
    pub extra_starts: Vec<Vec<f64>>,
    /// How the local runs get their Jacobians.
    pub jacobian: JacobianRule,
    /// How the runs after the first end (the valley test or not).
    pub later_runs: LaterRuns,
    /// Convergence: relative change of the cost, and of the step.
    pub ftol: f64,
    /// See `ftol`.
    pub xtol: f64,
    /// The given start, replacing the parameters' own (e.g. a fold's fit
    /// started from the whole data's optimum).
    pub start: Option<Vec<f64>>,
    /// Standard errors and correlations at the optimum (one more Jacobian;
    /// a cross-validation fold needs none).
    pub statistics: bool,
    /// Whether the parameters the residuals are linear in are solved at
    /// every point (`separable.rs`) or searched as the others.
    pub linear_keys: LinearKeys,
    /// Whether the cheap keys are fitted at every point of the costly
    /// ones (`profile.rs`) or searched with them.
    pub cheap_keys: CheapKeys,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            starts: 3,
            global_points: 16,
            seed: 1,
            max_evaluations: 200,
            progress: None,
            stop: crate::interrupt::Stop::new(),
            extra_starts: Vec::new(),
            jacobian: Default::default(),
            later_runs: Default::default(),
            ftol: 1e-10,
            xtol: 1e-8,
            start: None,
            statistics: true,
            linear_keys: Default::default(),
            cheap_keys: Default::default(),
        }
    }
}

impl Options {
    /// Report a progress line (if anyone listens).
    pub fn say(&self, line: &str) {
        if let Some(p) = &self.progress {
            p(line);
        }
    }
}

/// How a calibration searches, as its user asked (the command line's and
/// Python's settings); each model's fit gets its [`Options`] from these.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchSettings {
    /// Local runs: the start and the best distinct global points.
    pub starts: usize,
    /// Points of the global phase (0: none).
    pub global_points: usize,
    /// Seed of the global phase.
    pub seed: u64,
    /// Residual evaluations per local run.
    pub max_evaluations: usize,
    /// How the local runs get their Jacobians.
    pub jacobian: JacobianRule,
    /// How the runs after the first end.
    pub later_runs: LaterRuns,
    /// Whether the linear parameters are solved or searched.
    pub linear_keys: LinearKeys,
    /// Whether the cheap parameters are profiled or searched.
    pub cheap_keys: CheapKeys,
}

impl Default for SearchSettings {
    /// The command line's defaults.
    fn default() -> Self {
        Self {
            starts: 3,
            global_points: 16,
            seed: 1,
            max_evaluations: 200,
            jacobian: Default::default(),
            later_runs: Default::default(),
            linear_keys: Default::default(),
            cheap_keys: Default::default(),
        }
    }
}

impl SearchSettings {
    /// The ranges the command line enforces.
    pub fn check(&self) -> Result<(), super::FitError> {
        use super::error::range_error;
        if !(1..=100).contains(&self.starts) {
            return Err(range_error(
                "--starts",
                self.starts.to_string(),
                "in [1, 100]",
            ));
        }
        if self.global_points > 10_000 {
            return Err(range_error(
                "--global-points",
                self.global_points.to_string(),
                "in [0, 10000]",
            ));
        }
        if !(10..=100_000).contains(&self.max_evaluations) {
            return Err(range_error(
                "--max-evaluations",
                self.max_evaluations.to_string(),
                "in [10, 100000]",
            ));
        }
        Ok(())
    }

    /// The options of one model's fit, its progress lines labelled `label`.
    pub fn options(
        &self,
        label: &str,
        progress: Option<&LabelledProgress>,
        stop: &crate::interrupt::Stop,
    ) -> Options {
        let progress: Option<Progress> = progress.cloned().map(|p| {
            let label = label.to_string();
            Box::new(move |l: &str| p(&label, l)) as Progress
        });
        Options {
            starts: self.starts,
            global_points: self.global_points,
            seed: self.seed,
            max_evaluations: self.max_evaluations,
            progress,
            stop: stop.clone(),
            extra_starts: Vec::new(),
            jacobian: self.jacobian,
            later_runs: self.later_runs,
            linear_keys: self.linear_keys,
            cheap_keys: self.cheap_keys,
            ..Default::default()
        }
    }
}

/// The rule of `names` named `s`, or what `s` is not (`what`) and the
/// names it could be.
fn named<T: Copy>(names: &[(&'static str, T)], s: &str, what: &str) -> Result<T, String> {
    names
        .iter()
        .find(|(n, _)| *n == s)
        .map(|(_, r)| *r)
        .ok_or_else(|| {
            let all: Vec<&str> = names.iter().map(|(n, _)| *n).collect();
            format!("`{s}` is not {what}: {}", all.join(" or "))
        })
}

/// How a local run gets its Jacobian.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum JacobianRule {
    /// Forward differences at every iteration.
    Differences,
    /// Broyden's secant update between differences, polished on
    /// differences at the end.
    #[default]
    Secant,
}

impl JacobianRule {
    /// The rules by name (the command line's values).
    pub const NAMES: [(&'static str, JacobianRule); 2] = [
        ("secant", JacobianRule::Secant),
        ("differences", JacobianRule::Differences),
    ];

    /// The rule named `s`.
    pub fn parse(s: &str) -> Result<Self, String> {
        named(&Self::NAMES, s, "a Jacobian rule")
    }
}

/// How the runs after the first end.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LaterRuns {
    /// Each stops when a straight line from its point falls all the way
    /// to an earlier optimum (the valley test), or inside that optimum's
    /// confidence region. Faster, but it can stop short of a better
    /// optimum whose basin holds such a line: opt-in only.
    Valley,
    /// Each stops only inside an earlier optimum's confidence region (the
    /// default: no optimum is lost to save evaluations).
    #[default]
    Full,
}

impl LaterRuns {
    /// The rules by name (the command line's values).
    pub const NAMES: [(&'static str, LaterRuns); 2] =
        [("valley", LaterRuns::Valley), ("full", LaterRuns::Full)];

    /// The rule named `s`.
    pub fn parse(s: &str) -> Result<Self, String> {
        named(&Self::NAMES, s, "a rule for later runs")
    }
}

/// What the local runs do with the parameters the residuals are linear in
/// (with slopes no parameter changes: `separable.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearKeys {
    /// Solved exactly in their bounds at every point the runs evaluate;
    /// the runs search the others (variable projection).
    #[default]
    Solved,
    /// Searched by the runs as every other parameter.
    Searched,
}

impl LinearKeys {
    /// The rules by name (the command line's values).
    pub const NAMES: [(&'static str, LinearKeys); 2] = [
        ("solved", LinearKeys::Solved),
        ("searched", LinearKeys::Searched),
    ];

    /// The rule named `s`.
    pub fn parse(s: &str) -> Result<Self, String> {
        named(&Self::NAMES, s, "a rule for linear keys")
    }
}

/// What the local runs do with the cheap keys (a change of one only
/// recomposes the friction along the kept film) when costly ones (a change
/// needs a film solve) are fitted beside them (`profile.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CheapKeys {
    /// Fitted at every point of the costly keys, the film held; the runs
    /// search the costly keys alone (variable projection): far fewer film
    /// solves (the default).
    #[default]
    Profiled,
    /// Searched by the runs with the costly keys, as every other key.
    Searched,
}

impl CheapKeys {
    /// The rules by name (the command line's values).
    pub const NAMES: [(&'static str, CheapKeys); 2] = [
        ("profiled", CheapKeys::Profiled),
        ("searched", CheapKeys::Searched),
    ];

    /// The rule named `s`.
    pub fn parse(s: &str) -> Result<Self, String> {
        named(&Self::NAMES, s, "a rule for cheap keys")
    }
}
