//! Everything that can go wrong in the harness, with the path or the numbers that explain it.

use crate::platform::Platform;
use fmu_beam::scene::SceneError;
use fmu_beam::EngineError;
use std::path::PathBuf;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum HarnessError {
    /// The scene file was refused; the message names the file, the field and the rule.
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{origin}: {source}")]
    Engine { origin: String, source: EngineError },
    #[error(
        "cannot find the engine library libfmu_beam.so (looked for {}); build it with \
         `cargo build --release -p fmu-beam` or pass --binary",
        .searched.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
    )]
    BinaryNotFound { searched: Vec<PathBuf> },
    #[error(
        "{}: {}",
        .path.display(),
        binary_platform_message(*.named, *.found)
    )]
    BinaryPlatform {
        path: PathBuf,
        named: Option<Platform>,
        found: Option<Platform>,
    },
    #[error(
        "two engine libraries for {platform}: {} and {}; give one per platform",
        .first.display(),
        .second.display()
    )]
    DuplicatePlatform {
        platform: Platform,
        first: PathBuf,
        second: PathBuf,
    },
    #[error("{}: {action}: {source}", .path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        source: std::io::Error,
    },
    #[error("{}: writing the FMU archive: {source}", .path.display())]
    Zip {
        path: PathBuf,
        source: zip::result::ZipError,
    },
    #[error("modelDescription template: {message}")]
    Template { message: String },
    #[error(
        "scene `{scene}`: variable `{variable}` has unit `{unit}`, which \
         fmu_beam::UNITS does not define: the FMU would not validate"
    )]
    UndefinedUnit {
        scene: String,
        variable: String,
        unit: String,
    },
    #[error("scene `{scene}`: {message}")]
    /// The scene's `[accuracy]` names no Real output of the unit (a refused scene: exit 2).
    AccuracyStatement { scene: String, message: String },
    #[error("scene `{scene}`: its canonical text for resources/scene.toml is unusable: {message}")]
    CanonicalScene { scene: String, message: String },
    #[error(transparent)]
    MatrixFile(#[from] fmu_beam::scene::matrix_file::MatrixFileError),
    #[error(transparent)]
    Simulate(#[from] crate::simulate::SimulateError),
    /// `simulate`: the FMU ended the run before the stop time (its rows are written); exit 3.
    #[error("{0}")]
    Ended(Box<crate::simulate::Ended>),
    /// `cosim`: a unit ended the run before the stop time (the rows up to then are written);
    /// exit 3.
    #[error("{0}")]
    CosimEnded(String),
    #[error(transparent)]
    Cosim(#[from] crate::cosim::CosimError),
    #[error(transparent)]
    Animate(#[from] crate::animate::AnimateError),
    #[error(transparent)]
    Accuracy(#[from] crate::accuracy::AccuracyError),
    #[error("{origin}: {message}")]
    Input { origin: String, message: String },
    #[error(transparent)]
    InputFile(#[from] crate::input_file::InputFileError),
    #[error("{}: its symbol table cannot be read: {reason}", .path.display())]
    LibrarySymbols { path: PathBuf, reason: String },
    #[error(
        "{}: {}",
        .path.display(),
        missing_functions_message(*.count, *.of, .missing)
    )]
    MissingFunctions {
        path: PathBuf,
        count: usize,
        of: usize,
        missing: Vec<&'static str>,
    },
    #[error("{}: not a path to a file (give one such as build/fmus/<scene>.fmu or run.csv)", .path.display())]
    BadOutput { path: PathBuf },
    /// An output that is there and is not a regular file (issue 45): never replaced.
    #[error(
        "{}: a {kind}; an output must be a regular file or a new name (it is never written \
         through a link, nor over a FIFO, device or directory)",
        .path.display()
    )]
    NotRegularOutput { path: PathBuf, kind: &'static str },
}

/// Which FMI 2.0 functions a `--binary` does not export.
fn missing_functions_message(count: usize, of: usize, missing: &[&str]) -> String {
    // the list names the version: FMI 2.0's co-simulation functions or FMI 3.0's all
    let which = if missing.first().is_some_and(|f| f.starts_with("fmi3")) {
        "FMI 3.0"
    } else {
        "FMI 2.0 co-simulation"
    };
    if count == of {
        format!("exports none of the {of} {which} functions: not an FMU binary")
    } else {
        format!(
            "does not export {count} of the {of} {which} functions: {}",
            missing.join(", ")
        )
    }
}

/// Why a `--binary` cannot go under its platform's folder.
fn binary_platform_message(named: Option<Platform>, found: Option<Platform>) -> String {
    match (named, found) {
        (Some(named), Some(found)) => format!(
            "given as the {named} engine, but it is {} (a {found} library)",
            found.library_kind()
        ),
        _ => {
            let known: Vec<String> = Platform::ALL
                .iter()
                .map(|p| format!("{p}: {}", p.library_kind()))
                .collect();
            format!(
                "not an engine library of a platform the packager fills ({})",
                known.join("; ")
            )
        }
    }
}

impl HarnessError {
    /// Process exit status: 2 for a refused scene (an error of input), 3 for a run that a unit
    /// ended before the stop time (fmi2Discard with fmi2Terminated; its rows are written), 1 for
    /// anything else.
    pub fn exit_code(&self) -> i32 {
        match self {
            HarnessError::Scene(_) | HarnessError::AccuracyStatement { .. } => 2,
            HarnessError::Ended(_) | HarnessError::CosimEnded(_) => 3,
            _ => 1,
        }
    }

    pub(crate) fn io(
        path: impl Into<PathBuf>,
        action: &'static str,
        source: std::io::Error,
    ) -> Self {
        HarnessError::Io {
            path: path.into(),
            action,
            source,
        }
    }
}
