//! Lane-wise reductions over a column: sums, maxima and a finiteness check
//! kept in eight interleaved partial results, so that they vectorise (a
//! serial reduction is bound by the latency of its one accumulator). Their
//! rounding is not the serial loop's; every instruction-set version of the
//! step computes the same bits.

/// Σ (x − offset) over `xs`, in eight interleaved partial sums (the serial
/// sum is latency-bound; these vectorise). Not the serial sum's rounding.
#[inline(always)]
pub(crate) fn lane_sum(xs: &[f64], offset: f64) -> f64 {
    const L: usize = 8;
    let mut acc = [0.0f64; L];
    let chunks = xs.chunks_exact(L);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..L {
            acc[k] += c[k] - offset;
        }
    }
    for (k, x) in rest.iter().enumerate() {
        acc[k] += x - offset;
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]))
}

/// The largest of `xs` (−∞ when empty), lane-wise so it vectorises; NaN
/// entries are ignored like [`f64::max`] does.
#[inline(always)]
pub(crate) fn lane_max(xs: &[f64]) -> f64 {
    const L: usize = 8;
    let mut acc = [f64::NEG_INFINITY; L];
    let chunks = xs.chunks_exact(L);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..L {
            acc[k] = if c[k] > acc[k] { c[k] } else { acc[k] };
        }
    }
    for (k, &x) in rest.iter().enumerate() {
        acc[k] = acc[k].max(x);
    }
    acc.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
}

/// max(floor, max |x_i|), lane-wise so it vectorises; NaN entries are
/// ignored like [`f64::max`] does.
#[inline(always)]
pub(crate) fn lane_max_abs(xs: &[f64], floor: f64) -> f64 {
    const L: usize = 8;
    let mut acc = [floor; L];
    let chunks = xs.chunks_exact(L);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..L {
            let a = c[k].abs();
            acc[k] = if a > acc[k] { a } else { acc[k] };
        }
    }
    for (k, &x) in rest.iter().enumerate() {
        acc[k] = acc[k].max(x.abs());
    }
    acc.iter().fold(floor, |m, &x| m.max(x))
}

/// Whether every a_i + b_i is finite (lane-wise, so it vectorises).
#[inline(always)]
pub(crate) fn all_finite(a: &[f64], b: &[f64]) -> bool {
    const L: usize = 8;
    let mut acc = [0.0f64; L];
    let (ca, cb) = (a.chunks_exact(L), b.chunks_exact(L));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..L {
            // Zero for finite values, NaN otherwise (inf − inf or NaN).
            acc[k] += (x[k] + y[k]) * 0.0;
        }
    }
    for (k, (x, y)) in ra.iter().zip(rb).enumerate() {
        acc[k] += (x + y) * 0.0;
    }
    acc.iter().all(|&v| v == 0.0)
}
