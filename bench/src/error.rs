//! What can go wrong in a benchmark run, with the path or the origin that explains it.

use fmu_beam::scene::SceneError;
use fmu_beam::EngineError;
use std::path::PathBuf;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum BenchError {
    /// A scene file was refused; the message names the file, the field and the rule.
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("{origin}: {source}")]
    Engine { origin: String, source: EngineError },
    #[error("{}: {action}: {source}", .path.display())]
    Io {
        path: PathBuf,
        action: &'static str,
        source: std::io::Error,
    },
    #[error(transparent)]
    MatrixFile(#[from] fmu_beam::scene::matrix_file::MatrixFileError),
    #[error("{origin}: {message}")]
    Input { origin: String, message: String },
}

impl BenchError {
    /// Process exit status: 2 for a refused scene (an error of input), 1 for anything else.
    pub fn exit_code(&self) -> i32 {
        match self {
            BenchError::Scene(_) => 2,
            _ => 1,
        }
    }

    pub(crate) fn io(
        path: impl Into<PathBuf>,
        action: &'static str,
        source: std::io::Error,
    ) -> Self {
        BenchError::Io {
            path: path.into(),
            action,
            source,
        }
    }
}
