//! Error control of the generalized-α stepper: the local error of a step from the third
//! divided difference of positions (`remember`, `position_error`), its norm, the filter that
//! leaves to ρ∞'s damping what a step does not resolve (`filtered`), and the step-size
//! [`Controller`] (the largest recent error, quantized growth, a cap after a Newton failure).

use super::*;

/// A step-size factor rounded down to a multiple of 1/64. The factor is a power of the error
/// estimate, and libm's `pow` may round the last bit differently on another platform: rounded,
/// the step sizes (and with them every decision that follows) are the same bit for bit unless
/// the factor lies within a last bit of a multiple.
pub(super) fn quantized(factor: f64) -> f64 {
    let q = (factor * 64.0).floor() / 64.0;
    if q > 0.0 {
        q
    } else {
        factor
    }
}

/// The factor on the step size after an accepted step whose controller proposes `grow`.
pub(super) fn step_factor(grow: f64) -> f64 {
    let grow = grow.clamp(0.2, MAX_GROWTH);
    if (1.0..=KEEP_STEP).contains(&grow) {
        1.0
    } else {
        grow
    }
}

/// The step-size controller's memory.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Controller {
    /// Error norms of the last accepted steps (at most [`RECENT`], the newest last); a rejected
    /// step clears them.
    pub recent: Vec<f64>,
    /// A cap on the step size after Newton's iteration diverged with a fresh matrix, and the
    /// accepted steps it still holds for.
    pub cap: Option<(f64, u32)>,
}

impl Controller {
    /// The step after an accepted one of size `h` and error norm `err`.
    pub(super) fn accepted(&mut self, h: f64, err: f64) -> f64 {
        if self.recent.len() == RECENT {
            self.recent.remove(0);
        }
        self.recent.push(err);
        let worst = self.recent.iter().copied().fold(0.0, f64::max);
        let grow = if worst > 0.0 {
            0.9 * worst.powf(-1.0 / 3.0)
        } else {
            MAX_GROWTH
        };
        let mut next = h * quantized(step_factor(grow));
        if let Some((cap, left)) = self.cap {
            next = next.min(cap);
            self.cap = (left > 1).then_some((cap, left - 1));
        }
        next
    }

    /// The step after a rejected one of size `h` and error norm `err`.
    pub(super) fn rejected(&mut self, h: f64, err: f64) -> f64 {
        self.recent.clear();
        h * quantized((0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 1.0))
    }

    /// Newton's iteration diverged with a fresh matrix at step `h`.
    pub(super) fn newton_failed(&mut self, h: f64) {
        self.recent.clear();
        self.cap = Some((NEWTON_CAP * h, NEWTON_CAP_STEPS));
    }
}

impl Stepper {
    /// Appends the end (t1, q1) of an accepted step from (t0, q0) to the history of positions,
    /// which starts again at t0 where it does not end there.
    pub(super) fn remember(&mut self, t0: f64, q0: &DVector<f64>, t1: f64, q1: &DVector<f64>) {
        let history = &mut self.memory.history;
        if history.last().map(|p| p.0) != Some(t0) {
            history.clear();
            history.push((t0, q0.clone()));
        }
        if history.len() == HISTORY {
            // the oldest point's vector is reused: no allocation per step
            let (_, mut q) = history.remove(0);
            q.copy_from(q1);
            history.push((t1, q));
        } else {
            history.push((t1, q1.clone()));
        }
    }

    /// The local error of a step from `st` to (t1, q1) per coordinate, |β − 1/6| h³ q''', with
    /// q''' from the third divided difference of the positions at the last [`HISTORY`] points
    /// and the step's end. Where the history does not reach back that far (the first two steps
    /// after the start or a restart), the state at the step's start enters as a repeated node
    /// with its velocity (and, at the restart point itself, its acceleration): a cubic through
    /// the positions and derivatives since the restart, none from before it.
    ///
    /// Why positions, not the algorithmic accelerations' change (β − 1/6) h² Δa of Géradin and
    /// Cardona: both estimate the same h³ q''' where the motion is resolved, but a mode of
    /// frequency ω and amplitude A that the step does not resolve (ωh ≫ 1) weighs ω²h²A in
    /// Δa, and at most 8A in a third difference. A load's jump rings every mode of a mesh, each
    /// with an amplitude about its share of the static deflection, 1/ω²: in Δa the mesh's
    /// highest modes lead, and an error-controlled run resolved them at their own time scale.
    /// With positions a mode is resolved only where its amplitude matters at the tolerance,
    /// and ρ∞ damps the rest, as at fixed steps (C3's elastic crank after its torque's cut-off).
    /// The velocity and the acceleration at a restart stay bounded by the positions' scale on
    /// such a mode (h q' and h² q'' of order A: the jump is met through the iteration matrix,
    /// [`initial::meet_jump`]), so the first steps after it are estimated on the same footing.
    pub(super) fn position_error(
        &self,
        st: &GaState,
        t1: f64,
        q1: &DVector<f64>,
        c: &Coefficients,
    ) -> DVector<f64> {
        let history = self.memory.history.as_slice();
        // the points before the step's start, where the history ends there
        let earlier = match history.split_last() {
            Some((last, rest)) if last.0 == st.t && rest.iter().all(|p| p.1.len() == q1.len()) => {
                rest
            }
            _ => &[],
        };
        let h = t1 - st.t;
        let factor = (c.beta - 1.0 / 6.0).abs() * 6.0 * h * h * h;
        let tc = st.t;
        DVector::from_fn(q1.len(), |k, _| {
            let (qc, q) = (st.q[k], q1[k]);
            factor
                * match earlier {
                    [(ta, a), (tb, b)] => third_difference([*ta, *tb, tc, t1], [a[k], b[k], qc, q]),
                    [(tb, b)] => {
                        third_difference_with_velocity([*tb, tc, t1], [b[k], qc, q], st.v[k])
                    }
                    _ => third_difference_with_acceleration([tc, t1], [qc, q], st.v[k], st.qdd[k]),
                }
        })
    }

    /// Weighted RMS norm of a position-like vector against the tolerance.
    pub(super) fn norm(&self, dq: impl Iterator<Item = f64>, q: &DVector<f64>) -> f64 {
        let tol = self.settings.tolerance;
        let n = q.len().max(1) as f64;
        let s: f64 = dq
            .zip(q.as_slice())
            .zip(self.scale.as_slice())
            .map(|((d, x), sc)| {
                let w = tol * (x.abs() + sc);
                (d / w) * (d / w)
            })
            .sum();
        (s / n).sqrt()
    }

    /// The norm of the step's local error: that of the positions' estimate
    /// ([`Stepper::position_error`]), and where it refuses the step under ρ∞ < 1, that of the
    /// estimate filtered by the scheme's damping ([`Stepper::filtered`]) if smaller.
    pub(super) fn error_norm(
        &mut self,
        st: &GaState,
        t1: f64,
        q1: &DVector<f64>,
        c: &Coefficients,
    ) -> f64 {
        let e = self.position_error(st, t1, q1, c);
        let raw = self.norm(e.iter().copied(), q1);
        if raw <= 1.0 || self.settings.rho_inf >= 1.0 {
            return raw;
        }
        self.filtered(e, q1)
            .map_or(raw, |f| raw.min(self.norm(f.iter().copied(), q1)))
    }

    /// The position error `e` of a step ending at `q1`, filtered [`FILTER_PASSES`] times by
    /// the step's iteration matrix ([`IterationMatrix::filter`], turned as the Newton
    /// corrections are). With S = c_m M + d K_t + c_c C_t (d = βh², c_m = (1 − α_m)/(1 − α_f))
    /// each pass keeps the motion the step resolves (ωh ≪ 1) and multiplies a mode of
    /// frequency ω by 1/(1 + β'(ωh)²), β' = β(1 − α_f)/(1 − α_m) (0.27 at ρ∞ = 0.7): the
    /// modes generalized-α with ρ∞ < 1 damps instead of following. Their raw estimate stays
    /// up to 8|β − 1/6| × their amplitude however long the step (the third difference of an
    /// oscillation), so a step that lets ρ∞ damp a mode its jump struck, as a fixed step
    /// does, was refused for it while the mode lasted, and steps shrank until they resolved
    /// it: C3's elastic crank at tolerance 1e-5 took 1 368 steps, 1 200 of them after the
    /// torque's cut-off, to end 4.1e-4 off where the fixed 4e-3 s step (400) ends 1.9e-4 off.
    /// Filtered twice, such a mode's estimate falls as (ωh)⁻⁴: 183 steps, 6.9e-4 (issue 12,
    /// item 5; docs/accuracy.md). None when the matrix cannot solve.
    pub(super) fn filtered(
        &mut self,
        mut e: DVector<f64>,
        q1: &DVector<f64>,
    ) -> Option<DVector<f64>> {
        let delta = self.turned(q1);
        if let (Some(d), Some(t)) = (delta, &self.turning) {
            turn_pairs(&mut e, &t.pairs, -d);
        }
        for _ in 0..FILTER_PASSES {
            if !self.matrix.filter(&mut e, &mut self.rhs) {
                return None;
            }
        }
        if let (Some(d), Some(t)) = (delta, &self.turning) {
            turn_pairs(&mut e, &t.pairs, d);
        }
        Some(e)
    }
}

/// The third divided difference q[t0, t1, t2, t3] of four values at increasing times: q'''/6
/// somewhere in [t0, t3] for a smooth q.
pub(super) fn third_difference(t: [f64; 4], q: [f64; 4]) -> f64 {
    let first = |i: usize, j: usize, a: f64, b: f64| (b - a) / (t[j] - t[i]);
    let (s01, s12, s23) = (
        first(0, 1, q[0], q[1]),
        first(1, 2, q[1], q[2]),
        first(2, 3, q[2], q[3]),
    );
    let (s012, s123) = (first(0, 2, s01, s12), first(1, 3, s12, s23));
    first(0, 3, s012, s123)
}

/// The third divided difference q[t0, t1, t1, t2] of values at three increasing times and the
/// velocity at the middle one.
pub(super) fn third_difference_with_velocity(t: [f64; 3], q: [f64; 3], v1: f64) -> f64 {
    let s01 = (q[1] - q[0]) / (t[1] - t[0]);
    let s12 = (q[2] - q[1]) / (t[2] - t[1]);
    let (s011, s112) = ((v1 - s01) / (t[1] - t[0]), (s12 - v1) / (t[2] - t[1]));
    (s112 - s011) / (t[2] - t[0])
}

/// The third divided difference q[t0, t0, t0, t1] of values at two times and the velocity and
/// acceleration at the first.
pub(super) fn third_difference_with_acceleration(
    t: [f64; 2],
    q: [f64; 2],
    v0: f64,
    a0: f64,
) -> f64 {
    let h = t[1] - t[0];
    let s001 = ((q[1] - q[0]) / h - v0) / h;
    (s001 - 0.5 * a0) / h
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One low error among higher ones (an oscillation's estimate at a lucky phase) does not
    /// grow the step; the step grows once the higher ones have left the window.
    #[test]
    fn the_step_grows_on_the_largest_recent_error() {
        let mut c = Controller::default();
        assert_eq!(c.accepted(1.0, 1e-6), MAX_GROWTH);
        let after_high = c.accepted(1.0, 0.9);
        assert!(after_high < 1.0, "{after_high}");
        for _ in 1..RECENT {
            assert_eq!(c.accepted(1.0, 1e-3), after_high);
        }
        assert_eq!(c.accepted(1.0, 1e-3), 9.0f64.min(MAX_GROWTH));
        // a rejection forgets the errors before it
        assert!(c.rejected(1.0, 8.0) < 0.5);
        assert!(c.recent.is_empty());
        assert_eq!(c.accepted(1.0, 1e-6), MAX_GROWTH);
    }

    /// The position-level estimate is exact for a cubic at any step sizes, and bounded by the
    /// amplitude of a mode the steps do not resolve, where the change of the algorithmic
    /// acceleration grows as ω²h².
    #[test]
    fn the_third_difference_finds_a_cubic_and_stays_bounded_on_an_unresolved_mode() {
        let diff = |f: &dyn Fn(f64) -> f64, t: [f64; 4]| third_difference(t, t.map(f));
        // q''' = 9 of a cubic, from unequal steps
        let cubic = |t: f64| 2.0 - t + 0.5 * t * t + 1.5 * t * t * t;
        assert!((6.0 * diff(&cubic, [0.1, 0.13, 0.2, 0.45]) - 9.0).abs() < 1e-11);
        // a mode of amplitude 1 at ωh = 50 over equal steps h: h³ q''' estimated as the third
        // difference of four values within ±1, at most 8, where the acceleration changes by
        // up to 2 ω²h² = 5000
        let (omega, h) = (5e4, 1e-3);
        let t = [0.3, 0.3 + h, 0.3 + 2.0 * h, 0.3 + 3.0 * h];
        let estimate = 6.0 * h * h * h * diff(&|t: f64| (omega * t).cos(), t);
        assert!(estimate.abs() <= 8.0 + 1e-9, "{estimate}");
    }

    /// The first two steps after a restart take the restart point's derivatives as repeated
    /// nodes: both find a cubic's q''' from unequal steps.
    #[test]
    fn the_third_difference_with_derivatives_finds_a_cubic() {
        let q = |t: f64| 2.0 - t + 0.5 * t * t + 1.5 * t * t * t;
        let (v, a) = (|t: f64| -1.0 + t + 4.5 * t * t, |t: f64| 1.0 + 9.0 * t);
        let with_v =
            third_difference_with_velocity([0.1, 0.13, 0.2], [q(0.1), q(0.13), q(0.2)], v(0.13));
        assert!((6.0 * with_v - 9.0).abs() < 1e-10, "{with_v}");
        let with_a =
            third_difference_with_acceleration([0.13, 0.2], [q(0.13), q(0.2)], v(0.13), a(0.13));
        assert!((6.0 * with_a - 9.0).abs() < 1e-10, "{with_a}");
    }

    /// After Newton's iteration diverged at h, the steps stay below 0.9 h for
    /// `NEWTON_CAP_STEPS` accepted steps, and are free after.
    #[test]
    fn a_newton_failure_caps_the_step_for_a_while() {
        let mut c = Controller::default();
        c.newton_failed(1.0);
        let mut h = 0.25;
        for _ in 0..NEWTON_CAP_STEPS {
            h = c.accepted(h, 1e-6);
            assert!(h <= NEWTON_CAP, "{h}");
        }
        assert_eq!(c.cap, None);
        assert!(c.accepted(h, 1e-6) > 1.0);
    }

    /// The unit saves its memory into the last save's storage at every communication step:
    /// what it copies there is equal to the memory, whatever was there before (longer or
    /// shorter history, vectors of another length, a matrix point or none).
    #[test]
    fn a_memory_copied_into_another_equals_it() {
        let v = |n: usize, x: f64| DVector::from_fn(n, |i, _| x + i as f64);
        let point = |n: usize, x: f64| super::super::MatrixPoint {
            q: v(n, x),
            v: v(n, x + 1.0),
            qdd: v(n, x + 2.0),
            lambda: v(2, x + 3.0),
            t: x,
            h: 1e-3,
        };
        let memory = |n: usize, x: f64, kept: usize, with_point: bool| Memory {
            point: with_point.then(|| point(n, x)),
            grid: Some((x, kept as u64)),
            controller: Controller {
                recent: vec![x; kept],
                cap: (kept > 1).then_some((x, 3)),
            },
            noise: x,
            history: (0..kept).map(|k| (k as f64, v(n, x + k as f64))).collect(),
            ..Memory::default()
        };
        let sources = [
            memory(5, 1.0, 3, true),
            memory(7, 2.0, 1, false),
            memory(5, 3.0, 0, true),
        ];
        for source in &sources {
            for target in &sources {
                let mut copy = target.clone();
                copy.clone_from(source);
                assert_eq!(&copy, source);
            }
        }
    }
}
