//! Rollback and step-size control (points 3 and 4 of the module's step): one communication step
//! from t, attempted, refused and retried (units restored, step halved), and with a variable
//! step judged by the coupling error estimate, until it is accepted or the run ends in an error.

use super::attempt::{attempt, Refused};
use super::system::VariableStep;
use super::{is_close, CosimError, Link, Master, Unit};

/// A communication step taken.
pub(super) struct Accepted {
    /// Its length.
    pub(super) h: f64,
    /// The step proposed for the next one (a fixed step: the step given).
    pub(super) next_h: f64,
    /// It ends on the next jump of a unit's laws (joints).
    pub(super) on_event: bool,
}

impl Master<'_> {
    /// Takes one communication step from `t`, first trying `h_try`; `h` is the current step,
    /// proposed again for the next one when the step is fixed.
    pub(super) fn step(&mut self, t: f64, mut h_try: f64, h: f64) -> Result<Accepted, CosimError> {
        let mut halvings = 0;
        let mut on_event = false;
        loop {
            if let Some(j) = &self.joints {
                // land on the next jump of a unit's laws
                if let Some(e) = j.next_event(&mut self.units)? {
                    if e > t && e < t + h_try && !is_close(e, t + h_try) {
                        h_try = e - t;
                    }
                    on_event = is_close(t + h_try, e);
                }
            }
            if self.rollback.is_some() {
                for u in self.units.iter_mut() {
                    let r = u.slave.get_fmu_state(&mut u.state);
                    r.map_err(|e| u.fail(e))?;
                }
            }
            if let Some(why) = self.attempt(t, h_try)? {
                self.roll_back(why, t, h_try, halvings)?;
                halvings += 1;
                h_try /= 2.0;
                continue;
            }
            let Some(v) = self.system.step.variable else {
                return Ok(Accepted {
                    h: h_try,
                    next_h: h,
                    on_event,
                });
            };
            let (e, factor) = coupling_error(&self.links, t, h_try, &v);
            let proposal = (h_try * factor).clamp(v.min, v.max);
            if e > 1.0 && self.rollback.is_some() && h_try > v.min * (1.0 + 1e-12) {
                restore(&mut self.units)?;
                self.summary.error_rejections += 1;
                h_try = proposal.min(h_try);
                continue;
            }
            return Ok(Accepted {
                h: h_try,
                next_h: proposal,
                on_event,
            });
        }
    }

    /// One attempt of t → t + h, through the joint iteration when the system has joints;
    /// counts the units' steps.
    fn attempt(&mut self, t: f64, h: f64) -> Result<Option<Refused>, CosimError> {
        let mut unit_steps = 0;
        let mut step = |units: &mut [Unit]| {
            unit_steps += units.len() as u64;
            attempt(
                units,
                &mut self.links,
                &self.order,
                self.system.algorithm,
                &self.checks,
                t,
                h,
            )
        };
        let refused = match &mut self.joints {
            Some(j) => j.step(&mut self.units, t, h, step)?,
            None => step(&mut self.units)?,
        };
        self.summary.unit_steps += unit_steps;
        Ok(refused)
    }

    /// A refused attempt of t → t + h: with rollback (and `on_discard`, for a unit's refusal)
    /// and halvings left, the units are restored to t and the reason kept for the summary; else
    /// the run ends with the error saying why.
    fn roll_back(&mut self, why: Refused, t: f64, h: f64, halvings: u32) -> Result<(), CosimError> {
        let reason = why.text();
        if let Refused::Ended { unit, .. } = why {
            // no retry: the unit said it cannot go on; the run ends at t, its rows kept
            return Err(CosimError::UnitEnded { unit, t, reason });
        }
        let r = match self.rollback {
            Some(r) if r.on_discard || matches!(why, Refused::Check { .. }) => r,
            _ => {
                return Err(CosimError::StepRefused {
                    t,
                    h,
                    reason,
                    hint: if self.rollback.is_some() {
                        "rollback.on_discard = false"
                    } else {
                        "add [rollback] to the system file to retry it with smaller steps"
                    },
                })
            }
        };
        if halvings >= r.max_halvings {
            return Err(CosimError::RollbackExhausted {
                t,
                h,
                halvings,
                max: r.max_halvings,
                reason,
            });
        }
        restore(&mut self.units)?;
        self.summary.rollbacks += 1;
        if self.summary.retry_reasons.len() < 10 {
            self.summary
                .retry_reasons
                .push(format!("t = {t}, h = {h:e}: {reason}"));
        }
        Ok(())
    }

    /// After an accepted step to `t`: the joint forces made consistent at an event, the
    /// counters, and every coupling signal's new communication point.
    pub(super) fn accept(&mut self, t: f64, step: &Accepted) -> Result<(), CosimError> {
        if let (Some(j), true) = (&mut self.joints, step.on_event) {
            j.consistent_forces(&mut self.units, t)?;
        }
        self.summary.accepted_steps += 1;
        self.summary.min_step = self.summary.min_step.min(step.h);
        self.summary.max_step = self.summary.max_step.max(step.h);
        for l in self.links.iter_mut() {
            l.history.push(t, l.fresh.unwrap_or(0.0));
        }
        Ok(())
    }
}

/// Every unit back to the state saved at the start of the step.
pub(super) fn restore(units: &mut [Unit]) -> Result<(), CosimError> {
    for u in units.iter_mut() {
        let r = u.slave.set_fmu_state(&u.state);
        r.map_err(|e| u.fail(e))?;
    }
    Ok(())
}

/// The coupling error estimate E of the attempt t → t + h against the extrapolation from
/// before t + h, and the factor of the next step: each signal's 0.9·E_l^(−1/(p_l+1)) clamped to
/// [0.2, 5], the smallest wins.
fn coupling_error(links: &[Link], t: f64, h: f64, v: &VariableStep) -> (f64, f64) {
    links
        .iter()
        .map(|l| {
            let p = l.order.min(l.history.len() - 1);
            let y = l.fresh.unwrap_or(0.0);
            let pred = l.history.predict(p, t + h);
            let e = (y - pred).abs() / (v.abs_tolerance + v.tolerance * y.abs());
            let f = if e > 0.0 {
                (0.9 * e.powf(-1.0 / (p as f64 + 1.0))).clamp(0.2, 5.0)
            } else {
                5.0
            };
            (e, f)
        })
        .fold((0.0_f64, 5.0_f64), |(e0, f0), (e, f)| {
            (e0.max(e), f0.min(f))
        })
}
