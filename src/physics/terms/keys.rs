//! A term's configuration keys: their valid ranges ([`Interval`]), the
//! scale of their default fit bounds ([`FitScale`]) and their catalogue
//! entry ([`TermKey`]). Each term file declares its keys with these; the
//! catalogue (`mod.rs`) lists them all.

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

#[cfg(test)]
#[allow(clippy::float_cmp)]
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
}
