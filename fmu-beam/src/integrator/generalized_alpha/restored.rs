//! What a restored integration state must be for the stepper to go on from it (issue 45, item
//! 7): a state read from bytes is checked as a new one would be, against the system it is
//! restored into. Finite numbers are not enough: a forged state with q = 1e300 or a proposed
//! step of 0 had its next steps return fmi2OK.

use super::{GaState, Memory, Stepper, MAX_GROWTH};
use crate::mechanics::multibody::Equations;
use nalgebra::DVector;

/// A coordinate lies within this many of its scales (the system's length for a position or a
/// deformation, 1 rad for an angle) of zero: there a double still resolves 2.2e-7 of the
/// scale, what a run at tolerance 1e-6 needs. No run of a scene (whose parts lie within 1e4 m,
/// `LENGTH_RANGE`) comes near it; a forged q = 1e300 is far past it.
pub const COORDINATE_BOUND: f64 = 1e9;

/// A rate (an acceleration) may move a coordinate by at most [`COORDINATE_BOUND`] scales within
/// the smallest internal step a scene may ask for (`scene::validate::MIN_STEP`, 1e-9 s): a
/// faster one is no state of a step the solver took.
const RATE_STEP: f64 = crate::scene::MIN_STEP;

/// The joints of a state stepped to by Newton's iteration are closed to a small share of the
/// solver's tolerance at the system's length: over every shipped scene's default experiment the
/// largest residual was 7.8e-5 × tolerance × max(length, 1 m) (spin_up_omega10). A restored
/// state may be open by up to this many tolerances (1e-6 at least: the tolerance may have been
/// tightened after the state was taken) of that length: 1e-4 of the length at least, far below
/// a joint opened by a beam made longer in a closed loop.
pub const CONSTRAINT_SLACK: f64 = 1e2;

/// Whether |x| ≤ bound (false for NaN).
pub(crate) fn within(x: f64, bound: f64) -> bool {
    x.abs() <= bound
}

impl Stepper {
    /// Why `st` (named `what` in the message) cannot be a state of `sys` stepped by this
    /// stepper, if it cannot: its time not finite or before the start (0), its proposed step
    /// outside the stepper's smallest and largest, a coordinate, rate or acceleration beyond
    /// its bound, a multiplier not finite, and where `closed`, joints open beyond the
    /// tolerance's reach ([`CONSTRAINT_SLACK`]).
    pub fn implausible<S: Equations + ?Sized>(
        &self,
        sys: &S,
        st: &GaState,
        what: &str,
        closed: bool,
    ) -> Option<String> {
        let set = &self.settings;
        if !(st.t.is_finite() && st.t >= 0.0) {
            return Some(format!(
                "{what}: time {} s since the start is not a finite number ≥ 0",
                st.t
            ));
        }
        let h_min = 1e-12 * st.t.max(1.0);
        let h_max = MAX_GROWTH * crate::scene::MAX_STEP;
        if !(st.h >= h_min && st.h <= h_max) {
            return Some(format!(
                "{what}: proposed step {:e} s outside the stepper's [{h_min:e}, {h_max:e}] s",
                st.h
            ));
        }
        let scales = self.bounds(sys);
        let beyond = |x: &DVector<f64>, per: f64| {
            x.iter()
                .zip(scales.iter())
                .position(|(x, s)| !within(*x, COORDINATE_BOUND * s * per))
        };
        let checks = [
            (&st.q, 1.0, "coordinate"),
            (&st.v, 1.0 / RATE_STEP, "rate"),
            (&st.qdd, 1.0 / (RATE_STEP * RATE_STEP), "acceleration"),
            (
                &st.acc,
                1.0 / (RATE_STEP * RATE_STEP),
                "algorithmic acceleration",
            ),
        ];
        for (x, per, name) in checks {
            if let Some(k) = beyond(x, per) {
                return Some(format!(
                    "{what}: {name} {k} = {:e} is beyond {:e} (the bound of a coordinate of \
                     scale {:e} and its rates)",
                    x[k],
                    COORDINATE_BOUND * scales[k] * per,
                    scales[k]
                ));
            }
        }
        if let Some(k) = st.lambda.iter().position(|x| !x.is_finite()) {
            return Some(format!("{what}: multiplier {k} is not finite"));
        }
        if !st.work.is_finite() {
            return Some(format!("{what}: the work done is not finite"));
        }
        if closed {
            let mut g = DVector::zeros(sys.m());
            sys.constraints(&st.q, st.t, &mut g);
            let allowed = CONSTRAINT_SLACK * set.tolerance.max(1e-6) * sys.length_scale().max(1.0);
            if let Some(k) = g.iter().position(|x| !within(*x, allowed)) {
                return Some(format!(
                    "{what}: the joints are open: constraint {k} of joint {} is {:e}, beyond \
                     {allowed:e} (the solver's tolerance at the system's length): no state of \
                     this system",
                    sys.joints_of_rows(&[k]).join(", "),
                    g[k]
                ));
            }
        }
        None
    }

    /// Why the integrator's memory cannot go with a front at `front_t`, if it cannot: its
    /// iteration matrix's point or remembered positions ahead of the front or implausible.
    pub fn implausible_memory<S: Equations + ?Sized>(
        &self,
        sys: &S,
        memory: &Memory,
        front_t: f64,
    ) -> Option<String> {
        let scales = self.bounds(sys);
        let within = |q: &DVector<f64>| {
            q.len() == scales.len()
                && q.iter()
                    .zip(scales.iter())
                    .all(|(x, s)| x.abs() <= COORDINATE_BOUND * s)
        };
        if let Some(p) = &memory.point {
            let h_max = MAX_GROWTH * crate::scene::MAX_STEP;
            if !(p.t >= 0.0 && p.t <= front_t && p.h <= h_max && within(&p.q)) {
                return Some(
                    "integrator memory: the iteration matrix's point is not one of this run".into(),
                );
            }
        }
        if memory
            .history
            .iter()
            .any(|(t, q)| !(*t >= 0.0 && *t <= front_t && within(q)))
        {
            return Some("integrator memory: remembered positions not of this run".into());
        }
        if let Some((anchor, _)) = memory.grid {
            if !(anchor >= 0.0 && anchor <= front_t) {
                return Some("integrator memory: the fixed-step grid starts past the front".into());
            }
        }
        None
    }

    /// Each coordinate's scale for the bounds: its error weight's (a massless body's
    /// coordinates, out of the error norm, as lengths).
    fn bounds<S: Equations + ?Sized>(&self, sys: &S) -> DVector<f64> {
        let length = sys.length_scale().max(1.0);
        self.scale
            .map(|s| if s.is_finite() { s.max(1.0) } else { length })
    }
}
