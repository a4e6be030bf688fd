//! `fmu-harness cosim system.toml`: several FMI 2.0 co-simulation units (any, not only ours)
//! coupled output → input, through [`Slave`].
//!
//! One communication step from t to t + h:
//! 1. with rollback on, every unit's state is saved (fmi2GetFMUstate);
//! 2. each unit gets its inputs and steps (fmi2DoStep(t, h)): **Jacobi** from the coupling values
//!    at t; **Gauss–Seidel** in `order`, a unit getting the t + h outputs of the units that
//!    stepped before it. An input is held constant over the step (extrapolation `none`, or a unit
//!    without canInterpolateInputs: the value at t, or for Gauss–Seidel the newer value at t + h),
//!    or its value at t is set with the derivatives at t of the polynomial of order 1 (`linear`)
//!    or 2 (`quadratic`) through the last communication points (fmi2SetRealInputDerivatives); for
//!    Gauss–Seidel the polynomial also passes through the t + h value: interpolation;
//! 3. the step is refused if a unit returns fmi2Discard or a `[[rollback.check]]` bound fails:
//!    with rollback every unit is restored and the step halved (at most `max_halvings` times),
//!    without it the run ends with an error naming the unit, t, h and what it logged;
//! 4. variable step: each coupling signal at t + h is compared with its extrapolation from the
//!    communication points before t + h (order p of `extrapolation`); E = max over signals of
//!    |y − ŷ| / (abs_tolerance + tolerance·|y|). The local extrapolation error is O(h^(p+1)), so
//!    the next step is h·clamp(0.9·E^(−1/(p+1)), 0.2, 5), within [min, max]. With rollback, a
//!    step with E > 1 is restored and retried with that step (unless already at min).
//!
//! Before the first step every unit is initialized with its start values, then the coupling
//! values at the start time are read and set (one Jacobi pass).

pub mod extrapolation;
pub mod joint;
pub mod system;

use crate::fmi2_binding::{FmuState, LogMessage, Status};
use crate::simulate::Results;
use crate::slave::{Causality, Slave, SlaveError, VarType, Variable};
use extrapolation::History;
use joint::{JointStats, Joints};
use std::path::{Path, PathBuf};
use system::{Algorithm, RollbackSpec, StartValue, System, SystemError};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum CosimError {
    #[error(transparent)]
    System(#[from] SystemError),
    #[error("unit `{unit}` ({}): {source}", .fmu.display())]
    Unit {
        unit: String,
        fmu: PathBuf,
        source: SlaveError,
    },
    #[error("{}: {what} `{name}`: {message}", .path.display())]
    Variable {
        path: PathBuf,
        what: &'static str,
        name: String,
        message: String,
    },
    #[error(
        "unit `{unit}`: rollback needs fmi2GetFMUstate/fmi2SetFMUstate, but its model \
         description has canGetAndSetFMUstate=\"false\" (remove [rollback] or this unit)"
    )]
    NoFmuState { unit: String },
    #[error("at t = {t}, h = {h}: {reason}; the step is not retried ({hint})")]
    StepRefused {
        t: f64,
        h: f64,
        reason: String,
        hint: &'static str,
    },
    #[error(
        "unit `{unit}` cannot take part in joint `{joint}`: joints need \
         providesDirectionalDerivative=\"true\" (its interface mobility) and \
         canGetAndSetFMUstate=\"true\" (the iteration restores the units)"
    )]
    JointUnit { unit: String, joint: String },
    #[error(
        "at t = {t}: the joints' mobility matrix is singular: a joint direction that no unit \
         can move (a frame fixed in both units, or the same direction joined twice)"
    )]
    JointsSingular { t: f64 },
    #[error(
        "at t = {t}: the step was refused {halvings} times, down to h = {h} \
         (rollback.max_halvings = {max}); last: {reason}"
    )]
    RollbackExhausted {
        t: f64,
        h: f64,
        halvings: u32,
        max: u32,
        reason: String,
    },
}

/// Counters of a run, for the summary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Summary {
    pub units: Vec<String>,
    pub connections: usize,
    pub accepted_steps: u64,
    /// Steps retried after fmi2Discard or a failed check.
    pub rollbacks: u64,
    /// Variable step: steps retried because the coupling error estimate exceeded 1.
    pub error_rejections: u64,
    pub min_step: f64,
    pub max_step: f64,
    pub stop_time: f64,
    /// The reasons of the retries, in order (first few kept).
    pub retry_reasons: Vec<String>,
    /// fmi2DoStep calls of all units (iterations and retries included).
    pub unit_steps: u64,
    /// The joint coupling's counters, when the system has joints.
    pub joints: Option<JointStats>,
}

impl Summary {
    pub fn text(&self) -> String {
        let mut s = format!(
            "cosim: {} units ({}), {} connections; {} steps to t = {}, h in [{:e}, {:e}]; \
             {} rollbacks, {} rejections by the coupling error\n",
            self.units.len(),
            self.units.join(", "),
            self.connections,
            self.accepted_steps,
            self.stop_time,
            self.min_step,
            self.max_step,
            self.rollbacks,
            self.error_rejections
        );
        if let Some(j) = &self.joints {
            let per = |x: u64| x as f64 / self.accepted_steps.max(1) as f64;
            s.push_str(&format!(
                "joints: {:.2} iterations and {:.2} restores per step, {:.2} unit steps per step \
                 ({} in all), {} refused (substeps or no convergence), {} force jumps at events, \
                 largest accepted mismatch {:.2e} m\n",
                per(j.iterations),
                per(j.restores),
                per(self.unit_steps),
                self.unit_steps,
                j.refusals,
                j.jumps,
                j.largest_mismatch
            ));
        }
        for r in &self.retry_reasons {
            s.push_str(&format!("  retried: {r}\n"));
        }
        s
    }
}

/// One unit: its slave and what the master knows of it.
struct Unit {
    name: String,
    fmu: PathBuf,
    slave: Slave,
    interpolates: bool,
    state: FmuState,
}

impl Unit {
    fn fail(&self, source: SlaveError) -> CosimError {
        CosimError::Unit {
            unit: self.name.clone(),
            fmu: self.fmu.clone(),
            source,
        }
    }
}

/// A resolved connection: `to` input = factor × `from` output.
struct Link {
    from_unit: usize,
    from_vr: u32,
    to_unit: usize,
    to_vr: u32,
    factor: f64,
    /// Degree of the input polynomial (0 held, 1 linear, 2 quadratic).
    order: usize,
    history: History,
    /// The value at the end of the current attempt, once its source has stepped.
    fresh: Option<f64>,
}

/// Why an attempted step is refused (retried with rollback).
enum Refused {
    Discard {
        unit: String,
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
    fn text(&self) -> String {
        match self {
            Refused::Discard { unit, messages } => {
                let m: Vec<_> = messages.iter().map(|m| m.message.as_str()).collect();
                if m.is_empty() {
                    format!("unit `{unit}`: fmi2DoStep returned fmi2Discard")
                } else {
                    format!(
                        "unit `{unit}`: fmi2DoStep returned fmi2Discard: {}",
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

struct Check {
    unit: usize,
    vr: u32,
    name: String,
    min: Option<f64>,
    max: Option<f64>,
}

fn is_close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-9 * a.abs().max(b.abs())
}

/// Runs the system file; returns the recorded outputs and the summary.
pub fn cosim(path: &Path) -> Result<(Results, Summary), CosimError> {
    let system = System::load(path)?;
    run(&system, path)
}

/// Runs a checked system; `path` locates the FMUs (relative to its directory) and names errors.
pub fn run(system: &System, path: &Path) -> Result<(Results, Summary), CosimError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let var_err = |what, name: &str, message: String| CosimError::Variable {
        path: path.to_path_buf(),
        what,
        name: name.to_string(),
        message,
    };
    // joints retry refused steps with half the step even without [rollback]
    let implied = RollbackSpec::default();
    let rollback = system
        .rollback
        .as_ref()
        .or((!system.joints.is_empty()).then_some(&implied));

    // Load and initialize every unit with its start values.
    let mut units = Vec::with_capacity(system.units.len());
    for spec in &system.units {
        let fmu = dir.join(&spec.fmu);
        let fail = |source| CosimError::Unit {
            unit: spec.name.clone(),
            fmu: fmu.clone(),
            source,
        };
        let mut slave = Slave::load(&fmu).map_err(fail)?;
        let md = slave.model_description.clone();
        if rollback.is_some() && !md.can_get_and_set_fmu_state {
            return Err(CosimError::NoFmuState {
                unit: spec.name.clone(),
            });
        }
        slave.instantiate(&spec.name, false).map_err(fail)?;
        for (name, value) in &spec.start {
            let full = format!("{}.{name}", spec.name);
            let v = md
                .variable(name)
                .map_err(|e| var_err("start value", &full, e.to_string()))?;
            let vr = [v.value_reference];
            let r = match (v.var_type, *value) {
                (VarType::Real, StartValue::Real(x)) => slave.set_real(&vr, &[x]),
                (VarType::Real, StartValue::Integer(n)) => slave.set_real(&vr, &[n as f64]),
                (VarType::Integer | VarType::Enumeration, StartValue::Integer(n)) => {
                    let n = i32::try_from(n).map_err(|_| {
                        var_err(
                            "start value",
                            &full,
                            format!("{n} does not fit a 32-bit Integer"),
                        )
                    })?;
                    slave.set_integer(&vr, &[n])
                }
                (VarType::Boolean, StartValue::Boolean(b)) => slave.set_boolean(&vr, &[b]),
                (ty, value) => {
                    return Err(var_err(
                        "start value",
                        &full,
                        format!("{value:?} does not suit a {ty:?} variable"),
                    ))
                }
            };
            r.map_err(fail)?;
        }
        slave
            .setup_experiment(None, system.start_time, Some(system.stop_time))
            .map_err(fail)?;
        slave.enter_initialization_mode().map_err(fail)?;
        slave.exit_initialization_mode().map_err(fail)?;
        units.push(Unit {
            name: spec.name.clone(),
            fmu,
            interpolates: md.can_interpolate_inputs,
            slave,
            state: FmuState::empty(),
        });
    }

    // Resolve names: `<unit>.<variable>`.
    let unit_index = |full: &str| {
        let (u, v) = system::split_name(full).expect("checked by System::load");
        let i = system
            .units
            .iter()
            .position(|x| x.name == u)
            .expect("checked by System::load");
        (i, v.to_string())
    };
    let variable = |units: &[Unit], full: &str, what| -> Result<(usize, Variable), CosimError> {
        let (i, v) = unit_index(full);
        let var = units[i]
            .slave
            .model_description
            .variable(&v)
            .map_err(|e| var_err(what, full, e.to_string()))?
            .clone();
        Ok((i, var))
    };
    let mut links = Vec::with_capacity(system.connections.len());
    for c in &system.connections {
        let (fu, fv) = variable(&units, &c.from, "connection source")?;
        let (tu, tv) = variable(&units, &c.to, "connection target")?;
        if fv.var_type != VarType::Real || tv.var_type != VarType::Real {
            return Err(var_err(
                "connection",
                &format!("{} -> {}", c.from, c.to),
                "both ends must be Real variables".into(),
            ));
        }
        if fv.causality != Causality::Output {
            return Err(var_err(
                "connection source",
                &c.from,
                format!("has causality {:?}, not output", fv.causality),
            ));
        }
        if tv.causality != Causality::Input {
            return Err(var_err(
                "connection target",
                &c.to,
                format!("has causality {:?}, not input", tv.causality),
            ));
        }
        links.push(Link {
            from_unit: fu,
            from_vr: fv.value_reference,
            to_unit: tu,
            to_vr: tv.value_reference,
            factor: c.factor,
            order: c.extrapolation.unwrap_or(system.extrapolation).order(),
            history: History::default(),
            fresh: None,
        });
    }
    let mut checks = Vec::new();
    for c in rollback.map(|r| r.checks.as_slice()).unwrap_or(&[]) {
        let (u, v) = variable(&units, &c.variable, "rollback check")?;
        if v.var_type != VarType::Real {
            return Err(var_err(
                "rollback check",
                &c.variable,
                "must be a Real variable".into(),
            ));
        }
        checks.push(Check {
            unit: u,
            vr: v.value_reference,
            name: c.variable.clone(),
            min: c.min,
            max: c.max,
        });
    }
    let mut recorded: Vec<(usize, Variable, String)> = Vec::new();
    if system.outputs.is_empty() {
        for (i, u) in units.iter().enumerate() {
            for v in u.slave.model_description.outputs() {
                if v.var_type != VarType::String {
                    recorded.push((i, v.clone(), format!("{}.{}", u.name, v.name)));
                }
            }
        }
    } else {
        for o in &system.outputs {
            let (i, v) = variable(&units, o, "output")?;
            if v.var_type == VarType::String {
                return Err(var_err("output", o, "is a String variable".into()));
            }
            recorded.push((i, v, o.clone()));
        }
    }

    // Coupling values at the start time.
    let t0 = system.start_time;
    for l in links.iter_mut() {
        let u = &mut units[l.from_unit];
        let y = u.slave.get_real(&[l.from_vr]).map_err(|e| u.fail(e))?[0];
        l.history.push(t0, l.factor * y);
    }
    for l in &links {
        let u = &mut units[l.to_unit];
        u.slave
            .set_real(&[l.to_vr], &[l.history.last()])
            .map_err(|e| u.fail(e))?;
    }

    let mut joints = if system.joints.is_empty() {
        None
    } else {
        let names: Vec<String> = system.units.iter().map(|u| u.name.clone()).collect();
        let mut j = Joints::new(&system.joints, &system.coupling, &names, &units, path)?;
        j.consistent_forces(&mut units, t0)?;
        Some(j)
    };

    let mut rows = vec![record(&mut units, &recorded, t0)?];
    let order = match system.algorithm {
        Algorithm::Jacobi => (0..units.len()).collect(),
        Algorithm::GaussSeidel => system.stepping_order(),
    };
    let variable_step = system.step.variable;
    let stop = system.stop_time;
    let mut summary = Summary {
        units: units.iter().map(|u| u.name.clone()).collect(),
        connections: links.len(),
        min_step: f64::INFINITY,
        max_step: 0.0,
        ..Summary::default()
    };

    let mut t = t0;
    let mut grid: u64 = 0; // fixed step: index of the last grid point reached
    let mut h = system.step.size;
    while !(t > stop || is_close(t, stop)) {
        // The end of this step: the next grid point (fixed) or t + h (variable), never past stop.
        let target = if variable_step.is_some() {
            t + h
        } else {
            t0 + (grid + 1) as f64 * system.step.size
        };
        let target = if target > stop || is_close(target, stop) {
            stop
        } else {
            target
        };
        let mut h_try = target - t;
        if variable_step.is_none() {
            h_try = h_try.min(h);
        }
        let mut halvings = 0;
        let mut on_event = false;
        let (h_done, next_h) = loop {
            if let Some(j) = &joints {
                // land on the next jump of a unit's laws
                if let Some(e) = j.next_event(&mut units)? {
                    if e > t && e < t + h_try && !is_close(e, t + h_try) {
                        h_try = e - t;
                    }
                    on_event = is_close(t + h_try, e);
                }
            }
            if rollback.is_some() {
                for u in units.iter_mut() {
                    let r = u.slave.get_fmu_state(&mut u.state);
                    r.map_err(|e| u.fail(e))?;
                }
            }
            let mut unit_steps = 0;
            let mut step = |units: &mut [Unit]| {
                unit_steps += units.len() as u64;
                attempt(
                    units,
                    &mut links,
                    &order,
                    system.algorithm,
                    &checks,
                    t,
                    h_try,
                )
            };
            let refused = match &mut joints {
                Some(j) => j.step(&mut units, t, h_try, step)?,
                None => step(&mut units)?,
            };
            summary.unit_steps += unit_steps;
            if let Some(why) = refused {
                let reason = why.text();
                let r = match rollback {
                    Some(r) if r.on_discard || matches!(why, Refused::Check { .. }) => r,
                    _ => {
                        return Err(CosimError::StepRefused {
                            t,
                            h: h_try,
                            reason,
                            hint: if rollback.is_some() {
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
                        h: h_try,
                        halvings,
                        max: r.max_halvings,
                        reason,
                    });
                }
                restore(&mut units)?;
                halvings += 1;
                summary.rollbacks += 1;
                if summary.retry_reasons.len() < 10 {
                    summary
                        .retry_reasons
                        .push(format!("t = {t}, h = {h_try:e}: {reason}"));
                }
                h_try /= 2.0;
                continue;
            }
            let Some(v) = variable_step else {
                break (h_try, h);
            };
            // Coupling error estimate against the extrapolation from before t + h.
            // Each signal's factor 0.9·E_l^(−1/(p_l+1)), the smallest wins.
            let (e, factor) = links
                .iter()
                .map(|l| {
                    let p = l.order.min(l.history.len() - 1);
                    let y = l.fresh.unwrap_or(0.0);
                    let pred = l.history.predict(p, t + h_try);
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
                });
            let proposal = (h_try * factor).clamp(v.min, v.max);
            if e > 1.0 && rollback.is_some() && h_try > v.min * (1.0 + 1e-12) {
                restore(&mut units)?;
                summary.error_rejections += 1;
                h_try = proposal.min(h_try);
                continue;
            }
            break (h_try, proposal);
        };
        t += h_done;
        if variable_step.is_none() && is_close(t, target) {
            t = target;
            grid += 1;
        }
        h = next_h;
        if let (Some(j), true) = (&mut joints, on_event) {
            j.consistent_forces(&mut units, t)?;
        }
        summary.accepted_steps += 1;
        summary.min_step = summary.min_step.min(h_done);
        summary.max_step = summary.max_step.max(h_done);
        for l in links.iter_mut() {
            l.history.push(t, l.fresh.unwrap_or(0.0));
        }
        if variable_step.is_some() || t == target {
            rows.push(record(&mut units, &recorded, t)?);
        }
    }
    for u in units.iter_mut() {
        if !u.state.is_empty() {
            let r = u.slave.free_fmu_state(&mut u.state);
            r.map_err(|e| u.fail(e))?;
        }
        let r = u.slave.terminate();
        r.map_err(|e| u.fail(e))?;
    }
    summary.stop_time = t;
    summary.joints = joints.map(|j| j.stats);
    if summary.accepted_steps == 0 {
        summary.min_step = 0.0;
    }
    Ok((
        Results {
            columns: recorded.iter().map(|r| r.2.clone()).collect(),
            types: recorded.iter().map(|r| r.1.var_type).collect(),
            rows,
        },
        summary,
    ))
}

fn restore(units: &mut [Unit]) -> Result<(), CosimError> {
    for u in units.iter_mut() {
        let r = u.slave.set_fmu_state(&u.state);
        r.map_err(|e| u.fail(e))?;
    }
    Ok(())
}

/// One attempt of the step t → t + h; `Ok(Some)` when a unit or a check refuses it.
fn attempt(
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
                ..
            }) => {
                return Ok(Some(Refused::Discard {
                    unit: u.name.clone(),
                    messages,
                }))
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

fn record(
    units: &mut [Unit],
    recorded: &[(usize, Variable, String)],
    t: f64,
) -> Result<Vec<f64>, CosimError> {
    let mut row = Vec::with_capacity(recorded.len() + 1);
    row.push(t);
    for (i, v, _) in recorded {
        let u = &mut units[*i];
        let vr = [v.value_reference];
        let x = match v.var_type {
            VarType::Real => u.slave.get_real(&vr).map(|x| x[0]),
            VarType::Integer | VarType::Enumeration => {
                u.slave.get_integer(&vr).map(|x| x[0] as f64)
            }
            VarType::Boolean => u.slave.get_boolean(&vr).map(|x| f64::from(u8::from(x[0]))),
            VarType::String => Ok(f64::NAN),
        };
        row.push(x.map_err(|e| u.fail(e))?);
    }
    Ok(row)
}
