//! Dense output: the state at a time inside an internal step, so that a unit without inputs
//! steps across communication points instead of cutting its steps at each of them.
//!
//! Positions follow the cubic Hermite interpolant of (q, q') at both ends of the step (error
//! O(h⁴), below the scheme's own O(h²) for the step sizes it takes), velocities its derivative
//! (O(h³)); accelerations, multipliers and the work of the loads vary linearly (O(h²)).

use super::GaState;

impl GaState {
    /// Writes into `self` the state at `t` in [`back.t`, `front.t`].
    pub fn interpolate_into(&mut self, back: &GaState, front: &GaState, t: f64) {
        let h = front.t - back.t;
        let s = if h > 0.0 {
            ((t - back.t) / h).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (s2, s3) = (s * s, s * s * s);
        // Hermite basis and its derivative in s
        let (h00, h10, h01, h11) = (
            2.0 * s3 - 3.0 * s2 + 1.0,
            s3 - 2.0 * s2 + s,
            -2.0 * s3 + 3.0 * s2,
            s3 - s2,
        );
        let (d00, d10, d01, d11) = (
            6.0 * s2 - 6.0 * s,
            3.0 * s2 - 4.0 * s + 1.0,
            -6.0 * s2 + 6.0 * s,
            3.0 * s2 - 2.0 * s,
        );
        let n = back.q.len();
        self.q.resize_vertically_mut(n, 0.0);
        self.v.resize_vertically_mut(n, 0.0);
        for i in 0..n {
            let (q0, q1, v0, v1) = (back.q[i], front.q[i], back.v[i], front.v[i]);
            self.q[i] = h00 * q0 + h10 * h * v0 + h01 * q1 + h11 * h * v1;
            self.v[i] = if h > 0.0 {
                (d00 * q0 + d01 * q1) / h + d10 * v0 + d11 * v1
            } else {
                v1
            };
        }
        let lerp = |out: &mut nalgebra::DVector<f64>,
                    a: &nalgebra::DVector<f64>,
                    b: &nalgebra::DVector<f64>| {
            out.resize_vertically_mut(a.len(), 0.0);
            for i in 0..a.len() {
                out[i] = a[i] + s * (b[i] - a[i]);
            }
        };
        lerp(&mut self.acc, &back.acc, &front.acc);
        lerp(&mut self.qdd, &back.qdd, &front.qdd);
        lerp(&mut self.lambda, &back.lambda, &front.lambda);
        self.work = back.work + s * (front.work - back.work);
        self.h = front.h;
        self.t = t;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DVector;

    fn state(t: f64, q: f64, v: f64, a: f64) -> GaState {
        let one = |x: f64| DVector::from_vec(vec![x]);
        GaState {
            t,
            h: 0.1,
            q: one(q),
            v: one(v),
            acc: one(a),
            qdd: one(a),
            lambda: DVector::zeros(0),
            work: t,
        }
    }

    #[test]
    fn a_cubic_motion_is_reproduced_exactly() {
        // q = t³ − t, q' = 3t² − 1 on [0.5, 0.8]
        let q = |t: f64| t * t * t - t;
        let v = |t: f64| 3.0 * t * t - 1.0;
        let (b, f) = (
            state(0.5, q(0.5), v(0.5), 3.0),
            state(0.8, q(0.8), v(0.8), 4.8),
        );
        let mut out = state(0.0, 0.0, 0.0, 0.0);
        for t in [0.5, 0.6, 0.73, 0.8] {
            out.interpolate_into(&b, &f, t);
            assert!((out.q[0] - q(t)).abs() < 1e-14, "q at {t}");
            assert!((out.v[0] - v(t)).abs() < 1e-13, "v at {t}");
            assert_eq!(out.t, t);
            assert!((out.work - t).abs() < 1e-15);
        }
        // the ends are the states themselves
        out.interpolate_into(&b, &f, 0.8);
        assert_eq!(out.q, f.q);
    }
}
