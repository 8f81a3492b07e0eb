//! The verdict, the summary's first line, on records whose models' errors
//! are at the resolution of their arithmetic: a steady curve made by
//! Coulomb + viscous without noise is reproduced by ours (to ~1e-8 of
//! the friction) and by the classic (to ~1e-14), and the verdict says
//! that such data compare nothing instead of calling ours millions of
//! per cent worse. With a measurement's noise the verdict compares.

mod common;
use common::cli::run;

use std::path::Path;

/// A joint's steady curve f(ω) = sgn ω (0.3 + 0.05 |ω|) N·m at ten
/// speeds each way, with `noise` N·m added alternately up and down.
fn curve(path: &Path, noise: f64) {
    let mut text = String::from("velocity_rad_s,friction_nm\n");
    let speeds = [0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.8, 1.0, 1.2];
    for (k, w) in speeds.iter().enumerate() {
        let e = if k % 2 == 0 { noise } else { -noise };
        let f = 0.3 + 0.05 * w;
        text += &format!("{w},{}\n-{w},{}\n", f + e, -f + e);
    }
    std::fs::write(path, text).unwrap();
}

fn verdict(name: &str, noise: f64) -> String {
    let d = common::cli::fresh_dir("verdict", name);
    let data = d.join("curve.csv");
    curve(&data, noise);
    let (code, stdout, err) = run(&[
        "fit",
        data.to_str().unwrap(),
        "--rotary",
        "--fit",
        "auto",
        "--baselines",
        "--out",
        d.join("f.yaml").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    stdout
        .lines()
        .find(|l| l.starts_with("**Verdict"))
        .unwrap_or_else(|| panic!("no verdict in\n{stdout}"))
        .to_string()
}

#[test]
fn a_curve_without_noise_is_reproduced_by_both_and_the_verdict_compares_nothing() {
    let v = verdict("exact", 0.0);
    assert!(
        v.contains("both reproduce these data exactly")
            && v.contains("below 1e-6 of the measured friction's RMS"),
        "{v}"
    );
    assert!(!v.contains("not the best"), "{v}");
}

#[test]
fn a_curve_with_a_measurements_noise_is_compared() {
    let v = verdict("noisy", 0.003);
    assert!(!v.contains("reproduce these data exactly"), "{v}");
    assert!(
        v.contains("predict alike") || v.contains("predicts best") || v.contains("not the best"),
        "{v}"
    );
}
