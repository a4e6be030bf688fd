//! One attempt of a communication step t → t + h: the units get their inputs (held, or with the
//! derivatives of the extrapolating or interpolating polynomial) and step, Jacobi or
//! Gauss–Seidel; then the `[[rollback.check]]` bounds are read. A refusal is returned as
//! [`Refused`], for [`super::step_control`] to roll back or report.

use super::system::Algorithm;
use super::{Check, CosimError, Link, Unit};
use crate::binding::{LogMessage, Status};
use crate::slave::SlaveError;

/// Why an attempted step is refused (retried with rollback).
pub(super) enum Refused {
    Discard {
        unit: String,
        /// fmi2DoStep or fmi3DoStep.
        function: &'static str,
        messages: Vec<LogMessage>,
    },
    /// fmi2Discard with fmi2Terminated: the unit cannot go on; the run ends at t.
    Ended {
        unit: String,
        function: &'static str,
        messages: Vec<LogMessage>,
    },
    Check {
        variable: String,
        value: f64,
        bound: String,
    },
    /// A joint unit took more than one internal step.
    Substeps { unit: String, steps: i32 },
    /// The joint iteration did not converge.
    Joints {
        iterations: u32,
        mismatch: f64,
        tolerance: f64,
    },
}

impl Refused {
    pub(super) fn text(&self) -> String {
        match self {
            Refused::Discard {
                unit,
                function,
                messages,
            }
            | Refused::Ended {
                unit,
                function,
                messages,
            } => {
                let m: Vec<_> = messages.iter().map(|m| m.message.as_str()).collect();
                let discard = Status::Discard.named_for(function);
                if m.is_empty() {
                    format!("unit `{unit}`: {function} returned {discard}")
                } else {
                    format!(
                        "unit `{unit}`: {function} returned {discard}: {}",
                        m.join("; ")
                    )
                }
            }
            Refused::Check {
                variable,
                value,
                bound,
            } => format!("check `{variable}` = {value:e} violates {bound}"),
            Refused::Substeps { unit, steps } => format!(
                "unit `{unit}` took {steps} internal steps (its Newton iteration retried with \
                 substeps, which see the joint force inside the step)"
            ),
            Refused::Joints {
                iterations,
                mismatch,
                tolerance,
            } => format!(
                "the joint forces did not converge in {iterations} iterations: position \
                 mismatch {mismatch:.3e} m > coupling.tolerance = {tolerance:e}"
            ),
        }
    }
}

/// One attempt of the step t → t + h; `Ok(Some)` when a unit or a check refuses it.
pub(super) fn attempt(
    units: &mut [Unit],
    links: &mut [Link],
    order: &[usize],
    algorithm: Algorithm,
    checks: &[Check],
    t: f64,
    h: f64,
) -> Result<Option<Refused>, CosimError> {
    for l in links.iter_mut() {
        l.fresh = None;
    }
    for &k in order {
        let (mut vrs, mut values, mut der_vrs, mut orders, mut ders) =
            (vec![], vec![], vec![], vec![], vec![]);
        for l in links.iter().filter(|l| l.to_unit == k) {
            let p = l.order;
            let interpolates = units[k].interpolates && p > 0;
            let fresh = l.fresh.filter(|_| algorithm == Algorithm::GaussSeidel);
            let (value, d) = match (fresh, interpolates) {
                (Some(y), false) => (y, [0.0; 2]),
                (Some(y), true) => (
                    l.history.last(),
                    l.history.interpolation_derivatives(p, t + h, y),
                ),
                (None, false) => (l.history.last(), [0.0; 2]),
                (None, true) => (l.history.last(), l.history.extrapolation_derivatives(p)),
            };
            vrs.push(l.to_vr);
            values.push(value);
            if interpolates {
                for (o, dv) in d.iter().enumerate().take(p) {
                    der_vrs.push(l.to_vr);
                    orders.push(o as i32 + 1);
                    ders.push(*dv);
                }
            }
        }
        let u = &mut units[k];
        if !vrs.is_empty() {
            let r = u.slave.set_real(&vrs, &values);
            r.map_err(|e| u.fail(e))?;
        }
        if !der_vrs.is_empty() {
            let r = u.slave.set_real_input_derivatives(&der_vrs, &orders, &ders);
            r.map_err(|e| u.fail(e))?;
        }
        match u.slave.do_step(t, h, false) {
            Ok(_) => {}
            Err(SlaveError::Call {
                status: Status::Discard,
                messages,
                function,
            }) => {
                let unit = u.name.clone();
                let ended = u.slave.terminated().map_err(|e| u.fail(e))?;
                return Ok(Some(if ended {
                    Refused::Ended {
                        unit,
                        function,
                        messages,
                    }
                } else {
                    Refused::Discard {
                        unit,
                        function,
                        messages,
                    }
                }));
            }
            Err(e) => return Err(u.fail(e)),
        }
        for l in links.iter_mut().filter(|l| l.from_unit == k) {
            let y = u.slave.get_real(&[l.from_vr]).map_err(|e| u.fail(e))?[0];
            l.fresh = Some(l.factor * y);
        }
    }
    for c in checks {
        let u = &mut units[c.unit];
        let value = u.slave.get_real(&[c.vr]).map_err(|e| u.fail(e))?[0];
        let bound = match (c.min, c.max) {
            (Some(lo), _) if value.is_nan() || value < lo => Some(format!("min = {lo:e}")),
            (_, Some(hi)) if value.is_nan() || value > hi => Some(format!("max = {hi:e}")),
            _ => None,
        };
        if let Some(bound) = bound {
            return Ok(Some(Refused::Check {
                variable: c.name.clone(),
                value,
                bound,
            }));
        }
    }
    Ok(None)
}
