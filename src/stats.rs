//! Fixed-memory statistics for the loop (no allocation after construction).

/// The samples of one statistics window (ns).
#[derive(Debug, Clone)]
pub struct Window {
    samples: Vec<u64>,
    scratch: Vec<u64>,
    len: usize,
}

impl Window {
    /// A window of the last `capacity` samples.
    pub fn new(capacity: usize) -> Self {
        Self {
            samples: vec![0; capacity],
            scratch: vec![0; capacity],
            len: 0,
        }
    }

    /// Record a sample; beyond the capacity the oldest are overwritten.
    pub fn push(&mut self, v: u64) {
        let cap = self.samples.len();
        self.samples[self.len % cap] = v;
        self.len += 1;
    }

    /// Forget every sample.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// p50, p99 and max of the window (zeros when empty). O(n), in place.
    pub fn percentiles(&mut self) -> [u64; 3] {
        let n = self.len.min(self.samples.len());
        if n == 0 {
            return [0; 3];
        }
        let s = &mut self.scratch[..n];
        s.copy_from_slice(&self.samples[..n]);
        let max = *s.iter().max().expect("non-empty");
        let i50 = (n - 1) / 2;
        let p50 = *s.select_nth_unstable(i50).1;
        let i99 = ((n - 1) as f64 * 0.99).round() as usize;
        let p99 = *s.select_nth_unstable(i99).1;
        [p50, p99, max]
    }
}

/// Whole-run distribution: 100 ns bins up to 1 ms, 10 µs bins up to 100 ms,
/// one overflow bin; the maximum is exact.
#[derive(Debug, Clone)]
pub struct Histogram {
    bins: Vec<u64>,
    count: u64,
    max: u64,
}

const FINE: usize = 10_000; // 0..1 ms by 100 ns
const COARSE: usize = 9_900; // 1..100 ms by 10 µs

impl Default for Histogram {
    fn default() -> Self {
        Self::new()
    }
}

impl Histogram {
    /// An empty histogram.
    pub fn new() -> Self {
        Self {
            bins: vec![0; FINE + COARSE + 1],
            count: 0,
            max: 0,
        }
    }

    fn bin(ns: u64) -> usize {
        if ns < 1_000_000 {
            (ns / 100) as usize
        } else if ns < 100_000_000 {
            FINE + ((ns - 1_000_000) / 10_000) as usize
        } else {
            FINE + COARSE
        }
    }

    fn value(bin: usize) -> u64 {
        if bin < FINE {
            bin as u64 * 100 + 50
        } else if bin < FINE + COARSE {
            1_000_000 + (bin - FINE) as u64 * 10_000 + 5_000
        } else {
            100_000_000
        }
    }

    /// Count one duration, ns.
    pub fn record(&mut self, ns: u64) {
        let b = &mut self.bins[Self::bin(ns)];
        *b = b.saturating_add(1);
        self.count += 1;
        self.max = self.max.max(ns);
    }

    /// Durations counted.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The largest sample (exact).
    pub fn max(&self) -> u64 {
        self.max
    }

    /// The q-quantile: the centre of its bin (within 200 ns of the sample
    /// quantile below 1 ms, 20 µs below 100 ms).
    pub fn quantile(&self, q: f64) -> u64 {
        if self.count == 0 {
            return 0;
        }
        let target = ((self.count - 1) as f64 * q).round() as u64 + 1;
        let mut acc = 0u64;
        for (i, c) in self.bins.iter().enumerate() {
            acc += *c;
            if acc >= target {
                return Self::value(i).min(self.max);
            }
        }
        self.max
    }

    /// p50, p99, max.
    pub fn summary(&self) -> [u64; 3] {
        [self.quantile(0.5), self.quantile(0.99), self.max]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_percentiles_are_order_statistics() {
        let mut w = Window::new(1000);
        for v in (1..=1000).rev() {
            w.push(v);
        }
        assert_eq!(w.percentiles(), [500, 990, 1000]);
        w.clear();
        assert_eq!(w.percentiles(), [0, 0, 0]);
    }

    #[test]
    fn histogram_quantiles_are_exact_to_a_bin() {
        let mut h = Histogram::new();
        for v in 1..=10_000u64 {
            h.record(v * 100); // 0.1 µs … 1 ms
        }
        let [p50, p99, max] = h.summary();
        assert!((p50 as i64 - 500_000).abs() <= 200, "{p50}");
        assert!((p99 as i64 - 990_000).abs() <= 200, "{p99}");
        assert_eq!(max, 1_000_000);
        h.record(5_000_000_000);
        assert_eq!(h.summary()[2], 5_000_000_000);
    }
}
