//! Claim 1: the Stribeck curves.

use super::*;

/// Claim 1: the Stribeck curves.
pub fn claim1(r: &Results, mu_bl: f64) -> Claim {
    let mut c = Claim {
        number: 1,
        statement: "Stribeck: COF → μ_bl at low speed, falls through mixed lubrication to a minimum, rises in full film; more viscosity shifts the curve to lower speed, more load to higher speed.",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::Stribeck) else {
        return c;
    };
    let mut low = Vec::new();
    let mut minima = Vec::new();
    let mut rises = 0;
    let mut half = BTreeMap::new();
    for curve in &s.steady {
        let k = CurveKeys::of(curve, mu_bl);
        low.push(k.cof_low);
        rises += k.rising as usize;
        minima.push(k.minimum);
        half.insert(
            (
                curve.load_n.round() as i64,
                (curve.viscosity * 1e4).round() as i64,
            ),
            k.v_half,
        );
    }
    c.checks.push(check(
        "low_speed_limit",
        low.iter().all(|x| (x - mu_bl).abs() < 0.01 * mu_bl),
        format!(
            "COF at v = {LOW_SPEED} m/s: {} (μ_bl = {mu_bl})",
            list(&low, 4)
        ),
    ));
    c.checks.push(check(
        "minimum_then_rise",
        rises >= s.steady.len() - 1,
        format!(
            "{} of {} curves rise after their minimum within 5 m/s; {}",
            rises,
            s.steady.len(),
            minima.join("; ")
        ),
    ));
    c.checks.extend(shift_checks(&half));
    c
}

/// What claim 1 reads from one steady curve.
struct CurveKeys {
    /// The COF at [`LOW_SPEED`].
    cof_low: f64,
    /// Its minimum, as text.
    minimum: String,
    /// Whether it rises by a fifth after its minimum within the curve.
    rising: bool,
    /// The speed where the COF first falls to μ_bl/2, m/s.
    v_half: f64,
}

impl CurveKeys {
    fn of(curve: &crate::studies::SteadyCurve, mu_bl: f64) -> Self {
        let pos: Vec<_> = curve.points.iter().filter(|e| e.velocity > 0.0).collect();
        let cof_low = pos
            .iter()
            .find(|e| (e.velocity - LOW_SPEED).abs() < 1e-12)
            .map_or(f64::NAN, |e| e.cof);
        let min = pos
            .iter()
            .min_by(|a, b| a.cof.total_cmp(&b.cof))
            .expect("points");
        let last = pos.last().expect("points");
        let rising = min.velocity < last.velocity && last.cof > 1.2 * min.cof;
        let minimum = format!(
            "{} min {:.4} at {:.2} m/s{}",
            curve.label,
            min.cof,
            min.velocity,
            if rising { "" } else { " (no rise up to 5 m/s)" }
        );
        let v_half = pos
            .iter()
            .find(|e| e.cof <= 0.5 * mu_bl)
            .map_or(f64::NAN, |e| e.velocity);
        Self {
            cof_low,
            minimum,
            rising,
            v_half,
        }
    }
}

/// The curves' shifts: with viscosity to lower speed, with load to higher
/// speed (`half`: the μ_bl/2 speed by (load N, viscosity × 10⁴)).
fn shift_checks(half: &BTreeMap<(i64, i64), f64>) -> [Check; 2] {
    let loads: Vec<i64> = {
        let mut v: Vec<i64> = half.keys().map(|k| k.0).collect();
        v.dedup();
        v
    };
    let mus: Vec<i64> = {
        let mut v: Vec<i64> = half.keys().map(|k| k.1).collect();
        v.sort();
        v.dedup();
        v
    };
    let mut visc_ok = true;
    let mut visc_ev = Vec::new();
    for &f in &loads {
        let v: Vec<f64> = mus.iter().map(|&m| half[&(f, m)]).collect();
        visc_ok &= decreasing(&v);
        visc_ev.push(format!("F {f} N: {} m/s", list(&v, 3)));
    }
    let mut load_ok = true;
    let mut load_ev = Vec::new();
    for &m in &mus {
        let v: Vec<f64> = loads.iter().map(|&f| half[&(f, m)]).collect();
        load_ok &= increasing(&v);
        load_ev.push(format!("μ {}: {} m/s", m as f64 / 1e4, list(&v, 3)));
    }
    [
        check(
            "viscosity_shifts_to_lower_speed",
            visc_ok,
            format!(
                "speed where COF first falls to μ_bl/2, μ = 0.056, 0.103, 0.143: {}",
                visc_ev.join("; ")
            ),
        ),
        check(
            "load_shifts_to_higher_speed",
            load_ok,
            format!(
                "speed where COF first falls to μ_bl/2, F = 5720, 20762 N: {}",
                load_ev.join("; ")
            ),
        ),
    ]
}
