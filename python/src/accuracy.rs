//! `Scene.accuracy`: the accuracy study of `fmu-beam accuracy` ([`fmu_harness::accuracy`]) from
//! Python, run without the GIL and on every core, stopped by Ctrl-C (the study asks Python for
//! its signals about five times a second), its result an [`AccuracyStudy`]: the chosen
//! setting and scene, the estimate and what limits it, and the runs as a pandas DataFrame.

use crate::errors::{guard, harness_err, Error};
use fmu_beam::Scene;
use fmu_harness::accuracy::{self, report, AccuracyError, Options, Study};
use fmu_harness::HarnessError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use std::path::PathBuf;
use std::sync::Mutex;

/// What `Scene.accuracy` was asked, as Python gave it.
pub struct Args<'py> {
    pub output: Bound<'py, PyAny>,
    pub target: f64,
    pub stop: Option<f64>,
    pub comm: Option<f64>,
    pub step: Option<f64>,
    pub newton: Option<f64>,
    pub levels: usize,
    pub mesh_levels: usize,
    pub recentre: bool,
    pub max_runs: usize,
    pub reference: Option<Bound<'py, PyAny>>,
    pub column: Option<Bound<'py, PyAny>>,
    pub jobs: Option<usize>,
    pub max_work: Option<f64>,
    pub max_seconds: Option<f64>,
}

/// A finished accuracy study (`Scene.accuracy`).
#[pyclass(frozen, module = "fmu_beam", name = "AccuracyStudy")]
pub struct AccuracyStudy {
    /// The chosen setting: {'step': s, 'newton': tolerance, 'mesh': text, 'work': counted work,
    /// 'cpu_s': seconds}, or None where no setting of the ladders meets the target.
    #[pyo3(get)]
    choice: Py<PyAny>,
    /// The scene at the chosen setting (a `fmu_beam.Scene`), or None.
    #[pyo3(get)]
    scene: Py<PyAny>,
    /// The chosen setting's predicted error (the study's norm: the largest over the grid of
    /// |y - y*| / max |y*|, over the outputs), or None.
    #[pyo3(get)]
    estimate: Option<f64>,
    /// Its time, mesh and Newton shares, and which of them limits it.
    #[pyo3(get)]
    time_share: Option<f64>,
    #[pyo3(get)]
    mesh_share: Option<f64>,
    #[pyo3(get)]
    newton_share: Option<f64>,
    #[pyo3(get)]
    limited_by: Option<String>,
    /// The safety factor the prediction was held to (1.25 where every order is observed, 3).
    #[pyo3(get)]
    margin: f64,
    #[pyo3(get)]
    target: f64,
    #[pyo3(get)]
    outputs: Vec<String>,
    /// Remarks: runs the budget left out, a relaxed setting that missed, the re-centring.
    #[pyo3(get)]
    notes: Vec<String>,
    /// Why the study stopped before its end (its wall-clock safety stop), else None.
    #[pyo3(get)]
    incomplete: Option<String>,
    /// The study's counted work, CPU and wall seconds, and the runs it ran at once.
    #[pyo3(get)]
    work: f64,
    #[pyo3(get)]
    cpu_seconds: f64,
    #[pyo3(get)]
    wall_seconds: f64,
    #[pyo3(get)]
    jobs: usize,
    /// One row per run: role, step, newton, mesh, stiffening_switched, estimated_error (and
    /// error_<output> each), true_error (with a reference), work, cpu_s, steps,
    /// newton_iterations, jacobians, status ('ok' or why it failed).
    #[pyo3(get)]
    runs: Py<PyAny>,
    text: String,
    table: String,
}

#[pymethods]
impl AccuracyStudy {
    /// The report of `fmu-beam accuracy` (Markdown).
    fn markdown(&self) -> String {
        self.text.clone()
    }

    /// The runs as the command's accuracy.csv.
    fn csv(&self) -> String {
        self.table.clone()
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let choice = if self.choice.is_none(py) {
            "no setting meets the target".to_string()
        } else {
            self.choice
                .bind(py)
                .repr()
                .map_or_else(|_| "?".into(), |r| r.to_string())
        };
        format!(
            "<fmu_beam.AccuracyStudy of {} at {:e}: {choice}{}>",
            self.outputs.join(", "),
            self.target,
            if self.incomplete.is_some() {
                " (INCOMPLETE)"
            } else {
                ""
            }
        )
    }
}

/// One name or a list of names.
fn names(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<String>> {
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(vec![s.to_string()]);
    }
    obj.extract::<Vec<String>>().map_err(|_| {
        Error::new_err(format!(
            "{what}: a name or a list of names expected, got {}",
            obj.repr().map_or_else(|_| "?".into(), |r| r.to_string())
        ))
    })
}

/// A reference given as a pandas DataFrame (indexed by time, `columns` named) or Series, on
/// the study's grid: per column, its value at each grid time (a row within a millionth of the
/// communication step of it).
fn reference_values(
    obj: &Bound<'_, PyAny>,
    columns: &[String],
    (start, comm, n): (f64, f64, usize),
) -> PyResult<Vec<Vec<f64>>> {
    let floats = |o: Bound<'_, PyAny>| -> PyResult<Vec<f64>> {
        o.call_method1("to_numpy", (PyString::new(o.py(), "float64"),))?
            .call_method0("tolist")?
            .extract()
    };
    let times = floats(obj.getattr("index")?)?;
    let series: Vec<Vec<f64>> = if obj.hasattr("columns")? {
        columns
            .iter()
            .map(|c| {
                let col = obj.get_item(c).map_err(|_| {
                    Error::new_err(format!("reference: no column {c:?} in the DataFrame"))
                })?;
                floats(col)
            })
            .collect::<PyResult<_>>()?
    } else {
        if columns.len() != 1 {
            return Err(Error::new_err(format!(
                "reference: a Series holds one output, the study has {}",
                columns.len()
            )));
        }
        vec![floats(obj.clone())?]
    };
    let mut order: Vec<usize> = (0..times.len()).collect();
    order.sort_by(|&a, &b| times[a].total_cmp(&times[b]));
    let sorted: Vec<f64> = order.iter().map(|&i| times[i]).collect();
    let rows: Vec<usize> = (0..=n)
        .map(|k| {
            let t = start + k as f64 * comm;
            let at = sorted.partition_point(|&x| x < t - 1e-6 * comm);
            match sorted.get(at) {
                Some(&x) if (x - t).abs() <= 1e-6 * comm => Ok(order[at]),
                _ => Err(Error::new_err(format!(
                    "reference: no row at t = {t} s (the study compares every {comm} s from \
                     {start} s; give `comm` on the reference's grid)"
                ))),
            }
        })
        .collect::<PyResult<_>>()?;
    Ok(series
        .into_iter()
        .map(|v| rows.iter().map(|&i| v[i]).collect())
        .collect())
}

/// The study's options from `args`: outputs, reference (a CSV path, or values taken from a
/// pandas object on the study's grid).
fn options(args: &Args<'_>, scene: &Scene) -> PyResult<Options> {
    let outputs = names(&args.output, "output")?;
    let mut o = Options::new(outputs.clone(), args.target);
    o.stop = args.stop;
    o.comm = args.comm;
    o.step = args.step;
    o.newton = args.newton;
    o.levels = args.levels;
    o.mesh_levels = args.mesh_levels;
    o.recentre = args.recentre;
    o.max_runs = args.max_runs;
    o.jobs = args.jobs;
    if let Some(w) = args.max_work {
        o.max_work = w;
    }
    if let Some(s) = args.max_seconds {
        o.max_seconds = s;
    }
    let columns = match &args.column {
        Some(c) => names(c, "column")?,
        None => outputs,
    };
    if let Some(r) = &args.reference {
        if r.is_instance_of::<PyString>() || r.hasattr("__fspath__")? {
            o.reference = Some((r.extract::<PathBuf>()?, columns));
        } else if r.hasattr("index")? {
            let grid = accuracy::grid(scene, &o).map_err(|e| Error::new_err(e.to_string()))?;
            o.reference_values = Some(reference_values(r, &columns, grid)?);
        } else {
            return Err(Error::new_err(
                "reference: a CSV file's path, or a pandas DataFrame or Series indexed by time",
            ));
        }
    }
    o.check()
        .map_err(|e| Error::new_err(e.to_string().replace("--", "")))?;
    Ok(o)
}

/// The runs as a pandas DataFrame (pandas imported here: only a study needs it).
fn runs_frame<'py>(py: Python<'py>, s: &Study) -> PyResult<Bound<'py, PyAny>> {
    let pandas = py.import("pandas")?;
    let d = PyDict::new(py);
    let col = |name: &str, values: Bound<'py, PyList>| d.set_item(name, values);
    let list = |f: &dyn Fn(&accuracy::Run) -> Py<PyAny>| -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, s.runs.iter().map(f))
    };
    let num = |x: f64| {
        x.into_pyobject(py)
            .map_or_else(|_| py.None(), |v| v.into_any().unbind())
    };
    let opt = |x: Option<f64>| x.map_or_else(|| py.None(), num);
    col(
        "role",
        list(&|r| PyString::new(py, r.role.name()).into_any().unbind())?,
    )?;
    col("step", list(&|r| num(r.setting.step))?)?;
    col("newton", list(&|r| num(r.setting.newton))?)?;
    col(
        "mesh",
        list(&|r| {
            PyString::new(py, s.mesh_name(r.setting.mesh))
                .into_any()
                .unbind()
        })?,
    )?;
    col(
        "stiffening_switched",
        list(&|r| {
            pyo3::types::PyBool::new(py, r.setting.stiffening_switched)
                .to_owned()
                .into_any()
                .unbind()
        })?,
    )?;
    col("estimated_error", list(&|r| opt(r.error()))?)?;
    for (k, o) in s.outputs.iter().enumerate() {
        col(
            &format!("error_{o}"),
            list(&|r| opt(r.errors.get(k).copied()))?,
        )?;
    }
    if s.judged() {
        col("true_error", list(&|r| opt(r.true_error()))?)?;
    }
    col("work", list(&|r| num(r.work))?)?;
    col("cpu_s", list(&|r| num(r.seconds))?)?;
    let int = |x: u64| {
        x.into_pyobject(py)
            .map_or_else(|_| py.None(), |v| v.into_any().unbind())
    };
    col("steps", list(&|r| int(r.counts.steps))?)?;
    col("newton_iterations", list(&|r| int(r.counts.iterations))?)?;
    col("jacobians", list(&|r| int(r.counts.jacobians))?)?;
    col(
        "status",
        list(&|r| {
            let t = match &r.result {
                Ok(_) => "ok".to_string(),
                Err(e) => format!("failed: {e}"),
            };
            PyString::new(py, &t).into_any().unbind()
        })?,
    )?;
    pandas.getattr("DataFrame")?.call1((d,))
}

/// Runs the study of `scene` (its `origin` names the chosen scene) without the GIL, asking
/// Python for signals (Ctrl-C) between and within runs.
pub fn study(
    py: Python<'_>,
    scene: &Scene,
    origin: &str,
    args: Args<'_>,
) -> PyResult<AccuracyStudy> {
    let o = guard(|| options(&args, scene))?;
    let raised: Mutex<Option<PyErr>> = Mutex::new(None);
    let interrupted = || {
        Python::attach(|py| match py.check_signals() {
            Ok(()) => false,
            Err(e) => {
                if let Ok(mut slot) = raised.lock() {
                    slot.get_or_insert(e);
                }
                true
            }
        })
    };
    let result: Result<Study, HarnessError> =
        py.detach(|| guard(|| Ok(accuracy::study_with(scene, &o, &interrupted))))?;
    let s = match result {
        Ok(s) => s,
        Err(HarnessError::Accuracy(AccuracyError::Interrupted)) => {
            let e = raised.lock().ok().and_then(|mut slot| slot.take());
            return Err(e.unwrap_or_else(|| {
                pyo3::exceptions::PyKeyboardInterrupt::new_err("the study was interrupted")
            }));
        }
        Err(e) => return Err(harness_err(py, e)),
    };
    guard(|| {
        let (choice, chosen) = match &s.choice {
            Some(c) => {
                let d = PyDict::new(py);
                d.set_item("step", c.setting.step)?;
                d.set_item("newton", c.setting.newton)?;
                d.set_item("mesh", s.mesh_name(c.setting.mesh))?;
                d.set_item("work", s.runs[c.run].work)?;
                d.set_item("cpu_s", s.runs[c.run].seconds)?;
                let scene = py
                    .get_type::<crate::scene::PyScene>()
                    .call_method1(
                        "from_toml",
                        (
                            &c.scene_toml,
                            format!("{origin} (chosen for {:e})", s.target),
                        ),
                    )?
                    .unbind();
                (d.into_any().unbind(), scene)
            }
            None => (py.None(), py.None()),
        };
        let c = s.choice.as_ref();
        Ok(AccuracyStudy {
            choice,
            scene: chosen,
            estimate: c.map(|c| c.predicted),
            time_share: c.map(|c| c.time_share),
            mesh_share: c.map(|c| c.mesh_share),
            newton_share: c.and_then(|c| c.newton_share),
            limited_by: c.map(|c| {
                report::limit_name(c.time_share, c.mesh_share, c.newton_share.unwrap_or(0.0))
                    .to_string()
            }),
            margin: s.margin,
            target: s.target,
            outputs: s.outputs.clone(),
            notes: s.notes.clone(),
            incomplete: s.incomplete.clone(),
            work: s.work,
            cpu_seconds: s.cpu_seconds,
            wall_seconds: s.wall_seconds,
            jobs: s.jobs,
            runs: runs_frame(py, &s)?.unbind(),
            text: report::markdown(&s),
            table: report::csv(&s),
        })
    })
}
