//! `--holdout FRACTION`: which rows of a table are held out of the fit,
//! the table cut in two before anything reads it, and a held-out time
//! series scored from its first held-out row after the motion before it.

use super::series::{Mapping, Series, Source};
use super::FitError;

/// The rows `--holdout FRACTION` holds out of a table of `rows` rows: the
/// last fraction of a time series, or every k-th point of a steady curve
/// (k = round(1/fraction), interleaved so both ends stay in the fit).
pub(super) fn held_out_rows(rows: usize, steady: bool, fraction: f64) -> Vec<bool> {
    if fraction <= 0.0 {
        return vec![false; rows];
    }
    if steady {
        let every = (1.0 / fraction).round().max(2.0) as usize;
        (0..rows).map(|k| k % every == every / 2).collect()
    } else {
        let cut = ((1.0 - fraction) * rows as f64).round() as usize;
        (0..rows).map(|k| k >= cut).collect()
    }
}

impl Source {
    /// The first row that is scored (0 but for a time series' held-out
    /// part, which is simulated from the start of its file).
    pub fn scored_from(&self) -> usize {
        self.scored_from
    }

    /// `--holdout FRACTION`: the table cut in two before anything reads it,
    /// the training rows and the held-out rows (`held_out_rows`), each a
    /// source of its own with `mapping`, the held-out part named
    /// `NAME (held out)`. Nothing of the held-out rows reaches the training
    /// part (its `ddt()` is taken within it). A time series' held-out part
    /// is its later part: it is the whole table, scored from its first
    /// held-out row ([`Source::scored_from`]), so that the model runs
    /// through the motion before it, as a node that ran all along would,
    /// and meets the held-out part in the state that motion left (a
    /// bristle still loaded from the last reversal) instead of a guessed
    /// one. Only the inputs before it are read: the model's parameters come
    /// from the training part alone.
    pub fn split_held_out(
        &self,
        fraction: f64,
        mapping: &Mapping,
    ) -> Result<(Source, Source), FitError> {
        let held = held_out_rows(self.table.rows(), self.steady, fraction);
        // A time series' later part keeps the rows before it, unscored.
        let lead_in = if self.steady {
            0
        } else {
            held.iter().position(|h| *h).unwrap_or(0)
        };
        let part = |keep_held: bool, label: &str| -> Result<Source, FitError> {
            let keep: Vec<bool> = held
                .iter()
                .enumerate()
                .map(|(k, h)| *h == keep_held || (keep_held && k < lead_in))
                .collect();
            let table = self.table.select_rows(&keep);
            let mut s = Source::new(table, mapping).map_err(|e| FitError::Data {
                what: format!("{} ({label}, --holdout {fraction})", self.name),
                message: e.to_string(),
            })?;
            if keep_held {
                s.name = format!("{} (held out)", self.name);
                s.scored_from = lead_in;
            }
            Ok(s)
        };
        Ok((part(false, "training part")?, part(true, "held-out part")?))
    }
}

impl Series {
    /// The samples from `from` on (a held-out part after its lead-in).
    pub fn tail(&self, from: usize) -> Series {
        let cut = |v: &Vec<f64>| v[from.min(v.len())..].to_vec();
        Series {
            name: self.name.clone(),
            steady: self.steady,
            t: cut(&self.t),
            velocity: cut(&self.velocity),
            friction: cut(&self.friction),
            load: self.load.as_ref().map(cut),
            temperature: self.temperature.as_ref().map(cut),
            fit: self.fit[from.min(self.fit.len())..].to_vec(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::held_out_rows;

    #[test]
    fn a_time_series_holds_out_its_last_fraction_and_a_steady_curve_every_kth_point_inside_its_ends(
    ) {
        let series = held_out_rows(10, false, 0.3);
        assert_eq!(
            series,
            [false, false, false, false, false, false, false, true, true, true]
        );
        let curve = held_out_rows(10, true, 0.3);
        let held: Vec<usize> = (0..10).filter(|k| curve[*k]).collect();
        assert_eq!(held, vec![1, 4, 7]);
        assert!(
            !curve[0] && !curve[9],
            "both ends of the curve stay in the fit"
        );
        assert_eq!(held_out_rows(4, true, 0.0), vec![false; 4]);
    }
}
