//! Triangle meshes from OBJ (`tobj`) and PLY (`ply-rs-bw`) files: positions and triangles only
//! (the scene format uses face normals). Polygons are fan-triangulated; indices are checked.

use sampler_core::glam::Vec3;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("{path}: cannot read the mesh: {error}")]
    Io { path: PathBuf, error: std::io::Error },
    #[error("{path}: not a readable {format} mesh: {message}")]
    Decode { path: PathBuf, format: &'static str, message: String },
    #[error("{path}: unsupported mesh format (expected .obj or .ply)")]
    Unsupported { path: PathBuf },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
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
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let decode = |message: String| MeshError::Decode { path: path.to_owned(), format: "PLY", message };
    let mut reader = std::io::BufReader::new(bytes);
    let ply = Parser::<DefaultElement>::new().read_ply(&mut reader).map_err(|e| decode(e.to_string()))?;
    let scalar = |p: Option<&Property>| -> Option<f32> {
        Some(match p? {
            Property::Float(v) => *v,
            Property::Double(v) => *v as f32,
            Property::Int(v) => *v as f32,
            Property::UInt(v) => *v as f32,
            Property::Short(v) => *v as f32,
            Property::UShort(v) => *v as f32,
            Property::Char(v) => *v as f32,
            Property::UChar(v) => *v as f32,
            _ => return None,
        })
    };
    let vertices = ply.payload.get("vertex").ok_or_else(|| decode("no vertex element".into()))?;
    let mut positions = Vec::with_capacity(vertices.len());
    for v in vertices {
        let p = (scalar(v.get("x")), scalar(v.get("y")), scalar(v.get("z")));
        match p {
            (Some(x), Some(y), Some(z)) => positions.push(Vec3::new(x, y, z)),
            _ => return Err(decode("a vertex lacks numeric x, y, z".into())),
        }
    }
    let mut triangles = Vec::new();
    for f in ply.payload.get("face").map(Vec::as_slice).unwrap_or(&[]) {
        let list = f.get("vertex_indices").or_else(|| f.get("vertex_index"));
        let idx: Vec<i64> = match list {
            Some(Property::ListInt(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(Property::ListUInt(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(Property::ListShort(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(Property::ListUShort(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(Property::ListChar(l)) => l.iter().map(|&i| i as i64).collect(),
            Some(Property::ListUChar(l)) => l.iter().map(|&i| i as i64).collect(),
            _ => return Err(decode("a face lacks an integer vertex_indices list".into())),
        };
        if idx.iter().any(|&i| i < 0 || i > u32::MAX as i64) {
            return Err(decode("a face has a negative vertex index".into()));
        }
        for k in 2..idx.len() {
            triangles.push([idx[0] as u32, idx[k - 1] as u32, idx[k] as u32]);
        }
    }
    Ok((positions, triangles))
}
