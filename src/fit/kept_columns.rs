//! Factors of the speed alone kept along a film trace's steps, so that a
//! fit recomposing the friction along the trace many times computes each
//! only when the keys it depends on move (`film_run.rs`; the terms read
//! them from `physics::terms::Kept`).

use std::sync::{Arc, Mutex};

/// A factor of the speed alone at a trace's steps (the boundary rate's
/// asinh(v/v_a), the Stribeck fall e^(−|v/v_s|^α_s), the viscous bend
/// |v/v_b|^δ), kept for the last
/// [`COLUMNS_KEPT`] values of the keys it depends on. A fit recomposes the
/// friction along one film many times (the cheap keys' profile, the
/// Jacobian's columns) and mostly at the speed keys it composed with just
/// before (the key fixed, or another column moved): on the O-ring seal's
/// selection 92 % of the compositions, where the asinh took a fifth of the
/// whole calibration's time (`perf`, stop 96); on a robot joint's time
/// series `exp` and `pow` took a fifth, the fall's and the bend's parts
/// of them kept here since stop 100.
/// The numbers are those the term computes, bit for bit.
#[derive(Default)]
pub(super) struct KeptColumns(Mutex<Vec<KeptColumn>>);

/// One kept column: the bits of the key values it was computed at, and
/// the factor at each step.
type KeptColumn = ([u64; 2], Arc<[f64]>);

/// Key values whose columns a trace keeps: the last few a fit composed
/// with (its current point and a Jacobian column moving the key, on each
/// of the cores).
pub(super) const COLUMNS_KEPT: usize = 4;

impl KeptColumns {
    /// `factor` at each of `steps`' speeds for the key values `key`: kept,
    /// or computed and kept.
    pub(super) fn get(
        &self,
        key: [u64; 2],
        steps: &[[f64; 4]],
        factor: impl Fn(f64) -> f64,
    ) -> Arc<[f64]> {
        let lock = || self.0.lock().unwrap_or_else(|p| p.into_inner());
        if let Some((_, c)) = lock().iter().find(|(k, _)| *k == key) {
            return Arc::clone(c);
        }
        let column: Arc<[f64]> = steps.iter().map(|st| factor(st[0])).collect();
        let mut kept = lock();
        // Another thread may have kept it meanwhile: one entry per key.
        if let Some((_, c)) = kept.iter().find(|(k, _)| *k == key) {
            return Arc::clone(c);
        }
        if kept.len() >= COLUMNS_KEPT {
            kept.pop();
        }
        kept.insert(0, (key, Arc::clone(&column)));
        column
    }

    /// The key values of the columns kept, the latest first.
    #[cfg(test)]
    pub(super) fn keys(&self) -> Vec<[u64; 2]> {
        let kept = self.0.lock().unwrap_or_else(|p| p.into_inner());
        kept.iter().map(|(k, _)| *k).collect()
    }
}
