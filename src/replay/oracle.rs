//! The determinism oracle: a re-simulation of a friction-node bag compared
//! field by field, bit for bit, with the estimates it recorded. The
//! command status is not compared: it says what the node was told (held,
//! timed out), which a replay driven by the applied values cannot know.

use crate::msgs::EstimateRecord;
use crate::physics::Estimate;

/// Outcome of the determinism check.
#[derive(Debug, Clone)]
pub struct Oracle {
    /// Steps compared.
    pub compared: usize,
    /// Whether every compared field is bit-identical.
    pub identical: bool,
    /// (field, largest |replayed − recorded|, at step index), non-zero only.
    pub deviations: Vec<(&'static str, f64, usize)>,
    /// Steps recorded but not replayed or vice versa.
    pub count_mismatch: Option<(usize, usize)>,
}

pub(super) fn compare(
    replayed: &[(Estimate, EstimateRecord)],
    recorded: &[EstimateRecord],
) -> Oracle {
    type Field = (&'static str, fn(&EstimateRecord) -> f64);
    let fields: [Field; 13] = [
        ("velocity_m_s", |r| r.velocity_m_s),
        ("load_n", |r| r.load_n),
        ("friction_force_n", |r| r.friction_force_n),
        ("contact_friction_force_n", |r| r.contact_friction_force_n),
        ("cof", |r| r.cof),
        ("h0_m", |r| r.h0_m),
        ("h_min_m", |r| r.h_min_m),
        ("hydrodynamic_force_n", |r| r.hydrodynamic_force_n),
        ("asperity_force_n", |r| r.asperity_force_n),
        ("asperity_load_share", |r| r.asperity_load_share),
        ("regime", |r| r.regime as f64),
        ("status", |r| r.status as f64),
        ("iterations", |r| r.iterations as f64),
    ];
    let n = replayed.len().min(recorded.len());
    let mut identical = replayed.len() == recorded.len();
    let mut deviations = Vec::new();
    for (name, f) in fields {
        let (mut worst, mut at) = (0.0f64, 0usize);
        for k in 0..n {
            let (a, b) = (f(&replayed[k].1), f(&recorded[k]));
            if a.to_bits() != b.to_bits() {
                identical = false;
                let d = (a - b).abs();
                if d > worst || worst == 0.0 {
                    worst = d;
                    at = k;
                }
            }
        }
        if worst != 0.0 || (0..n).any(|k| f(&replayed[k].1).to_bits() != f(&recorded[k]).to_bits())
        {
            deviations.push((name, worst, at));
        }
    }
    Oracle {
        compared: n,
        identical,
        deviations,
        count_mismatch: (replayed.len() != recorded.len())
            .then_some((recorded.len(), replayed.len())),
    }
}

/// Several contacts' verdicts as one: identical when all are, every
/// deviation, the steps compared summed, the first count mismatch.
pub(super) fn combine<'a>(oracles: impl Iterator<Item = &'a Oracle>) -> Oracle {
    let mut all = Oracle {
        compared: 0,
        identical: true,
        deviations: Vec::new(),
        count_mismatch: None,
    };
    for o in oracles {
        all.compared += o.compared;
        all.identical &= o.identical;
        all.deviations.extend(o.deviations.iter().cloned());
        if all.count_mismatch.is_none() {
            all.count_mismatch = o.count_mismatch;
        }
    }
    all
}
