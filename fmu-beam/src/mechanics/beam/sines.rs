//! The angle a body turned by last, with its sine and cosine: a memo of `f64::sin_cos`, bit for
//! bit, that each body keeps ([`RecentTurn`]). One Newton iteration turns a body by its angle
//! about five times (its joints' frames, its residual, the reactions' tangents): `sin_cos` was
//! 9 % of a slider-crank's time (rod 2 at 1e-2 s, 2026-12-07).

use nalgebra::Matrix2;
use std::cell::Cell;

/// A body's last angle (by its bits) with its sine and cosine. Held by the body like its
/// [`super::planar_beam::TermCounts`], not in a thread-local (which, without native
/// thread-locals, takes a key of the operating system that a unit loaded and unloaded again
/// and again might leave behind each time); a clone carries it along, which changes nothing: a
/// remembered value is the one `sin_cos` gives.
#[derive(Debug, Clone)]
pub struct RecentTurn(Cell<(u64, f64, f64)>);

impl Default for RecentTurn {
    fn default() -> RecentTurn {
        let (s, c) = 0.0f64.sin_cos();
        RecentTurn(Cell::new((0.0f64.to_bits(), s, c)))
    }
}

impl RecentTurn {
    /// `theta.sin_cos()`, bit for bit: what it gave for the same bits.
    pub fn sin_cos(&self, theta: f64) -> (f64, f64) {
        let bits = theta.to_bits();
        let (key, s, c) = self.0.get();
        if key == bits {
            return (s, c);
        }
        let (s, c) = theta.sin_cos();
        self.0.set((bits, s, c));
        (s, c)
    }

    /// [`super::planar_beam::rot`] through the memo.
    pub fn rot(&self, theta: f64) -> (Matrix2<f64>, Matrix2<f64>) {
        super::planar_beam::rot_of(self.sin_cos(theta))
    }
}

#[cfg(test)]
mod tests {
    use super::RecentTurn;

    fn same(a: (f64, f64), b: (f64, f64)) -> bool {
        a.0.to_bits() == b.0.to_bits() && a.1.to_bits() == b.1.to_bits()
    }

    /// The memo gives `f64::sin_cos` bit for bit: for an angle met again, for angles in turns,
    /// for -0 against +0 (a new memo holds +0), and a NaN stays a NaN.
    #[test]
    fn remembered_sines_are_the_computed_ones() {
        let turn = RecentTurn::default();
        let angles: Vec<f64> = (0..40)
            .map(|k| (k as f64 - 20.0) * 0.37 + 1e-9 * k as f64)
            .chain([0.0, -0.0, 1e300, -1e-300, f64::INFINITY])
            .collect();
        for round in 0..3 {
            for &a in angles.iter().chain(angles.iter().rev()) {
                for _ in 0..2 {
                    let (m, c) = (turn.sin_cos(a), a.sin_cos());
                    assert!(
                        same(m, c) || (m.0.is_nan() && c.0.is_nan()),
                        "{a} in round {round}"
                    );
                }
            }
        }
        for a in [0.0, -0.0] {
            assert!(
                same(RecentTurn::default().sin_cos(a), a.sin_cos()),
                "{a} first"
            );
        }
        for nan in [f64::NAN, f64::from_bits(u64::MAX)] {
            for _ in 0..2 {
                let (s, c) = turn.sin_cos(nan);
                assert!(s.is_nan() && c.is_nan());
            }
        }
    }
}
