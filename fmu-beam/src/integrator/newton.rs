//! Newton's convergence monitor: a stopping test that bounds the error left in the iterate,
//! from the contraction rate of the (possibly reused) iteration matrix.
//!
//! With a contraction rate θ < 1 the error left after a correction Δ is at most
//! θ/(1 − θ)·‖Δ‖; the iteration stops when that bound is below κ (in the integrator's weighted
//! norm, 1 = the tolerance). θ is measured from two successive corrections. A step that
//! converges in one iteration has no θ of its own: it borrows the rate last measured with the
//! same iteration matrix, and only for a few steps in a row ([`RECHECK`]); then a second
//! iteration measures it again, so an iteration matrix that has grown stale cannot hide behind
//! small corrections (the failure mode of a test on the correction alone: errors that pile up
//! over thousands of internal steps while the matrix is kept).
//!
//! # References
//! - E. Hairer, G. Wanner (1996), Solving Ordinary Differential Equations II, §IV.8
//!   (the stopping criterion η_k‖Δ_k‖ ≤ κ·Tol with η_k = θ_k/(1 − θ_k)).
//! - P. Deuflhard (2004), Newton Methods for Nonlinear Problems, §2.1 (contraction estimates).

/// The bound on the error left in the iterate, as a fraction of the tolerance.
pub const KAPPA: f64 = 0.01;
/// Consecutive steps that may converge in one iteration on a borrowed contraction rate.
pub const RECHECK: u32 = 8;
/// The smallest η = θ/(1 − θ) a borrowed rate counts as: a rate measured in the quadratic
/// phase of a fresh matrix says little about the same matrix some steps later.
pub const ETA_FLOOR: f64 = 0.1;
/// Corrections that stop shrinking below this multiple of the rounding floor count as converged.
pub const STAGNATION: f64 = 10.0;
/// Corrections of the current step that shrink slower than this stall: the matrix is evaluated
/// again at the current iterate, within the step.
pub const SLOW: f64 = 0.3;
/// Corrections a matrix evaluated at the current iterate needs to converge (quadratically,
/// close to the solution); a matrix evaluated for this step, at its predictor, is evaluated
/// again within the step when the corrections still needed at its measured rate cost more
/// than these and a factorization (`Stepper::refresh_pays`). One frame of 10 elements (C2) at
/// a fixed step of 1e-2 s: its matrix, evaluated at the predictor, contracted at 0.24 for 13
/// corrections where one evaluated after 3 converged in 2; with the rule 7.6 instead of 9.0
/// iterations a step at Newton 1e-6 (0.91 × the work counted, outputs 9e-8 relative from the
/// run without it), and at 1e-8 8.3 instead of 10.4 with none of the 20 split steps (0.82 ×).
/// At 5e-3 and 1e-3 s, and C2 in substructures, C3, C4, the 3D pendulum and the 3D roll-up
/// at their steps: the same counts within one matrix. A matrix kept from earlier steps is not
/// judged so: on the 3D rigid twin at 1.25e-5 s (80 000 steps), replacing such matrices moved
/// the result by 4.4e-8 rad with the communication step (`fixed_steps_converge_as_they_shrink`).
pub const AFTER_REFRESH: f64 = 2.0;
/// A measured rate slower than this keeps the step but asks for a new iteration matrix for the
/// next one. A new matrix costs a few Newton iterations (its assembly and sparse or dense LU)
/// and saves up to one per step for many steps. At fixed steps, 0.1 instead of 0.3 took C4
/// Ω = 4 (10 × 1 substructures at 5e-3 s) from 4.5 to 3.2 iterations per step, 0.75 × the CPU
/// time, C3 (2e-4 s) from 4.7 to 3.9, 0.80 ×, C2 (5 × 2 at 2e-4 s) from 3.8 to 3.3, 0.90 ×
/// (issue 12; fastest of 3 runs). Systems that turn their matrix ([`STALE_TURNED`]) use less.
pub const STALE: f64 = 0.1;
/// [`STALE`] for a system whose Newton turns its matrix with it (`Stepper::solve_turned`):
/// what ages the matrix then is slow (a spin rate that changes, deformation), and a rate above
/// 0.03 is worth replacing. At fixed steps, 0.03 instead of 0.1 (with turning, fastest of 3
/// runs, issue 12): C4 Ω = 10 (10 × 1 at 5e-3 s) from 3.04 to 2.73 iterations per step, 0.91 ×
/// the CPU time; C4 Ω = 4 (40 × 1 at 1e-3 s, tolerance 1e-6) 2.84 to 2.72, 0.94 ×; C3 (2e-4 s)
/// 3.74 to 3.37, 0.94 ×; C2 (5 × 2 at 1e-4 s) 3.13 to 2.91, 0.99 ×. (On the 3D roll-up at
/// 5e-4 s and Newton at 1e-10, 0.03 met a step whose fresh matrix did not converge, and a
/// split step: the 3D system does not turn its matrix and keeps 0.1.)
pub const STALE_TURNED: f64 = 0.03;

/// What the monitor says after a correction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Verdict {
    Converged,
    Continue,
    /// The corrections grow, or cannot reach κ within the iterations left.
    Diverging,
}

/// The contraction rate of the current iteration matrix, kept across steps.
///
/// The ratio of the first two corrections says little: the first correction mostly removes the
/// predictor's error in the stiff, nearly linear directions, which any iteration matrix removes
/// at once, and the ratio can be 1e-4 where the later ones are 0.4. The matrix's rate is
/// therefore measured on corrections after the second ([`Contraction::theta`]); a step may stop
/// after its second correction only on such a rate, measured within the last [`RECHECK`] steps,
/// else it iterates once more to measure it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Contraction {
    /// The largest ratio of successive corrections beyond the first, in the last step that
    /// measured one; `None` for a matrix not yet measured.
    pub theta: Option<f64>,
    /// Steps accepted since `theta` was measured.
    pub since: u32,
    /// The ratio of the last two corrections of the current step.
    ratio: Option<f64>,
    /// The largest ratio beyond the first in the current step.
    step_max: f64,
}

impl Contraction {
    /// A rate measured before (a restored state).
    pub fn measured(theta: Option<f64>, since: u32) -> Contraction {
        Contraction {
            theta,
            since,
            ..Contraction::default()
        }
    }

    /// A new iteration matrix: its rate is unknown.
    pub fn fresh(&mut self) {
        *self = Contraction::default();
    }

    /// Whether the matrix converges slowly enough to be replaced before the next step: its
    /// rate is above `stale` ([`STALE`] or [`STALE_TURNED`]).
    pub fn slow(&self, stale: f64) -> bool {
        self.theta.is_some_and(|t| t > stale)
    }

    /// Whether the corrections of the current step beyond the second shrink slowly (or grow):
    /// the matrix is worth evaluating again at the current iterate.
    pub fn stalls(&self) -> bool {
        self.step_max > SLOW
    }

    /// The corrections still needed, at the rate the current step measured beyond its first
    /// correction, until the error left is within `kappa`; None before such a rate.
    pub fn remaining(&self, norm: f64, kappa: f64) -> Option<f64> {
        let theta = self.step_max;
        if !(theta > 0.0 && theta < 1.0) {
            return None;
        }
        let eta = theta / (1.0 - theta);
        Some(((kappa / (eta * norm)).ln() / theta.ln()).max(0.0))
    }

    /// The rate a step may rely on without measuring it.
    fn borrowed(&self) -> Option<f64> {
        self.theta.filter(|_| self.since < RECHECK)
    }

    /// Judges correction `k` (0-based) of weighted norm `norm`, the previous one being `prev`;
    /// `floor` is the norm below which a correction is rounding (converged whatever the rate),
    /// `left` the iterations left after this one, `kappa` the bound to reach; `fresh` says
    /// whether the matrix was factorized for this step.
    #[allow(clippy::too_many_arguments)]
    pub fn judge(
        &mut self,
        k: usize,
        norm: f64,
        prev: f64,
        floor: f64,
        left: usize,
        kappa: f64,
        fresh: bool,
    ) -> Verdict {
        if !norm.is_finite() {
            return Verdict::Diverging;
        }
        if k == 0 {
            self.ratio = None;
            self.step_max = 0.0;
            let eta = match self.borrowed() {
                Some(theta) => (theta / (1.0 - theta)).max(ETA_FLOOR),
                None if norm <= floor => 0.0,
                None => return Verdict::Continue,
            };
            return if eta * norm <= kappa || norm <= floor {
                self.since += 1;
                Verdict::Converged
            } else {
                Verdict::Continue
            };
        }
        if norm <= floor {
            self.since += 1;
            return Verdict::Converged;
        }
        let ratio = norm / prev;
        // the corrections may alternate in size (those of q and of λ): the iteration counts as
        // diverging only when the geometric mean of the last two ratios is above 1
        let mean = self.ratio.map_or(ratio, |r| (r * ratio).sqrt());
        self.ratio = Some(ratio);
        // corrections that stop shrinking near the rounding level have converged as far as
        // the arithmetic allows
        if ratio >= 1.0 && norm <= STAGNATION * floor {
            self.since += 1;
            return Verdict::Converged;
        }
        if mean >= 1.0 {
            return Verdict::Diverging;
        }
        let theta = if k == 1 {
            match self.borrowed() {
                Some(theta) => theta.max(ratio),
                None => return Verdict::Continue, // measure the rate first
            }
        } else {
            self.step_max = self.step_max.max(ratio);
            if self.step_max < 1.0 {
                self.theta = Some(self.step_max);
                self.since = 0;
            }
            self.step_max
        };
        if theta >= 1.0 {
            return Verdict::Continue;
        }
        let eta = theta / (1.0 - theta);
        if eta * norm <= kappa {
            if k == 1 {
                self.since += 1;
            }
            return Verdict::Converged;
        }
        // a reused matrix that will not get there in the iterations left, at this rate, is
        // replaced (a new one converges faster); a fresh one is given every iteration
        if !fresh && k >= 2 && theta.powi(left as i32) * eta * norm > kappa {
            return Verdict::Diverging;
        }
        Verdict::Continue
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const INF: f64 = f64::INFINITY;

    #[test]
    fn the_corrections_left_follow_the_rate_measured_in_the_step() {
        let mut c = Contraction::default();
        assert_eq!(c.remaining(1.0, 0.01), None, "no rate yet");
        // 100, then 25, 6.25: the rate beyond the first correction is 0.25, eta = 1/3
        assert_eq!(
            c.judge(0, 100.0, INF, 0.0, 10, 0.01, true),
            Verdict::Continue
        );
        assert_eq!(
            c.judge(1, 25.0, 100.0, 0.0, 9, 0.01, true),
            Verdict::Continue
        );
        assert_eq!(
            c.judge(2, 6.25, 25.0, 0.0, 8, 0.01, true),
            Verdict::Continue
        );
        // 0.25^n * 6.25 / 3 <= 0.01: n = ln(0.0048) / ln(0.25) = 3.85
        let left = c.remaining(6.25, 0.01).unwrap();
        assert!(
            (left - (0.0048f64).ln() / 0.25f64.ln()).abs() < 1e-12,
            "{left}"
        );
        assert_eq!(c.remaining(1e-3, 0.01), Some(0.0), "already within");
    }

    #[test]
    fn a_matrix_rate_is_measured_beyond_the_second_correction() {
        let mut c = Contraction::default();
        assert_eq!(
            c.judge(0, 1e-9, INF, 0.0, 7, KAPPA, true),
            Verdict::Continue
        );
        // the first ratio (1e-3) does not count: one more iteration measures the rate
        assert_eq!(
            c.judge(1, 1e-6, 1e-3, 0.0, 6, KAPPA, true),
            Verdict::Continue
        );
        assert_eq!(
            c.judge(2, 1e-8, 1e-6, 0.0, 5, KAPPA, true),
            Verdict::Converged
        );
        assert_eq!(c.theta, Some(1e-2));
    }

    #[test]
    fn a_second_correction_that_looks_converged_is_not_when_the_matrix_is_slow() {
        // the case that made errors pile up: ratio 1e-4 on the first pair, 0.4 after
        let mut c = Contraction::measured(Some(0.4), 0);
        c.judge(0, 1.0, INF, 0.0, 7, 1e-6, false);
        assert_eq!(
            c.judge(1, 1e-4, 1.0, 0.0, 6, 1e-6, false),
            Verdict::Continue
        );
        let mut c = Contraction::measured(Some(0.001), 0);
        c.judge(0, 1.0, INF, 0.0, 7, 1e-6, false);
        assert_eq!(
            c.judge(1, 1e-4, 1.0, 0.0, 6, 1e-6, false),
            Verdict::Converged
        );
    }

    #[test]
    fn a_borrowed_rate_serves_a_few_steps_then_is_measured_again() {
        let mut c = Contraction::measured(Some(0.01), 0);
        for _ in 0..RECHECK {
            assert_eq!(
                c.judge(0, 1e-3, INF, 0.0, 7, KAPPA, false),
                Verdict::Converged
            );
        }
        assert_eq!(
            c.judge(0, 1e-3, INF, 0.0, 7, KAPPA, false),
            Verdict::Continue
        );
        assert_eq!(
            c.judge(1, 5e-4, 1e-3, 0.0, 6, KAPPA, false),
            Verdict::Continue
        );
        assert_eq!(
            c.judge(2, 1e-5, 5e-4, 0.0, 5, KAPPA, false),
            Verdict::Converged
        );
        assert_eq!((c.theta, c.since), (Some(0.02), 0));
    }

    #[test]
    fn a_slow_reused_matrix_is_given_up() {
        let mut c = Contraction::measured(Some(0.9), 0);
        c.judge(0, 2e-3, INF, 0.0, 7, KAPPA, false);
        assert_eq!(
            c.judge(1, 1.8e-3, 2e-3, 0.0, 6, KAPPA, false),
            Verdict::Continue
        );
        // rate 0.9 with 2 iterations left cannot reach κ
        assert_eq!(
            c.judge(2, 1.62e-3, 1.8e-3, 0.0, 2, KAPPA, false),
            Verdict::Diverging
        );
        assert!(c.slow(STALE));
        // growing corrections diverge
        let mut c = Contraction::default();
        c.judge(0, 2e-3, INF, 0.0, 7, KAPPA, false);
        c.judge(1, 2.2e-3, 2e-3, 0.0, 6, KAPPA, false);
        assert_eq!(
            c.judge(2, 2.5e-3, 2.2e-3, 0.0, 5, KAPPA, false),
            Verdict::Diverging
        );
    }

    #[test]
    fn rounding_converges_whatever_the_rate() {
        let mut c = Contraction::default();
        assert_eq!(
            c.judge(0, 1e-13, INF, 1e-12, 7, KAPPA, true),
            Verdict::Converged
        );
        assert_eq!(
            c.judge(2, f64::NAN, 1.0, 1e-12, 5, KAPPA, true),
            Verdict::Diverging
        );
        // stagnation near the floor
        let mut c = Contraction::default();
        c.judge(0, 1.0, INF, 1e-12, 7, 1e-14, true);
        c.judge(1, 4e-12, 1.0, 1e-12, 6, 1e-14, true);
        assert_eq!(
            c.judge(2, 5e-12, 4e-12, 1e-12, 5, 1e-14, true),
            Verdict::Converged
        );
        let mut c = Contraction::default();
        c.judge(0, 1.0, INF, 1e-12, 7, 1e-14, true);
        c.judge(1, 4e-10, 1.0, 1e-12, 6, 1e-14, true);
        // one growing correction after a large drop may be the alternation; two are not
        assert_eq!(
            c.judge(2, 5e-10, 4e-10, 1e-12, 5, 1e-14, true),
            Verdict::Continue
        );
        assert_eq!(
            c.judge(3, 6e-10, 5e-10, 1e-12, 4, 1e-14, true),
            Verdict::Diverging
        );
    }
}
