//! `fmu_beam.Scene`: a validated scene (fmu_beam's [`Scene`]) and what the packager does with
//! it; `fmu_beam.Packaged`: what packaging wrote.

use crate::convert;
use crate::engines;
use crate::errors::{guard, harness_err, Refusal};
use fmu_beam::Scene;
use fmu_harness::package::{self, BinaryArg};
use fmu_harness::platform::{FmiVersion, Platform};
use fmu_harness::HarnessError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A validated scene: loaded from a file, read from TOML text, or built from a dict.
#[pyclass(frozen, module = "fmu_beam", name = "Scene")]
pub struct PyScene {
    scene: Scene,
    origin: String,
}

/// Runs `f` without holding the GIL (packaging and eigenvalues take a while), its panics
/// caught, its error mapped to the package's exceptions.
fn detached<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> Result<T, HarnessError> + Send,
) -> PyResult<T> {
    py.detach(|| guard(|| Ok(f())))?
        .map_err(|e| harness_err(py, e))
}

impl PyScene {
    /// The validated scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }
}

#[pymethods]
impl PyScene {
    /// Reads and validates a scene file (TOML), as `fmu-beam package` does; a beam's
    /// `matrix_file` is read relative to the file. Raises SceneError naming the field.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyScene> {
        let origin = path.display().to_string();
        let scene = detached(py, || Ok(Scene::load(&path)?))?;
        Ok(PyScene { scene, origin })
    }

    /// Parses and validates scene text (TOML); `origin` prefixes the messages. A beam's
    /// `matrix_file` is read below `directory` (default: the working directory), as
    /// `from_dict` reads it.
    #[staticmethod]
    #[pyo3(signature = (text, origin = "<string>", directory = None))]
    fn from_toml(
        py: Python<'_>,
        text: &str,
        origin: &str,
        directory: Option<PathBuf>,
    ) -> PyResult<PyScene> {
        let dir = directory.unwrap_or_else(|| PathBuf::from("."));
        let scene = guard(|| {
            Scene::from_toml_in(text, origin, &dir).map_err(|e| Refusal::of(&e).into_err(py))
        })?;
        Ok(PyScene {
            scene,
            origin: origin.to_string(),
        })
    }

    /// Builds a scene from nested dicts and lists shaped like the TOML file (the scene
    /// reference applies key for key; a key set to None takes its default) and validates it as
    /// the packager does. A beam's `matrix_file` is read below `directory` (default: the
    /// working directory) by the engine's one reader: a regular file there, links followed
    /// but not out of it, capped. Any object is refused (SceneError) rather than crash: nested
    /// more than 64 deep, holding itself, or larger than a scene file may be. Raises
    /// SceneError naming the field.
    #[staticmethod]
    #[pyo3(signature = (d, origin = "<dict>", directory = None))]
    fn from_dict(
        py: Python<'_>,
        d: &Bound<'_, PyAny>,
        origin: &str,
        directory: Option<PathBuf>,
    ) -> PyResult<PyScene> {
        guard(|| {
            let value = convert::to_toml(d, "", origin).map_err(|r| (*r).into_err(py))?;
            let toml::Value::Table(table) = value else {
                return Err(Refusal {
                    message: format!("{origin}: a scene is a dict of its tables and keys"),
                    origin: origin.to_string(),
                    rule: Some("a scene is a dict".into()),
                    ..Refusal::default()
                }
                .into_err(py));
            };
            let dir = directory.unwrap_or_else(|| PathBuf::from("."));
            let scene = Scene::from_toml_in(&toml_text(&table), origin, &dir)
                .map_err(|e| refusal_in_dict(&e, &table).into_err(py))?;
            Ok(PyScene {
                scene,
                origin: origin.to_string(),
            })
        })
    }

    /// The scene's name: the FMU's modelIdentifier.
    #[getter]
    fn name(&self) -> &str {
        &self.scene.name
    }

    /// The scene's description.
    #[getter]
    fn description(&self) -> &str {
        &self.scene.description
    }

    /// 2 (planar) or 3.
    #[getter]
    fn dimensions(&self) -> u32 {
        self.scene.dimensions as u32
    }

    /// Where the scene came from: its file, '<dict>' or '<string>'.
    #[getter]
    fn origin(&self) -> &str {
        &self.origin
    }

    /// The canonical TOML text: what the FMU carries as resources/scene.toml.
    fn to_toml(&self) -> String {
        self.scene.to_toml_string()
    }

    /// The scene as nested dicts and lists (the canonical text's tables, every default
    /// written out); `Scene.from_dict(s.to_dict()) == s`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        guard(|| {
            let table: toml::Table = toml::from_str(&self.scene.to_toml_string())
                .map_err(|e| crate::errors::Error::new_err(e.to_string()))?;
            convert::table_to_python(py, &table)
        })
    }

    /// Runs the scene in process with the unit's own engine and returns a pandas DataFrame
    /// indexed by time (see `fmu_beam._simulate.simulate`, which this hands over to).
    #[pyo3(signature = (*args, **kwargs))]
    fn simulate<'py>(
        slf: &Bound<'py, Self>,
        args: &Bound<'py, PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let run = py.import("fmu_beam._simulate")?.getattr("simulate")?;
        let mut all = vec![slf.clone().into_any()];
        all.extend(args.iter());
        run.call(PyTuple::new(py, all)?, kwargs)
    }

    /// Pickles as its canonical text (a few kB: what a sweep's task ships to a worker).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<(Bound<'py, PyAny>, (String, String))> {
        let me = slf.get();
        let from_toml = slf.get_type().getattr("from_toml")?;
        Ok((from_toml, (me.scene.to_toml_string(), me.origin.clone())))
    }

    /// The accuracy the scene was tuned for (its `[accuracy]`, if any), then the effects the
    /// unit simulates, why, and their estimated share of the cost (the text of `fmu-beam
    /// explain` and of the FMU's documentation).
    fn explain(&self, py: Python<'_>) -> PyResult<String> {
        detached(py, || fmu_harness::package::explain(&self.scene))
    }

    // --- modes (python/src/modes.rs, python/fmu_beam/_modes.py) ---

    /// The linearized modes (fmu_beam.Modes: a list of the natural frequencies in Hz, with
    /// their damping ratios and shapes as numpy arrays), at most `count` (all when None): at
    /// rest, or about the steady state spinning at `speed` rad/s about the `hub`; joints
    /// `lock`ed (a name, a list, or True for all); at rest about the static `equilibrium`.
    #[pyo3(signature = (count = None, speed = None, lock = None, equilibrium = false, hub = None))]
    fn modes<'py>(
        &self,
        py: Python<'py>,
        count: Option<usize>,
        speed: Option<f64>,
        lock: Option<&Bound<'py, PyAny>>,
        equilibrium: bool,
        hub: Option<String>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = crate::modes::options(lock, speed, hub, equilibrium)?;
        crate::modes::modes(py, &self.scene, &self.origin, count, o)
    }

    /// The Campbell diagram: the first `count` modes at each of `speeds` (rad/s) as a pandas
    /// DataFrame indexed by speed, one column per mode (Hz), on `jobs` threads (all cores when
    /// None).
    #[pyo3(signature = (speeds, count = None, lock = None, hub = None, jobs = None))]
    fn campbell<'py>(
        &self,
        py: Python<'py>,
        speeds: Vec<f64>,
        count: Option<usize>,
        lock: Option<&Bound<'py, PyAny>>,
        hub: Option<String>,
        jobs: Option<usize>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let o = crate::modes::options(lock, None, hub, false)?;
        crate::modes::campbell(py, &self.scene, &self.origin, speeds, count, o, jobs)
    }

    // --- end of modes ---

    /// The unit's variables, in value-reference order, as dicts: name, value_reference,
    /// causality, variability, type, unit (None if dimensionless), start (parameters), and
    /// description: the table modelDescription.xml is written from.
    fn variables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let table = guard(|| Ok(fmu_beam::VariableTable::build(&self.scene)))?;
        let list = PyList::empty(py);
        for v in &table.variables {
            let d = PyDict::new(py);
            d.set_item("name", &v.name)?;
            d.set_item("value_reference", v.vr)?;
            d.set_item("causality", v.causality.as_str())?;
            d.set_item("variability", v.variability.as_str())?;
            d.set_item("type", v.ty.as_str())?;
            d.set_item("unit", v.unit)?;
            d.set_item("start", v.start)?;
            d.set_item("description", &v.description)?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// Writes the scene's FMU to `path` with the engines of `platforms` ('linux64', 'win64';
    /// default: every engine this package carries, see fmu_beam.engines()), or with the engine
    /// libraries of `binaries` ({'linux64': path, ...}, like `--binary`), as an FMI 2.0 unit
    /// or (`fmi_version=3`) an FMI 3.0 one. Returns what it wrote.
    #[pyo3(signature = (path, platforms = None, binaries = None, fmi_version = 2))]
    fn package(
        &self,
        py: Python<'_>,
        path: PathBuf,
        platforms: Option<Vec<String>>,
        binaries: Option<BTreeMap<String, PathBuf>>,
        fmi_version: u32,
    ) -> PyResult<Packaged> {
        let version = fmi_version
            .to_string()
            .parse::<FmiVersion>()
            .map_err(crate::errors::Error::new_err)?;
        let args = engine_args(platforms, binaries)?;
        let p = detached(py, || {
            package::package_scene_as(&self.scene, &path, &args, version)
        })?;
        Ok(Packaged {
            path: p.output.display().to_string(),
            model_identifier: p.model_identifier,
            guid: p.guid,
            variables: p.variables,
            platforms: p.binaries.iter().map(|(p, _)| p.to_string()).collect(),
        })
    }

    /// The accuracy study of `fmu-beam accuracy` (docs/accuracy.md): the cheapest fixed step,
    /// Newton tolerance and mesh whose error in `output` (a name or a list) meets `target`,
    /// ranked by counted work, run on `jobs` cores (default: all) without the GIL; Ctrl-C stops
    /// it. `reference`: a CSV path (with `column`) or a pandas DataFrame/Series indexed by time.
    #[pyo3(signature = (output, target, stop = None, comm = None, step = None, newton = None,
        levels = 5, mesh_levels = 3, recentre = true, max_runs = 60, reference = None,
        column = None, jobs = None, max_work = None, max_seconds = None))]
    #[allow(clippy::too_many_arguments)]
    fn accuracy<'py>(
        &self,
        py: Python<'py>,
        output: Bound<'py, PyAny>,
        target: f64,
        stop: Option<f64>,
        comm: Option<f64>,
        step: Option<f64>,
        newton: Option<f64>,
        levels: usize,
        mesh_levels: usize,
        recentre: bool,
        max_runs: usize,
        reference: Option<Bound<'py, PyAny>>,
        column: Option<Bound<'py, PyAny>>,
        jobs: Option<usize>,
        max_work: Option<f64>,
        max_seconds: Option<f64>,
    ) -> PyResult<crate::accuracy::AccuracyStudy> {
        let args = crate::accuracy::Args {
            output,
            target,
            stop,
            comm,
            step,
            newton,
            levels,
            mesh_levels,
            recentre,
            max_runs,
            reference,
            column,
            jobs,
            max_work,
            max_seconds,
        };
        crate::accuracy::study(py, &self.scene, &self.origin, args)
    }

    fn __eq__(&self, other: PyRef<'_, PyScene>) -> bool {
        self.scene == other.scene
    }

    fn __repr__(&self) -> String {
        format!(
            "<fmu_beam.Scene '{}' ({}D, from {})>",
            self.scene.name, self.scene.dimensions, self.origin
        )
    }
}

/// The `--binary` arguments of a packaging: the engine libraries given, or this package's own
/// engines of the platforms asked for (all it carries by default).
fn engine_args(
    platforms: Option<Vec<String>>,
    binaries: Option<BTreeMap<String, PathBuf>>,
) -> PyResult<Vec<BinaryArg>> {
    let known = || {
        Platform::ALL
            .iter()
            .map(|p| p.folder())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let platform = |name: &str| {
        Platform::from_folder(name).ok_or_else(|| {
            crate::errors::Error::new_err(format!(
                "unknown platform '{name}' (the packager fills {})",
                known()
            ))
        })
    };
    if let Some(given) = binaries {
        return given
            .into_iter()
            .map(|(name, path)| {
                Ok(BinaryArg {
                    platform: Some(platform(&name)?),
                    path,
                })
            })
            .collect();
    }
    let carried = engines::carried()?;
    let Some(wanted) = platforms else {
        if carried.is_empty() {
            return Err(crate::errors::Error::new_err(format!(
                "this fmu_beam carries no engine library (looked in {}); pass binaries=",
                engines::directory()?.display()
            )));
        }
        return Ok(carried);
    };
    wanted
        .iter()
        .map(|name| {
            let p = platform(name)?;
            carried
                .iter()
                .find(|a| a.platform == Some(p))
                .cloned()
                .ok_or_else(|| {
                    crate::errors::Error::new_err(format!(
                        "this fmu_beam carries no {p} engine (it has: {}); pass binaries=",
                        carried
                            .iter()
                            .filter_map(|a| a.platform.map(|p| p.to_string()))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                })
        })
        .collect()
}

/// The text of a table built from a dict (TOML serializes every table of ours).
fn toml_text(table: &toml::Table) -> String {
    toml::to_string(table).unwrap_or_default()
}

/// The refusal of a scene built from a dict. A value refused by a rule is the packager's
/// refusal as it is; one the parser refused (an unknown key, a missing one, a wrong type) is
/// told by the field's path in the dict, not by a line of the TOML text made from it.
fn refusal_in_dict(e: &fmu_beam::SceneError, table: &toml::Table) -> Refusal {
    let fmu_beam::SceneError::Parse { origin, .. } = e else {
        return Refusal::of(e);
    };
    let value = toml::Value::Table(table.clone());
    match serde_path_to_error::deserialize::<_, Scene>(value) {
        Err(err) => {
            let field = crate::convert::named_path(&err.path().to_string(), table);
            // the first line: toml's own `in <table>` after it is what the path says
            let inner = err.inner().to_string();
            let rule = inner.lines().next().unwrap_or_default().to_string();
            let (field, message) = if field.is_empty() || field == "." {
                (None, format!("{origin}: {rule}"))
            } else {
                let m = format!("{origin}: field `{field}`: {rule}");
                (Some(field), m)
            };
            Refusal {
                message,
                origin: origin.clone(),
                field,
                rule: Some(rule),
                ..Refusal::default()
            }
        }
        Ok(_) => Refusal::of(e),
    }
}

/// What `Scene.package` wrote.
#[pyclass(frozen, get_all, module = "fmu_beam", name = "Packaged")]
pub struct Packaged {
    /// The FMU written.
    path: String,
    /// Its modelIdentifier (the scene's name).
    model_identifier: String,
    /// Its GUID: a digest of its model description, scene and engines.
    guid: String,
    /// How many variables it has.
    variables: usize,
    /// The platforms it carries an engine for, e.g. ['linux64', 'win64'].
    platforms: Vec<String>,
}

#[pymethods]
impl Packaged {
    fn __repr__(&self) -> String {
        format!(
            "<fmu_beam.Packaged {} ({} variables, {})>",
            self.path,
            self.variables,
            self.platforms.join(", ")
        )
    }
}
