//! `fmu_beam._native.Unit`: one instance of a scene's unit in process: the engine the FMU
//! carries ([`fmu_beam::Engine`]), driven with the calls an FMI 2.0 master makes
//! (fmi2SetupExperiment, fmi2Set*, fmi2ExitInitializationMode, fmi2DoStep, fmi2Get*), so that a
//! run through it is, bit for bit, the run of the packaged FMU through fmpy. The master's loop
//! is Python's (`fmu_beam/_simulate.py`); a step runs without the GIL.

use crate::errors::{guard, Error, SimulationError};
use crate::scene::PyScene;
use fmu_beam::{Causality, Engine, EngineError, VarType};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::sync::{Mutex, MutexGuard};

/// One instance of a scene's unit, in process.
#[pyclass(frozen, module = "fmu_beam", name = "Unit")]
pub struct PyUnit {
    /// Behind a lock: Python may call from several threads (the engine is Send, not Sync).
    engine: Mutex<Engine>,
    /// The scene's name, for messages.
    name: String,
}

/// An engine error as [`Error`], its message the unit's.
fn refused(e: EngineError) -> PyErr {
    Error::new_err(e.to_string())
}

/// A set call's values match its value references one for one.
fn same_length(vrs: &[u32], values: usize) -> PyResult<()> {
    if vrs.len() == values {
        Ok(())
    } else {
        Err(Error::new_err(format!(
            "{} values for {} value references",
            values,
            vrs.len()
        )))
    }
}

impl PyUnit {
    /// The engine, locked; an instance whose call panicked is left unusable.
    fn engine(&self) -> PyResult<MutexGuard<'_, Engine>> {
        self.engine.lock().map_err(|_| {
            Error::new_err(format!(
                "{}: this unit is unusable after an internal error; make a new one",
                self.name
            ))
        })
    }
}

#[pymethods]
impl PyUnit {
    /// An instance of `scene`'s unit, as fmi2Instantiate makes it: parameters at their start
    /// values, not yet initialized.
    #[new]
    fn new(scene: PyRef<'_, PyScene>) -> PyResult<PyUnit> {
        let scene = scene.scene().clone();
        guard(|| {
            Ok(PyUnit {
                name: scene.name.clone(),
                engine: Mutex::new(Engine::new(scene)),
            })
        })
    }

    /// The unit's variables in value-reference order: (name, type, causality, variability,
    /// unit) tuples.
    fn variables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for v in &self.engine()?.variables().variables {
            list.append((
                &v.name,
                v.ty.as_str(),
                v.causality.as_str(),
                v.variability.as_str(),
                v.unit,
            ))?;
        }
        Ok(list)
    }

    /// The value reference and type ('Real', 'Integer', 'Boolean') of each of `names`, in
    /// order; a name the unit does not have raises Error naming it.
    fn references(&self, names: Vec<String>) -> PyResult<Vec<(u32, &'static str)>> {
        let e = self.engine()?;
        names
            .iter()
            .map(|n| {
                e.variables()
                    .by_name(n)
                    .map(|v| (v.vr, v.ty.as_str()))
                    .ok_or_else(|| {
                        Error::new_err(format!("{}: the unit has no variable {n}", self.name))
                    })
            })
            .collect()
    }

    /// The names of the outputs, in value-reference order (what fmpy records by default).
    fn output_names(&self) -> PyResult<Vec<String>> {
        Ok(self
            .engine()?
            .variables()
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| v.name.clone())
            .collect())
    }

    /// fmi2SetupExperiment: a tolerance goes to `solver.tolerance` (as the FMU does with
    /// toleranceDefined), then the start time.
    #[pyo3(signature = (start_time, tolerance = None))]
    fn setup(&self, start_time: f64, tolerance: Option<f64>) -> PyResult<()> {
        guard(|| {
            let mut e = self.engine()?;
            if let Some(tol) = tolerance {
                if let Some(v) = e.variables().by_name("solver.tolerance") {
                    let vr = v.vr;
                    e.set_real(vr, tol).map_err(refused)?;
                }
            }
            e.set_start_time(start_time).map_err(refused)
        })
    }

    /// fmi2SetReal of the variables `vrs` (value references), all or nothing.
    fn set_real(&self, vrs: Vec<u32>, values: Vec<f64>) -> PyResult<()> {
        guard(|| {
            same_length(&vrs, values.len())?;
            let mut e = self.engine()?;
            e.set_reals(&vrs, &values).map_err(refused)
        })
    }

    /// fmi2SetInteger (values as numbers), all or nothing.
    fn set_integer(&self, vrs: Vec<u32>, values: Vec<i32>) -> PyResult<()> {
        guard(|| {
            same_length(&vrs, values.len())?;
            let mut e = self.engine()?;
            let v: Vec<f64> = values.iter().map(|&x| f64::from(x)).collect();
            e.set_many(&vrs, VarType::Integer, &v).map_err(refused)
        })
    }

    /// fmi2SetBoolean, all or nothing.
    fn set_boolean(&self, vrs: Vec<u32>, values: Vec<bool>) -> PyResult<()> {
        guard(|| {
            same_length(&vrs, values.len())?;
            let mut e = self.engine()?;
            let v: Vec<f64> = values.iter().map(|&x| f64::from(u8::from(x))).collect();
            e.set_many(&vrs, VarType::Boolean, &v).map_err(refused)
        })
    }

    /// fmi2SetRealInputDerivatives of order 1 (the inputs' slopes over the step to come).
    fn set_input_derivatives(&self, vrs: Vec<u32>, values: Vec<f64>) -> PyResult<()> {
        guard(|| {
            same_length(&vrs, values.len())?;
            let mut e = self.engine()?;
            let order = vec![1; vrs.len()];
            e.set_input_derivatives(&vrs, &order, &values)
                .map_err(refused)
        })
    }

    /// fmi2ExitInitializationMode: builds the model (without the GIL).
    fn exit_initialization(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| guard(|| self.engine()?.exit_initialization().map_err(refused)))
    }

    /// fmi2DoStep from `t` by `h` (without the GIL). A step the unit refuses raises
    /// SimulationError (`time`: the last good time, where the state stays; `reason`; `ended`:
    /// no smaller step can pass).
    fn do_step(&self, py: Python<'_>, t: f64, h: f64) -> PyResult<()> {
        let (outcome, now) = py.detach(|| {
            guard(|| {
                let mut e = self.engine()?;
                let outcome = e.do_step(t, h);
                Ok((outcome, e.time()))
            })
        })?;
        outcome.map_err(|e| {
            let err = SimulationError::new_err(e.to_string());
            let value = err.value(py);
            let attrs = value
                .setattr("time", now)
                .and_then(|_| value.setattr("reason", e.to_string()))
                .and_then(|_| value.setattr("ended", e.ends_run()))
                .and_then(|_| value.setattr("discard", e.is_discard()));
            match attrs {
                Ok(()) => err,
                Err(x) => x,
            }
        })
    }

    /// fmi2GetReal of the variables `vrs`.
    fn get_real(&self, vrs: Vec<u32>) -> PyResult<Vec<f64>> {
        guard(|| {
            let mut e = self.engine()?;
            vrs.iter()
                .map(|&vr| e.get_real(vr).map_err(refused))
                .collect()
        })
    }

    /// fmi2GetInteger of the variables `vrs`.
    fn get_integer(&self, vrs: Vec<u32>) -> PyResult<Vec<i32>> {
        guard(|| {
            let mut e = self.engine()?;
            vrs.iter()
                .map(|&vr| e.get_integer(vr).map_err(refused))
                .collect()
        })
    }

    /// fmi2GetBoolean of the variables `vrs`.
    fn get_boolean(&self, vrs: Vec<u32>) -> PyResult<Vec<bool>> {
        guard(|| {
            let mut e = self.engine()?;
            vrs.iter()
                .map(|&vr| e.get_boolean(vr).map_err(refused))
                .collect()
        })
    }

    /// The time of the last accepted communication point (s).
    #[getter]
    fn time(&self) -> PyResult<f64> {
        Ok(self.engine()?.time())
    }

    /// The warnings the unit logged since the last call (what an FMU logs as fmi2Warning).
    fn messages(&self) -> PyResult<Vec<String>> {
        Ok(self.engine()?.take_messages())
    }

    /// The information the unit logged since the last call (what an FMU logs with fmi2OK in
    /// category logInformation: a split step, an input's effective inertia).
    fn notes(&self) -> PyResult<Vec<String>> {
        Ok(self.engine()?.take_notes())
    }

    /// The units of the variables `names` (None: dimensionless), as a dict.
    fn units<'py>(&self, py: Python<'py>, names: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let e = self.engine()?;
        for n in names {
            let unit = e.variables().by_name(&n).and_then(|v| v.unit);
            d.set_item(n, unit)?;
        }
        Ok(d)
    }
}
