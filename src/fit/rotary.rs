//! A rotary joint's recording in its own units: velocity in rad/s,
//! friction in N·m (`fit --rotary`).
//!
//! The model is a sliding contact; the joint drives it through a lever arm
//! r, the contact's `gain`: it slides at v = r ω and puts τ = r F on the
//! joint. A joint's recording cannot tell the contact's size, load and
//! lever arm apart from the friction coefficients and the viscosity fitted
//! on them, so the tool keeps the configured contact's geometry and
//! chooses r and the load F_N from the data:
//!
//! 1. the data's top speed maps to the contact's **transition speed**:
//!    r ω_top = v_t(F_N), the speed at which the configured lubricant
//!    carries half the load on its film (steady state). The data then span
//!    the boundary and the mixed regime, so the boundary friction and the
//!    film both act on them from the start, and the viscosity's bounds (a
//!    decade either way) move the transition anywhere across the data;
//! 2. the configured boundary friction gives the data's **sliding level**:
//!    μ_bl F_N r = τ_level, the mean |τ| of the samples that slide faster
//!    than a tenth of the top speed.
//!
//! Together: F_N v_t(F_N) = τ_level ω_top / μ_bl. The film's lift grows
//! with speed and falls with load (v_t ∝ F_N for a rigid contact, the
//! Hersey number), so the left side grows with F_N; it is solved by the
//! secant method on log F_N and bisection as a fall-back.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | ω, ω_top | joint speed, the data's largest | rad/s |
//! | τ, τ_level | joint friction, the data's sliding level | N·m |
//! | r | lever arm (`gain`) | m |
//! | F_N | contact load (`contact.load_n`) | N |
//! | v_t | transition speed: half the load on the film | m/s |
//! | μ_bl | boundary friction (`contact.boundary_friction`) | – |

use super::series::Source;
use super::unknowns::ParamSpec;
use super::FitError;
use crate::config::Config;
use crate::physics::Solver;

/// The lever arm and load chosen for (or configured with) a joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Lever {
    /// r, m: contact speed = r ω, joint torque = r F.
    pub lever_m: f64,
    /// The contact's load F_N, N.
    pub load_n: f64,
    /// How they were found, in words (for the report).
    pub how: String,
}

/// The transition speed's search range, m/s (within the solver's inputs).
const SPEEDS_M_S: (f64, f64) = (1e-7, 50.0);
/// Points per decade of the sweep.
const POINTS_PER_DECADE: f64 = 6.0;
/// The load's search range, N.
const LOADS_N: (f64, f64) = (1e-3, 1e9);

/// The asperity share of the load in steady sliding at `v` under `load`.
/// A steady state that did not converge counts as no lift (share 1).
fn asperity_share(solver: &mut Solver, v: f64, load: f64) -> f64 {
    let e = solver.steady(v, load);
    if e.status == crate::physics::Status::Converged && e.asperity_load_share.is_finite() {
        e.asperity_load_share
    } else {
        1.0
    }
}

/// v_t(F_N): the speed at which half the load is on the film. A Stribeck
/// sweep upward in speed on a log grid (each steady state warm-started
/// from the one before, as `stribeck` does), interpolated in log v at the
/// first crossing of ½; the range's end when the share does not cross ½
/// inside it.
fn transition_speed(config: &Config, load: f64) -> Result<f64, FitError> {
    let mut c = config.clone();
    c.contact.load_n = load;
    c.validate()?;
    let mut solver = Solver::new(&c.model(), &c.solver_settings()).map_err(|e| FitError::Data {
        what: "--rotary".into(),
        message: format!("the configured contact cannot be solved at {load} N: {e}"),
    })?;
    let (lo, hi) = (SPEEDS_M_S.0.ln(), SPEEDS_M_S.1.ln());
    let points = ((hi - lo) / std::f64::consts::LN_10 * POINTS_PER_DECADE).ceil() as usize;
    let mut before: Option<(f64, f64)> = None;
    for k in 0..=points {
        let ln_v = lo + (hi - lo) * k as f64 / points as f64;
        let share = asperity_share(&mut solver, ln_v.exp(), load);
        if share <= 0.5 {
            return Ok(match before {
                None => ln_v.exp(),
                Some((ln_b, b)) => (ln_b + (ln_v - ln_b) * (b - 0.5) / (b - share)).exp(),
            });
        }
        before = Some((ln_v, share));
    }
    Ok(SPEEDS_M_S.1)
}

/// Choose r and F_N for a joint whose data have top speed `omega_top`
/// (rad/s) and sliding level `tau_level` (N·m), on `config`'s contact.
pub fn choose(config: &Config, omega_top: f64, tau_level: f64) -> Result<Lever, FitError> {
    let mu = config.contact.boundary_friction;
    if !(omega_top > 0.0 && tau_level > 0.0 && omega_top.is_finite() && tau_level.is_finite()) {
        return Err(FitError::Data {
            what: "--rotary".into(),
            message: format!(
                "the data's top speed ({omega_top} rad/s) and sliding level ({tau_level} N·m) must be positive to choose a lever arm"
            ),
        });
    }
    if mu <= 0.0 {
        return Err(FitError::Data {
            what: "--rotary".into(),
            message: "contact.boundary_friction is 0: the load cannot be chosen from the data's level; set it (e.g. 0.1) as the start".into(),
        });
    }
    let target = (tau_level * omega_top / mu).ln();
    // g(ln F) = ln(F v_t(F)) − target, increasing.
    let g = |ln_f: f64| -> Result<f64, FitError> {
        let f = ln_f.exp();
        Ok((f * transition_speed(config, f)?).ln() - target)
    };
    let (mut a, mut b) = (LOADS_N.0.ln(), LOADS_N.1.ln());
    let ln_f = if g(a)? >= 0.0 {
        a
    } else if g(b)? <= 0.0 {
        b
    } else {
        // Secant steps from the configured load, kept inside the bracket
        // [a, b] (g(a) < 0 < g(b)); a step that leaves it bisects.
        let mut x = config.contact.load_n.ln().clamp(a, b);
        let mut gx = g(x)?;
        let mut x_prev = x + 1.0;
        let mut g_prev = g(x_prev)?;
        for _ in 0..40 {
            if gx.abs() < 1e-3 {
                break;
            }
            if gx < 0.0 {
                a = x;
            } else {
                b = x;
            }
            let slope = (gx - g_prev) / (x - x_prev);
            let mut next = x - gx / slope;
            if !(slope > 0.0 && next > a && next < b) {
                next = 0.5 * (a + b);
            }
            (x_prev, g_prev) = (x, gx);
            x = next;
            gx = g(x)?;
        }
        x
    };
    let load_n = ln_f.exp();
    let v_t = transition_speed(config, load_n)?;
    let lever_m = v_t / omega_top;
    Ok(Lever {
        lever_m,
        load_n,
        how: format!(
            "chosen from the data: the top speed {} rad/s slides at the contact's transition speed {} m/s (half the load on the film at the configured viscosity), and the boundary friction {} gives the sliding level {} N·m",
            crate::text::Num(omega_top),
            crate::text::Num(v_t),
            crate::text::Num(mu),
            crate::text::Num(tau_level)
        ),
    })
}

/// A rotary joint's model configuration and lever: the configuration's
/// one contact with its gain, or a lever arm and load chosen from the data
/// (their start values); a bound on the boundary friction that excludes the
/// value the chosen load rests on is an error naming both.
pub fn setup(
    config: &Config,
    train: &[Source],
    map: &[f64],
    specs: &[ParamSpec],
) -> Result<(Config, Lever), FitError> {
    let contacts = config.resolved_contacts();
    if config.contacts.0.len() > 1 {
        return Err(FitError::Data {
            what: "--rotary".into(),
            message: format!(
                "the configuration has {} contacts; a joint's fit needs one (or none: the top level)",
                contacts.len()
            ),
        });
    }
    let one = &contacts[0];
    if !config.contacts.is_empty() && one.gain != 1.0 {
        return Ok((
            one.config.clone(),
            Lever {
                lever_m: one.gain,
                load_n: one.config.contact.load_n,
                how: format!("configured: contacts.{}.gain", one.name),
            },
        ));
    }
    let (mut top, mut sum, mut n) = (0.0f64, 0.0, 0usize);
    let mut all = Vec::new();
    for s in train {
        all.push(s.series(map)?);
    }
    for se in &all {
        top = se.velocity.iter().fold(top, |m, v| m.max(v.abs()));
    }
    for se in &all {
        for k in (0..se.len()).filter(|&k| se.velocity[k].abs() > 0.1 * top) {
            sum += se.friction[k].abs();
            n += 1;
        }
    }
    let level = sum / n.max(1) as f64;
    let lever = choose(&one.config, top, level)?;
    let mut c = one.config.clone();
    if all.iter().all(|s| s.load.is_none()) {
        c.contact.load_n = lever.load_n;
    }
    let mu = c.contact.boundary_friction;
    for s in specs
        .iter()
        .filter(|s| s.name == "contact.boundary_friction")
    {
        if let Some((lo, hi)) = s.bounds {
            if !(lo..=hi).contains(&mu) {
                return Err(FitError::Bounds {
                    key: s.name.clone(),
                    message: format!(
                        "{lo}:{hi} excludes {mu}, the boundary friction on which the chosen scale rests (load {} N and lever arm {} m give the data's sliding level {} N·m with it): widen the bounds, or set contact.boundary_friction inside them in the configuration (the load is then chosen from that value)",
                        crate::text::Num(lever.load_n),
                        crate::text::Num(lever.lever_m),
                        crate::text::Num(level)
                    ),
                });
            }
        }
    }
    Ok((c, lever))
}

/// `config` as the one contact of joint `joint` with lever arm `lever_m`
/// as its gain: the node, driven by that joint's `JointState`, slides the
/// contact at `lever_m` × the joint's velocity and publishes its effort in
/// N·m.
pub fn on_joint(config: Config, joint: &str, lever_m: f64) -> Config {
    use crate::config::{ContactEntry, ContactList, ContactSolverConfig};
    let entry = ContactEntry {
        name: joint.to_string(),
        joint: joint.to_string(),
        gain: lever_m,
        contact: config.contact.clone(),
        texture: config.texture.clone(),
        lubricant: config.lubricant.clone(),
        roughness: config.roughness.clone(),
        solver: ContactSolverConfig {
            cells: config.solver.cells,
        },
    };
    Config {
        contacts: ContactList(vec![entry]),
        ..config
    }
}

/// A fitted contact key's value as it acts on the joint behind lever arm
/// `lever_m` (v = r ω, τ = r F): a force times r (N·m), a stiffness or a
/// damping times r² (per rad), a quadratic loss times r³, a speed divided
/// by r (rad/s). None for a property of the contact itself (a friction
/// coefficient, the viscosity, the roughness, a load), which reads the
/// same on the joint.
pub fn joint_equivalent(key: &str, value: f64, lever_m: f64) -> Option<(f64, &'static str)> {
    let r = lever_m;
    Some(match key {
        "drivetrain.coulomb_n" | "drivetrain.coulomb_asymmetry_n" => (value * r, "N·m"),
        "drivetrain.viscous_n_s_m" => (value * r * r, "N·m·s/rad"),
        "drivetrain.quadratic_n_s2_m2" => (value * r * r * r, "N·m·s²/rad²"),
        "contact.presliding_stiffness_n_m" => (value * r * r, "N·m/rad"),
        "contact.presliding_damping_n_s_m" => (value * r * r, "N·m·s/rad"),
        "contact.boundary_activation_speed_m_s" | "contact.sign_regularization_m_s" => {
            (value / r, "rad/s")
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn every_friction_term_key_with_a_force_or_a_speed_has_its_joint_equivalent() {
        for k in crate::physics::terms::catalogue() {
            let dimensional = k.unit.contains('N') || k.unit.contains("m/s");
            // A load is the contact's normal load, not a force on the joint.
            let load = k.key.ends_with("_load_n");
            assert_eq!(
                joint_equivalent(k.key, 1.0, 0.1).is_some(),
                dimensional && !load,
                "{} ({})",
                k.key,
                k.unit
            );
        }
        let (v, unit) = joint_equivalent("contact.presliding_stiffness_n_m", 2e6, 0.01).unwrap();
        assert_relative_eq!(v, 200.0, max_relative = 1e-12);
        assert_eq!(unit, "N·m/rad");
        let (v, _) = joint_equivalent("contact.boundary_activation_speed_m_s", 1e-3, 0.01).unwrap();
        assert_relative_eq!(v, 0.1, max_relative = 1e-12);
    }

    #[test]
    fn the_chosen_lever_puts_the_top_speed_at_the_transition_and_the_level_on_the_boundary_friction(
    ) {
        let mut config = Config::default();
        config.solver.cells = 32;
        let (omega, tau) = (2.0, 5.0);
        let l = choose(&config, omega, tau).unwrap();
        // Level: μ_bl F_N r = τ_level.
        assert_relative_eq!(
            config.contact.boundary_friction * l.load_n * l.lever_m,
            tau,
            max_relative = 0.01
        );
        // Top speed: half the load on the film there.
        let mut c = config.clone();
        c.contact.load_n = l.load_n;
        let mut s = Solver::new(&c.model(), &c.solver_settings()).unwrap();
        let share = s
            .initialize_steady(l.lever_m * omega, l.load_n)
            .asperity_load_share;
        assert!((share - 0.5).abs() < 0.02, "asperity share {share}");
        // The film's lift falls with load: a stronger joint gets a larger load.
        let strong = choose(&config, omega, 10.0 * tau).unwrap();
        assert!(strong.load_n > l.load_n);
    }
}
