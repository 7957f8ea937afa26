//! Triangle meshes from OBJ (`tobj`) and PLY (`ply.rs`) files: positions and triangles only
//! (the scene format uses face normals). Polygons are fan-triangulated; indices are checked.

use sampler_core::glam::{Mat4, Vec3};
use std::path::{Path, PathBuf};

/// Why a mesh cannot be loaded.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file cannot be read.
    #[error("{path}: cannot read the mesh: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The file is not valid in its format.
    #[error("{path}: not a readable {format} mesh: {message}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// The format it was read as.
        format: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The file's extension names no format this build reads.
    #[error("{path}: unsupported mesh format (expected .obj or .ply)")]
    Unsupported {
        /// The file.
        path: PathBuf,
    },
    /// The file is well-formed but describes something invalid.
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Positions and triangles of a mesh file, its positions moved by `to_world` where given (the
/// scene format's row-major 4×4 matrix).
pub fn load_placed(path: &Path, to_world: Option<[[f32; 4]; 4]>) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), MeshError> {
    let (mut positions, triangles) = load(path)?;
    if let Some(m) = to_world {
        // Row-major in the file; glam is column-major.
        let m = Mat4::from_cols_array_2d(&m).transpose();
        positions.iter_mut().for_each(|p| *p = m.transform_point3(*p));
    }
    Ok((positions, triangles))
}

/// Positions and triangles of a mesh file.
pub fn load(path: &Path) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), MeshError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    let bytes = std::fs::read(path).map_err(|error| MeshError::Io { path: path.to_owned(), error })?;
    let (positions, triangles) = match ext.as_str() {
        "obj" => load_obj(path, &bytes)?,
        "ply" => load_ply(path, &bytes)?,
        _ => {
            return Err(MeshError::Unsupported { path: path.to_owned() });
        }
    };
    let invalid = |message: String| MeshError::Invalid { path: path.to_owned(), message };
    if let Some(t) = triangles.iter().find(|t| t.iter().any(|&i| i as usize >= positions.len())) {
        return Err(invalid(format!("triangle {t:?} indexes past the {} vertices", positions.len())));
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(invalid("a vertex position is NaN or infinite".into()));
    }
    Ok((positions, triangles))
}

fn load_obj(path: &Path, bytes: &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), MeshError> {
    let options = tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
    let mut reader = std::io::BufReader::new(bytes);
    // Materials come from the scene file, not from .mtl files.
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| Err(tobj::LoadError::OpenFileFailed))
        .map_err(|e| MeshError::Decode { path: path.to_owned(), format: "OBJ", message: e.to_string() })?;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for m in models {
        let base = positions.len() as u32;
        positions.extend(m.mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        triangles.extend(m.mesh.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    Ok((positions, triangles))
}

fn load_ply(path: &Path, bytes: &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), MeshError> {
    crate::scene::ply::parse(bytes).map_err(|message| MeshError::Decode {
        path: path.to_owned(),
        format: "PLY",
        message,
    })
}
