//! The contact's scale, chosen from the data when they do not fix it.
//!
//! The model is a sliding contact; the data's axis drives it through a gain
//! g, as a robot joint drives a contact through a lever: the contact slides
//! at v = g ẋ and puts F_data = g F on the axis (a rotary joint: ẋ = ω in
//! rad/s, g a lever arm in m, F_data a torque in N·m; a linear axis: ẋ in
//! m/s, g dimensionless, F_data in N). A recording of friction against
//! speed cannot tell the contact's size, load and gain apart from the
//! friction coefficients and viscosity fitted on them, so the tool keeps
//! the configured contact's geometry and lubricant and chooses g and the
//! load F_N from the data, when the data do not give the load and the
//! configuration gives no gain:
//!
//! 1. the configured boundary friction gives the data's **sliding level**:
//!    μ_bl F_N g = F_level, the mean |F_data| of the samples sliding faster
//!    than a tenth of the top speed;
//! 2. the film's **transition** — the speed v_t(F_N) at which the
//!    configured lubricant carries half the load (steady state) — lies
//!    [`TRANSITION_FAR`] times above the data's top speed: g ẋ_top =
//!    v_t(F_N) / [`TRANSITION_FAR`]. The data then see the boundary friction
//!    and the terms beside it, not a film regime they do not show; whether
//!    the film acts inside the data is the selection's to decide (the film
//!    candidate's starts place its transition inside them).
//!
//! Together: F_N v_t(F_N) = F_level ẋ_top [`TRANSITION_FAR`] / μ_bl. The
//! film's lift grows with speed and falls with load (v_t ∝ F_N for a rigid
//! contact, the Hersey number), so the left side grows with F_N; it is
//! solved by the secant method on log F_N and bisection as a fall-back.
//! The sign's regularisation, a numerical device, follows the contact's
//! speeds: [`SIGN_REGULARIZATION_FRACTION`] of the contact's top speed when
//! the configured one is larger. The scale is kept inside what the node accepts (a gain up to
//! [`MAX_GAIN`], a contact speed up to `node.max_abs_velocity_m_s`, a load in
//! [`node.min_load_n`, `node.max_load_n`]); at one of those limits the
//! transition lies nearer the data, and the scale says which limit to
//! raise.
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | ẋ, ẋ_top | the data's speed, its largest | m/s or rad/s |
//! | F_data, F_level | the data's friction, its sliding level | N or N·m |
//! | g | gain (`contacts.NAME.gain`): m/rad for a joint, – for a linear axis | m or – |
//! | F_N | contact load (`contact.load_n`) | N |
//! | v_t | transition speed: half the load on the film | m/s |
//! | μ_bl | boundary friction (`contact.boundary_friction`) | – |

use super::series::Source;
use super::unknowns::ParamSpec;
use super::{FitError, Units};
use crate::config::Config;
use crate::physics::Solver;

/// The gain and load chosen for (or configured with) the data's axis.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactScale {
    /// g: contact speed = g ẋ, the axis's friction = g F (m for a rotary
    /// joint, dimensionless for a linear axis).
    pub gain: f64,
    /// The contact's load F_N, N.
    pub load_n: f64,
    /// The data's units.
    pub units: Units,
    /// Chosen from the data (the film's transition then lies far above
    /// them), not configured.
    pub chosen: bool,
    /// How they were found, in words (for the report).
    pub how: String,
}

/// How far above the data's top speed the chosen scale puts the film's
/// transition: far enough that the film shapes nothing the data show.
/// Three decades: at two the transition's tail still bent the curve by a
/// few tenths of a percent (a classic model's own record was predicted
/// 0.04–0.13 % worse by ours with the same terms; at three, equal).
pub const TRANSITION_FAR: f64 = 1000.0;

/// The sign's regularisation speed on a chosen scale, as a fraction of the
/// contact's top speed (when the configured one is larger): the classic
/// models switch with sgn v, and a time series' first sample after a
/// reversal can lie at a thousandth of the top speed (1 kHz, moves of
/// 0.2 m/s), where a wider tanh would still round the switch.
pub const SIGN_REGULARIZATION_FRACTION: f64 = 1e-5;

/// The smallest sign regularisation a chosen scale sets, m/s (the key's
/// valid range is open at 1e-9).
pub const MIN_SIGN_REGULARIZATION_M_S: f64 = 1e-8;

/// The largest viscosity the film candidate's starts may ask for (the
/// key's valid range ends at 100 Pa·s).
pub const MAX_PLACED_VISCOSITY_PA_S: f64 = 99.0;

/// The largest gain the node accepts (`contacts.NAME.gain`).
pub const MAX_GAIN: f64 = 1e3;

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

/// The root of `g`, increasing, in `bracket` (ln F, its end when `g` has
/// no sign change there): secant steps from `start`, kept inside the
/// bracket; a step that leaves it bisects.
fn root_in(
    g: impl Fn(f64) -> Result<f64, FitError>,
    (mut a, mut b): (f64, f64),
    start: f64,
) -> Result<f64, FitError> {
    if g(a)? >= 0.0 {
        return Ok(a);
    }
    if g(b)? <= 0.0 {
        return Ok(b);
    }
    let mut x = start.clamp(a, b);
    let mut gx = g(x)?;
    let mut x_prev = if x + 1.0 <= b { x + 1.0 } else { x - 1.0 };
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
    Ok(x)
}

/// Choose g and F_N for data whose top speed is `top` (m/s or rad/s) and
/// sliding level `level` (N or N·m), on `config`'s contact, within the
/// node's limits.
pub fn choose(
    config: &Config,
    top: f64,
    level: f64,
    units: Units,
) -> Result<ContactScale, FitError> {
    let mu = config.contact.boundary_friction;
    let (su, fu) = (units.speed(), units.force());
    if !(top > 0.0 && level > 0.0 && top.is_finite() && level.is_finite()) {
        return Err(FitError::Data {
            what: "data".into(),
            message: format!(
                "the data's top speed ({top} {su}) and sliding level ({level} {fu}) must be positive to choose the contact's scale"
            ),
        });
    }
    if mu <= 0.0 {
        return Err(FitError::Data {
            what: "contact.boundary_friction".into(),
            message: "is 0: the load cannot be chosen from the data's level; set it (e.g. 0.1) as the start".into(),
        });
    }
    let limits = Limits::of(config, top);
    let target = (level * top * TRANSITION_FAR / mu).ln();
    // g(ln F) = ln(F v_t(F)) − target, increasing.
    let g = |ln_f: f64| -> Result<f64, FitError> {
        let f = ln_f.exp();
        Ok((f * transition_speed(config, f)?).ln() - target)
    };
    let bracket = (limits.load.0.ln(), limits.load.1.ln());
    let ln_f = root_in(g, bracket, config.contact.load_n.ln())?;
    let mut load_n = ln_f.exp();
    let mut gain = level / (mu * load_n);
    // The node's limits on the gain and the contact's speed bound the gain
    // from above; a smaller gain needs a larger load for the same level.
    let mut at_limit = Vec::new();
    if gain > limits.gain {
        at_limit.push(limits.gain_reason);
        gain = limits.gain;
        load_n = level / (mu * gain);
    }
    if load_n > limits.load.1 {
        at_limit.push("the load reaches node.max_load_n: raise it to place the transition farther from the data");
        load_n = limits.load.1;
        gain = level / (mu * load_n);
    }
    if gain > limits.gain || load_n < limits.load.0 {
        return Err(FitError::Data {
            what: "data".into(),
            message: format!(
                "no contact scale fits the node's limits: the level {} {fu} at {} {su} needs a gain above {} or a load below node.min_load_n ({} N); raise node.max_abs_velocity_m_s or lower node.min_load_n",
                crate::text::Num::sig(level, 5),
                crate::text::Num::sig(top, 5),
                crate::text::Num(limits.gain),
                crate::text::Num(limits.load.0)
            ),
        });
    }
    let v_t = transition_speed(config, load_n)?;
    let how = format!(
        "chosen from the data: the boundary friction {} gives the sliding level {} {fu}, and the film's transition ({} m/s at this load and viscosity) lies {}× above the contact's top speed {} m/s{}",
        crate::text::Num(mu),
        crate::text::Num::sig(level, 5),
        crate::text::Num::sig(v_t, 5),
        crate::text::Num((v_t / (gain * top)).round()),
        crate::text::Num::sig(gain * top, 5),
        if at_limit.is_empty() {
            String::new()
        } else {
            format!(" ({})", at_limit.join("; "))
        }
    );
    Ok(ContactScale {
        gain,
        load_n,
        units,
        chosen: true,
        how,
    })
}

/// What the node accepts of a scale for data of top speed `top`.
struct Limits {
    /// The largest gain: [`MAX_GAIN`], or what keeps the contact's top speed
    /// within `node.max_abs_velocity_m_s`.
    gain: f64,
    /// Why that is the largest.
    gain_reason: &'static str,
    /// The loads it accepts, N.
    load: (f64, f64),
}

impl Limits {
    fn of(config: &Config, top: f64) -> Self {
        let by_speed = config.node.max_abs_velocity_m_s / top;
        let (gain, gain_reason) = if by_speed < MAX_GAIN {
            (
                by_speed,
                "the contact's top speed reaches node.max_abs_velocity_m_s: raise it to place the transition farther from the data",
            )
        } else {
            (
                MAX_GAIN,
                "the gain reaches its largest, 1000: the transition lies nearer the data",
            )
        };
        Self {
            gain,
            gain_reason,
            load: (
                config.node.min_load_n.max(LOADS_N.0),
                config.node.max_load_n.min(LOADS_N.1),
            ),
        }
    }
}

/// The slowest sliding speed of the training data (the tenth percentile of
/// |v| over the samples faster than a hundredth of the top speed), in the
/// data's units.
pub fn slow_speed(train: &[Source], map: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = train
        .iter()
        .filter_map(|s| s.series(map).ok())
        .flat_map(|s| s.velocity.into_iter().map(f64::abs))
        .collect();
    let top = v.iter().copied().fold(0.0f64, f64::max);
    v.retain(|x| *x > 0.01 * top);
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 10).copied()
}

/// The transition speed goes as 1/μ_l at a given load (the Hersey number),
/// so the film candidate moves it from [`TRANSITION_FAR`] × the top speed
/// down to the slowest sliding speed by raising the viscosity
/// [`TRANSITION_FAR`] × top / slow times. When that would pass
/// [`MAX_PLACED_VISCOSITY_PA_S`], the scale starts from a viscosity low
/// enough (the load is then chosen for it, so the data see the same
/// boundary level and no film). Returns (configured, lowered) when it did.
fn lower_viscosity_for_placements(
    c: &mut Config,
    top: f64,
    slow: Option<f64>,
) -> Option<(f64, f64)> {
    let slow = slow.unwrap_or(0.1 * top).min(top);
    if slow.is_nan() || slow <= 0.0 {
        return None;
    }
    let reach = TRANSITION_FAR * top / slow;
    let highest = MAX_PLACED_VISCOSITY_PA_S / reach;
    let from = c.lubricant.viscosity_pa_s;
    if from <= highest {
        return None;
    }
    // Two significant digits, rounded down: a number a reader can carry.
    let e = highest.log10().floor() - 1.0;
    let to = (highest / 10f64.powf(e)).floor() * 10f64.powf(e);
    c.lubricant.viscosity_pa_s = to;
    Some((from, to))
}

/// The training data's top speed and sliding level (the mean |F| of the
/// samples faster than a tenth of the top speed).
fn top_and_level(train: &[Source], map: &[f64]) -> Result<(f64, f64), FitError> {
    let all = train
        .iter()
        .map(|s| s.series(map))
        .collect::<Result<Vec<_>, _>>()?;
    let top = all
        .iter()
        .flat_map(|s| s.velocity.iter())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let (mut sum, mut n) = (0.0, 0usize);
    for se in &all {
        for k in (0..se.len()).filter(|&k| se.velocity[k].abs() > 0.1 * top) {
            sum += se.friction[k].abs();
            n += 1;
        }
    }
    Ok((top, sum / n.max(1) as f64))
}

/// The model configuration and scale for the data: the configuration's
/// one contact with its gain, the scale chosen from the data (`choose`),
/// or none (the configured contact as it is, gain 1). A bound on the
/// boundary friction that excludes the value the chosen scale rests on is
/// an error naming both.
pub fn setup(
    config: &Config,
    train: &[Source],
    map: &[f64],
    specs: &[ParamSpec],
    units: Units,
    choose_scale: bool,
) -> Result<(Config, Option<ContactScale>), FitError> {
    let contacts = config.resolved_contacts();
    if config.contacts.0.len() > 1 {
        return Err(FitError::Data {
            what: "configuration".into(),
            message: format!(
                "it has {} contacts; a fit needs one (or none: the top level)",
                contacts.len()
            ),
        });
    }
    let one = &contacts[0];
    if !config.contacts.is_empty() && one.gain != 1.0 {
        return Ok((
            one.config.clone(),
            Some(ContactScale {
                gain: one.gain,
                load_n: one.config.contact.load_n,
                units,
                chosen: false,
                how: format!("configured: contacts.{}.gain", one.name),
            }),
        ));
    }
    if !choose_scale {
        return Ok((one.config.clone(), None));
    }
    let (top, level) = top_and_level(train, map)?;
    let mut c = one.config.clone();
    let lowered = lower_viscosity_for_placements(&mut c, top, slow_speed(train, map));
    let mut scale = choose(&c, top, level, units)?;
    if let Some((from, to)) = lowered {
        scale.how.push_str(&format!(
            "; the viscosity is {} Pa·s, not the configured {} Pa·s: a part of the scale, low enough that the film candidate can place its transition inside the data within the viscosity's range",
            crate::text::Num::sig(to, 2),
            crate::text::Num(from)
        ));
    }
    let all_without_load = train
        .iter()
        .map(|s| s.series(map).map(|se| se.load.is_none()))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .all(|none| none);
    if all_without_load {
        c.contact.load_n = scale.load_n;
    }
    // The sign's regularisation is a numerical device on the contact's
    // speed: at the scale's contact speeds it must not shape the data's
    // friction (1e-5 of the top speed switches the sign before the first
    // sample after a reversal).
    let v_reg = (SIGN_REGULARIZATION_FRACTION * scale.gain * top).max(MIN_SIGN_REGULARIZATION_M_S);
    if v_reg < c.contact.sign_regularization_m_s {
        c.contact.sign_regularization_m_s = v_reg;
    }
    level_within_bounds(specs, c.contact.boundary_friction, &scale, level)?;
    Ok((c, Some(scale)))
}

/// A bound on the boundary friction that excludes `mu`, the value the
/// chosen scale rests on, is an error naming both.
fn level_within_bounds(
    specs: &[ParamSpec],
    mu: f64,
    scale: &ContactScale,
    level: f64,
) -> Result<(), FitError> {
    let units = scale.units;
    for s in specs
        .iter()
        .filter(|s| s.name == "contact.boundary_friction")
    {
        if let Some((lo, hi)) = s.bounds {
            if !(lo..=hi).contains(&mu) {
                return Err(FitError::Bounds {
                    key: s.name.clone(),
                    message: format!(
                        "{lo}:{hi} excludes {mu}, the boundary friction on which the chosen scale rests (load {} N and gain {} give the data's sliding level {} {} with it): widen the bounds, or set contact.boundary_friction inside them in the configuration (the load is then chosen from that value)",
                        crate::text::Num(scale.load_n),
                        crate::text::Num(scale.gain),
                        crate::text::Num::sig(level, 5),
                        units.force()
                    ),
                });
            }
        }
    }
    Ok(())
}

/// `config` as the one contact of joint `joint` with gain `gain`: the
/// node, driven by that joint's `JointState`, slides the contact at `gain`
/// × the joint's velocity and publishes `gain` × its friction as the
/// joint's effort (N·m for a rotary joint, N for a linear axis).
pub fn on_joint(config: Config, joint: &str, gain: f64) -> Config {
    use crate::config::{ContactEntry, ContactList, ContactSolverConfig};
    let entry = ContactEntry {
        name: joint.to_string(),
        joint: joint.to_string(),
        gain,
        contact: config.contact.clone(),
        texture: config.texture.clone(),
        lubricant: config.lubricant.clone(),
        roughness: config.roughness.clone(),
        solver: ContactSolverConfig {
            cells: config.solver.cells,
        },
        calibrated_range: config.calibrated_range.clone(),
    };
    Config {
        contacts: ContactList(vec![entry]),
        calibrated_range: None,
        ..config
    }
}

/// A fitted contact key's value as it acts on the data's axis behind gain
/// `gain` (v = g ẋ, F_data = g F): a force times g, a stiffness or a
/// damping times g², a quadratic loss times g³, a speed divided by g, in
/// the data's units (a joint: N·m, per rad, rad/s). None for a property of
/// the contact itself (a friction coefficient, the viscosity, the
/// roughness, a load), which reads the same on the axis.
pub fn joint_equivalent(
    key: &str,
    value: f64,
    gain: f64,
    units: Units,
) -> Option<(f64, &'static str)> {
    let g = gain;
    let rotary = units == Units::Rotary;
    let pick = |joint: &'static str, axis: &'static str| if rotary { joint } else { axis };
    Some(match key {
        "drivetrain.coulomb_n" | "drivetrain.coulomb_asymmetry_n" | "drivetrain.stribeck_n" => {
            (value * g, pick("N·m", "N"))
        }
        "drivetrain.viscous_n_s_m" => (value * g * g, pick("N·m·s/rad", "N·s/m")),
        "drivetrain.quadratic_n_s2_m2" => (value * g * g * g, pick("N·m·s²/rad²", "N·s²/m²")),
        "contact.presliding_stiffness_n_m" => (value * g * g, pick("N·m/rad", "N/m")),
        "contact.presliding_damping_n_s_m" => (value * g * g, pick("N·m·s/rad", "N·s/m")),
        "contact.boundary_activation_speed_m_s"
        | "contact.sign_regularization_m_s"
        | "drivetrain.stribeck_speed_m_s"
        | "drivetrain.viscous_reference_speed_m_s" => (value / g, pick("rad/s", "m/s")),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn every_friction_term_key_with_a_force_or_a_speed_has_its_joint_equivalent() {
        for k in crate::physics::terms::configured_catalogue() {
            let dimensional = k.unit.contains('N') || k.unit.contains("m/s");
            // A load is the contact's normal load, not a force on the joint.
            let load = k.key.ends_with("_load_n");
            assert_eq!(
                joint_equivalent(k.key, 1.0, 0.1, Units::Rotary).is_some(),
                dimensional && !load,
                "{} ({})",
                k.key,
                k.unit
            );
        }
        let (v, unit) =
            joint_equivalent("contact.presliding_stiffness_n_m", 2e6, 0.01, Units::Rotary).unwrap();
        assert_relative_eq!(v, 200.0, max_relative = 1e-12);
        assert_eq!(unit, "N·m/rad");
        let (v, _) = joint_equivalent(
            "contact.boundary_activation_speed_m_s",
            1e-3,
            0.01,
            Units::Rotary,
        )
        .unwrap();
        assert_relative_eq!(v, 0.1, max_relative = 1e-12);
    }

    #[test]
    fn the_chosen_scale_puts_the_level_on_the_boundary_friction_and_the_transition_far_above_the_data(
    ) {
        let mut config = Config::default();
        config.solver.cells = 32;
        for (units, top, level) in [(Units::Rotary, 2.0, 5.0), (Units::Linear, 0.13, 20.0)] {
            let l = choose(&config, top, level, units).unwrap();
            // Level: μ_bl F_N g = F_level.
            assert_relative_eq!(
                config.contact.boundary_friction * l.load_n * l.gain,
                level,
                max_relative = 1e-9
            );
            // The transition, half the load on the film, TRANSITION_FAR
            // times above the contact's top speed.
            let v_t = transition_speed(&config, l.load_n).unwrap();
            assert_relative_eq!(v_t / (l.gain * top), TRANSITION_FAR, max_relative = 0.01);
            let mut c = config.clone();
            c.contact.load_n = l.load_n;
            let mut s = Solver::new(&c.model(), &c.solver_settings()).unwrap();
            let share = s
                .initialize_steady(l.gain * top, l.load_n)
                .asperity_load_share;
            assert!(
                share > 0.99,
                "at the data's top speed the asperities carry {share}"
            );
            // The film's lift falls with load: a stronger axis gets a larger load.
            let strong = choose(&config, top, 10.0 * level, units).unwrap();
            assert!(strong.load_n > l.load_n);
        }
    }

    #[test]
    fn a_scale_the_node_would_refuse_is_held_at_its_limit_and_says_which() {
        let mut config = Config::default();
        config.solver.cells = 32;
        // A contact speed limit of 1 m/s for data at 0.5 m/s: the gain is 2
        // at most.
        config.node.max_abs_velocity_m_s = 1.0;
        let l = choose(&config, 0.5, 200.0, Units::Linear).unwrap();
        assert!(l.gain <= 2.0 + 1e-12, "gain {}", l.gain);
        assert!(l.gain * 0.5 <= config.node.max_abs_velocity_m_s + 1e-12);
        assert!(
            l.gain < 2.0 || l.how.contains("node.max_abs_velocity_m_s"),
            "{}",
            l.how
        );
        let fitted = on_joint(config.clone(), "axis", l.gain);
        assert!(fitted.validate().is_ok());
    }

    #[test]
    fn a_scale_lowers_the_viscosity_so_the_film_candidate_can_reach_the_slowest_sliding_speed() {
        let mut c = Config::default();
        let configured = c.lubricant.viscosity_pa_s;
        // Data from 0.005 to 0.2 m/s: the candidate must raise the viscosity
        // TRANSITION_FAR × 40 times to bring the transition to 0.005 m/s.
        let (from, to) = lower_viscosity_for_placements(&mut c, 0.2, Some(0.005)).unwrap();
        assert_eq!(from, configured);
        assert_eq!(c.lubricant.viscosity_pa_s, to);
        assert!(to * TRANSITION_FAR * 0.2 / 0.005 <= MAX_PLACED_VISCOSITY_PA_S);
        // Rounded down to two digits, not far below what is needed.
        assert!(to * TRANSITION_FAR * 0.2 / 0.005 > 0.9 * MAX_PLACED_VISCOSITY_PA_S);
        assert!(c.validate().is_ok());
        // Data a narrow range that the configured viscosity already reaches: kept.
        let mut k = Config::default();
        assert!(lower_viscosity_for_placements(&mut k, 0.2, Some(0.15)).is_none());
        assert_eq!(k.lubricant.viscosity_pa_s, configured);
    }
}
