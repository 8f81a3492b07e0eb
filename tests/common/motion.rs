//! The motions the fit tests drive their synthetic records with.

/// Point-to-point moves at 1 kHz (the motion of docs/classic-synthetic.sh,
/// shorter), as `(t_s, velocity_m_s)`: top speeds of 5 to 200 mm/s either
/// way times `scale` (2: the same moves twice as fast), ramps at 2 m/s², a
/// flat of 0.5 s and a dwell of 0.2 s.
pub fn point_to_point(duration: f64, scale: f64) -> Vec<(f64, f64)> {
    let tops = [
        0.02, -0.2, 0.005, 0.1, -0.05, 0.2, -0.02, 0.05, -0.1, -0.005,
    ];
    let (flat, dwell) = (0.5, 0.2);
    let mut out = Vec::new();
    let mut t0 = 0.0;
    let mut k = 0usize;
    'outer: for top in tops.iter().cycle() {
        let vm = top * scale;
        let r = f64::abs(vm) / 2.0;
        let len = 2.0 * r + flat + dwell;
        loop {
            let t = k as f64 * 1e-3;
            if t > duration {
                break 'outer;
            }
            let s = t - t0;
            if s >= len {
                break;
            }
            let v = if s < r {
                vm * s / r
            } else if s < r + flat {
                vm
            } else if s < 2.0 * r + flat {
                vm * (2.0 * r + flat - s) / r
            } else {
                0.0
            };
            // To the nanometre per second, as docs/point-to-point-motion.py
            // writes it: the end of a ramp is at rest, not at 4e-16 m/s.
            out.push((t, (v * 1e9).round() / 1e9));
            k += 1;
        }
        t0 += len;
    }
    out
}
