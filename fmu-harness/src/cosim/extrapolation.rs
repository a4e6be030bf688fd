//! Coupling signals between communication points: the history of one signal and the polynomial
//! through its last points (Newton divided differences), evaluated as value and derivatives at the
//! start of a step for fmi2SetRealInputDerivatives, or at its end to predict the signal (the
//! error estimate of the variable communication step).

/// The last three accepted communication points (t, value) of one signal, oldest first.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct History {
    points: Vec<(f64, f64)>,
}

impl History {
    pub fn push(&mut self, t: f64, value: f64) {
        if self.points.len() == 3 {
            self.points.remove(0);
        }
        self.points.push((t, value));
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The latest value (at the current communication point).
    pub fn last(&self) -> f64 {
        self.points.last().map_or(0.0, |p| p.1)
    }

    /// The last `n` points (fewer if there are fewer).
    fn tail(&self, n: usize) -> &[(f64, f64)] {
        &self.points[self.points.len().saturating_sub(n)..]
    }

    /// Derivatives (first, second) at the latest point of the polynomial of degree ≤ `order`
    /// through the last order + 1 points (lower degree while fewer points exist).
    pub fn extrapolation_derivatives(&self, order: usize) -> [f64; 2] {
        let pts = self.tail(order + 1);
        let t = pts.last().map_or(0.0, |p| p.0);
        Poly::through(pts).derivatives_at(t)
    }

    /// The polynomial of degree ≤ `order` through the last order + 1 points, at `t`.
    pub fn predict(&self, order: usize, t: f64) -> f64 {
        Poly::through(self.tail(order + 1)).value_at(t)
    }

    /// Derivatives (first, second) at the latest point t_n of the polynomial through the last
    /// `order` points and the new point (t_next, next): interpolation over [t_n, t_next].
    pub fn interpolation_derivatives(&self, order: usize, t_next: f64, next: f64) -> [f64; 2] {
        let mut pts = self.tail(order).to_vec();
        pts.push((t_next, next));
        let t = self.points.last().map_or(t_next, |p| p.0);
        Poly::through(&pts).derivatives_at(t)
    }
}

/// Newton form p(t) = c0 + c1 (t − t0) + c2 (t − t0)(t − t1), up to three points.
struct Poly {
    t: [f64; 2],
    c: [f64; 3],
}

impl Poly {
    fn through(pts: &[(f64, f64)]) -> Poly {
        let mut p = Poly {
            t: [0.0; 2],
            c: [0.0; 3],
        };
        match pts {
            [] => {}
            [a] => p.c[0] = a.1,
            [a, b] => {
                p.t[0] = a.0;
                p.c = [a.1, (b.1 - a.1) / (b.0 - a.0), 0.0];
            }
            [a, b, c, ..] => {
                let ab = (b.1 - a.1) / (b.0 - a.0);
                let bc = (c.1 - b.1) / (c.0 - b.0);
                p.t = [a.0, b.0];
                p.c = [a.1, ab, (bc - ab) / (c.0 - a.0)];
            }
        }
        p
    }

    fn value_at(&self, t: f64) -> f64 {
        self.c[0] + (t - self.t[0]) * (self.c[1] + self.c[2] * (t - self.t[1]))
    }

    fn derivatives_at(&self, t: f64) -> [f64; 2] {
        [
            self.c[1] + self.c[2] * (2.0 * t - self.t[0] - self.t[1]),
            2.0 * self.c[2],
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn history(f: impl Fn(f64) -> f64, ts: &[f64]) -> History {
        let mut h = History::default();
        for &t in ts {
            h.push(t, f(t));
        }
        h
    }

    #[test]
    fn a_quadratic_is_reproduced_exactly_from_uneven_points() {
        let f = |t: f64| 1.0 - 2.0 * t + 3.0 * t * t;
        let h = history(f, &[0.0, 0.1, 0.25, 0.4]);
        let [d1, d2] = h.extrapolation_derivatives(2);
        assert!((d1 - (-2.0 + 6.0 * 0.4)).abs() < 1e-12, "{d1}");
        assert!((d2 - 6.0).abs() < 1e-11, "{d2}");
        assert!((h.predict(2, 0.7) - f(0.7)).abs() < 1e-12);
        let [i1, i2] = h.interpolation_derivatives(2, 0.5, f(0.5));
        assert!((i1 - (-2.0 + 6.0 * 0.4)).abs() < 1e-12 && (i2 - 6.0).abs() < 1e-11);
    }

    #[test]
    fn lower_orders_use_fewer_points() {
        let f = |t: f64| t * t;
        let h = history(f, &[0.0, 1.0, 2.0]);
        assert_eq!(h.extrapolation_derivatives(1), [3.0, 0.0]);
        assert_eq!(h.extrapolation_derivatives(0), [0.0, 0.0]);
        assert_eq!(h.predict(0, 5.0), 4.0);
        assert_eq!(h.predict(1, 3.0), 7.0);
        assert_eq!(h.interpolation_derivatives(1, 3.0, 9.0), [5.0, 0.0]);
        let one = history(f, &[2.0]);
        assert_eq!(one.extrapolation_derivatives(2), [0.0, 0.0]);
        assert_eq!(one.predict(2, 9.0), 4.0);
    }
}
