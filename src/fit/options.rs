//! How a fit searches: the number of starts and global points, the
//! evaluation budget, progress lines and the stop request.

/// Where progress lines go.
pub type Progress = Box<dyn Fn(&str) + Sync>;

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
    pub jacobian: super::local_run::JacobianRule,
    /// How the runs after the first end (the valley test or not).
    pub later_runs: super::local_run::LaterRuns,
    /// Convergence: relative change of the cost, and of the step.
    pub ftol: f64,
    /// See `ftol`.
    pub xtol: f64,
    /// Blocks of the one-step blocked cross-validation computed at the
    /// optimum (0: none; see [`super::stats::block_cv`]).
    pub cv_blocks: usize,
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
            cv_blocks: 0,
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
