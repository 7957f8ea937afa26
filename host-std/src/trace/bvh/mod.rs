//! Ray intersection: spheres and triangles in a bounding volume hierarchy, built binary with
//! the binned surface-area heuristic (`build.rs`) and collapsed to eight children per node
//! (`wide.rs`) whose boxes a ray tests at once in SIMD lanes (`lanes.rs`, `traverse.rs`).
//! Primitive tests (`primitive.rs`, four to a leaf block in `leaf.rs`) decide every hit, so the
//! closest hit is the one a test of every primitive finds. Rays also come in batches
//! (`batch.rs`, `rays_ahead.rs`), which a scene that is one leaf answers eight rays to an AVX2
//! register and a tree answers for camera rays as packets of eight (`ray_lanes/`). Traversals
//! ask for their children's cache lines ahead (`prefetch.rs`). Area lights' surfaces are
//! primitives too (`gather.rs`), each hit saying what it is the surface of (`surface.rs`);
//! disks are tested beside the tree (`disk.rs`).

mod batch;
mod build;
mod disk;
mod gather;
mod lanes;
mod leaf;
mod prefetch;
mod primitive;
#[cfg(target_arch = "x86_64")]
mod ray_lanes;
mod rays_ahead;
mod surface;
mod traverse;
mod wide;
#[cfg(target_arch = "x86_64")]
mod wide_avx2;

pub(crate) use lanes::F4;
use primitive::Aabb;
pub use primitive::Primitive;
pub use rays_ahead::RaysAhead;
pub use surface::Surface;

use crate::scene::Scene;
use sampler_core::glam::{Vec2, Vec3};

const NO_ATTRS: u32 = u32::MAX;

/// Per-corner shading normals and texture coordinates of a triangle (either may be absent).
#[derive(Clone, Copy, Debug)]
struct CornerAttrs {
    normals: Option<[Vec3; 3]>,
    uvs: Option<[Vec2; 3]>,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    bounds: Aabb,
    /// Leaf: first primitive; inner: index of the second child (the first follows the node).
    offset: u32,
    /// Primitives in a leaf; 0 for an inner node.
    count: u32,
}

/// Where a ray hit.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Distance along the ray (in units of its direction).
    pub t: f32,
    /// The hit point.
    pub point: Vec3,
    /// Geometric normal, unit, on the front side of the surface.
    pub normal: Vec3,
    /// Interpolated shading normal (the geometric normal where none is given), unit, on the
    /// side of the front face's authored normals.
    pub shading_normal: Vec3,
    /// Interpolated texture coordinates, where the mesh has them.
    pub uv: Option<Vec2>,
    /// What was hit: a shape's material or a light's surface.
    pub surface: Surface,
}

/// A shadow ray for [`Bvh::occluded_many`]: is anything on origin + t·dir, t ∈ (t_min, t_max)?
#[derive(Clone, Copy, Debug)]
pub struct ShadowRay {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Its direction (unit for distances in units of length).
    pub dir: Vec3,
    /// Start of the tested interval (exclusive).
    pub t_min: f32,
    /// End of the tested interval (exclusive).
    pub t_max: f32,
}

/// The scene's primitives and their hierarchy.
pub struct Bvh {
    prims: Vec<Primitive>,
    nodes: Vec<wide::WideNode>,
    /// The leaves' primitives, four to a block.
    blocks: Vec<leaf::Block>,
    /// Per-corner shading normals and texture coordinates of triangles that have them.
    corner_attrs: Vec<CornerAttrs>,
    /// Disk lights' surfaces.
    disks: Vec<disk::Disk>,
    /// The blocks (first, count) of a tree that is one leaf, which rays test directly.
    lone_leaf: Option<(u32, u32)>,
    /// The lone leaf's primitives for rays eight at a time, where the tree is one leaf, no
    /// disk is beside it and the CPU has AVX2.
    #[cfg(target_arch = "x86_64")]
    lanes: Option<ray_lanes::LoneLeaf>,
    /// Whether rays take the AVX2 paths (`sampler_core::cpu::has_avx2`): they then test a
    /// node's eight boxes in one register.
    #[cfg(target_arch = "x86_64")]
    avx2: bool,
}

impl Bvh {
    /// Builds the hierarchy over every shape of the scene and every area light's surface
    /// (rectangles become two triangles).
    pub fn build(scene: &Scene) -> Self {
        let gather::Gathered { prims, corner_attrs, disks } = gather::gather(scene);
        let (prims, binary) = build::build(prims);
        let (nodes, blocks) = wide::collapse(&binary, &prims);
        let lone_leaf = wide::lone_leaf(&nodes);
        #[cfg(target_arch = "x86_64")]
        let avx2 = sampler_core::cpu::has_avx2();
        #[cfg(target_arch = "x86_64")]
        let lanes = lone_leaf
            .filter(|_| disks.is_empty() && avx2)
            .map(|(first, count)| ray_lanes::LoneLeaf::new(&blocks[first as usize..(first + count) as usize], &prims));
        Bvh {
            prims,
            nodes,
            blocks,
            corner_attrs,
            disks,
            lone_leaf,
            #[cfg(target_arch = "x86_64")]
            lanes,
            #[cfg(target_arch = "x86_64")]
            avx2,
        }
    }

    /// The number of primitives `build` makes of `scene`, without building: a sphere is
    /// one, a rectangle two, a mesh one per triangle with an area (disk lights aside).
    pub fn count_primitives(scene: &Scene) -> usize {
        gather::count(scene)
    }

    /// The radius of a sphere around every primitive (0 for an empty scene): the scale at
    /// which distant lights' power is compared with the others'.
    #[must_use]
    pub fn bounding_radius(&self) -> f32 {
        let boxes = self.prims.iter().map(Primitive::aabb).chain(self.disks.iter().map(|d| {
            let r = Vec3::splat(d.radius_squared.sqrt());
            Aabb { min: d.center - r, max: d.center + r }
        }));
        let (lo, hi) = boxes.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), b| (lo.min(b.min), hi.max(b.max)));
        if lo.cmple(hi).all() { 0.5 * (hi - lo).length() } else { 0.0 }
    }

    /// Number of primitives.
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
    }

    /// The primitives, in the hierarchy's order.
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// The nearest hit along o + t·d (d unit), t ∈ (t_min, t_max).
    pub fn intersect(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<Hit> {
        let mut best: Option<usize> = None;
        let mut t_max = t_max;
        match self.lone_leaf {
            Some((first, count)) => self.closest_in(first, count, o, d, t_min, &mut t_max, &mut best),
            None => self.closest_in_tree(o, d, t_min, &mut t_max, &mut best),
        }
        self.nearest_of(best, o, d, t_min, t_max)
    }

    /// The hit of the ray o + t·d, t ∈ (t_min, t_max), whose nearest primitive hit is `best` at
    /// `t_max` (or none, `t_max` then the interval's end): a disk's where one is nearer.
    #[inline(always)]
    fn nearest_of(&self, best: Option<usize>, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<Hit> {
        if let Some((k, t)) = disk::closest(&self.disks, o, d, t_min, t_max) {
            let disk = &self.disks[k];
            let (point, normal) = (o + t * d, disk.normal);
            let surface = Surface::from_id(disk.surface);
            return Some(Hit { t, point, normal, shading_normal: normal, uv: None, surface });
        }
        best.map(|prim| self.hit_at(prim, o, d, t_max))
    }

    /// The hit of the ray o + t·d on primitive `prim` at distance `t`. Inlined, so that the
    /// hit is built where the caller keeps it: copied out of a callee's frame, its wide loads
    /// wait on the callee's narrower stores.
    #[inline(always)]
    fn hit_at(&self, prim: usize, o: Vec3, d: Vec3, t: f32) -> Hit {
        let point = o + t * d;
        let mut uv = None;
        let (normal, shading, surface) = match self.prims[prim] {
            Primitive::Sphere { center, radius, surface } => {
                let n = ((point - center) / radius).normalize();
                (n, n, surface)
            }
            Primitive::Triangle { v0, e1, e2, surface, attrs } => {
                let n = e1.cross(e2).normalize();
                match self.corner_attrs.get(attrs as usize) {
                    Some(c) => {
                        // Barycentrics of the hit point (its projection on the plane).
                        let p = point - v0;
                        let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
                        let (d20, d21) = (p.dot(e1), p.dot(e2));
                        let den = d00 * d11 - d01 * d01;
                        let v = ((d11 * d20 - d01 * d21) / den).clamp(0.0, 1.0);
                        let w = ((d00 * d21 - d01 * d20) / den).clamp(0.0, 1.0 - v);
                        let u = 1.0 - v - w;
                        let shading = c.normals.map_or(n, |c| {
                            let s = (c[0] * u + c[1] * v + c[2] * w).normalize_or_zero();
                            if s == Vec3::ZERO { n } else { s }
                        });
                        uv = c.uvs.map(|c| c[0] * u + c[1] * v + c[2] * w);
                        (n, shading, surface)
                    }
                    None => (n, n, surface),
                }
            }
        };
        Hit { t, point, normal, shading_normal: shading, uv, surface: Surface::from_id(surface) }
    }

    /// True if anything blocks o + t·d for t ∈ (t_min, t_max).
    pub fn occluded(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        if self.disks.iter().any(|k| k.intersect(o, d, t_min, t_max).is_some()) {
            return true;
        }
        match self.lone_leaf {
            Some((first, count)) => self.blocked_in(first, count, o, d, t_min, t_max),
            None => self.blocked_in_tree(o, d, t_min, t_max),
        }
    }

    /// The nearest hit in the blocks `first..first + count` within (t_min, `t_max`), if nearer
    /// than `t_max`: `t_max` becomes its distance and `best` its primitive.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn closest_in(
        &self,
        first: u32,
        count: u32,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: &mut f32,
        best: &mut Option<usize>,
    ) {
        for b in &self.blocks[first as usize..(first + count) as usize] {
            let (tris, t_tri) = b.triangles(o, d, t_min, *t_max);
            let (spheres, t_sphere) = b.spheres(o, d, t_min, *t_max);
            // Lane by lane as a loop over the primitives would meet them, so that the first
            // of equal distances wins either way.
            for k in 0..4 {
                let t = if tris & (1 << k) != 0 {
                    t_tri[k]
                } else if spheres & (1 << k) != 0 {
                    t_sphere[k]
                } else {
                    continue;
                };
                if t < *t_max {
                    *t_max = t;
                    *best = Some(b.prim[k] as usize);
                }
            }
        }
    }

    /// Whether a primitive of the blocks `first..first + count` blocks the ray in (t_min, t_max).
    #[inline(always)]
    fn blocked_in(&self, first: u32, count: u32, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        // A loop rather than `Iterator::any`, which is kept out of line in the traversal.
        for b in &self.blocks[first as usize..(first + count) as usize] {
            if b.occludes(o, d, t_min, t_max) {
                return true;
            }
        }
        false
    }

    /// [`Bvh::occluded`] for each ray: `out[k]` is ray k's answer, bit for bit the one-at-a-time
    /// call's. Panics unless `out` has one entry per ray.
    pub fn occluded_many(&self, rays: &[ShadowRay], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "occluded_many: one answer per ray");
        for (r, o) in rays.iter().zip(out) {
            *o = self.occluded(r.origin, r.dir, r.t_min, r.t_max);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, Object, Shape};
    use sampler_core::brdf::Lambert;

    #[test]
    fn nearest_hits_and_occlusion_agree_with_testing_every_primitive() {
        let mut objects = Vec::new();
        for k in 0..400 {
            let c = Vec3::new((k % 20) as f32, ((k / 20) % 20) as f32, (k % 7) as f32) * 0.7;
            let shape = if k % 3 == 0 {
                Shape::Sphere { center: c, radius: 0.3 }
            } else {
                Shape::Rectangle { p0: c, e1: Vec3::new(0.5, 0.1, 0.0), e2: Vec3::new(0.0, 0.2, 0.5) }
            };
            objects.push(Object { shape, material: 0 });
        }
        let material = Material::new(crate::scene::Bsdf::Diffuse(Lambert::new(Vec3::ONE)), false);
        let scene = Scene { objects, materials: vec![material], ..crate::scene::builtin::scene() };
        let bvh = Bvh::build(&scene);
        let mut hits = 0;
        let mut rays = Vec::new();
        for k in 0..2000 {
            let f = k as f32;
            let o = Vec3::new(-3.0 + (f * 0.37) % 20.0, -2.0 + (f * 0.11) % 16.0, -5.0);
            let d = Vec3::new((f * 0.013).sin() * 0.3, (f * 0.029).cos() * 0.3, 1.0).normalize();
            let brute =
                bvh.prims.iter().filter_map(|p| p.intersect(o, d, 1e-4, f32::INFINITY)).fold(f32::INFINITY, f32::min);
            let hit = bvh.intersect(o, d, 1e-4, f32::INFINITY).map_or(f32::INFINITY, |h| h.t);
            assert_eq!(hit, brute, "ray {k}");
            assert_eq!(bvh.occluded(o, d, 1e-4, 50.0), brute < 50.0, "ray {k}");
            rays.push(ShadowRay { origin: o, dir: d, t_min: 1e-4, t_max: if k % 2 == 0 { 50.0 } else { brute } });
            hits += usize::from(brute.is_finite());
        }
        assert!(hits > 300 && hits < 1900, "{hits} of 2000 rays hit: the test would miss some failures");
        let mut many = vec![false; rays.len()];
        bvh.occluded_many(&rays, &mut many);
        for (r, m) in rays.iter().zip(&many) {
            assert_eq!(*m, bvh.occluded(r.origin, r.dir, r.t_min, r.t_max));
        }
        assert!(many.iter().any(|&m| m) && !many.iter().all(|&m| m));
    }

    #[test]
    fn primitives_are_counted_as_built() {
        let material = Material::new(crate::scene::Bsdf::Diffuse(Lambert::new(Vec3::ONE)), false);
        // Two triangles with an area, one with two equal corners, one on a line.
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE, 2.0 * Vec3::ONE];
        let triangles = vec![[0, 1, 2], [1, 2, 3], [0, 0, 1], [0, 3, 4]];
        let mesh = Shape::Mesh {
            positions: positions.into(),
            triangles: triangles.into(),
            normals: Box::new([]),
            uvs: Box::new([]),
        };
        let objects = vec![
            Object { shape: mesh, material: 0 },
            Object { shape: Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, material: 0 },
            Object { shape: Shape::Rectangle { p0: Vec3::ZERO, e1: Vec3::X, e2: Vec3::Z }, material: 0 },
        ];
        let scene = Scene { objects, materials: vec![material], ..crate::scene::builtin::scene() };
        assert_eq!(Bvh::count_primitives(&scene), 5);
        assert_eq!(Bvh::build(&scene).primitive_count(), 5);
    }

    #[test]
    fn a_lone_sphere_and_an_empty_scene_answer() {
        let material = Material::new(crate::scene::Bsdf::Diffuse(Lambert::new(Vec3::ONE)), false);
        let sphere = Object { shape: Shape::Sphere { center: Vec3::ZERO, radius: 1.0 }, material: 0 };
        let scene = |objects| Scene { objects, materials: vec![material.clone()], ..crate::scene::builtin::scene() };
        let (o, d) = (Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        let one = Bvh::build(&scene(vec![sphere]));
        assert_eq!(one.intersect(o, d, 0.0, f32::INFINITY).map(|h| h.t), Some(4.0));
        assert!(one.occluded(o, d, 0.0, f32::INFINITY) && !one.occluded(o, -d, 0.0, f32::INFINITY));
        let none = Bvh::build(&scene(Vec::new()));
        assert!(none.intersect(o, d, 0.0, f32::INFINITY).is_none() && !none.occluded(o, d, 0.0, f32::INFINITY));
    }
}
