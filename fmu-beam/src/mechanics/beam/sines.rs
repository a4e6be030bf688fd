//! Sines and cosines of the angles this thread turned by last: a memo of `f64::sin_cos`,
//! bit for bit, behind [`super::planar_beam::rot`].

use std::cell::Cell;

/// Sines and cosines of the angles this thread turned by last, by the angle's bits. One Newton
/// iteration turns each body by its angle about five times (its joints' frames, its residual,
/// the reactions' tangents): sin_cos was 9 % of a slider-crank's time (rod 2 at 1e-2 s).
const SIN_COS_SLOTS: usize = 8;
thread_local! {
    static SIN_COS: [Cell<(u64, f64, f64)>; SIN_COS_SLOTS] =
        const { [const { Cell::new((u64::MAX, f64::NAN, f64::NAN)) }; SIN_COS_SLOTS] };
}

/// `theta.sin_cos()`, bit for bit, remembered per thread for the last angles.
pub fn sin_cos(theta: f64) -> (f64, f64) {
    let bits = theta.to_bits();
    if theta.is_nan() {
        return theta.sin_cos(); // the empty slots' key is a NaN's
    }
    let slot = ((bits ^ (bits >> 17) ^ (bits >> 41)) as usize) % SIN_COS_SLOTS;
    SIN_COS.with(|memo| {
        let (key, s, c) = memo[slot].get();
        if key == bits {
            return (s, c);
        }
        let (s, c) = theta.sin_cos();
        memo[slot].set((bits, s, c));
        (s, c)
    })
}

#[cfg(test)]
mod tests {
    use super::sin_cos;

    fn same(a: (f64, f64), b: (f64, f64)) -> bool {
        a.0.to_bits() == b.0.to_bits() && a.1.to_bits() == b.1.to_bits()
    }

    /// The memo gives `f64::sin_cos` bit for bit: for angles met again, for angles that share a
    /// slot (more angles than slots, in turns), for -0 against +0, and a NaN stays a NaN.
    #[test]
    fn remembered_sines_are_the_computed_ones() {
        let angles: Vec<f64> = (0..40)
            .map(|k| (k as f64 - 20.0) * 0.37 + 1e-9 * k as f64)
            .chain([0.0, -0.0, 1e300, -1e-300, f64::INFINITY])
            .collect();
        for round in 0..3 {
            for &a in angles.iter().chain(angles.iter().rev()) {
                let (m, c) = (sin_cos(a), a.sin_cos());
                assert!(
                    same(m, c) || (m.0.is_nan() && c.0.is_nan()),
                    "{a} in round {round}"
                );
            }
        }
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
        // a NaN whose bits are the empty slots' key
        let (s, c) = sin_cos(f64::from_bits(u64::MAX));
        assert!(s.is_nan() && c.is_nan());
    }
}
