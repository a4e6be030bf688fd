//! Numbers in messages: [`Short`] writes an f64 as its shortest round-tripping digits, in
//! scientific form when it is huge or tiny, so that a refusal of 1e300 reads "1e300" and not a
//! number of 301 digits (Rust's `{}` of an f64 never uses an exponent).

use std::fmt;

/// An f64 written for a message: the shortest digits that read back as the same number,
/// plainly for 1e-4 ≤ |x| < 1e6 (and 0), else as `1.5e-7`, `1e300`; NaN and inf as Rust
/// writes them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Short(pub f64);

impl fmt::Display for Short {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let plain = x == 0.0 || !x.is_finite() || (1e-4..1e6).contains(&x.abs());
        if plain {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Short;

    #[test]
    fn huge_and_tiny_numbers_are_short() {
        let cases = [
            (1e300, "1e300"),
            (-1.0001e16, "-1.0001e16"),
            (5e-324, "5e-324"),
            (2e-5, "2e-5"),
            (0.001, "0.001"),
            (123456.5, "123456.5"),
            (1e6, "1e6"),
            (0.0, "0"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
        ];
        for (x, text) in cases {
            assert_eq!(Short(x).to_string(), text);
            if x.is_finite() {
                assert_eq!(text.parse::<f64>().unwrap(), x, "{text} reads back");
            }
        }
    }
}
