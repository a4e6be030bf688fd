//! `Scene.modes` and `Scene.campbell`: fmu_beam's [`fmu_beam::modes`] computed without the GIL
//! (a Campbell diagram's speeds on several threads, [`modes_at_speeds`]), handed to the
//! pure-Python `fmu_beam._modes` as plain data: numbers, names, and arrays as the bytes of
//! their f64 values (`numpy.frombuffer` reads them back bit for bit), so that numpy and pandas
//! are imported only when these are called.

use crate::errors::{guard, harness_err, Error};
use fmu_beam::{ModeOptions, Modes, Scene};
use fmu_harness::modes::campbell::modes_at_speeds;
use fmu_harness::HarnessError;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

/// The linearization's options from `Scene.modes`'s arguments: `lock` a joint's name, a list
/// of names, or True for every joint that moves.
pub fn options(
    lock: Option<&Bound<'_, PyAny>>,
    speed: Option<f64>,
    hub: Option<String>,
    equilibrium: bool,
) -> PyResult<ModeOptions> {
    let (lock, lock_all) = match lock {
        None => (Vec::new(), false),
        Some(l) if l.is_instance_of::<pyo3::types::PyBool>() => (Vec::new(), l.extract()?),
        Some(l) => match l.extract::<String>() {
            Ok(name) => (vec![name], false),
            Err(_) => (
                l.extract::<Vec<String>>().map_err(|_| {
                    pyo3::exceptions::PyTypeError::new_err(
                        "lock: a joint's name, a list of names, or True (every joint)",
                    )
                })?,
                false,
            ),
        },
    };
    Ok(ModeOptions {
        lock,
        lock_all,
        speed: speed.unwrap_or(0.0),
        hub,
        equilibrium,
    })
}

/// The bytes of `values` as f64 (native order, numpy's "=f8").
fn f64_bytes<'py>(py: Python<'py>, values: impl IntoIterator<Item = f64>) -> Bound<'py, PyBytes> {
    let bytes: Vec<u8> = values.into_iter().flat_map(f64::to_ne_bytes).collect();
    PyBytes::new(py, &bytes)
}

/// Runs `f` without the GIL, its panics caught, its error mapped to the package's exceptions.
fn detached<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> Result<T, HarnessError> + Send,
) -> PyResult<T> {
    py.detach(|| guard(|| Ok(f())))?
        .map_err(|e| harness_err(py, e))
}

/// What was linearized, shared by `Modes` and the Campbell diagram's `attrs`.
fn linearized(d: &Bound<'_, PyDict>, m: &Modes) -> PyResult<()> {
    d.set_item("hub", m.hub.as_deref())?;
    d.set_item("locked", m.locked.clone())?;
    d.set_item("driven", m.driven.clone())?;
    d.set_item("rigid_body_modes", m.rigid_body_modes)?;
    d.set_item("damped", m.damped)?;
    d.set_item("runs_planar", m.runs_planar)?;
    Ok(())
}

/// `Scene.modes`: the first `count` modes (all when None) as `fmu_beam._modes.Modes`.
pub fn modes<'py>(
    py: Python<'py>,
    scene: &Scene,
    origin: &str,
    count: Option<usize>,
    options: ModeOptions,
) -> PyResult<Bound<'py, PyAny>> {
    let m = detached(py, || fmu_harness::modes::modes_of(scene, origin, &options))?;
    let n = count.map_or(m.modes.len(), |c| c.min(m.modes.len()));
    let listed = &m.modes[..n];
    let d = PyDict::new(py);
    d.set_item("count", n)?;
    d.set_item(
        "frequencies",
        f64_bytes(py, listed.iter().map(|x| x.frequency)),
    )?;
    d.set_item(
        "damped_frequencies",
        f64_bytes(py, listed.iter().map(|x| x.damped_frequency)),
    )?;
    d.set_item(
        "damping_ratios",
        f64_bytes(py, listed.iter().map(|x| x.damping_ratio)),
    )?;
    // coordinates × modes, row by row
    let rows = m.coordinates.len();
    d.set_item(
        "shapes",
        f64_bytes(
            py,
            (0..rows).flat_map(|i| {
                listed
                    .iter()
                    .map(move |x| x.shape.get(i).copied().unwrap_or(f64::NAN))
            }),
        ),
    )?;
    d.set_item("coordinates", m.coordinates.clone())?;
    let undamped = count.map_or(m.frequencies.len(), |c| c.min(m.frequencies.len()));
    d.set_item(
        "undamped_frequencies",
        f64_bytes(py, m.frequencies[..undamped].iter().copied()),
    )?;
    d.set_item("speed", m.speed)?;
    d.set_item("non_oscillating", m.non_oscillating)?;
    d.set_item("equilibrium", m.equilibrium)?;
    d.set_item("off_equilibrium", m.off_equilibrium)?;
    linearized(&d, &m)?;
    py.import("fmu_beam._modes")?
        .getattr("Modes")?
        .call_method1("_from_native", (d,))
}

/// `Scene.campbell`: the first `count` modes at each of `speeds` on `jobs` threads (all cores
/// when None), as a pandas DataFrame built by `fmu_beam._modes.campbell_frame`.
pub fn campbell<'py>(
    py: Python<'py>,
    scene: &Scene,
    origin: &str,
    speeds: Vec<f64>,
    count: Option<usize>,
    options: ModeOptions,
    jobs: Option<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    if jobs == Some(0) {
        return Err(Error::new_err("jobs: at least 1 (None: every core)"));
    }
    let all = if speeds.is_empty() {
        Vec::new()
    } else {
        detached(py, || {
            modes_at_speeds(scene, origin, &options, &speeds, jobs.unwrap_or(0))
        })?
    };
    let columns = all
        .iter()
        .map(|m| count.map_or(m.modes.len(), |c| c.min(m.modes.len())))
        .max()
        .unwrap_or(0);
    // speeds × columns, row by row; NaN where a speed has fewer modes
    let table = |f: fn(&fmu_beam::Mode) -> f64| -> Vec<f64> {
        all.iter()
            .flat_map(|m| (0..columns).map(move |k| m.modes.get(k).map_or(f64::NAN, f)))
            .collect()
    };
    let d = PyDict::new(py);
    d.set_item("speeds", f64_bytes(py, speeds.iter().copied()))?;
    d.set_item("columns", columns)?;
    d.set_item("frequencies", f64_bytes(py, table(|x| x.frequency)))?;
    let damped = all.iter().any(|m| m.damped);
    d.set_item(
        "damping_ratios",
        damped.then(|| f64_bytes(py, table(|x| x.damping_ratio))),
    )?;
    d.set_item("scene", &scene.name)?;
    match all.last() {
        Some(m) => linearized(&d, m)?,
        None => {
            d.set_item("hub", options.hub.as_deref())?;
            d.set_item("locked", options.lock.clone())?;
        }
    }
    py.import("fmu_beam._modes")?
        .getattr("campbell_frame")?
        .call1((d,))
}
