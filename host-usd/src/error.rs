//! Import errors: each names the file and what is wrong.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum UsdError {
    #[error("{file}: USD file not found")]
    NotFound { file: PathBuf },
    #[error("{file}: cannot open the USD stage: {message}")]
    Open { file: PathBuf, message: String },
    #[error("{file}: {prim}: {message}")]
    Prim { file: PathBuf, prim: String, message: String },
}
