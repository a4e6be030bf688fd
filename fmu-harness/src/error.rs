//! Everything that can go wrong in the harness, with the path or the numbers that explain it.

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
         fmu_beam::variables::UNITS does not define: the FMU would not validate"
    )]
    UndefinedUnit {
        scene: String,
        variable: String,
        unit: String,
    },
    #[error("scene `{scene}`: its canonical text for resources/scene.toml is unusable: {message}")]
    CanonicalScene { scene: String, message: String },
    #[error(transparent)]
    MatrixFile(#[from] fmu_beam::beam::matrix_file::MatrixFileError),
    #[error(transparent)]
    Simulate(#[from] crate::simulate::SimulateError),
    #[error(transparent)]
    Cosim(#[from] crate::cosim::CosimError),
    #[error(transparent)]
    Animate(#[from] crate::animate::AnimateError),
    #[error("{origin}: {message}")]
    Input { origin: String, message: String },
    #[error("{}: not a file path for the FMU (give one such as build/fmus/<scene>.fmu)", .path.display())]
    BadOutput { path: PathBuf },
}

impl HarnessError {
    /// Process exit status: 2 for a refused scene (an error of input), 1 for anything else.
    pub fn exit_code(&self) -> i32 {
        match self {
            HarnessError::Scene(_) => 2,
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
