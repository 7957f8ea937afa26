//! One gprim into the scene: a sphere kept as a sphere when its transform is a uniform scale,
//! anything else as triangles in world space, one mesh per material of its faces.

use super::Importer;
use crate::mesh::{self, LocalMesh};
use crate::scene::{Mesh, Sphere};
use crate::shapes;
use crate::stage::PrimPath;
use crate::xform::uniform_scale;
use glam::{DMat3, DMat4, DVec3, Vec3};
use std::collections::HashMap;

/// What a gprim authors, read from the stage once and placed under any number of transforms
/// (a PointInstancer's prototype part under each of its instances). The sphere's radius and
/// the tessellation are read on first use: a sphere under uniform scales never needs its
/// triangles.
pub(super) struct GprimSource {
    prim: PrimPath,
    type_name: String,
    double_sided: bool,
    material: usize,
    radius: Option<f64>,
    shape: Option<LocalShape>,
}

/// A gprim's triangles in its local space, grouped by material (in material order).
struct LocalShape {
    local: LocalMesh,
    groups: Vec<(usize, Vec<usize>)>,
}

impl Importer<'_> {
    /// One gprim with its local-to-renderer transform `m`.
    pub(super) fn gprim(&mut self, prim: &PrimPath, type_name: &str, label: &str, m: &DMat4) -> Result<(), String> {
        let mut source = self.gprim_source(prim, type_name)?;
        self.place_gprim(&mut source, label, m)
    }

    /// What `prim` (a gprim of `type_name`) authors that does not depend on where it is placed.
    pub(super) fn gprim_source(&mut self, prim: &PrimPath, type_name: &str) -> Result<GprimSource, String> {
        let double_sided = self.stage.value(prim, "doubleSided")?.and_then(|v| v.scalar()).is_some_and(|v| v != 0.0);
        let material = self.material_for(prim)?;
        let (prim, type_name) = (prim.clone(), type_name.to_string());
        Ok(GprimSource { prim, type_name, double_sided, material, radius: None, shape: None })
    }

    /// The gprim of `source` placed by the local-to-renderer transform `m`.
    pub(super) fn place_gprim(&mut self, source: &mut GprimSource, label: &str, m: &DMat4) -> Result<(), String> {
        let stage = self.stage;
        let (material, double_sided) = (source.material, source.double_sided);
        self.scene.counts.gprims += 1;
        if source.type_name == "Sphere"
            && let Some(s) = uniform_scale(m)
        {
            let radius = match source.radius {
                Some(r) => r,
                None => *source.radius.insert(shapes::number(stage, &source.prim, "radius", 1.0)?),
            };
            let (r, center) = (radius * s, m.transform_point3(DVec3::ZERO));
            if !(r.is_finite() && center.is_finite()) {
                return Err("the sphere's transform or radius is not finite".into());
            }
            let (c, r) = (center.as_vec3(), r as f32);
            self.grow(c - Vec3::splat(r));
            self.grow(c + Vec3::splat(r));
            let path = label.to_string();
            self.scene.spheres.push(Sphere { path, center: c, radius: r, material, double_sided });
            return Ok(());
        }
        if source.type_name == "Mesh" {
            self.scene.counts.meshes += 1;
        }
        let shape = match source.shape.take() {
            Some(shape) => shape,
            None => self.local_shape(&source.prim, &source.type_name, material)?,
        };
        let placed = self.place_shape(&shape, label, m, double_sided);
        source.shape = Some(shape);
        placed
    }

    /// A gprim's triangles in its local space, grouped by the materials of its faces.
    fn local_shape(&mut self, prim: &PrimPath, type_name: &str, material: usize) -> Result<LocalShape, String> {
        let stage = self.stage;
        // Per-face materials from GeomSubsets of the materialBind family.
        let face_materials = if type_name == "Mesh" { self.subset_materials(prim)? } else { Default::default() };
        let local = if type_name == "Mesh" {
            // Texture coordinates only for a mesh whose materials read textures.
            let uv = std::iter::once(material)
                .chain(face_materials.materials().iter().copied())
                .find_map(|m| self.scene.materials[m].textures.first().map(|t| t.source.varname.clone()));
            mesh::read(stage, prim, uv.as_deref())?
        } else {
            shapes::tessellate(stage, prim, type_name)?.unwrap_or_default()
        };
        let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
        for (i, &face) in local.faces.iter().enumerate() {
            let mat = face_materials.get(face).unwrap_or(material);
            groups.entry(mat).or_default().push(i);
        }
        let mut groups: Vec<(usize, Vec<usize>)> = groups.into_iter().collect();
        groups.sort_unstable_by_key(|(mat, _)| *mat);
        Ok(LocalShape { local, groups })
    }

    /// The triangles of `shape` placed by `m`, one mesh per material.
    fn place_shape(&mut self, shape: &LocalShape, label: &str, m: &DMat4, double_sided: bool) -> Result<(), String> {
        let m3 = DMat3::from_mat4(*m);
        let det = m3.determinant();
        if !(det.is_finite() && det != 0.0) {
            self.skip(label, "its world transform is singular (the gprim has no area)");
            return Ok(());
        }
        let normal_matrix = m3.inverse().transpose();
        let mut remap = vec![UNMAPPED; shape.local.positions.len()];
        for (mat, which) in &shape.groups {
            let placed = Placement { m, normal_matrix: &normal_matrix, mirror: det < 0.0 };
            let mesh = transform(&shape.local, which, &placed, &mut remap, label, *mat, double_sided)?;
            self.scene.counts.triangles += mesh.triangles.len();
            for &p in &mesh.positions {
                self.grow(p);
            }
            self.scene.meshes.push(mesh);
        }
        Ok(())
    }

    /// Grows the scene's bounds to hold `p`.
    pub(super) fn grow(&mut self, p: Vec3) {
        let b = self.scene.bounds.get_or_insert((p, p));
        *b = (b.0.min(p), b.1.max(p));
    }
}

/// A local point not yet placed in the mesh being built.
const UNMAPPED: u32 = u32::MAX;

/// Where a local mesh goes: `m` (non-singular), normals by `normal_matrix`, its inverse
/// transpose, winding reversed when it `mirror`s.
struct Placement<'a> {
    m: &'a DMat4,
    normal_matrix: &'a DMat3,
    mirror: bool,
}

/// The triangles `which` of a local mesh, placed. `remap` (one entry per local point, all
/// [`UNMAPPED`]) numbers the points the triangles use in the order they first use them, and
/// is left all [`UNMAPPED`] again.
fn transform(
    local: &LocalMesh,
    which: &[usize],
    placed: &Placement<'_>,
    remap: &mut [u32],
    label: &str,
    material: usize,
    double_sided: bool,
) -> Result<Mesh, String> {
    let Placement { m, normal_matrix, mirror } = *placed;
    // The lists are sized once: the scene holds every gprim's lists at once, and a list
    // grown by pushing keeps up to half of it spare.
    let mut positions = Vec::new();
    let mut triangles = Vec::with_capacity(which.len());
    let mut normals = Vec::with_capacity(if local.normals.is_empty() { 0 } else { which.len() });
    let mut uvs = Vec::with_capacity(if local.uvs.is_empty() { 0 } else { which.len() });
    for &i in which {
        let mut t = local.triangles[i];
        let mut n = local.normals.get(i).copied();
        let mut uv = local.uvs.get(i).copied();
        if mirror {
            t.swap(1, 2);
            if let Some(n) = n.as_mut() {
                n.swap(1, 2);
            }
            if let Some(uv) = uv.as_mut() {
                uv.swap(1, 2);
            }
        }
        uvs.extend(uv);
        let t = t.map(|v| {
            let slot = &mut remap[v as usize];
            if *slot == UNMAPPED {
                positions.push(m.transform_point3(local.positions[v as usize]).as_vec3());
                *slot = (positions.len() - 1) as u32;
            }
            *slot
        });
        triangles.push(t);
        if let Some(n) = n {
            normals.push(n.map(|n| (*normal_matrix * n).normalize_or_zero().as_vec3()));
        }
    }
    for &i in which {
        local.triangles[i].iter().for_each(|&v| remap[v as usize] = UNMAPPED);
    }
    if normals.len() != triangles.len() {
        normals.clear();
    }
    if uvs.len() != triangles.len() {
        uvs.clear();
    }
    if positions.iter().any(|p: &Vec3| !p.is_finite()) {
        return Err("a transformed point is not finite".into());
    }
    Ok(Mesh {
        path: label.to_string(),
        positions: positions.into_boxed_slice(),
        triangles: triangles.into_boxed_slice(),
        normals: normals.into_boxed_slice(),
        uvs: uvs.into_boxed_slice(),
        material,
        double_sided,
    })
}
