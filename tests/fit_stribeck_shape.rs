//! Rule 7d of `--fit auto` (`fit/candidates.rs`, "drivetrain Stribeck
//! shape"): a Stribeck fall with its own exponent, ΔF_s e^(−|v/v_s|^α_s)
//! (`physics::terms::drivetrain`). Measured falls have α_s of 0.5–2; the
//! classic curve and LuGre fix 2, the Gaussian fall, whose tail is too
//! short for a fall with α_s below 2. Without the exponent a fit lets
//! another term take that tail (on the time-series draw d199 a bend of a
//! straight viscous part, 1.166× LuGre on the faster motion), and that
//! term changes the prediction past the data.

mod common;

/// A drive whose friction rises from 0.5 to 1 N with a fall of exponent
/// 0.8 (a long tail: at 3 v_s, 9 % of the rise is left) over a straight
/// viscous part of 1 N at 0.2 m/s.
const LONG_TAIL: common::records::Drive = common::records::Drive {
    fc: 1.0,
    fs: 0.5,
    vs: 0.01,
    alpha: 0.8,
    b_top: 1.0,
    v_top: 0.2,
    delta: 1.0,
};

#[test]
fn a_stribeck_fall_with_a_long_tail_is_fitted_with_its_own_exponent_and_predicts_faster_moves_better_than_the_gaussian_classics(
) {
    // 8 s of point-to-point moves up to 0.2 m/s, predicting the same
    // moves twice as fast.
    let (code, stdout, err) = LONG_TAIL.fit_auto_on_moves("stribeck-shape", (21, 22));
    assert_eq!(code, 0, "{err}");
    let chosen = common::cli::chosen(&stdout);
    assert!(chosen.contains("drivetrain Stribeck shape"), "{chosen}");
    assert!(!chosen.contains("drivetrain bend"), "{chosen}");
    let alpha = common::cli::fitted_key(&stdout, "drivetrain.stribeck_exponent");
    approx::assert_abs_diff_eq!(alpha, 0.8, epsilon = 0.15);
    let held = |m: &str| common::cli::held_out(&stdout, m);
    let best_classic = ["Coulomb + viscous", "Stribeck", "LuGre"]
        .iter()
        .filter(|m| stdout.contains(&format!("| {m} |")))
        .map(|m| held(m))
        .fold(f64::INFINITY, f64::min);
    // Ours 0.016428 N against the Stribeck classic's 0.022232 (0.739x).
    assert!(
        held("friction-node") < 0.8 * best_classic,
        "ours {} against the best classic {best_classic}",
        held("friction-node")
    );
}
