//! Text formatting shared by the output layers.

/// A float in the shortest form that reads back to the same bits:
/// positional for ordinary magnitudes, exponent form for tiny or huge ones.
/// The project's one number formatter: [`Num::sig`] rounds to significant
/// digits first (tables), [`Num::sci`] writes a fixed mantissa (parameter
/// tables, where columns of estimates and errors line up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl Num {
    /// `v` rounded to `digits` significant digits, shown as [`Num`] shows
    /// it: a joint's friction in N·m or a lead screw's in N keeps its digits
    /// whatever its scale (0.00071234, not 0.0007).
    pub fn sig(v: f64, digits: u32) -> Self {
        if v == 0.0 || !v.is_finite() {
            return Self(v);
        }
        let e = v.abs().log10().floor() as i32 - (digits as i32 - 1);
        let m = 10f64.powi(-e);
        let rounded = (v * m).round() / m;
        // `rounded` is within an ulp of the decimal (10^k is not always a
        // double: 6.5933000000000005e-25); the nearest double to the
        // decimal itself shows as that decimal.
        let digits = digits.clamp(1, 17) as usize;
        Self(
            format!("{:.*e}", digits - 1, rounded)
                .parse()
                .unwrap_or(rounded),
        )
    }

    /// Scientific notation with `decimals` digits after the point
    /// (`1.2346e-3`); a non-finite value as it is.
    pub fn sci(self, decimals: usize) -> String {
        if self.0.is_finite() {
            format!("{:.*e}", decimals, self.0)
        } else {
            format!("{}", self.0)
        }
    }
}

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

#[cfg(test)]
mod tests {
    use super::Num;

    #[test]
    fn small_numbers_keep_their_significant_digits() {
        // A joint's friction in N·m (before: "0.0007", "0.0000").
        assert_eq!(Num::sig(0.000_712_345, 5).to_string(), "7.1235e-4");
        assert_eq!(Num::sig(0.002_198_765, 5).to_string(), "0.0021988");
        assert_eq!(Num::sig(1.002_345_6, 5).to_string(), "1.0023");
        assert_eq!(Num::sig(7_290.123, 5).to_string(), "7290.1");
        assert_eq!(Num::sig(14_734.2, 4).to_string(), "14730");
        assert_eq!(Num::sig(0.0, 5).to_string(), "0");
        // Tiny and huge magnitudes, whose scale 10^k is not a double.
        assert_eq!(Num::sig(6.593_299_9e-25, 5).to_string(), "6.5933e-25");
        assert_eq!(Num::sig(-1.234_567e-31, 3).to_string(), "-1.23e-31");
        assert_eq!(Num::sig(9.999_96e22, 5).to_string(), "1e23");
        assert_eq!(Num::sig(f64::NAN, 5).to_string(), "NaN");
        assert_eq!(Num(1.23456e-3).sci(4), "1.2346e-3");
        assert_eq!(Num(f64::INFINITY).sci(4), "inf");
    }
}
