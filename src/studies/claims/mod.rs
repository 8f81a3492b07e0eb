//! The paper's claims (docs/model.md §9, 1–9), evaluated on study results.
//!
//! Each claim is a list of named checks with the numbers behind them; the
//! verdict is computed from the checks, never set by hand. Where docs/model.md
//! expects our model to differ from the paper, the paper's statement is still
//! a check (and is allowed to fail); the difference is explained in
//! `docs/paper-reproduction.md`.
//!
//! | file | job |
//! |---|---|
//! | `stribeck.rs` | claim 1: the Stribeck curves |
//! | `loops.rs` | claims about the loops' shape (amplitude, frequency, branches) |
//! | `parameters.rs` | claims about the operating parameters (load, viscosity, roughness, texture) |

use super::{StudyKind, StudyResult, LOW_SPEED};
use std::collections::BTreeMap;

/// One check of a claim.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// What is checked.
    pub name: String,
    /// Whether it holds.
    pub pass: bool,
    /// The numbers behind the check.
    pub evidence: String,
}

/// Outcome of a claim.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Every check holds.
    Reproduced,
    /// Some checks hold.
    Partly,
    /// No check holds.
    NotReproduced,
    /// Some study the claim needs was not run or failed.
    NotEvaluated,
}

impl Verdict {
    /// The verdict in words.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::Partly => "partly reproduced",
            Verdict::NotReproduced => "not reproduced",
            Verdict::NotEvaluated => "not evaluated",
        }
    }
}

/// A claim of docs/model.md §9 with its checks.
#[derive(Debug, Clone, PartialEq)]
pub struct Claim {
    /// The claim's number in docs/model.md §9.
    pub number: u8,
    /// The claim.
    pub statement: &'static str,
    /// Its checks.
    pub checks: Vec<Check>,
    /// Facts worth reporting that are not checks.
    pub observations: Vec<String>,
}

impl Claim {
    /// The verdict from the checks.
    pub fn verdict(&self) -> Verdict {
        if self.checks.is_empty() {
            Verdict::NotEvaluated
        } else if self.checks.iter().all(|c| c.pass) {
            Verdict::Reproduced
        } else if self.checks.iter().any(|c| c.pass) {
            Verdict::Partly
        } else {
            Verdict::NotReproduced
        }
    }

    /// The check named `name`.
    pub fn check(&self, name: &str) -> Option<&Check> {
        self.checks.iter().find(|c| c.name == name)
    }
}

/// Results by study.
pub type Results = BTreeMap<StudyKind, StudyResult>;

fn check(name: &str, pass: bool, evidence: String) -> Check {
    Check {
        name: name.to_string(),
        pass,
        evidence,
    }
}

fn increasing(v: &[f64]) -> bool {
    v.windows(2).all(|w| w[1] > w[0])
}

fn decreasing(v: &[f64]) -> bool {
    v.windows(2).all(|w| w[1] < w[0])
}

fn list(v: &[f64], digits: usize) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{x:.digits$}")).collect();
    format!("[{}]", s.join(", "))
}

fn sci(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{x:.2e}")).collect();
    format!("[{}]", s.join(", "))
}

const FREQS: [&str; 3] = ["0.25", "1", "4"];

/// Evaluate every claim whose studies are present.
pub fn evaluate(r: &Results, mu_bl: f64) -> Vec<Claim> {
    vec![
        claim1(r, mu_bl),
        claim2(r),
        claim3(r, mu_bl),
        claim4(r),
        claim5(r),
        claim6(r),
        claim7(r),
        claim8(r),
        claim9(r),
    ]
}

fn metric(r: &StudyResult, id: &str, f: impl Fn(&crate::analysis::LoopMetrics) -> f64) -> f64 {
    r.metrics(id).map(&f).unwrap_or(f64::NAN)
}

fn offsets(r: &StudyResult, id: &str) -> Option<super::SteadyOffsets> {
    let c = r.case(id)?;
    c.steady_offsets(r.steady(&c.case.steady_key)?)
}

mod loops;
mod parameters;
mod stribeck;

pub use loops::{claim2, claim3, claim7, claim9};
pub use parameters::{claim4, claim5, claim6, claim8};
pub use stribeck::claim1;
