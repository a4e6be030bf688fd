//! Mechanical joints between units (`[[joint]]` in the system file): both units take the joint
//! force as an input load, and in each communication step the master finds the force at its
//! end that makes the joint's positions agree there — an implicit co-simulation on the
//! interface forces, with the units' interface Jacobians.
//!
//! One communication step t → t + h:
//! 1. every unit gets its joint forces as a linear ramp from λ(t) to the trial λ(t + h)
//!    (fmi2SetRealInputDerivatives; a unit that cannot interpolate holds the end value) and
//!    steps once (the units run one fixed internal step per communication step, so each sees
//!    the force at the step's end, as one monolithic generalized-α step sees its multipliers);
//! 2. r = Σ sides ± x(t + h), the position mismatch of every joint; below `coupling.tolerance`
//!    the step is accepted, else λ(t + h) −= J⁻¹ r, the units are restored (fmi2SetFMUstate)
//!    and step again;
//! 3. J starts as h²/4 Σ_units ±W ±, W = ∂(acceleration)/∂(force) of each unit's joint frames
//!    from fmi2GetDirectionalDerivative (the interface mobility: the position response of a
//!    step to a force at its end, for the units' slow motions), and learns the rest from the
//!    iterates by Broyden's rank-one update, carried from step to step (rescaled by h²);
//! 4. a unit that took more than one internal step (its `solver.steps` output, when it has
//!    one) saw the force inside the step, where a ramp's start value acts explicitly and makes
//!    the iteration unstable: the step is refused and retried with half the step, as are steps
//!    whose iteration does not converge;
//! 5. events: the step is cut to land on the next jump of any unit's laws (its
//!    `solver.next_event_time` output); there, and at the start, the force jumps to the value
//!    that makes the joints' accelerations agree (consistent with the units' states):
//!    Σ ±W Δλ = −Σ ±a, one linear solve with the mobilities, and the units restart from it.
//!
//! Without events and with units that take one internal step, the coupled run is the monolithic
//! generalized-α run (to the iteration tolerance): no added-mass limit, whatever the masses.
//!
//! # References
//! - Schweizer, B., Li, P., Lu, D. (2016): Implicit co-simulation methods: stability and
//!   convergence analysis for solver coupling approaches with algebraic constraints. ZAMM 96(8).
//! - Gu, B., Asada, H. H. (2004): Co-simulation of algebraically coupled dynamic subsystems
//!   without disclosure of proprietary subsystem models. J. Dyn. Syst. Meas. Control 126(1).
//! - Broyden, C. G. (1965): A class of methods for solving nonlinear simultaneous equations.
//!   Math. Comp. 19(92).

use super::attempt::Refused;
use super::step_control::restore;
use super::system::{CouplingSpec, JointSpec};
use super::{CosimError, Unit};
use crate::slave::{Causality, VarType};
use nalgebra::{DMatrix, DVector};
use std::path::Path;

/// Scale of the first Jacobian: the position response to a force applied at the end of a
/// step of length h is h²/4 per unit of mobility under the trapezoidal rule (generalized-α
/// with ρ∞ = 0.9: 0.252).
pub const JACOBIAN_SCALE: f64 = 0.25;

/// One end of a joint: a unit's frame.
struct Side {
    unit: usize,
    /// +1 for the first frame (it gets λ), −1 for the second.
    sign: f64,
    force: Vec<u32>,
    position: Vec<u32>,
    acceleration: Vec<u32>,
}

struct Joint {
    sides: [Side; 2],
    /// Index of the joint's first component in λ.
    offset: usize,
}

/// Counters of the joint coupling, for the summary.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct JointStats {
    /// Iterations: each one fmi2DoStep of every unit.
    pub iterations: u64,
    /// Restores of the units' states between iterations of one step.
    pub restores: u64,
    /// Steps refused because a unit took internal substeps, or because the iteration did not
    /// converge (each retried with half the step).
    pub refusals: u64,
    /// Jumps of the joint forces at the units' events (and at the start).
    pub jumps: u64,
    /// Largest position mismatch accepted (m).
    pub largest_mismatch: f64,
}

pub(super) struct Joints {
    joints: Vec<Joint>,
    /// Total number of force components.
    n: usize,
    tolerance: f64,
    max_iterations: u32,
    /// λ at the current communication point.
    lambda: DVector<f64>,
    /// λ at the point before and the step since, for the predictor (none after a jump).
    previous: Option<(DVector<f64>, f64)>,
    /// The Jacobian and the step it belongs to.
    jacobian: Option<(DMatrix<f64>, f64)>,
    /// (unit, value reference) of each joint unit's `solver.next_event_time` and
    /// `solver.steps`, where it has them.
    events: Vec<(usize, u32)>,
    counters: Vec<(usize, u32)>,
    pub stats: JointStats,
}

impl Joints {
    /// Resolves the joints' variables; every joint unit must provide directional derivatives
    /// and FMU states.
    pub(super) fn new(
        specs: &[JointSpec],
        coupling: &CouplingSpec,
        unit_names: &[String],
        units: &[Unit],
        path: &Path,
    ) -> Result<Joints, CosimError> {
        let var_err = |name: &str, message: String| CosimError::Variable {
            path: path.to_path_buf(),
            what: "joint frame",
            name: name.to_string(),
            message,
        };
        let mut joints = Vec::new();
        let mut n = 0;
        let mut involved: Vec<usize> = Vec::new();
        for spec in specs {
            let axes = spec.kind.axes();
            let mut side = |k: usize| -> Result<Side, CosimError> {
                let frame = &spec.frames[k];
                let (unit_name, prefix) =
                    super::system::split_name(frame).expect("checked by System::load");
                let unit = unit_names
                    .iter()
                    .position(|u| u == unit_name)
                    .expect("checked by System::load");
                let md = &units[unit].slave.model_description;
                if !md.provides_directional_derivative || !md.can_get_and_set_fmu_state {
                    return Err(CosimError::JointUnit {
                        unit: unit_name.to_string(),
                        joint: spec.name.clone(),
                    });
                }
                let find = |suffix: &str, causality: Causality| -> Result<u32, CosimError> {
                    let name = format!("{prefix}.{suffix}");
                    let v = md
                        .variable(&name)
                        .map_err(|e| var_err(&format!("{unit_name}.{name}"), e.to_string()))?;
                    if v.var_type != VarType::Real || !v.is_scalar() || v.causality != causality {
                        return Err(var_err(
                            &format!("{unit_name}.{name}"),
                            format!("must be a Real {causality:?} variable"),
                        ));
                    }
                    Ok(v.value_reference)
                };
                let mut side = Side {
                    unit,
                    sign: if k == 0 { 1.0 } else { -1.0 },
                    force: Vec::new(),
                    position: Vec::new(),
                    acceleration: Vec::new(),
                };
                for (f, x, a) in axes {
                    side.force.push(find(f, Causality::Input)?);
                    side.position.push(find(x, Causality::Output)?);
                    side.acceleration.push(find(a, Causality::Output)?);
                }
                if !involved.contains(&unit) {
                    involved.push(unit);
                }
                Ok(side)
            };
            let sides = [side(0)?, side(1)?];
            joints.push(Joint { sides, offset: n });
            n += axes.len();
        }
        let optional = |unit: usize, name: &str, ty: VarType| {
            let md = &units[unit].slave.model_description;
            md.variable(name)
                .ok()
                .filter(|v| v.var_type == ty && v.causality == Causality::Output)
                .map(|v| (unit, v.value_reference))
        };
        Ok(Joints {
            events: involved
                .iter()
                .filter_map(|&u| optional(u, "solver.next_event_time", VarType::Real))
                .collect(),
            counters: involved
                .iter()
                .filter_map(|&u| optional(u, "solver.steps", VarType::Integer))
                .collect(),
            joints,
            n,
            tolerance: coupling.tolerance,
            max_iterations: coupling.max_iterations,
            lambda: DVector::zeros(n),
            previous: None,
            jacobian: None,
            stats: JointStats::default(),
        })
    }

    fn sides(&self) -> impl Iterator<Item = (&Side, usize)> {
        self.joints
            .iter()
            .flat_map(|j| j.sides.iter().map(move |s| (s, j.offset)))
    }

    /// Σ sides ± (the outputs `pick` of each side), one entry per force component.
    fn residual(
        &self,
        units: &mut [Unit],
        pick: fn(&Side) -> &[u32],
    ) -> Result<DVector<f64>, CosimError> {
        let mut r = DVector::zeros(self.n);
        for (side, offset) in self.sides() {
            let u = &mut units[side.unit];
            let y = u.slave.get_real(pick(side)).map_err(|e| u.fail(e))?;
            for (k, v) in y.iter().enumerate() {
                r[offset + k] += side.sign * v;
            }
        }
        Ok(r)
    }

    /// The mobility of the joints: ∂(Σ ± acceleration)/∂λ = Σ_units ± W ±, from each unit's
    /// directional derivatives of its joint frames' accelerations with respect to its joint
    /// forces.
    fn mobility(&self, units: &mut [Unit]) -> Result<DMatrix<f64>, CosimError> {
        let mut k = DMatrix::zeros(self.n, self.n);
        let mut by_unit: Vec<usize> = self.sides().map(|(s, _)| s.unit).collect();
        by_unit.sort_unstable();
        by_unit.dedup();
        for unit in by_unit {
            let sides: Vec<(&Side, usize)> = self.sides().filter(|(s, _)| s.unit == unit).collect();
            let unknowns: Vec<u32> = sides
                .iter()
                .flat_map(|(s, _)| s.acceleration.iter().copied())
                .collect();
            let rows: Vec<(usize, f64)> = sides
                .iter()
                .flat_map(|(s, o)| (0..s.acceleration.len()).map(move |a| (o + a, s.sign)))
                .collect();
            for (s, o) in &sides {
                for (a, &f) in s.force.iter().enumerate() {
                    let u = &mut units[unit];
                    let column = u
                        .slave
                        .get_directional_derivative(&unknowns, &[f], &[1.0])
                        .map_err(|e| u.fail(e))?;
                    for ((row, row_sign), w) in rows.iter().zip(column) {
                        k[(*row, o + a)] += row_sign * s.sign * w;
                    }
                }
            }
        }
        Ok(k)
    }

    /// Sets the joint forces: ±`value` at the start of the step and, with `slope`, rising by
    /// ±`slope` per second (a unit that cannot interpolate holds the end value
    /// value + slope·h); without, held (derivatives cleared).
    fn set_forces(
        &self,
        units: &mut [Unit],
        value: &DVector<f64>,
        slope: Option<(&DVector<f64>, f64)>,
    ) -> Result<(), CosimError> {
        for (side, offset) in self.sides() {
            let u = &mut units[side.unit];
            let m = side.force.len();
            let part = |x: &DVector<f64>| -> Vec<f64> {
                (0..m).map(|k| side.sign * x[offset + k]).collect()
            };
            let (held, rate) = match slope {
                Some((s, h)) if !u.interpolates => (part(&(value + s * h)), None),
                Some((s, _)) => (part(value), Some(part(s))),
                None => (part(value), u.interpolates.then(|| vec![0.0; m])),
            };
            let r = u.slave.set_real(&side.force, &held);
            r.map_err(|e| u.fail(e))?;
            if let Some(rate) = rate {
                let r = u
                    .slave
                    .set_real_input_derivatives(&side.force, &vec![1; m], &rate);
                r.map_err(|e| u.fail(e))?;
            }
        }
        Ok(())
    }

    /// The joint forces that make the joints' accelerations agree at the units' current
    /// states (Σ ± a = 0; the accelerations are affine in the forces, so one solve with the
    /// mobility is exact); set on the units, and the predictor and Jacobian start afresh.
    pub(super) fn consistent_forces(
        &mut self,
        units: &mut [Unit],
        t: f64,
    ) -> Result<(), CosimError> {
        self.set_forces(units, &self.lambda, None)?;
        let r = self.residual(units, |s| &s.acceleration)?;
        let k = self.mobility(units)?;
        let delta = k
            .lu()
            .solve(&r)
            .filter(|d| d.iter().all(|x| x.is_finite()))
            .ok_or(CosimError::JointsSingular { t })?;
        self.lambda -= delta;
        self.set_forces(units, &self.lambda, None)?;
        self.previous = None;
        self.jacobian = None;
        self.stats.jumps += 1;
        Ok(())
    }

    /// The earliest next event of the joint units (their `solver.next_event_time`).
    pub(super) fn next_event(&self, units: &mut [Unit]) -> Result<Option<f64>, CosimError> {
        let mut first: Option<f64> = None;
        for &(unit, vr) in &self.events {
            let u = &mut units[unit];
            let e = u.slave.get_real(&[vr]).map_err(|e| u.fail(e))?[0];
            first = Some(first.map_or(e, |f| f.min(e)));
        }
        Ok(first)
    }

    fn step_counts(&self, units: &mut [Unit]) -> Result<Vec<i32>, CosimError> {
        self.counters
            .iter()
            .map(|&(unit, vr)| {
                let u = &mut units[unit];
                u.slave
                    .get_integer(&[vr])
                    .map(|c| c[0])
                    .map_err(|e| u.fail(e))
            })
            .collect()
    }

    /// One communication step t → t + h (the units' states at t saved in `Unit::state`):
    /// iterates the joint forces at t + h; `step` sets the other inputs and steps every unit
    /// once. Ok(None) when accepted (the units are at t + h), Ok(Some) when refused.
    pub(super) fn step(
        &mut self,
        units: &mut [Unit],
        t: f64,
        h: f64,
        mut step: impl FnMut(&mut [Unit]) -> Result<Option<Refused>, CosimError>,
    ) -> Result<Option<Refused>, CosimError> {
        let mut end = match &self.previous {
            Some((prev, hp)) => &self.lambda + (&self.lambda - prev) * (h / hp),
            None => self.lambda.clone(),
        };
        let mut jac = match self.jacobian.take() {
            Some((j, hj)) => j * (h / hj).powi(2),
            None => self.mobility(units)? * (JACOBIAN_SCALE * h * h),
        };
        let counts = self.step_counts(units)?;
        let mut last: Option<(DVector<f64>, DVector<f64>)> = None;
        let mut mismatch = f64::INFINITY;
        for k in 0..self.max_iterations {
            if k > 0 {
                restore(units)?;
                self.stats.restores += 1;
            }
            let slope = (&end - &self.lambda) / h;
            self.set_forces(units, &self.lambda, Some((&slope, h)))?;
            self.stats.iterations += 1;
            if let Some(refused) = step(units)? {
                return Ok(Some(self.refused(refused)));
            }
            for ((&(unit, _), c0), c1) in self
                .counters
                .iter()
                .zip(&counts)
                .zip(self.step_counts(units)?)
            {
                if c1 != c0 + 1 {
                    self.stats.refusals += 1;
                    return Ok(Some(self.refused(Refused::Substeps {
                        unit: units[unit].name.clone(),
                        steps: c1 - c0,
                    })));
                }
            }
            let r = self.residual(units, |s| &s.position)?;
            mismatch = r.amax();
            if let Some((e0, r0)) = &last {
                // Broyden: J += (Δr − J Δλ) Δλᵀ / |Δλ|²
                let dl = &end - e0;
                let dn = dl.norm_squared();
                if dn > 0.0 {
                    let dr = &r - r0;
                    jac += (dr - &jac * &dl) * dl.transpose() / dn;
                }
            }
            if mismatch <= self.tolerance {
                self.stats.largest_mismatch = self.stats.largest_mismatch.max(mismatch);
                self.previous = Some((std::mem::replace(&mut self.lambda, end), h));
                self.jacobian = Some((jac, h));
                return Ok(None);
            }
            let delta = jac
                .clone()
                .lu()
                .solve(&r)
                .filter(|d| d.iter().all(|x| x.is_finite()));
            let delta = match delta {
                Some(d) => d,
                None => {
                    // a degenerate secant: start again from the mobilities
                    jac = self.mobility(units)? * (JACOBIAN_SCALE * h * h);
                    jac.clone()
                        .lu()
                        .solve(&r)
                        .ok_or(CosimError::JointsSingular { t })?
                }
            };
            last = Some((end.clone(), r));
            end -= delta;
        }
        self.stats.refusals += 1;
        Ok(Some(self.refused(Refused::Joints {
            iterations: self.max_iterations,
            mismatch,
            tolerance: self.tolerance,
        })))
    }

    /// A refused step is retried (with half the step) from what is certain: the Jacobian of
    /// the mobilities and the force held from the step's start.
    fn refused(&mut self, why: Refused) -> Refused {
        self.jacobian = None;
        self.previous = None;
        why
    }
}
