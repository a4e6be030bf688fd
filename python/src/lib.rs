//! The extension module `fmu_beam._native` of the Python package `fmu_beam` (the pure-Python
//! `python/fmu_beam/__init__.py` re-exports it): scenes loaded, built from dicts and written
//! back ([`scene::PyScene`]), packaged with the engines the wheel carries
//! ([`engines::carried`]), explained, their natural frequencies; the scene schema; and the
//! `fmu-beam` command ([`cli`]), which is fmu-harness's command line. Everything goes through
//! fmu_beam's and fmu_harness's public API; every call goes through [`errors::guard`], so that
//! an error is a Python exception and no panic reaches Python.

mod accuracy;
mod convert;
mod engines;
mod errors;
mod modes;
mod scene;
mod unit;

use clap::{CommandFactory, FromArgMatches};
use fmu_harness::cli::Cli;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::io::Write;

/// The JSON Schema of scene files (what scenes/scene.schema.json holds), as text.
#[pyfunction]
fn schema_text() -> PyResult<String> {
    errors::guard(|| Ok(fmu_harness::schema::scene_schema_text()))
}

/// The scene reference (Markdown): every field of every table with its unit, default and
/// rules.
#[pyfunction]
fn reference_text() -> PyResult<String> {
    errors::guard(|| Ok(fmu_harness::reference::scene_reference()))
}

/// The engine libraries this package carries: {platform: path}.
#[pyfunction]
#[pyo3(name = "engines")]
fn carried_engines<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for a in engines::carried()? {
        if let Some(p) = a.platform {
            d.set_item(p.folder(), a.path)?;
        }
    }
    Ok(d)
}

/// Runs the `fmu-beam` command with `argv` (the program's name first): fmu-harness's command
/// line under this name, `package` embedding this package's engines when given no
/// `--binary`. Writes to the process's standard output and error; returns the exit status.
/// `as_command` (the console script): SIGINT, SIGTERM and SIGHUP end the process at once, its
/// temporary files removed, as they end `fmu-harness` (Python's own handler would wait for the
/// call to return).
#[pyfunction]
#[pyo3(signature = (argv, as_command = false))]
fn cli(py: Python<'_>, argv: Vec<String>, as_command: bool) -> PyResult<i32> {
    let command = Cli::command()
        .name("fmu-beam")
        .bin_name("fmu-beam")
        .mut_subcommand("package", |c| {
            c.mut_arg("binary", |a| {
                a.help(
                    "An engine library to embed, one per platform: `[PLATFORM=]PATH` (linux64, \
                     win64) [default: the engines this Python package carries, see \
                     `python -c 'import fmu_beam; print(fmu_beam.engines())'`]",
                )
            })
        });
    let parsed = command
        .try_get_matches_from(argv)
        .and_then(|m| Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) => {
            // --help and --version print and succeed; a usage error prints and fails
            let _ = e.print();
            return Ok(e.exit_code());
        }
    };
    if as_command {
        if let Err(e) = fmu_harness::scratch::remove_on_signals() {
            eprintln!("warning: temporary files will stay behind if interrupted: {e}");
        }
    }
    let defaults = engines::carried()?;
    let status = py.detach(|| {
        errors::guard(|| {
            let stdout = std::io::stdout();
            let mut out = stdout.lock();
            let status = match fmu_harness::cli::run_with_engines(cli, &defaults, &mut out) {
                Ok(()) => 0,
                Err(e) => {
                    eprintln!("error: {e}");
                    e.exit_code()
                }
            };
            let _ = out.flush();
            Ok(status)
        })
    })?;
    Ok(status)
}

/// The module `fmu_beam._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("Error", py.get_type::<errors::Error>())?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("SimulationError", py.get_type::<errors::SimulationError>())?;
    m.add_class::<scene::PyScene>()?;
    m.add_class::<scene::Packaged>()?;
    m.add_class::<unit::PyUnit>()?;
    m.add_class::<accuracy::AccuracyStudy>()?;
    m.add_function(wrap_pyfunction!(schema_text, m)?)?;
    m.add_function(wrap_pyfunction!(reference_text, m)?)?;
    m.add_function(wrap_pyfunction!(carried_engines, m)?)?;
    m.add_function(wrap_pyfunction!(cli, m)?)?;
    Ok(())
}
