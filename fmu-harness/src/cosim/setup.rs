//! Before the first step: every unit loaded and initialized with its start values; the system
//! file's `<unit>.<variable>` names resolved to value references (connections, rollback checks,
//! recorded outputs); the coupling values at the start time read and set (one Jacobi pass);
//! with joints, the joint forces consistent with the units' start states.

use super::extrapolation::History;
use super::joint::Joints;
use super::system::{self, RollbackSpec, StartValue, System, UnitSpec};
use super::{Check, CosimError, Link, Unit};
use crate::binding::FmuState;
use crate::slave::{Causality, Slave, SlaveError, VarType, Variable};
use std::path::Path;

/// An error about a name of the system file at `path`.
fn var_err(path: &Path, what: &'static str, name: &str, message: String) -> CosimError {
    CosimError::Variable {
        path: path.to_path_buf(),
        what,
        name: name.to_string(),
        message,
    }
}

/// Loads and initializes every unit with its start values (FMUs relative to `path`'s
/// directory); with rollback, every unit must be able to get and set its FMU state.
pub(super) fn load_units(
    system: &System,
    path: &Path,
    rollback: bool,
) -> Result<Vec<Unit>, CosimError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    // what the FMUs declare, all together, before any is extracted; then what each inflates,
    // counted against what is left
    let mut declared: u64 = 0;
    for spec in &system.units {
        let fmu = dir.join(&spec.fmu);
        let bytes = crate::slave::declared_bytes(&fmu).map_err(|source| CosimError::Unit {
            unit: spec.name.clone(),
            fmu: fmu.clone(),
            source,
        })?;
        declared = declared.saturating_add(bytes);
        if declared > system::MAX_SYSTEM_EXTRACTED_BYTES {
            return Err(CosimError::TooManyBytes {
                path: path.to_path_buf(),
                unit: spec.name.clone(),
                fmu,
                declared,
                limit: system::MAX_SYSTEM_EXTRACTED_BYTES,
            });
        }
    }
    let mut left = system::MAX_SYSTEM_EXTRACTED_BYTES;
    let mut units = Vec::with_capacity(system.units.len());
    for spec in &system.units {
        let unit = load_unit(system, spec, dir, path, rollback, left)?;
        left -= unit.slave.extracted_bytes().min(left);
        units.push(unit);
    }
    Ok(units)
}

fn load_unit(
    system: &System,
    spec: &UnitSpec,
    dir: &Path,
    path: &Path,
    rollback: bool,
    budget: u64,
) -> Result<Unit, CosimError> {
    let fmu = dir.join(&spec.fmu);
    let fail = |source| CosimError::Unit {
        unit: spec.name.clone(),
        fmu: fmu.clone(),
        source,
    };
    let mut slave = Slave::load_within(&fmu, budget).map_err(fail)?;
    let md = slave.model_description.clone();
    if rollback && !md.can_get_and_set_fmu_state {
        return Err(CosimError::NoFmuState {
            unit: spec.name.clone(),
        });
    }
    slave.instantiate(&spec.name, false).map_err(fail)?;
    for (name, value) in &spec.start {
        let full = format!("{}.{name}", spec.name);
        let v = md
            .variable(name)
            .map_err(|e| var_err(path, "start value", &full, e.to_string()))?;
        set_start_value(&mut slave, v, *value, &full, path, fail)?;
    }
    slave
        .setup_experiment(None, system.start_time, Some(system.stop_time))
        .map_err(fail)?;
    slave.enter_initialization_mode().map_err(fail)?;
    slave.exit_initialization_mode().map_err(fail)?;
    Ok(Unit {
        name: spec.name.clone(),
        fmu,
        interpolates: md.can_interpolate_inputs,
        slave,
        state: FmuState::empty(),
    })
}

/// Sets the start value of `full` (`<unit>.<variable>`), which must suit the variable's type.
fn set_start_value(
    slave: &mut Slave,
    v: &Variable,
    value: StartValue,
    full: &str,
    path: &Path,
    fail: impl Fn(SlaveError) -> CosimError,
) -> Result<(), CosimError> {
    let vr = [v.value_reference];
    if !v.is_scalar() {
        return Err(var_err(
            path,
            "start value",
            full,
            format!(
                "is an array of {} values: a start value sets a scalar",
                v.value_count()
            ),
        ));
    }
    let r = match (v.var_type, value) {
        (VarType::Real, StartValue::Real(x)) => slave.set_real(&vr, &[x]),
        (VarType::Real, StartValue::Integer(n)) => slave.set_real(&vr, &[n as f64]),
        (VarType::Integer | VarType::Enumeration, StartValue::Integer(n)) => {
            let n = i32::try_from(n).map_err(|_| {
                var_err(
                    path,
                    "start value",
                    full,
                    format!("{n} does not fit a 32-bit Integer"),
                )
            })?;
            slave.set_integer(&vr, &[n])
        }
        (VarType::Boolean, StartValue::Boolean(b)) => slave.set_boolean(&vr, &[b]),
        (ty, value) => {
            return Err(var_err(
                path,
                "start value",
                full,
                format!(
                    "{value:?} does not suit a {} variable",
                    ty.name(slave.model_description.fmi_version)
                ),
            ))
        }
    };
    r.map_err(fail)?;
    Ok(())
}

/// `<unit>.<variable>` of the system file at `path`: the unit's index and the variable.
fn variable(
    system: &System,
    path: &Path,
    units: &[Unit],
    full: &str,
    what: &'static str,
) -> Result<(usize, Variable), CosimError> {
    let (u, v) = system::split_name(full).expect("checked by System::load");
    let i = system
        .units
        .iter()
        .position(|x| x.name == u)
        .expect("checked by System::load");
    let var = units[i]
        .slave
        .model_description
        .variable(v)
        .map_err(|e| var_err(path, what, full, e.to_string()))?
        .clone();
    Ok((i, var))
}

/// The connections, each from a Real output to a Real input.
pub(super) fn links(system: &System, path: &Path, units: &[Unit]) -> Result<Vec<Link>, CosimError> {
    let mut links = Vec::with_capacity(system.connections.len());
    for c in &system.connections {
        let (fu, fv) = variable(system, path, units, &c.from, "connection source")?;
        let (tu, tv) = variable(system, path, units, &c.to, "connection target")?;
        let real = |v: &Variable| v.var_type == VarType::Real && v.is_scalar();
        if !real(&fv) || !real(&tv) {
            return Err(var_err(
                path,
                "connection",
                &format!("{} -> {}", c.from, c.to),
                "both ends must be scalar Real (Float64) variables".into(),
            ));
        }
        if fv.causality != Causality::Output {
            return Err(var_err(
                path,
                "connection source",
                &c.from,
                format!("has causality {:?}, not output", fv.causality),
            ));
        }
        if tv.causality != Causality::Input {
            return Err(var_err(
                path,
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
    Ok(links)
}

/// The `[[rollback.check]]` bounds, each on a Real variable.
pub(super) fn checks(
    system: &System,
    path: &Path,
    rollback: Option<&RollbackSpec>,
    units: &[Unit],
) -> Result<Vec<Check>, CosimError> {
    let mut checks = Vec::new();
    for c in rollback.map(|r| r.checks.as_slice()).unwrap_or(&[]) {
        let (u, v) = variable(system, path, units, &c.variable, "rollback check")?;
        if v.var_type != VarType::Real || !v.is_scalar() {
            return Err(var_err(
                path,
                "rollback check",
                &c.variable,
                "must be a scalar Real (Float64) variable".into(),
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
    Ok(checks)
}

/// The recorded variables, `(unit, variable, column name)`: the system's `outputs`, or every
/// output of every unit but those that are no numbers (String, FMI 3.0 types the master does
/// not move).
pub(super) fn recorded(
    system: &System,
    path: &Path,
    units: &[Unit],
) -> Result<Vec<(usize, Variable, String)>, CosimError> {
    let mut recorded: Vec<(usize, Variable, String)> = Vec::new();
    if system.outputs.is_empty() {
        for (i, u) in units.iter().enumerate() {
            for v in u.slave.model_description.outputs() {
                if v.var_type.is_numeric() {
                    recorded.push((i, v.clone(), format!("{}.{}", u.name, v.name)));
                }
            }
        }
    } else {
        for o in &system.outputs {
            let (i, v) = variable(system, path, units, o, "output")?;
            if !v.var_type.is_numeric() {
                let version = units[i].slave.model_description.fmi_version;
                return Err(var_err(
                    path,
                    "output",
                    o,
                    format!("is a {} variable", v.var_type.name(version)),
                ));
            }
            recorded.push((i, v, o.clone()));
        }
    }
    Ok(recorded)
}

/// The coupling values at the start time `t0`: every source read, then every target set.
pub(super) fn start_values(
    units: &mut [Unit],
    links: &mut [Link],
    t0: f64,
) -> Result<(), CosimError> {
    for l in links.iter_mut() {
        let u = &mut units[l.from_unit];
        let y = u.slave.get_real(&[l.from_vr]).map_err(|e| u.fail(e))?[0];
        l.history.push(t0, l.factor * y);
    }
    for l in links.iter() {
        let u = &mut units[l.to_unit];
        u.slave
            .set_real(&[l.to_vr], &[l.history.last()])
            .map_err(|e| u.fail(e))?;
    }
    Ok(())
}

/// The joint coupling, when the system has joints, with its forces consistent at `t0`.
pub(super) fn joints(
    system: &System,
    path: &Path,
    units: &mut [Unit],
    t0: f64,
) -> Result<Option<Joints>, CosimError> {
    if system.joints.is_empty() {
        return Ok(None);
    }
    let names: Vec<String> = system.units.iter().map(|u| u.name.clone()).collect();
    let mut j = Joints::new(&system.joints, &system.coupling, &names, units, path)?;
    j.consistent_forces(units, t0)?;
    Ok(Some(j))
}
