//! The starts of a set's trial fit besides its warm start (`trial.rs`):
//! each new key at its placements, a Stribeck curve at its classic
//! curves, and a set reached by taking a term away where it would be
//! fitted alone. A term that bends the curve has as many optima as the
//! data have places to bend it; one start finds one of them.

use super::candidates::{CANDIDATES, FILM_KEY};
use super::contact_scale::slow_speed;
use super::prepared::{model_for, Prepared};
use super::problem::Model;
use super::unknowns::ParamSpec;
use super::FitError;

/// The viscosities that put the film's transition inside the data, when
/// the contact's scale put it far above them (`contact_scale.rs`): at the
/// top speed, the slowest sliding speed and between (the transition speed
/// goes as 1/μ at a given load, the Hersey number). Empty otherwise.
pub(super) fn film_placements(p: &Prepared) -> Vec<f64> {
    let Some(scale) = p.contact_scale.as_ref().filter(|s| s.chosen) else {
        return Vec::new();
    };
    let top = p.model_scale.velocity_m_s;
    let slow = slow_speed(&p.data.train, &p.data.map_values).unwrap_or(0.1 * top) * scale.gain;
    let mu0 = p.model_config.lubricant.viscosity_pa_s;
    let v_t = super::contact_scale::TRANSITION_FAR * top;
    [top, (slow * top).sqrt(), slow]
        .iter()
        .map(|target| (mu0 * v_t / target).min(super::contact_scale::MAX_PLACED_VISCOSITY_PA_S))
        .collect()
}

/// The start of every key of `model` and every map coefficient of `map_fit`,
/// in the order of the fit's parameter vector.
fn starts_of(
    model: &super::physics_model::PhysicsModel,
    map_fit: &super::prepared::MapFit,
) -> Vec<f64> {
    let keys = model.parameters().iter().map(|q| q.start);
    keys.chain(map_fit.iter().map(|(_, q)| q.start)).collect()
}

/// The drivetrain Stribeck curve's keys: its speed and its amplitude.
pub(super) const STRIBECK_SPEED_KEY: &str = "drivetrain.stribeck_speed_m_s";
pub(super) const STRIBECK_AMPLITUDE_KEY: &str = "drivetrain.stribeck_n";
/// The direction asymmetry's key.
const ASYMMETRY_KEY: &str = "drivetrain.coulomb_asymmetry_n";

/// The best Stribeck curves on the training data by variable projection
/// ([`super::classic_regression::stribeck_curve_by_grid`]: a log grid of speeds,
/// the curve's levels and slope solved at each), without and with a level
/// that differs by direction, in the data's units. A start of our
/// Stribeck term at one of them (its speed and amplitude) is in the basin
/// of a curve that a start at zero amplitude cannot see, whose speed then
/// has no gradient: a rise that saturates inside the data beside an
/// offset (seed 197 joint 22 of `OFFSET=0.2 docs/arm-steady-draws.sh`,
/// where the three placements at zero amplitude found a straight line,
/// training RMS 0.0149 against the curve's 0.0033 N·m).
fn stribeck_curves(p: &Prepared) -> Vec<super::classic_regression::GridCurve> {
    let series: Vec<_> = p
        .data
        .train
        .iter()
        .filter_map(|s| s.series(&p.data.map_values).ok())
        .collect();
    let mut out: Vec<_> = [false, true]
        .into_iter()
        .filter_map(|offset| super::classic_regression::stribeck_curve_by_grid(&series, offset))
        .collect();
    // A time series passes through zero smoothly at its reversals (the
    // bristle), and a steady curve fitted there spends its rise on that
    // crossing: a sign function at a few thousandths of the top speed
    // (draw 88 of `docs/joint-series-draws.sh`: the curve of all samples
    // rises at 0.009 rad/s, the joint's at 0.19). The same curves on the
    // samples sliding faster than a tenth of the top speed are starts too.
    if series.iter().any(|s| !s.steady) {
        let sliding: Vec<_> = series
            .iter()
            .cloned()
            .map(|mut s| {
                if !s.steady {
                    let top = s.velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    for (f, v) in s.fit.iter_mut().zip(&s.velocity) {
                        *f = *f && v.abs() > 0.1 * top;
                    }
                }
                s
            })
            .collect();
        out.extend([false, true].into_iter().filter_map(|offset| {
            super::classic_regression::stribeck_curve_by_grid(&sliding, offset)
        }));
    }
    out
}

/// Where a new term's speed-like key starts besides its own start: the
/// film's viscosity at [`film_placements`]; a Stribeck speed or a boundary
/// film's activation speed at the data's slowest sliding speed, its top
/// speed and between (contact units), a Stribeck speed also where the
/// best Stribeck curves on the data bend ([`stribeck_speeds`]). A term that bends the curve at a
/// speed has as many optima as the data have places to bend it: one start
/// finds one of them.
fn placements(p: &Prepared, key: &str) -> Vec<f64> {
    match key {
        FILM_KEY => film_placements(p),
        k if super::unknowns::BEND_SPEED_KEYS.contains(&k) => {
            let gain = p.contact_scale.as_ref().map_or(1.0, |s| s.gain);
            let top = p.model_scale.velocity_m_s;
            let slow =
                slow_speed(&p.data.train, &p.data.map_values).map_or(0.1 * top, |v| v * gain);
            vec![slow, (slow * top).sqrt(), top]
        }
        _ => Vec::new(),
    }
}

/// A selection's starts besides the warm one: on its prepared data, with
/// the best Stribeck curves on its training data made once, when the first
/// set with a new Stribeck term is tried.
pub(super) struct Starts<'a> {
    p: &'a Prepared,
    stribeck_curves: std::sync::OnceLock<Vec<super::classic_regression::GridCurve>>,
}

impl<'a> Starts<'a> {
    /// The starts of sets fitted on `p`.
    pub(super) fn new(p: &'a Prepared) -> Self {
        Starts {
            p,
            stribeck_curves: std::sync::OnceLock::new(),
        }
    }

    /// The starts besides the warm one: each key new to the set (not in
    /// `warm`) at each of its placements, the others at the warm start.
    pub(super) fn extra(
        &self,
        model: &super::physics_model::PhysicsModel,
        map_fit: &super::prepared::MapFit,
        terms: &[&'static str],
        warm: &[(String, f64)],
        film: &[f64],
    ) -> Vec<Vec<f64>> {
        let new_keys: Vec<&str> = terms
            .iter()
            .filter_map(|t| CANDIDATES.iter().find(|c| c.name == *t))
            .flat_map(|c| c.keys.iter().copied())
            .filter(|k| warm.iter().all(|(n, _)| n != k))
            .collect();
        let start = starts_of(model, map_fit);
        let mut out = Vec::new();
        for (i, q) in model.parameters().iter().enumerate() {
            if !new_keys.contains(&q.name.as_str()) {
                continue;
            }
            let values = if q.name == FILM_KEY {
                film.to_vec()
            } else {
                placements(self.p, &q.name)
            };
            for v in values {
                let mut x = start.clone();
                x[i] = v.clamp(q.lo, q.hi);
                out.push(x);
            }
        }
        // The curve's classic starts where it is new, and where pre-sliding
        // is new beside it: the bristle then takes the zero crossing that
        // the curve alone may have fitted.
        let presliding_new = new_keys.contains(&"contact.presliding_stiffness_n_m");
        let holds_curve = model
            .parameters()
            .iter()
            .any(|q| q.name == STRIBECK_SPEED_KEY);
        if new_keys.contains(&STRIBECK_SPEED_KEY) || (presliding_new && holds_curve) {
            out.extend(self.stribeck_starts(model, &start));
        }
        out
    }

    /// The starts a set reached by taking a term away has of its own: where
    /// the warm optimum fits a key this set does not, the other keys there
    /// carried a part of that term's effect (a Stribeck curve a peak beside
    /// a rising boundary rate), and the set is also started where it would
    /// be fitted alone: every key at its configured start, and the Stribeck
    /// curve at each of its classic starts. A set's score does not depend
    /// on the path that reached it.
    pub(super) fn own(
        &self,
        specs: &[ParamSpec],
        model: &super::physics_model::PhysicsModel,
        map_fit: &super::prepared::MapFit,
        warm: &[(String, f64)],
    ) -> Result<Vec<Vec<f64>>, FitError> {
        let fits = |k: &str| {
            model.parameters().iter().any(|q| q.name == k)
                || map_fit.iter().any(|(_, q)| q.name == k)
        };
        if warm.iter().all(|(n, _)| fits(n)) {
            return Ok(Vec::new());
        }
        let (cold, _) = model_for(self.p, specs, &[])?;
        let start = starts_of(&cold, map_fit);
        let mut out = self.stribeck_starts(&cold, &start);
        out.push(start);
        Ok(out)
    }

    /// Starts of a set whose Stribeck curve is new: `start` with the
    /// curve's speed and amplitude (and the direction asymmetry, where the
    /// set fits it) at each of [`stribeck_curves`], in contact units.
    fn stribeck_starts(
        &self,
        model: &super::physics_model::PhysicsModel,
        start: &[f64],
    ) -> Vec<Vec<f64>> {
        let gain = self.p.contact_scale.as_ref().map_or(1.0, |s| s.gain);
        let params = model.parameters();
        let at = |key: &str| params.iter().position(|q| q.name == key);
        let (Some(speed), Some(amplitude)) = (at(STRIBECK_SPEED_KEY), at(STRIBECK_AMPLITUDE_KEY))
        else {
            return Vec::new();
        };
        let mut out: Vec<Vec<f64>> = Vec::new();
        let curves = self.stribeck_curves.get_or_init(|| stribeck_curves(self.p));
        for x in curves.iter().map(|c| {
            let mut x = start.to_vec();
            let mut set = |i: usize, v: f64| x[i] = v.clamp(params[i].lo, params[i].hi);
            set(speed, c.speed * gain);
            set(amplitude, c.amplitude / gain);
            if let Some(i) = at(ASYMMETRY_KEY) {
                set(i, c.offset / gain);
            }
            x
        }) {
            // On speeds taken both ways the two curves are one.
            if !out.contains(&x) {
                out.push(x);
            }
        }
        out
    }
}
