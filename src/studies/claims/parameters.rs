//! Claims about the operating parameters: 4 (load), 5 (viscosity), 6
//! (inertia, with the slope helper), 8 (roughness).

use super::*;

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
    inertia_size(s, &mut c);
    inertia_scaling(s, &mut c);
    c
}

/// Claim 6: the loops' indifference to mass and the size of the inertia
/// share.
fn inertia_size(s: &StudyResult, c: &mut Claim) {
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
}

/// Claim 6: the inertia share's proportionality to mass and to f².
fn inertia_scaling(s: &StudyResult, c: &mut Claim) {
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
