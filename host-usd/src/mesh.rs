//! UsdGeomMesh → triangles: fan triangulation of each face (skipping `holeIndices`),
//! `orientation = leftHanded` reversed, normals expanded from `primvars:normals` (over
//! `normals`) in any interpolation. Subdivision meshes render as their control cage with
//! smooth (area-weighted) vertex normals; authored normals apply to `subdivisionScheme =
//! none` only, as USD specifies.

use crate::primvar::Primvar;
use crate::stage::{PrimPath, Stage, Value};
use glam::{DVec3, Vec2};

/// A mesh in its prim's local space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LocalMesh {
    /// Points in the prim's local space.
    pub positions: Vec<DVec3>,
    /// Counter-clockwise triangles (left-handed faces already reversed).
    pub triangles: Vec<[u32; 3]>,
    /// The face each triangle came from.
    pub faces: Vec<u32>,
    /// Per-triangle corner normals, or empty.
    pub normals: Vec<[DVec3; 3]>,
    /// Per-triangle corner texture coordinates, or empty.
    pub uvs: Vec<[Vec2; 3]>,
    /// True unless `subdivisionScheme` is `none` (rendered as its control cage, smooth normals).
    pub subdivision: bool,
}

fn ints(v: Option<Value>, what: &str) -> Result<Vec<i64>, String> {
    match v {
        None => Ok(Vec::new()),
        Some(Value::Numbers { values, .. }) => Ok(values.iter().map(|&x| x as i64).collect()),
        Some(_) => Err(format!("{what} is not an integer array")),
    }
}

/// Reads a Mesh prim, with texture coordinates from `primvars:<uv_primvar>` when asked.
pub fn read(stage: &Stage, prim: &PrimPath, uv_primvar: Option<&str>) -> Result<LocalMesh, String> {
    let positions: Vec<DVec3> = match stage.value(prim, "points")? {
        None => Vec::new(),
        Some(Value::Numbers { values, shape: 3, .. }) => {
            values.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect()
        }
        Some(_) => return Err("points is not a point3 array".into()),
    };
    let counts = ints(stage.value(prim, "faceVertexCounts")?, "faceVertexCounts")?;
    let indices = ints(stage.value(prim, "faceVertexIndices")?, "faceVertexIndices")?;
    let holes: std::collections::HashSet<i64> =
        ints(stage.value(prim, "holeIndices")?, "holeIndices")?.into_iter().collect();
    let left_handed = stage.value(prim, "orientation")?.as_ref().and_then(Value::token) == Some("leftHanded");
    let scheme = stage.value(prim, "subdivisionScheme")?;
    let subdivision = scheme.as_ref().and_then(Value::token).unwrap_or("catmullClark") != "none";
    if positions.iter().any(|p| !p.is_finite()) {
        return Err("a point is NaN or infinite".into());
    }
    let total: i64 = counts.iter().sum();
    if counts.iter().any(|&c| c < 0) || total != indices.len() as i64 {
        return Err(format!("faceVertexCounts sum to {total} but faceVertexIndices holds {} entries", indices.len()));
    }
    if let Some(bad) = indices.iter().find(|&&i| i < 0 || i as usize >= positions.len()) {
        return Err(format!("faceVertexIndices holds {bad}, past the {} points", positions.len()));
    }

    let normals_pv = if subdivision { None } else { Primvar::read(stage, prim, "normals", Some("normals"))? };
    let normals_pv =
        normals_pv.filter(|n| n.width == 3 && n.len() >= n.expected_len(counts.len(), indices.len(), positions.len()));

    let uvs_pv = match uv_primvar {
        Some(name) => Primvar::read(stage, prim, name, None)?,
        None => None,
    };
    let uvs_pv =
        uvs_pv.filter(|t| t.width == 2 && t.len() >= t.expected_len(counts.len(), indices.len(), positions.len()));

    let mut mesh = LocalMesh { positions, subdivision, ..LocalMesh::default() };
    let mut fv = 0usize;
    for (face, &count) in counts.iter().enumerate() {
        let count = count as usize;
        let corners = fv..fv + count;
        fv += count;
        if count < 3 || holes.contains(&(face as i64)) {
            continue;
        }
        let corner_list: Vec<usize> = corners.collect();
        for k in 1..count - 1 {
            let mut tri = [corner_list[0], corner_list[k], corner_list[k + 1]];
            if left_handed {
                tri.swap(1, 2);
            }
            let pts = tri.map(|c| indices[c] as u32);
            mesh.triangles.push(pts);
            mesh.faces.push(face as u32);
            if let Some(n) = &normals_pv {
                let corner_normal = |c: usize| {
                    let e = n.element_for(face, c, indices[c] as usize);
                    n.element(e).map_or(DVec3::ZERO, |v| DVec3::new(v[0], v[1], v[2]))
                };
                mesh.normals.push(tri.map(corner_normal));
            }
            if let Some(t) = &uvs_pv {
                let corner_uv = |c: usize| {
                    let e = t.element_for(face, c, indices[c] as usize);
                    t.element(e).map_or(Vec2::ZERO, |v| Vec2::new(v[0] as f32, v[1] as f32))
                };
                mesh.uvs.push(tri.map(corner_uv));
            }
        }
    }
    if mesh.subdivision && !mesh.triangles.is_empty() {
        mesh.normals = smooth_normals(&mesh.positions, &mesh.triangles);
    }
    Ok(mesh)
}

/// Area-weighted vertex normals of a triangle mesh, per corner.
fn smooth_normals(positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[DVec3; 3]> {
    let mut acc = vec![DVec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            acc[i as usize] += n;
        }
    }
    triangles.iter().map(|t| t.map(|i| acc[i as usize].normalize_or_zero())).collect()
}
