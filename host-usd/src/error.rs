//! Import errors: each names the file and what is wrong.

use std::path::PathBuf;

/// Why a USD file could not be imported; the message names the file.
#[derive(Debug, thiserror::Error)]
pub enum UsdError {
    /// The file does not exist.
    #[error("{file}: USD file not found")]
    NotFound {
        /// The file asked for.
        file: PathBuf,
    },
    /// openusd could not open the stage (or panicked on it): its message.
    #[error("{file}: cannot open the USD stage: {message}")]
    Open {
        /// The file.
        file: PathBuf,
        /// openusd's message.
        message: String,
    },
    /// A prim cannot be imported, or a camera the options or settings name does not exist.
    #[error("{file}: {prim}: {message}")]
    Prim {
        /// The file.
        file: PathBuf,
        /// The prim's path (or the camera's name).
        prim: String,
        /// What is wrong with it.
        message: String,
    },
}
