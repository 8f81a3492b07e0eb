//! Friction in the wrong sign convention (a drive's reaction, a magnitude)
//! is refused, naming the sign, on time series and on short steady curves.

use super::*;

#[test]
fn friction_whose_sign_opposes_the_velocity_is_refused_naming_the_sign_not_fitted() {
    let d = dir("sign");
    let joint = joint_record(&d, 0.5, 2.0);
    let fit = |friction: &str| {
        run(&[
            "fit",
            joint.to_str().unwrap(),
            "--rotary",
            "--velocity",
            "velocity_rad_s",
            "--friction",
            friction,
            "--set",
            "solver.cells=32",
            "--fit",
            "auto",
            "--starts",
            "1",
            "--global-points",
            "0",
            "--max-evaluations",
            "10",
            "--out",
            d.join("f.yaml").to_str().unwrap(),
        ])
    };
    // The recording's torque as a drive would log the reaction: negated.
    let (code, _, err) = fit("-torque_nm");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("its sign opposes the velocity's") && err.contains("--friction '-(EXPR)'"),
        "{err}"
    );
    assert!(!d.join("f.yaml").exists());
    // The same record with its own sign is fitted.
    let (code, _, err) = fit("torque_nm");
    assert!(code == 0 || code == 4, "{err}");
}

#[test]
fn a_steady_curve_whose_friction_opposes_the_velocity_or_is_its_magnitude_is_refused_though_it_has_only_a_few_points(
) {
    // Eight steady points one way, as a lead screw's curve is measured:
    // each point a steady state, so eight that all oppose the velocity are
    // a sign convention (the drivetrain asymmetry would otherwise carry
    // the flipped level and the fit say "converged").
    let d = dir("sign-steady");
    // `backward`: each speed also taken backward with friction `backward`
    // times the forward one (-1 friction, +1 its magnitude).
    let write_both = |name: &str, sign: f64, backward: Option<f64>| {
        let mut text = String::from("velocity_rad_s,friction_nm\n");
        for k in 1..=8 {
            let w = 2.0 * k as f64;
            let f = sign * (2.6e-3 + 1e-5 * w);
            text += &format!("{w},{f}\n");
            if let Some(b) = backward {
                text += &format!("{},{}\n", -w, b * f);
            }
        }
        let path = d.join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    let write = |name: &str, sign: f64| write_both(name, sign, None);
    let out = d.join("f.yaml");
    // `fit` with `--validate` files besides.
    let fit_validated = |csv: &Path, validate: &[&Path]| {
        let mut args = vec!["fit", csv.to_str().unwrap()];
        for v in validate {
            args.extend(["--validate", v.to_str().unwrap()]);
        }
        args.extend(["--rotary", "--fit", "auto", "--out", out.to_str().unwrap()]);
        run(&args)
    };
    let fit = |csv: &Path| fit_validated(csv, &[]);
    let (code, _, err) = fit(&write("negated.csv", -1.0));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("its sign opposes the velocity's in 100.0 % of the sliding samples (8 of 8"),
        "{err}"
    );
    assert!(!d.join("f.yaml").exists());
    // Its magnitude both ways, as a tribometer reports μ: one sign, no
    // change with the direction of motion.
    let (code, _, err) = fit(&write_both("magnitude.csv", 1.0, Some(1.0)));
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("one sign in both directions")
            && err.contains("--friction 'if(VELOCITY < 0, -(EXPR), EXPR)'"),
        "{err}"
    );
    assert!(!d.join("f.yaml").exists());
    // A held-out file in the other convention: refused by its name, not
    // scored against a model with the right one.
    let negated = write("negated-validation.csv", -1.0);
    let (code, _, err) = fit_validated(&write("own-sign.csv", 1.0), &[&negated]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("the friction of --validate") && err.contains("negated-validation.csv"),
        "{err}"
    );
    assert!(!d.join("f.yaml").exists());
    let (code, _, err) = fit(&write("own-sign.csv", 1.0));
    assert!(code == 0 || code == 4, "{err}");
    assert!(d.join("f.yaml").exists());
    std::fs::remove_file(d.join("f.yaml")).unwrap();
    let (code, _, err) = fit(&write_both("both-ways.csv", 1.0, Some(-1.0)));
    assert!(code == 0 || code == 4, "{err}");
    assert!(d.join("f.yaml").exists());
}
