//! Text formatting shared by the output layers.

/// A float in the shortest form that reads back to the same bits:
/// positional for ordinary magnitudes, exponent form for tiny or huge ones.
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if a == 0.0 || (1e-3..1e7).contains(&a) || !a.is_finite() {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}
