//! Scalar time laws of drives: value and first two time derivatives.

use std::f64::consts::PI;

/// An FMU input held over a communication step, or extrapolated from the derivatives the master
/// set with fmi2SetRealInputDerivatives: u(t) = u0 + u1 (t - t0) + u2 (t - t0)^2 / 2.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InputValue {
    /// u0, the value set at `t0` (the input variable's unit).
    pub value: f64,
    /// u1, its first time derivative (unit/s), from fmi2SetRealInputDerivatives; setting the
    /// value resets it to 0.
    pub der1: f64,
    /// u2, its second time derivative (unit/s²), likewise.
    pub der2: f64,
    /// Time the value and derivatives were set at (s).
    pub t0: f64,
}

impl InputValue {
    /// `n` inputs of which only `slot` is 1 (constant, set at t): one unit of that input, for
    /// the derivatives of what acts linearly in the inputs.
    pub fn unit(n: usize, slot: usize, t: f64) -> Vec<InputValue> {
        let mut u = vec![InputValue::default(); n];
        u[slot] = InputValue {
            value: 1.0,
            der1: 0.0,
            der2: 0.0,
            t0: t,
        };
        u
    }
}

/// A function of time that drives a joint or scales a load, in the unit of what it drives (rad
/// or m, N·m or N; a factor for a load's scale).
#[derive(Debug, Clone, PartialEq)]
pub enum Law {
    /// This value at all times.
    Constant(f64),
    /// value (1 - exp(-t/tau)), zero after `until`.
    Exponential {
        /// The final value, approached as t → ∞.
        value: f64,
        /// Time constant τ (s).
        tau: f64,
    },
    /// Planar paper eq. (18).
    SpinUp {
        /// Final angular speed (rad/s), reached at the end of the ramp.
        omega: f64,
        /// Duration of the ramp (s); the speed is constant after it.
        ramp: f64,
    },
    /// Rows [t (s), value], interpolated linearly, held before the first and after the last.
    Table(Vec<[f64; 2]>),
    /// The FMU input in slot `slot` of the system's inputs.
    Input(usize),
}

/// A law with its cut-off: what a drive or a load evaluates at each time.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeLaw {
    /// The function of time.
    pub law: Law,
    /// The law is zero from this time on.
    pub until: Option<f64>,
    /// The absolute time of the system's time 0 (the run's start time): the law is a function
    /// of absolute time, evaluated at `origin + t` for the system's time t, while an input's
    /// extrapolation and the integrator work in the system's time, which double precision
    /// resolves as finely at any start time ([`TimeLaw::shifted`]).
    pub origin: f64,
}

impl TimeLaw {
    /// A law of absolute time `law` (zero from `until` on), in a system whose time 0 is
    /// absolute time 0.
    pub fn new(law: Law, until: Option<f64>) -> TimeLaw {
        TimeLaw {
            law,
            until,
            origin: 0.0,
        }
    }

    /// The same law in a system whose time 0 is absolute time `origin`.
    pub fn shifted(mut self, origin: f64) -> TimeLaw {
        self.origin = origin;
        self
    }

    /// (f(t), f'(t), f''(t)) at the system's time t (absolute time `origin + t`; an input's
    /// extrapolation in the system's time, as its `t0` is).
    pub fn eval(&self, t: f64, inputs: &[InputValue]) -> (f64, f64, f64) {
        let tau = t;
        let t = self.origin + tau;
        if self.until.is_some_and(|u| t > u) {
            return (0.0, 0.0, 0.0);
        }
        match &self.law {
            Law::Constant(v) => (*v, 0.0, 0.0),
            Law::Exponential { value, tau } => {
                let e = (-t / tau).exp();
                (value * (1.0 - e), value * e / tau, -value * e / (tau * tau))
            }
            Law::SpinUp { omega, ramp } => {
                if t < *ramp {
                    let w = 2.0 * PI / ramp;
                    let c = (ramp / (2.0 * PI)).powi(2);
                    (
                        omega / ramp * (t * t / 2.0 + c * ((w * t).cos() - 1.0)),
                        omega / ramp * (t - (w * t).sin() / w),
                        omega / ramp * (1.0 - (w * t).cos()),
                    )
                } else {
                    (omega * (t - ramp / 2.0), *omega, 0.0)
                }
            }
            Law::Table(rows) => {
                let last = rows.len() - 1;
                if t <= rows[0][0] {
                    return (rows[0][1], 0.0, 0.0);
                }
                if t >= rows[last][0] {
                    return (rows[last][1], 0.0, 0.0);
                }
                let k = rows.partition_point(|r| r[0] <= t).max(1);
                let (a, b) = (rows[k - 1], rows[k]);
                let slope = (b[1] - a[1]) / (b[0] - a[0]);
                (a[1] + slope * (t - a[0]), slope, 0.0)
            }
            Law::Input(slot) => {
                let u = inputs.get(*slot).copied().unwrap_or_default();
                let dt = tau - u.t0;
                (
                    u.value + u.der1 * dt + 0.5 * u.der2 * dt * dt,
                    u.der1 + u.der2 * dt,
                    u.der2,
                )
            }
        }
    }

    /// Times where the law or its derivatives jump, in the system's time: the integrator lands
    /// on them.
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b: Vec<f64> = self.until.into_iter().collect();
        match &self.law {
            Law::SpinUp { ramp, .. } => b.push(*ramp),
            Law::Table(rows) => b.extend(rows.iter().map(|r| r[0])),
            _ => {}
        }
        for t in &mut b {
            *t -= self.origin;
        }
        b
    }

    /// The breakpoints of several laws (a system's drives and loads), sorted, each once.
    pub fn breakpoints_of<'a>(laws: impl IntoIterator<Item = &'a TimeLaw>) -> Vec<f64> {
        let mut b: Vec<f64> = laws.into_iter().flat_map(TimeLaw::breakpoints).collect();
        b.sort_by(|x, y| x.total_cmp(y));
        b.dedup();
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(law: &TimeLaw, ts: &[f64]) {
        let h = 1e-5;
        for &t in ts {
            let (_, d1, d2) = law.eval(t, &[]);
            let fd1 = (law.eval(t + h, &[]).0 - law.eval(t - h, &[]).0) / (2.0 * h);
            let fd2 = (law.eval(t + h, &[]).1 - law.eval(t - h, &[]).1) / (2.0 * h);
            assert!(
                (d1 - fd1).abs() < 1e-6 * (1.0 + d1.abs()),
                "{law:?} d1 at {t}"
            );
            assert!(
                (d2 - fd2).abs() < 1e-5 * (1.0 + d2.abs()),
                "{law:?} d2 at {t}"
            );
        }
    }

    #[test]
    fn spin_up_is_smooth_and_reaches_omega() {
        let law = TimeLaw::new(
            Law::SpinUp {
                omega: 4.0,
                ramp: 15.0,
            },
            None,
        );
        check_derivatives(&law, &[0.3, 7.0, 14.0, 16.0]);
        let (th, w, a) = law.eval(15.0, &[]);
        assert!((th - 4.0 * 7.5).abs() < 1e-12 && (w - 4.0).abs() < 1e-12 && a.abs() < 1e-12);
        assert_eq!(law.eval(0.0, &[]), (0.0, 0.0, 0.0));
    }

    #[test]
    fn exponential_torque_cuts_off() {
        let law = TimeLaw::new(
            Law::Exponential {
                value: 0.01,
                tau: 0.167,
            },
            Some(0.7),
        );
        check_derivatives(&law, &[0.1, 0.5]);
        assert!((law.eval(0.7, &[]).0 - 0.01 * (1.0 - (-0.7f64 / 0.167).exp())).abs() < 1e-15);
        assert_eq!(law.eval(0.70001, &[]).0, 0.0);
        assert_eq!(law.breakpoints(), vec![0.7]);
    }

    #[test]
    fn table_interpolates() {
        let law = TimeLaw::new(Law::Table(vec![[0.0, 0.0], [1.0, 2.0], [3.0, 0.0]]), None);
        assert_eq!(law.eval(0.5, &[]), (1.0, 2.0, 0.0));
        assert_eq!(law.eval(2.0, &[]), (1.0, -1.0, 0.0));
        assert_eq!(law.eval(5.0, &[]).0, 0.0);
    }
}
