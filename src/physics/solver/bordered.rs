//! The bordered linear solve of one Newton iteration.
//!
//! The Jacobian is tridiagonal in p, bordered by the dense column ∂R/∂h0 and
//! the uniform row ∂G/∂p; one factorisation of the tridiagonal block serves
//! two right-hand sides and a scalar Schur complement gives Δh0: O(N).

use super::assembly::Work;

/// Factors of one row of the twisted elimination, plus z = A⁻¹ col.
/// `fa` is the coupling to the already-eliminated neighbour (a above the
/// meeting row, c below it) and `cp` the multiplier of the other neighbour.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Factor {
    pub fa: f64,
    pub cp: f64,
    pub inv_m: f64,
    pub z: f64,
}

/// Factor the bordered system and solve it for the Newton direction.
///
/// The tridiagonal block is factored "twisted" (burn at both ends): rows
/// 0..k are eliminated downwards and rows N−1..k+1 upwards, meeting at
/// k = N/2. The two recurrences are independent, so their division latencies
/// overlap (the sweep is latency-bound, not flop-bound); stability is that of
/// the Thomas algorithm. Both right-hand sides (residual and border column)
/// ride along. Direction into `w.dp`; returns Δh0, or None when the system is
/// singular or non-finite.
pub(crate) fn factor_solve(w: &mut Work) -> Option<f64> {
    let n = w.rows.len();
    let k = n / 2;
    let nb = n - 1 - k;
    let rows = &w.rows[..n];
    let fs = &mut w.factors[..n];
    let y = &mut w.dp[..n];
    // Downward (top) and upward (bottom) eliminations, interleaved.
    let (mut pt, mut zt, mut yt) = (0.0, 0.0, 0.0);
    let (mut pb, mut zb, mut yb) = (0.0, 0.0, 0.0);
    for j in 0..k {
        let t = &rows[j];
        let inv = 1.0 / (t.b - t.a * pt);
        pt = t.c * inv;
        zt = (t.col - t.a * zt) * inv;
        yt = (t.r - t.a * yt) * inv;
        fs[j] = Factor {
            fa: t.a,
            cp: pt,
            inv_m: inv,
            z: zt,
        };
        y[j] = yt;
        if j < nb {
            let i = n - 1 - j;
            let u = &rows[i];
            let inv = 1.0 / (u.b - u.c * pb);
            pb = u.a * inv;
            zb = (u.col - u.c * zb) * inv;
            yb = (u.r - u.c * yb) * inv;
            fs[i] = Factor {
                fa: u.c,
                cp: pb,
                inv_m: inv,
                z: zb,
            };
            y[i] = yb;
        }
    }
    // Meeting row.
    let m = &rows[k];
    let inv = 1.0 / (m.b - m.a * pt - m.c * pb);
    let zk = (m.col - m.a * zt - m.c * zb) * inv;
    let yk = (m.r - m.a * yt - m.c * yb) * inv;
    fs[k] = Factor {
        fa: 0.0,
        cp: 0.0,
        inv_m: inv,
        z: zk,
    };
    y[k] = yk;
    // Back substitution outwards from k, both directions interleaved.
    let (mut sz, mut sy) = (zk, yk);
    let (mut zu, mut yu, mut zd, mut yd) = (zk, yk, zk, yk);
    for j in 1..=k.max(nb) {
        if j <= k {
            let i = k - j;
            let f = &mut fs[i];
            f.z -= f.cp * zu;
            y[i] -= f.cp * yu;
            zu = f.z;
            yu = y[i];
            sz += zu;
            sy += yu;
        }
        if j <= nb {
            let i = k + j;
            let f = &mut fs[i];
            f.z -= f.cp * zd;
            y[i] -= f.cp * yd;
            zd = f.z;
            yd = y[i];
            sz += zd;
            sy += yd;
        }
    }
    if !(sz.is_finite() && sy.is_finite()) {
        return None;
    }
    if !w.balance {
        for v in y.iter_mut() {
            *v = -*v;
        }
        return Some(0.0);
    }
    w.schur = w.dgdh - w.c_row * sz;
    if !(w.schur.is_finite() && w.schur != 0.0) {
        return None;
    }
    let dh = (-w.g + w.c_row * sy) / w.schur;
    for (v, f) in y.iter_mut().zip(fs.iter()) {
        *v = -*v - f.z * dh;
    }
    Some(dh)
}

/// Simplified Newton direction: the current residual (rows' r, w.g) with the
/// stored (old) factors, into `w.dbar`. Returns Δh0.
pub(crate) fn direction_with_old_factors(w: &mut Work) -> f64 {
    let n = w.rows.len();
    let k = n / 2;
    let nb = n - 1 - k;
    let rows = &w.rows[..n];
    let fs = &w.factors[..n];
    let y = &mut w.dbar[..n];
    let (mut yt, mut yb) = (0.0, 0.0);
    for j in 0..k {
        yt = (rows[j].r - fs[j].fa * yt) * fs[j].inv_m;
        y[j] = yt;
        if j < nb {
            let i = n - 1 - j;
            yb = (rows[i].r - fs[i].fa * yb) * fs[i].inv_m;
            y[i] = yb;
        }
    }
    let m = &rows[k];
    let yk = (m.r - m.a * yt - m.c * yb) * fs[k].inv_m;
    y[k] = yk;
    let mut sy = yk;
    let (mut yu, mut yd) = (yk, yk);
    for j in 1..=k.max(nb) {
        if j <= k {
            let i = k - j;
            y[i] -= fs[i].cp * yu;
            yu = y[i];
            sy += yu;
        }
        if j <= nb {
            let i = k + j;
            y[i] -= fs[i].cp * yd;
            yd = y[i];
            sy += yd;
        }
    }
    if w.balance {
        let dh = (-w.g + w.c_row * sy) / w.schur;
        for (v, f) in y.iter_mut().zip(fs) {
            *v = -*v - f.z * dh;
        }
        dh
    } else {
        for v in y.iter_mut() {
            *v = -*v;
        }
        0.0
    }
}
