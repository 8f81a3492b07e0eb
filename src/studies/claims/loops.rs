//! Claims about the loops' shape: 2 (amplitude, frequency, branches), 3
//! (COF at zero velocity), 7 (unidirectional loops), 9 (the Hersey number).

use super::*;

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
    c.checks.extend(area_checks(s));
    let (checks, observation) = branch_checks(s);
    c.checks.extend(checks);
    c.observations.push(observation);
    c
}

/// Claim 2's loop areas: growing with amplitude, more so at higher
/// frequency, and with frequency at large amplitude.
fn area_checks(s: &StudyResult) -> [Check; 3] {
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
    let mut freq_ev = Vec::new();
    let mut freq_ok = true;
    for v1 in ["0.1", "0.5", "1"] {
        let a: Vec<f64> = FREQS.iter().map(|f| area(v1, f)).collect();
        if v1 != "0.1" {
            freq_ok &= increasing(&a);
        }
        freq_ev.push(format!("V1 {v1}: {}", sci(&a)));
    }
    [
        check(
            "area_grows_with_amplitude",
            amp_ok,
            format!(
                "COF loop area (m/s) for V1 = 0.1, 0.5, 1 m/s: {}",
                ev.join("; ")
            ),
        ),
        check(
            "growth_larger_at_higher_frequency",
            increasing(&growth),
            format!(
                "area(V1 = 1) − area(V1 = 0.1) at f = 0.25, 1, 4 Hz: {}",
                sci(&growth)
            ),
        ),
        check(
            "area_grows_with_frequency_at_large_amplitude",
            freq_ok,
            format!(
                "COF loop area at f = 0.25, 1, 4 Hz (V1 ≥ 0.5 checked): {}",
                freq_ev.join("; ")
            ),
        ),
    ]
}

/// Claim 2's branches against the steady curve and each other, and the
/// mean offsets as an observation.
fn branch_checks(s: &StudyResult) -> ([Check; 5], String) {
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
    let all = |name: &str, k: usize| {
        check(
            name,
            n > 0 && counts[k] == n,
            format!("{}/{n} cases", counts[k]),
        )
    };
    (
        [
            all("accelerating_branch_above_decelerating", 4),
            all("accelerating_branch_above_steady", 0),
            all("decelerating_branch_below_steady", 1),
            all("film_thinner_than_steady_when_accelerating", 2),
            all("film_thicker_than_steady_when_decelerating", 3),
        ],
        format!(
            "Mean offsets from the steady curve at the same velocity: {}",
            rows.join("; ")
        ),
    )
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
