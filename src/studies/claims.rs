//! The paper's claims (MODEL.md §8, 1–9), evaluated on study results.
//!
//! Each claim is a list of named checks with the numbers behind them; the
//! verdict is computed from the checks, never set by hand. Where MODEL.md
//! expects our model to differ from the paper, the paper's statement is still
//! a check (and is allowed to fail); the difference is explained in
//! `docs/paper-reproduction.md`.

use super::{CaseResult, StudyKind, StudyResult, LOW_SPEED};
use std::collections::BTreeMap;

/// One check of a claim.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    pub name: String,
    pub pass: bool,
    /// The numbers behind the check.
    pub evidence: String,
}

/// Outcome of a claim.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    Reproduced,
    Partly,
    NotReproduced,
    /// Some study the claim needs was not run or failed.
    NotEvaluated,
}

impl Verdict {
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Reproduced => "reproduced",
            Verdict::Partly => "partly reproduced",
            Verdict::NotReproduced => "not reproduced",
            Verdict::NotEvaluated => "not evaluated",
        }
    }
}

/// A claim of MODEL.md §8 with its checks.
#[derive(Debug, Clone, PartialEq)]
pub struct Claim {
    pub number: u8,
    pub statement: &'static str,
    pub checks: Vec<Check>,
    /// Facts worth reporting that are not checks.
    pub observations: Vec<String>,
}

impl Claim {
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
        let pos: Vec<_> = curve.points.iter().filter(|e| e.velocity > 0.0).collect();
        let at_low = pos
            .iter()
            .find(|e| (e.velocity - LOW_SPEED).abs() < 1e-12)
            .map_or(f64::NAN, |e| e.cof);
        low.push(at_low);
        let min = pos
            .iter()
            .min_by(|a, b| a.cof.total_cmp(&b.cof))
            .expect("points");
        let last = pos.last().expect("points");
        let rising = min.velocity < last.velocity && last.cof > 1.2 * min.cof;
        rises += rising as usize;
        minima.push(format!(
            "{} min {:.4} at {:.2} m/s{}",
            curve.label,
            min.cof,
            min.velocity,
            if rising { "" } else { " (no rise up to 5 m/s)" }
        ));
        let v_half = pos
            .iter()
            .find(|e| e.cof <= 0.5 * mu_bl)
            .map_or(f64::NAN, |e| e.velocity);
        half.insert(
            (
                curve.load_n.round() as i64,
                (curve.viscosity * 1e4).round() as i64,
            ),
            v_half,
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
    c.checks.push(check(
        "viscosity_shifts_to_lower_speed",
        visc_ok,
        format!(
            "speed where COF first falls to μ_bl/2, μ = 0.056, 0.103, 0.143: {}",
            visc_ev.join("; ")
        ),
    ));
    let mut load_ok = true;
    let mut load_ev = Vec::new();
    for &m in &mus {
        let v: Vec<f64> = loads.iter().map(|&f| half[&(f, m)]).collect();
        load_ok &= increasing(&v);
        load_ev.push(format!("μ {}: {} m/s", m as f64 / 1e4, list(&v, 3)));
    }
    c.checks.push(check(
        "load_shifts_to_higher_speed",
        load_ok,
        format!(
            "speed where COF first falls to μ_bl/2, F = 5720, 20762 N: {}",
            load_ev.join("; ")
        ),
    ));
    c
}

/// Claim 2: loops grow with amplitude and frequency; branches around the steady curve.
pub fn claim2(r: &Results) -> Claim {
    let mut c = Claim {
        number: 2,
        statement: "Loops grow with amplitude, more so with frequency. Accelerating branch above the steady curve, decelerating below; film thinner than steady when accelerating, thicker when decelerating.",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::AmplitudeFrequency) else {
        return c;
    };
    let area = |v1: &str, f: &str| metric(s, &format!("v1-{v1}_f-{f}"), |m| m.cof_loop_area);
    let mut amp_ok = true;
    let mut ev = Vec::new();
    let mut growth = Vec::new();
    for f in FREQS {
        let a: Vec<f64> = ["0.1", "0.5", "1"].iter().map(|v1| area(v1, f)).collect();
        amp_ok &= increasing(&a);
        growth.push(a[2] - a[0]);
        ev.push(format!("f {f} Hz: {}", sci(&a)));
    }
    c.checks.push(check(
        "area_grows_with_amplitude",
        amp_ok,
        format!(
            "COF loop area (m/s) for V1 = 0.1, 0.5, 1 m/s: {}",
            ev.join("; ")
        ),
    ));
    c.checks.push(check(
        "growth_larger_at_higher_frequency",
        increasing(&growth),
        format!(
            "area(V1 = 1) − area(V1 = 0.1) at f = 0.25, 1, 4 Hz: {}",
            sci(&growth)
        ),
    ));
    let mut freq_ev = Vec::new();
    let mut freq_ok = true;
    for v1 in ["0.1", "0.5", "1"] {
        let a: Vec<f64> = FREQS.iter().map(|f| area(v1, f)).collect();
        if v1 != "0.1" {
            freq_ok &= increasing(&a);
        }
        freq_ev.push(format!("V1 {v1}: {}", sci(&a)));
    }
    c.checks.push(check(
        "area_grows_with_frequency_at_large_amplitude",
        freq_ok,
        format!(
            "COF loop area at f = 0.25, 1, 4 Hz (V1 ≥ 0.5 checked): {}",
            freq_ev.join("; ")
        ),
    ));
    let mut counts = [0usize; 5];
    let mut n = 0;
    let mut rows = Vec::new();
    for v1 in ["0.1", "0.5", "1"] {
        for f in FREQS {
            let id = format!("v1-{v1}_f-{f}");
            let Some(o) = offsets(s, &id) else { continue };
            let gap = metric(s, &id, |m| m.branch_cof_gap.unwrap_or(f64::NAN));
            n += 1;
            counts[0] += (o.cof_accelerating > 0.0) as usize;
            counts[1] += (o.cof_decelerating < 0.0) as usize;
            counts[2] += (o.h0_accelerating < 0.0) as usize;
            counts[3] += (o.h0_decelerating > 0.0) as usize;
            counts[4] += (gap > 0.0) as usize;
            rows.push(format!(
                "V1 {v1} f {f}: ΔCOF acc {:+.4} dec {:+.4}, Δh0 acc {:+.1} nm dec {:+.1} nm",
                o.cof_accelerating,
                o.cof_decelerating,
                o.h0_accelerating * 1e9,
                o.h0_decelerating * 1e9
            ));
        }
    }
    let all = |k: usize| n > 0 && counts[k] == n;
    c.checks.push(check(
        "accelerating_branch_above_decelerating",
        all(4),
        format!("{}/{n} cases", counts[4]),
    ));
    c.checks.push(check(
        "accelerating_branch_above_steady",
        all(0),
        format!("{}/{n} cases", counts[0]),
    ));
    c.checks.push(check(
        "decelerating_branch_below_steady",
        all(1),
        format!("{}/{n} cases", counts[1]),
    ));
    c.checks.push(check(
        "film_thinner_than_steady_when_accelerating",
        all(2),
        format!("{}/{n} cases", counts[2]),
    ));
    c.checks.push(check(
        "film_thicker_than_steady_when_decelerating",
        all(3),
        format!("{}/{n} cases", counts[3]),
    ));
    c.observations.push(format!(
        "Mean offsets from the steady curve at the same velocity: {}",
        rows.join("; ")
    ));
    c
}

/// Claim 3: COF at zero velocity.
pub fn claim3(r: &Results, mu_bl: f64) -> Claim {
    let mut c = Claim {
        number: 3,
        statement: "At v = 0 the COF is non-zero but below μ_bl; it falls as frequency rises.",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::AmplitudeFrequency) else {
        return c;
    };
    let (mut below, mut n, mut falls) = (0, 0, true);
    let mut ev = Vec::new();
    for v1 in ["0.1", "0.5", "1"] {
        let mut acc = Vec::new();
        for f in FREQS {
            let id = format!("v1-{v1}_f-{f}");
            let a = metric(s, &id, |m| m.cof_v0_accelerating.unwrap_or(f64::NAN));
            let d = metric(s, &id, |m| m.cof_v0_decelerating.unwrap_or(f64::NAN));
            n += 2;
            below +=
                (a < mu_bl && a > 0.5 * mu_bl) as usize + (d < mu_bl && d > 0.5 * mu_bl) as usize;
            acc.push(0.5 * (a + d));
            ev.push(format!("V1 {v1} f {f}: acc {a:.4} dec {d:.4}"));
        }
        falls &= decreasing(&acc);
    }
    c.checks.push(check(
        "nonzero_and_below_boundary_friction",
        below == n,
        format!(
            "{below}/{n} one-sided limits in (μ_bl/2, μ_bl); {}",
            ev.join("; ")
        ),
    ));
    c.checks.push(check(
        "falls_with_frequency",
        falls,
        "mean of the two limits decreases over f = 0.25, 1, 4 Hz for every V1 (values above)"
            .into(),
    ));
    c
}

/// Claim 4: load.
pub fn claim4(r: &Results) -> Claim {
    let mut c = Claim {
        number: 4,
        statement: "Load: mean friction rises with load, loop size falls with load.",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::Load) else {
        return c;
    };
    let loads = ["5762", "10762", "20762"];
    let (mut f_ok, mut a_ok) = (true, true);
    let (mut fe, mut ae) = (Vec::new(), Vec::new());
    for f in FREQS {
        let mf: Vec<f64> = loads
            .iter()
            .map(|l| {
                metric(s, &format!("load-{l}_f-{f}"), |m| m.mean_cof)
                    * l.parse::<f64>().expect("load")
            })
            .collect();
        let a: Vec<f64> = loads
            .iter()
            .map(|l| metric(s, &format!("load-{l}_f-{f}"), |m| m.cof_loop_area))
            .collect();
        f_ok &= increasing(&mf);
        a_ok &= decreasing(&a);
        fe.push(format!("f {f} Hz: {} N", list(&mf, 0)));
        ae.push(format!("f {f} Hz: {}", sci(&a)));
    }
    c.checks.push(check(
        "mean_friction_rises_with_load",
        f_ok,
        format!("mean |F_f| for F = 5762, 10762, 20762 N: {}", fe.join("; ")),
    ));
    c.checks.push(check(
        "loop_size_falls_with_load",
        a_ok,
        format!("COF loop area (m/s): {}", ae.join("; ")),
    ));
    c
}

/// Claim 5: viscosity.
pub fn claim5(r: &Results) -> Claim {
    let mut c = Claim {
        number: 5,
        statement: "Viscosity: mean friction falls with viscosity.",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::Viscosity) else {
        return c;
    };
    let mus = ["0.056", "0.103", "0.143"];
    let mut ok = true;
    let mut ev = Vec::new();
    let mut grow = Vec::new();
    for f in FREQS {
        let m: Vec<f64> = mus
            .iter()
            .map(|mu| metric(s, &format!("mu-{mu}_f-{f}"), |m| m.mean_cof))
            .collect();
        ok &= decreasing(&m);
        ev.push(format!("f {f} Hz: {}", list(&m, 4)));
    }
    for mu in mus {
        let a: Vec<f64> = FREQS
            .iter()
            .map(|f| metric(s, &format!("mu-{mu}_f-{f}"), |m| m.cof_loop_area))
            .collect();
        grow.push(format!(
            "μ {mu}: {}{}",
            sci(&a),
            if increasing(&a) {
                " (grows with f)"
            } else {
                ""
            }
        ));
    }
    c.checks.push(check(
        "mean_friction_falls_with_viscosity",
        ok,
        format!(
            "mean COF for μ = 0.056, 0.103, 0.143 Pa·s: {}",
            ev.join("; ")
        ),
    ));
    c.observations.push(format!(
        "COF loop area over f = 0.25, 1, 4 Hz: {}",
        grow.join("; ")
    ));
    c
}

fn slope(a: f64, b: f64, fa: f64, fb: f64) -> f64 {
    (b / a).ln() / (fb / fa).ln()
}

/// Claim 6: inertia.
pub fn claim6(r: &Results) -> Claim {
    let mut c = Claim {
        number: 6,
        statement: "Inertia: loops for m = 0.1…100 kg are indistinguishable; M ≈ 1e-6 %…1e-3 %, M ∝ m and ∝ f².",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::Inertia) else {
        return c;
    };
    let masses = ["0.1", "1", "10", "100"];
    let mut worst: f64 = 0.0;
    for f in FREQS {
        let Some(base) = s.case(&format!("m-1_f-{f}")) else {
            continue;
        };
        for m in masses {
            if let Some(o) = s.case(&format!("m-{m}_f-{f}")) {
                worst = worst.max(o.max_cof_difference(base));
            }
        }
    }
    c.checks.push(check(
        "loops_indistinguishable",
        worst < 1e-3,
        format!("largest COF difference from m = 1 kg over a cycle: {worst:.2e}"),
    ));
    let raw: Vec<f64> = masses
        .iter()
        .flat_map(|m| FREQS.iter().map(move |f| (m, f)))
        .map(|(m, f)| metric(s, &format!("m-{m}_f-{f}"), |x| x.inertia_share))
        .collect();
    let smooth: Vec<f64> = masses
        .iter()
        .flat_map(|m| FREQS.iter().map(move |f| (m, f)))
        .map(|(m, f)| metric(s, &format!("m-{m}_f-{f}"), |x| x.inertia_share_smooth))
        .collect();
    let range = |v: &[f64]| {
        (
            v.iter().cloned().fold(f64::INFINITY, f64::min) * 100.0,
            v.iter().cloned().fold(0.0, f64::max) * 100.0,
        )
    };
    let (rl, rh) = range(&raw);
    let (sl, sh) = range(&smooth);
    c.checks.push(check(
        "inertia_negligible",
        rh < 1.0,
        format!("largest raw M {rh:.2e} % (m = 100 kg, 4 Hz)"),
    ));
    c.observations.push(format!(
        "M over m = 0.1…100 kg and f = 0.25…4 Hz: raw maximum {rl:.1e} % … {rh:.1e} %, smooth part {sl:.1e} % … {sh:.1e} % (paper: 1e-6 % … 1e-3 %; m·f² alone spans a factor 2.6e5)"
    ));
    let mut prop = Vec::new();
    let mut prop_ok = true;
    for f in FREQS {
        let a = metric(s, &format!("m-0.1_f-{f}"), |x| x.inertia_share);
        let b = metric(s, &format!("m-100_f-{f}"), |x| x.inertia_share);
        prop_ok &= (b / a / 1000.0 - 1.0).abs() < 0.02;
        prop.push(b / a);
    }
    c.checks.push(check(
        "proportional_to_mass",
        prop_ok,
        format!(
            "M(100 kg)/M(0.1 kg) at f = 0.25, 1, 4 Hz: {}",
            list(&prop, 1)
        ),
    ));
    let fs = [0.25, 1.0, 4.0];
    let sm: Vec<f64> = FREQS
        .iter()
        .map(|f| metric(s, &format!("m-1_f-{f}"), |x| x.inertia_share_smooth))
        .collect();
    let rw: Vec<f64> = FREQS
        .iter()
        .map(|f| metric(s, &format!("m-1_f-{f}"), |x| x.inertia_share))
        .collect();
    let ss = [
        slope(sm[0], sm[1], fs[0], fs[1]),
        slope(sm[1], sm[2], fs[1], fs[2]),
    ];
    let rs = [
        slope(rw[0], rw[1], fs[0], fs[1]),
        slope(rw[1], rw[2], fs[1], fs[2]),
    ];
    c.checks.push(check(
        "smooth_part_scales_with_frequency_squared",
        ss.iter().all(|x| (1.5..2.5).contains(x)),
        format!("log–log slope of the smooth M against f: {}", list(&ss, 2)),
    ));
    c.checks.push(check(
        "raw_maximum_scales_with_frequency_squared",
        rs.iter().all(|x| (1.5..2.5).contains(x)),
        format!("log–log slope of the raw max |m h0''| / F against f: {} (the maximum sits on the vapour-pocket collapse spike)", list(&rs, 2)),
    ));
    c
}

/// Claim 7: unidirectional loops.
pub fn claim7(r: &Results) -> Claim {
    let mut c = Claim {
        number: 7,
        statement: "Unidirectional loops are centred on the steady Stribeck curve; largest in mixed lubrication, small near full film.",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::Unidirectional) else {
        return c;
    };
    let v0s = ["0.05", "0.25", "0.5", "1", "2", "3"];
    // The paper's Fig. 11 covers V0 = 0.05, 0.25, 0.5 m/s; 1, 2, 3 m/s extend
    // it to full film.
    let paper = ["0.05", "0.25", "0.5"];
    let mut worst: f64 = 0.0;
    let mut extended = Vec::new();
    let mut place_ok = true;
    let mut ev = Vec::new();
    for f in FREQS {
        let mut areas = Vec::new();
        let mut shares = Vec::new();
        for v0 in v0s {
            let id = format!("v0-{v0}_f-{f}");
            if let (Some(o), Some(cr)) = (offsets(s, &id), s.case(&id)) {
                let lo = cr
                    .last_cycle
                    .iter()
                    .map(|e| e.cof)
                    .fold(f64::INFINITY, f64::min);
                let hi = cr.last_cycle.iter().map(|e| e.cof).fold(0.0, f64::max);
                let rel = o.cof_mean / (0.5 * (hi - lo));
                if paper.contains(&v0) {
                    worst = worst.max(rel.abs());
                } else {
                    extended.push(format!("V0 {v0} f {f}: {rel:+.2}"));
                }
            }
            areas.push(metric(s, &id, |m| m.cof_loop_area));
            shares.push(metric(s, &id, |m| m.mean_asperity_share));
        }
        let (imax, amax) =
            areas
                .iter()
                .enumerate()
                .fold((0, f64::MIN), |a, (i, &x)| if x > a.1 { (i, x) } else { a });
        let mixed = shares[imax] > 0.05 && shares[imax] < 0.95;
        let small_ends = areas[0] < 0.25 * amax
            && areas[areas.len() - 1] < 0.25 * amax
            && shares[shares.len() - 1] < 0.05;
        place_ok &= mixed && small_ends;
        ev.push(format!(
            "f {f} Hz: areas {} with asperity shares {}; largest at V0 = {} m/s",
            sci(&areas),
            list(&shares, 3),
            v0s[imax]
        ));
    }
    c.observations.push(format!(
        "Beyond the paper's range, mean offset from the steady curve over the loop's half-height: {} (at 4 Hz near full film the squeeze film keeps the film thick and the whole loop lies below the steady curve)",
        extended.join("; ")
    ));
    c.checks.push(check(
        "centred_on_steady_curve",
        worst < 0.05,
        format!(
            "largest |mean(COF − COF_steady(v(t)))| over the loop's half-height, V0 = 0.05, 0.25, 0.5 m/s, all f: {:.1} %",
            100.0 * worst
        ),
    ));
    c.checks.push(check(
        "largest_in_mixed_small_near_full_film",
        place_ok,
        format!("V0 = 0.05 … 3 m/s: {}", ev.join("; ")),
    ));
    c
}

/// Claim 8: roughness.
pub fn claim8(r: &Results) -> Claim {
    let mut c = Claim {
        number: 8,
        statement: "Roughness: COF rises and loops shrink with σ; at σ = 2.5 µm the fluid carries > 75 % of the load, at 7.5 µm the asperities do (at the speeds of Fig. 13).",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::Roughness) else {
        return c;
    };
    let sigmas = ["2.5", "5", "7.5"];
    let (mut cof_ok, mut area_ok) = (true, true);
    let (mut ce, mut ae) = (Vec::new(), Vec::new());
    for v0 in ["1", "0.25"] {
        for f in FREQS {
            let m: Vec<f64> = sigmas
                .iter()
                .map(|sg| metric(s, &format!("v0-{v0}_sigma-{sg}_f-{f}"), |m| m.mean_cof))
                .collect();
            let a: Vec<f64> = sigmas
                .iter()
                .map(|sg| metric(s, &format!("v0-{v0}_sigma-{sg}_f-{f}"), |m| m.cof_loop_area))
                .collect();
            cof_ok &= increasing(&m);
            area_ok &= decreasing(&a);
            ce.push(format!("V0 {v0} f {f}: {}", list(&m, 4)));
            ae.push(format!("V0 {v0} f {f}: {}", sci(&a)));
        }
    }
    c.checks.push(check(
        "cof_rises_with_roughness",
        cof_ok,
        format!("mean COF for σ = 2.5, 5, 7.5 µm: {}", ce.join("; ")),
    ));
    c.checks.push(check(
        "loops_shrink_with_roughness",
        area_ok,
        format!("COF loop area (m/s): {}", ae.join("; ")),
    ));
    let share = |v0: &str, sg: &str, fluid: bool| -> Vec<f64> {
        FREQS
            .iter()
            .map(|f| {
                metric(s, &format!("v0-{v0}_sigma-{sg}_f-{f}"), |m| {
                    if fluid {
                        m.mean_fluid_share
                    } else {
                        m.mean_asperity_share
                    }
                })
            })
            .collect()
    };
    let fl = share("1", "2.5", true);
    let asp = share("1", "7.5", false);
    c.checks.push(check(
        "fluid_carries_load_at_2_5_um",
        fl.iter().all(|x| *x > 0.75),
        format!(
            "mean fluid share at σ = 2.5 µm, V0 = 1 m/s, f = 0.25, 1, 4 Hz: {}",
            list(&fl, 3)
        ),
    ));
    c.checks.push(check(
        "asperities_carry_load_at_7_5_um",
        asp.iter().all(|x| *x > 0.75),
        format!(
            "mean asperity share at σ = 7.5 µm, V0 = 1 m/s: {}",
            list(&asp, 3)
        ),
    ));
    c.observations.push(format!(
        "At V0 = 0.25 m/s the fluid share at σ = 2.5 µm is {} and the asperity share at 7.5 µm is {}",
        list(&share("0.25", "2.5", true), 3),
        list(&share("0.25", "7.5", false), 3)
    ));
    c
}

/// Claim 9: the Hersey number.
pub fn claim9(r: &Results) -> Claim {
    let mut c = Claim {
        number: 9,
        statement: "The Hersey number alone does not collapse the loops.",
        checks: Vec::new(),
        observations: Vec::new(),
    };
    let Some(s) = r.get(&StudyKind::Hersey) else {
        return c;
    };
    let mut ok = true;
    let mut ev = Vec::new();
    for g in ["1", "2"] {
        let a: Vec<f64> = (1..=4)
            .map(|k| metric(s, &format!("group-{g}_{k}"), |m| m.cof_loop_area))
            .collect();
        let mean: Vec<f64> = (1..=4)
            .map(|k| metric(s, &format!("group-{g}_{k}"), |m| m.mean_cof))
            .collect();
        let ratio =
            a.iter().cloned().fold(0.0, f64::max) / a.iter().cloned().fold(f64::INFINITY, f64::min);
        ok &= ratio > 1.5;
        ev.push(format!(
            "group {g}: COF loop areas {} (max/min {ratio:.2}), mean COF {}",
            sci(&a),
            list(&mean, 4)
        ));
    }
    c.checks.push(check(
        "equal_hersey_ranges_give_different_loops",
        ok,
        ev.join("; "),
    ));
    c
}

/// Whether a case failed (for reporting).
pub fn failed_cases(r: &Results) -> Vec<&CaseResult> {
    r.values()
        .flat_map(|s| s.cases.iter().filter(|c| c.failed()))
        .collect()
}
