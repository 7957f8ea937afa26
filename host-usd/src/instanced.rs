//! A PointInstancer's instances kept as instances: each prototype gprim's triangles read once
//! in its own space, and per instance only which prototype and where. The renderer places
//! them when it needs their triangles ([`Instanced::mesh`]) by `place`, the arithmetic that
//! places a gprim's own mesh, so an instance's points are those of its twin mesh to the bit; a
//! stage of many instances holds one small record per instance, not a mesh per instance. See
//! docs/usd.md, "Import speed" (the PointInstancer's table).

use crate::mesh::LocalMesh;
use crate::scene::Mesh;
use glam::{DAffine3, DMat3, Vec3};

/// A gprim under a PointInstancer's prototype, in its own space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Prototype {
    /// The gprim's prim path.
    pub path: String,
    /// Its triangles in its own space.
    pub local: LocalMesh,
    /// Its triangles grouped by the material of their faces (in material order): a mesh
    /// per group per instance.
    pub groups: Vec<(usize, Vec<usize>)>,
    /// The points its triangles use, each once: what bounds an instance.
    pub used: Vec<u32>,
    /// `doubleSided`: back faces shade like front faces.
    pub double_sided: bool,
}

/// One instance of a prototype: a PointInstancer's instance of a prototype root, for one
/// gprim under that root.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// Index into [`Instanced::prototypes`].
    pub prototype: u32,
    /// Index into [`Instanced::instancers`].
    pub instancer: u32,
    /// The instance's index among its instancer's `protoIndices`.
    pub index: u32,
    /// How many of [`crate::UsdScene::meshes`] the import made before this instance: its
    /// meshes come after those, in the import's order.
    pub after_meshes: u32,
    /// Prototype space to the renderer's world (non-singular).
    pub transform: DAffine3,
}

// A stage of many instances holds one record per instance and nothing on the heap for it.
const _: () = assert!(std::mem::size_of::<Instance>() == 112);

/// Every PointInstancer instance of a scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Instanced {
    /// The prototype gprims, each read once.
    pub prototypes: Vec<Prototype>,
    /// The instances, in import order.
    pub instances: Vec<Instance>,
    /// The PointInstancer prims' paths, for the instances' names.
    pub instancers: Vec<String>,
}

impl Instanced {
    /// The prim path that names instance `i`: the gprim's, with `[instancer:index]`.
    pub fn path(&self, i: usize) -> String {
        let inst = &self.instances[i];
        let proto = &self.prototypes[inst.prototype as usize];
        format!("{}[{}:{}]", proto.path, self.instancers[inst.instancer as usize], inst.index)
    }

    /// The number of meshes instance `i` renders as (one per material of its faces).
    pub fn groups(&self, i: usize) -> usize {
        self.prototypes[self.instances[i].prototype as usize].groups.len()
    }

    /// The corners of each triangle of instance `i`'s `group`th material, placed in the
    /// world as [`Instanced::mesh`] places them (in either winding), without making the mesh;
    /// `points` is scratch space.
    pub fn for_each_triangle(&self, i: usize, group: usize, points: &mut Vec<Vec3>, mut f: impl FnMut([Vec3; 3])) {
        let inst = &self.instances[i];
        let proto = &self.prototypes[inst.prototype as usize];
        points.clear();
        points.extend(proto.local.positions.iter().map(|&p| inst.transform.transform_point3(p).as_vec3()));
        for &t in &proto.groups[group].1 {
            f(proto.local.triangles[t].map(|v| points[v as usize]));
        }
    }

    /// The triangles of instance `i`'s `group`th material, placed in the world.
    pub fn mesh(&self, i: usize, group: usize) -> Mesh {
        Mesh { path: self.path(i), ..self.placed(i, group) }
    }

    /// [`Instanced::mesh`] without its name (an empty path): what a renderer needs.
    pub fn placed(&self, i: usize, group: usize) -> Mesh {
        let inst = &self.instances[i];
        let proto = &self.prototypes[inst.prototype as usize];
        let (material, which) = &proto.groups[group];
        let mut remap = vec![UNMAPPED; proto.local.positions.len()];
        let placed = Placement::new(&inst.transform);
        place(&proto.local, which, &placed, &mut remap, *material, proto.double_sided)
    }
}

/// A local point not yet placed in the mesh being built.
pub(crate) const UNMAPPED: u32 = u32::MAX;

/// Where a local mesh goes: `m` (non-singular), normals by `normal_matrix`, its inverse
/// transpose, winding reversed when it `mirror`s.
pub(crate) struct Placement<'a> {
    pub(crate) m: &'a DAffine3,
    normal_matrix: DMat3,
    mirror: bool,
}

impl<'a> Placement<'a> {
    /// The placement by `m`, which must be non-singular.
    pub(crate) fn new(m: &'a DAffine3) -> Self {
        let det = m.matrix3.determinant();
        Placement { m, normal_matrix: m.matrix3.inverse().transpose(), mirror: det < 0.0 }
    }
}

/// The triangles `which` of a local mesh, placed (a mesh with an empty path). `remap` (one
/// entry per local point, all [`UNMAPPED`]) numbers the points the triangles use in the
/// order they first use them, and is left all [`UNMAPPED`] again.
pub(crate) fn place(
    local: &LocalMesh,
    which: &[usize],
    placed: &Placement<'_>,
    remap: &mut [u32],
    material: usize,
    double_sided: bool,
) -> Mesh {
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
            normals.push(n.map(|n| (normal_matrix * n).normalize_or_zero().as_vec3()));
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
    Mesh {
        path: String::new(),
        positions: positions.into_boxed_slice(),
        triangles: triangles.into_boxed_slice(),
        normals: normals.into_boxed_slice(),
        uvs: uvs.into_boxed_slice(),
        material,
        double_sided,
    }
}

/// Whether every point of `positions` is finite.
pub(crate) fn all_finite(positions: &[Vec3]) -> bool {
    positions.iter().all(|p| p.is_finite())
}
