//! Friction terms: what the contact's friction is made of besides the
//! film's shear, each in a file of its own, and composed here in one
//! documented order ([`FrictionTerms`]). Each term file declares its
//! configuration keys ([`TermKey`]: unit, valid range, whether it may
//! change while running, the scale of its default fit bounds); the
//! catalogue ([`catalogue`]) is what the configuration's validation, the
//! node's runtime-key list, the fit's default bounds and the README's key
//! table are derived from.
//!
//! | file | term |
//! |---|---|
//! | `mod.rs` | the catalogue, the sign functions, the composition |
//! | `boundary_film.rs` | the boundary film: friction μ_bl on the asperity load, the rigid contact's sign regularisation, and the boundary film's rise with the logarithm of speed (Eyring) |
//! | `presliding.rs` | the contact's elastic displacement before gross sliding (a bristle on the model's own level) |
//! | `soft_width.rs` | a soft contact whose width follows the load |
//! | `drivetrain.rs` | losses beside the contact (bearings, seals, gears, a motor) |
//!
//! Composition, every step, once the film is solved (F_visc, F_asp are the
//! film's forces on the width B(F) of `soft_width.rs`):
//!
//! ```text
//! 1. level     L_c = F_visc + μ_bl F_asp s(v) + F_asp μ_r asinh(v/v_a)
//!                    s(v) = tanh(v/v_reg) for the rigid contact, sgn(v) with pre-sliding
//! rigid contact:
//! 2. contact   F_c = L_c
//! 3. total     F_f = F_c + F_dt(v, F_ext)
//! with pre-sliding (the compliance at a reversal is the whole axis's):
//! 2. level     L   = L_c + (F_cd + c_N F_ext) sgn(v) + ΔF_cd |sgn(v)|   (what acts at zero speed)
//!              F_b = σ0 z + σ1 ż on L                                  (the bristle)
//!              F_c = F_b L_c / L   (the contact's share; F_b when L = 0)
//! 3. total     F_f = F_b + b v + c_q v |v|
//! 4. COF           = (|F_visc| + (μ_bl + μ_r asinh(|v|/v_a)) F_asp) / F_ext (rigid)
//!                    |F_c| / F_ext (pre-sliding)
//! ```
//!
//! | symbol | meaning | unit |
//! |---|---|---|
//! | F_visc | the film's shear force | N |
//! | F_asp | the load the asperities carry | N |
//! | F_ext | the normal load | N |
//! | L | the contact's friction in gross sliding | N |
//! | F_c | the friction the contact transmits | N |
//! | F_dt | the drivetrain's terms | N |
//! | F_f | the friction estimate | N |
//!
//! Every term is off by default (0) and then leaves every number of the
//! paper's model unchanged, bit for bit (a term is applied only when on).
//!
//! Adding a term: its file (struct, equation, symbol table, `KEYS`), a field
//! of [`FrictionTerms`] and its place in the composition above, its slice in
//! [`catalogue`], its configuration fields (`config/model.rs`, `config/mod.rs`)
//! and its tests. Validation, live-ness, the fit's bounds and the docs'
//! table follow from `KEYS`.

pub mod boundary_film;
pub mod drivetrain;
pub mod presliding;
pub mod soft_width;

use boundary_film::BoundaryRate;
use drivetrain::Drivetrain;
use presliding::Presliding;
use soft_width::WidthLaw;

/// The coefficient of friction as users read it, in one line of ASCII:
/// the text every shape of the estimate carries beside its `cof` field
/// (`msg/msg/FrictionEstimate.msg`, the C header, the wire, record and
/// iceoryx2 structs, Python's stubs); `tests/cof_definition.rs` holds them
/// to it. [`FrictionTerms::cof`] computes it.
pub const COF_DEFINITION: &str =
    "contact friction per unit load: rigid (|F_visc| + (mu_bl + mu_r asinh(|v|/v_a)) F_asp) / F_ext; with pre-sliding |F_c| / F_ext; drivetrain terms excluded";

/// sgn(v): ±1, and 0 at rest (`f64::signum` gives ±1 at ±0). The sign of
/// gross sliding in the pre-sliding level, and of the classic models'
/// Coulomb terms.
pub fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// One end of a key's valid range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum End {
    /// The value itself is allowed.
    Closed(f64),
    /// The value itself is not allowed.
    Open(f64),
}

impl End {
    /// The number at this end.
    pub fn value(self) -> f64 {
        match self {
            End::Closed(v) | End::Open(v) => v,
        }
    }
}

/// An interval of allowed values: a key's valid range (the one interval
/// type: the catalogue, validation and the parameter descriptors use it;
/// `config::validate` writes it as `[lo, hi)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// The lower end.
    pub lo: End,
    /// The upper end.
    pub hi: End,
}

impl Interval {
    /// Whether `v` is finite and lies in the interval.
    pub fn contains(self, v: f64) -> bool {
        let above = match self.lo {
            End::Closed(l) => v >= l,
            End::Open(l) => v > l,
        };
        let below = match self.hi {
            End::Closed(h) => v <= h,
            End::Open(h) => v < h,
        };
        v.is_finite() && above && below
    }
}

/// The scale of a key's default fit bounds when its start gives none (a
/// term that is off starts at 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FitScale {
    /// Only from its start: a decade either side of a positive start;
    /// `--bounds` is needed for a start of 0.
    FromStart,
    /// [0, factor · F / (v^speed_power · (F_N if per_load))], capped at the
    /// key's upper bound; `symmetric`: [−hi, hi]. F is the data's largest
    /// friction, v its largest speed, F_N its smallest load.
    Data {
        /// The multiple of the data's friction scale.
        factor: f64,
        /// The power of the data's speed the friction is divided by.
        speed_power: i32,
        /// Divided by the data's smallest load (a coefficient).
        per_load: bool,
        /// Bounds either side of zero (a signed term).
        symmetric: bool,
    },
    /// A speed: [lo · v, hi · v], v the data's largest speed (log scale).
    Speed {
        /// The lower bound as a fraction of the data's largest speed.
        lo: f64,
        /// The upper bound as a multiple of it.
        hi: f64,
    },
    /// A stiffness: [F / x_hi, F / x_lo], F the data's largest friction:
    /// the displacement |F|/k at which the force builds lies within
    /// [x_lo, x_hi] (m).
    Stiffness {
        /// The smallest displacement, m.
        x_lo: f64,
        /// The largest displacement, m.
        x_hi: f64,
    },
}

/// One configuration key of a friction term.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TermKey {
    /// The dotted configuration key.
    pub key: &'static str,
    /// Its symbol in the equations.
    pub symbol: &'static str,
    /// Its unit ("–" when dimensionless).
    pub unit: &'static str,
    /// The lower end of its valid range.
    pub lo: End,
    /// The upper end of its valid range.
    pub hi: End,
    /// Whether it may change while the node runs.
    pub live: bool,
    /// The scale of its default fit bounds.
    pub fit: FitScale,
    /// What it is, in a few words.
    pub meaning: &'static str,
}

/// Every friction term's keys, term by term, in the composition's order.
pub fn catalogue() -> impl Iterator<Item = &'static TermKey> {
    [
        boundary_film::KEYS,
        presliding::KEYS,
        soft_width::KEYS,
        drivetrain::KEYS,
    ]
    .into_iter()
    .flatten()
}

/// The catalogue's entry for `key`.
pub fn term_key(key: &str) -> Option<&'static TermKey> {
    catalogue().find(|k| k.key == key)
}

/// Whether configuration key `key` acts after the film: a friction term's
/// key that the film's solution (pressure, gap, the film's forces) does not
/// depend on. Every term's keys are, but the soft width's, which scale the
/// film's forces. A change of such keys alone leaves the film as it was,
/// and the friction follows from the film's forces step by step through
/// [`FrictionTerms::friction`] (what a calibration uses to evaluate them
/// without solving the film again).
pub fn acts_after_the_film(key: &str) -> bool {
    [boundary_film::KEYS, presliding::KEYS, drivetrain::KEYS]
        .into_iter()
        .flatten()
        .any(|k| k.key == key)
}

/// The friction terms of one contact, composed in the order of the module
/// documentation. All off by default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionTerms {
    /// μ_bl, the boundary friction coefficient.
    pub boundary_friction: f64,
    /// v_reg of the rigid contact's (and the drivetrain's) tanh sign, m/s.
    pub sign_regularization: f64,
    /// The boundary film's rise with speed.
    pub boundary_rate: BoundaryRate,
    /// The pre-sliding bristle.
    pub presliding: Presliding,
    /// The soft contact's width against the load.
    pub width_law: WidthLaw,
    /// The drivetrain's terms.
    pub drivetrain: Drivetrain,
}

impl FrictionTerms {
    /// The terms of `model` (its contact's and its drivetrain's keys).
    pub fn of(model: &crate::physics::ModelParams) -> Self {
        let c = &model.contact;
        Self {
            boundary_friction: c.boundary_friction,
            sign_regularization: c.sign_regularization,
            boundary_rate: c.boundary_rate,
            presliding: c.presliding,
            width_law: c.width_law,
            drivetrain: model.drivetrain,
        }
    }
}

impl FrictionTerms {
    /// Set the term key `key` (one that acts after the film, see
    /// [`acts_after_the_film`]) to `value`; false for any other key. The
    /// value is taken as it is (the caller keeps it in the key's valid
    /// range).
    pub fn set(&mut self, key: &str, value: f64) -> bool {
        let d = &mut self.drivetrain;
        let slot = match key {
            "contact.boundary_friction" => &mut self.boundary_friction,
            "contact.sign_regularization_m_s" => &mut self.sign_regularization,
            "contact.boundary_friction_rate" => &mut self.boundary_rate.sensitivity,
            "contact.boundary_activation_speed_m_s" => &mut self.boundary_rate.activation_speed,
            "contact.presliding_stiffness_n_m" => &mut self.presliding.stiffness,
            "contact.presliding_damping_n_s_m" => &mut self.presliding.damping,
            "drivetrain.coulomb_n" => &mut d.coulomb,
            "drivetrain.viscous_n_s_m" => &mut d.viscous,
            "drivetrain.load_coefficient" => &mut d.load_coefficient,
            "drivetrain.quadratic_n_s2_m2" => &mut d.quadratic,
            "drivetrain.stribeck_n" => &mut d.stribeck,
            "drivetrain.stribeck_speed_m_s" => &mut d.stribeck_speed,
            "drivetrain.coulomb_asymmetry_n" => &mut d.coulomb_asymmetry,
            _ => return false,
        };
        *slot = value;
        true
    }
}

/// What the composition produced at one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Composed {
    /// F_c, the friction the contact transmits, N.
    pub contact: f64,
    /// F_f, with the drivetrain's terms, N.
    pub total: f64,
    /// The COF.
    pub cof: f64,
    /// The boundary rate's part of the COF (0 with pre-sliding).
    pub boundary_rate_cof: f64,
}

/// How the bristle moves in this evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BristleMove {
    /// A step of this length, s: the bristle advances.
    Step(f64),
    /// A steady state: the bristle takes its steady displacement.
    Steady,
    /// Neither (a solve that does not advance time): the bristle is held.
    Hold,
}

impl FrictionTerms {
    /// L with the boundary rate's term added when it is on (off: the
    /// paper's constant μ_bl, bit for bit, signed zeros included).
    #[inline(always)]
    fn with_rate(&self, f: f64, v: f64, f_asp: f64) -> f64 {
        if self.boundary_rate.is_on() {
            f + f_asp * self.boundary_rate.signed_term(v)
        } else {
            f
        }
    }

    /// (F_c, F_f): the contact's friction and the total at load `load`,
    /// from the film's forces (steps 1–3); `bristle` is the pre-sliding
    /// displacement z, moved as `how` says. Zero drivetrain terms leave
    /// F_f = F_c, bit for bit.
    #[inline(always)]
    pub fn friction(
        &self,
        (v, load): (f64, f64),
        (f_visc, f_asp): (f64, f64),
        bristle: &mut f64,
        how: BristleMove,
    ) -> (f64, f64) {
        let mu_bl = self.boundary_friction;
        let dt = self.drivetrain;
        if !self.presliding.is_on() {
            let s = (v / self.sign_regularization).tanh();
            let contact = self.with_rate(f_visc + mu_bl * f_asp * s, v, f_asp);
            if dt.is_zero() {
                return (contact, contact);
            }
            let total = contact + dt.force(v, load, self.sign_regularization);
            return (contact, total);
        }
        let level_c = self.with_rate(f_visc + mu_bl * f_asp * sgn(v), v, f_asp);
        if dt.is_zero() {
            let f = self.bristle(level_c, v, bristle, how);
            return (f, f);
        }
        // What acts at zero speed rides on the bristle; the contact's share
        // of its force is its share of the level.
        let level = level_c + dt.level_at_rest(v, sgn(v), load);
        let f = self.bristle(level, v, bristle, how);
        let contact = if level == 0.0 {
            f
        } else {
            f * (level_c / level)
        };
        (contact, f + dt.rate_terms(v))
    }

    /// The bristle's force on `level`, z moved as `how` says.
    #[inline(always)]
    fn bristle(&self, level: f64, v: f64, bristle: &mut f64, how: BristleMove) -> f64 {
        let p = self.presliding;
        match how {
            BristleMove::Step(dt) => {
                let (z, f) = p.advance(*bristle, level, v, dt);
                *bristle = z;
                f
            }
            BristleMove::Steady => {
                *bristle = p.steady_displacement(level);
                level
            }
            BristleMove::Hold => level,
        }
    }

    /// The COF and the boundary rate's part of it (step 4): the magnitude
    /// of the friction the contact transmits per unit load. Rigid contact:
    /// it always slides, so (|F_visc| + μ(v) F_asp) / F_ext, the sign's
    /// regularisation not applied; with pre-sliding, |F_c| / F_ext. The
    /// rate's part μ_r asinh(|v|/v_a) F_asp / F_ext is 0 at v = 0 and steep
    /// near it: the one-sided limits at v = 0 are taken without it.
    #[inline(always)]
    pub fn cof(&self, v: f64, f_visc: f64, f_asp: f64, contact: f64, load: f64) -> (f64, f64) {
        if self.presliding.is_on() {
            return (contact.abs() / load, 0.0);
        }
        let mu_bl = self.boundary_friction;
        if self.boundary_rate.is_on() {
            let rate = self.boundary_rate.signed_term(v.abs()) * f_asp / load;
            let mu = mu_bl + self.boundary_rate.signed_term(v.abs());
            ((f_visc.abs() + mu * f_asp) / load, rate)
        } else {
            ((f_visc.abs() + mu_bl * f_asp) / load, 0.0)
        }
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)] // the values compared exactly are exact claims
mod tests {
    use super::*;

    #[test]
    fn an_interval_holds_its_closed_ends_but_not_its_open_ones_nor_a_non_finite_value() {
        let r = Interval {
            lo: End::Open(0.0),
            hi: End::Closed(1.0),
        };
        assert!(!r.contains(0.0));
        assert!(r.contains(1e-300));
        assert!(r.contains(1.0));
        assert!(!r.contains(1.0 + f64::EPSILON));
        assert!(!r.contains(f64::NAN));
        let all = Interval {
            lo: End::Closed(f64::NEG_INFINITY),
            hi: End::Closed(f64::INFINITY),
        };
        assert!(!all.contains(f64::INFINITY));
    }

    #[test]
    fn every_key_of_the_catalogue_is_named_once_with_a_unit_and_an_ordered_range() {
        let keys: Vec<&str> = catalogue().map(|k| k.key).collect();
        let mut unique = keys.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), keys.len(), "{keys:?}");
        for k in catalogue() {
            assert!(!k.unit.is_empty() && !k.symbol.is_empty(), "{}", k.key);
            assert!(k.lo.value() < k.hi.value(), "{}", k.key);
        }
        assert_eq!(
            term_key("contact.boundary_friction").unwrap().symbol,
            "μ_bl"
        );
        assert!(term_key("contact.load_n").is_none());
    }

    #[test]
    fn off_terms_leave_the_rigid_contact_as_the_paper_has_it() {
        let t = FrictionTerms::of(&crate::physics::ModelParams::default());
        let mut z = 0.0;
        let (v, f_visc, f_asp, load) = (0.01, 12.0, 5000.0, 20_000.0);
        let (c, total) = t.friction((v, load), (f_visc, f_asp), &mut z, BristleMove::Step(1e-3));
        assert_eq!(c, f_visc + 0.3 * f_asp * (v / 1e-4).tanh());
        assert_eq!(total, c);
        assert_eq!(
            t.cof(v, f_visc, f_asp, c, load),
            ((12.0 + 0.3 * 5000.0) / load, 0.0)
        );
        assert_eq!(z, 0.0);
        assert_eq!(sgn(-0.0), 0.0);
        assert_eq!(sgn(-2.0), -1.0);
    }
}
