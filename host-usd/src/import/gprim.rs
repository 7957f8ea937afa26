//! One gprim into the scene: a sphere kept as a sphere when its transform is a uniform scale,
//! anything else as triangles, one mesh per material of its faces: in world space, or for a
//! PointInstancer's instance, its prototype's triangles read once and an instance record.

use super::Importer;
use crate::instanced::{self, Instance, Placement, Prototype, UNMAPPED};
use crate::mesh;
use crate::scene::Sphere;
use crate::shapes;
use crate::stage::PrimPath;
use crate::xform::uniform_scale;
use glam::{DAffine3, DMat4, DVec3, Vec3};
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
    shape: Option<Prototype>,
    /// Its place among the scene's prototypes, once an instance has needed its triangles.
    prototype: Option<u32>,
}

/// Which PointInstancer instance a prototype gprim is placed for.
#[derive(Clone, Copy)]
pub(super) struct InstanceOf {
    /// Index into the scene's instancer paths.
    pub(super) instancer: u32,
    /// The instance's index among the instancer's `protoIndices`.
    pub(super) index: u32,
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
        Ok(GprimSource { prim, type_name, double_sided, material, radius: None, shape: None, prototype: None })
    }

    /// The gprim of `source` placed by the local-to-renderer transform `m`.
    pub(super) fn place_gprim(&mut self, source: &mut GprimSource, label: &str, m: &DMat4) -> Result<(), String> {
        self.scene.counts.gprims += 1;
        if source.type_name == "Sphere"
            && let Some(s) = uniform_scale(m)
        {
            return self.place_sphere(source, label, m, s);
        }
        if source.type_name == "Mesh" {
            self.scene.counts.meshes += 1;
        }
        let shape = match source.shape.take() {
            Some(shape) => shape,
            None => self.local_shape(source)?,
        };
        let placed = self.place_shape(&shape, label, m);
        source.shape = Some(shape);
        placed
    }

    /// The gprim of `source` placed by `m` as a PointInstancer's instance `of`: a sphere
    /// under a uniform scale is a sphere, anything else an instance of its prototype.
    pub(super) fn place_instance(&mut self, source: &mut GprimSource, of: InstanceOf, m: &DMat4) -> Result<(), String> {
        self.scene.counts.gprims += 1;
        if source.type_name == "Sphere"
            && let Some(s) = uniform_scale(m)
        {
            let label = self.instance_label(&source.prim, of);
            return self.place_sphere(source, &label, m, s);
        }
        if source.type_name == "Mesh" {
            self.scene.counts.meshes += 1;
        }
        let k = match source.prototype {
            Some(k) => k,
            None => {
                let shape = self.local_shape(source)?;
                let prototypes = &mut self.scene.instanced.prototypes;
                prototypes.push(shape);
                *source.prototype.insert((prototypes.len() - 1) as u32)
            }
        };
        let transform = DAffine3::from_mat4(*m);
        let det = transform.matrix3.determinant();
        if !(det.is_finite() && det != 0.0) {
            let label = self.instance_label(&source.prim, of);
            self.skip(&label, "its world transform is singular (the gprim has no area)");
            return Ok(());
        }
        let proto = &self.scene.instanced.prototypes[k as usize];
        if proto.groups.is_empty() {
            return Ok(());
        }
        let mut bounds = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for &v in &proto.used {
            let p = transform.transform_point3(proto.local.positions[v as usize]).as_vec3();
            if !p.is_finite() {
                return Err("a transformed point is not finite".into());
            }
            bounds = (bounds.0.min(p), bounds.1.max(p));
        }
        self.scene.counts.triangles += proto.local.triangles.len();
        self.grow(bounds.0);
        self.grow(bounds.1);
        let after_meshes = self.scene.meshes.len() as u32;
        let instance = Instance { prototype: k, instancer: of.instancer, index: of.index, after_meshes, transform };
        self.scene.instanced.instances.push(instance);
        Ok(())
    }

    /// The name of the gprim `prim` as the instance `of`.
    pub(super) fn instance_label(&self, prim: &PrimPath, of: InstanceOf) -> String {
        format!("{prim}[{}:{}]", self.scene.instanced.instancers[of.instancer as usize], of.index)
    }

    /// The sphere of `source` placed by `m`, a uniform scale by `s`.
    fn place_sphere(&mut self, source: &mut GprimSource, label: &str, m: &DMat4, s: f64) -> Result<(), String> {
        let radius = match source.radius {
            Some(r) => r,
            None => *source.radius.insert(shapes::number(self.stage, &source.prim, "radius", 1.0)?),
        };
        let (r, center) = (radius * s, m.transform_point3(DVec3::ZERO));
        if !(r.is_finite() && center.is_finite()) {
            return Err("the sphere's transform or radius is not finite".into());
        }
        let (c, r) = (center.as_vec3(), r as f32);
        self.grow(c - Vec3::splat(r));
        self.grow(c + Vec3::splat(r));
        let (path, material, double_sided) = (label.to_string(), source.material, source.double_sided);
        self.scene.spheres.push(Sphere { path, center: c, radius: r, material, double_sided });
        Ok(())
    }

    /// The gprim's triangles in its local space, grouped by the materials of its faces.
    fn local_shape(&mut self, source: &GprimSource) -> Result<Prototype, String> {
        let stage = self.stage;
        let (prim, type_name, material) = (&source.prim, source.type_name.as_str(), source.material);
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
        let mut is_used = vec![false; local.positions.len()];
        local.triangles.iter().flatten().for_each(|&v| is_used[v as usize] = true);
        let used = (0..local.positions.len() as u32).filter(|&v| is_used[v as usize]).collect();
        let (path, double_sided) = (prim.to_string(), source.double_sided);
        Ok(Prototype { path, local, groups, used, double_sided })
    }

    /// The triangles of `shape` placed by `m`, one mesh per material.
    fn place_shape(&mut self, shape: &Prototype, label: &str, m: &DMat4) -> Result<(), String> {
        let m = DAffine3::from_mat4(*m);
        let det = m.matrix3.determinant();
        if !(det.is_finite() && det != 0.0) {
            self.skip(label, "its world transform is singular (the gprim has no area)");
            return Ok(());
        }
        let mut remap = vec![UNMAPPED; shape.local.positions.len()];
        let placed = Placement::new(&m);
        for (mat, which) in &shape.groups {
            let mut mesh = instanced::place(&shape.local, which, &placed, &mut remap, *mat, shape.double_sided);
            if !instanced::all_finite(&mesh.positions) {
                return Err("a transformed point is not finite".into());
            }
            mesh.path = label.to_string();
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
