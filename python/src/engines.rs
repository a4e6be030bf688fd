//! The engine libraries the wheel carries as package data, `fmu_beam/engines/<platform>/`: what
//! `Scene.package` and the `fmu-beam package` command embed when given no other.

use crate::errors::Error;
use fmu_harness::package::{BinaryArg, ENGINE_LIBRARY};
use fmu_harness::platform::Platform;
use pyo3::prelude::*;
use std::path::PathBuf;

/// The engine's file name for a platform: cargo's names of the cdylib.
pub fn file_name(platform: Platform) -> &'static str {
    match platform {
        Platform::Linux64 => ENGINE_LIBRARY,
        Platform::Win64 => "fmu_beam.dll",
    }
}

/// `fmu_beam/engines/`, beside the package's `__init__.py`.
pub fn directory() -> PyResult<PathBuf> {
    Python::attach(|py| {
        let init: PathBuf = py.import("fmu_beam")?.getattr("__file__")?.extract()?;
        let package = init
            .parent()
            .ok_or_else(|| Error::new_err("fmu_beam.__file__ has no directory"))?;
        Ok(package.join("engines"))
    })
}

/// The engines present, one per platform in `Platform::ALL` order, as `--binary` arguments.
pub fn carried() -> PyResult<Vec<BinaryArg>> {
    let dir = directory()?;
    Ok(Platform::ALL
        .iter()
        .map(|&p| (p, dir.join(p.folder()).join(file_name(p))))
        .filter(|(_, path)| path.is_file())
        .map(|(p, path)| BinaryArg {
            platform: Some(p),
            path,
        })
        .collect())
}
