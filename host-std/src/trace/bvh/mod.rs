//! Ray intersection: spheres and triangles in a bounding volume hierarchy built with the binned
//! surface-area heuristic (`build.rs`), flattened depth-first.

mod build;

use crate::scene::{Scene, Shape};
use sampler_core::glam::{Vec2, Vec3};
use std::mem::MaybeUninit;

/// One intersectable primitive.
#[derive(Clone, Copy, Debug)]
pub enum Primitive {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
        /// Index into the scene's materials.
        material: u32,
    },
    /// v0 and two edges; the front face is normalize(e1 × e2).
    Triangle {
        /// A vertex.
        v0: Vec3,
        /// The edge from `v0` to the second vertex.
        e1: Vec3,
        /// The edge from `v0` to the third vertex.
        e2: Vec3,
        /// Index into the scene's materials.
        material: u32,
        /// Index into the corner attributes, or `NO_ATTRS` (face normal, no texture
        /// coordinates).
        attrs: u32,
    },
}

const NO_ATTRS: u32 = u32::MAX;

/// Per-corner shading normals and texture coordinates of a triangle (either may be absent).
#[derive(Clone, Copy, Debug)]
struct CornerAttrs {
    normals: Option<[Vec3; 3]>,
    uvs: Option<[Vec2; 3]>,
}

impl Primitive {
    /// The corners (min, max) of the primitive's bounding box.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let b = self.aabb();
        (b.min, b.max)
    }

    fn aabb(&self) -> Aabb {
        match *self {
            Primitive::Sphere { center, radius, .. } => {
                Aabb { min: center - Vec3::splat(radius), max: center + Vec3::splat(radius) }
            }
            Primitive::Triangle { v0, e1, e2, .. } => {
                let (a, b) = (v0 + e1, v0 + e2);
                Aabb { min: v0.min(a).min(b), max: v0.max(a).max(b) }
            }
        }
    }

    /// Distance along o + t·d to the nearest hit in (t_min, t_max), if any.
    #[inline]
    pub fn intersect(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
        match *self {
            Primitive::Sphere { center, radius, .. } => {
                // Numerically robust: the closest approach first (Ray Tracing Gems ch. 7).
                let f = o - center;
                let b = -f.dot(d);
                let perp = f + b * d;
                let disc = radius * radius - perp.length_squared();
                if disc < 0.0 {
                    return None;
                }
                // Roots of t² − 2bt + c = 0: q = b ± √disc with the sign of b, and c/q.
                let c = f.length_squared() - radius * radius;
                let q = b + disc.sqrt().copysign(b);
                let (t0, t1) = if q != 0.0 { (q, c / q) } else { (0.0, 0.0) };
                let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
                if near > t_min && near < t_max {
                    Some(near)
                } else if far > t_min && far < t_max {
                    Some(far)
                } else {
                    None
                }
            }
            Primitive::Triangle { v0, e1, e2, .. } => {
                // Möller–Trumbore.
                let p = d.cross(e2);
                let det = e1.dot(p);
                if det.abs() < 1e-20 {
                    return None;
                }
                let inv = 1.0 / det;
                let s = o - v0;
                let u = s.dot(p) * inv;
                if !(0.0..=1.0).contains(&u) {
                    return None;
                }
                let q = s.cross(e1);
                let v = d.dot(q) * inv;
                if v < 0.0 || u + v > 1.0 {
                    return None;
                }
                let t = e2.dot(q) * inv;
                (t > t_min && t < t_max).then_some(t)
            }
        }
    }
}

/// Axis-aligned box.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Aabb {
    min: Vec3,
    max: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    fn area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    #[inline]
    fn hit(&self, o: Vec3, inv_d: Vec3, t_max: f32) -> bool {
        let t0 = (self.min - o) * inv_d;
        let t1 = (self.max - o) * inv_d;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element().min(t_max);
        near <= far
    }
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Node {
    bounds: Aabb,
    /// Leaf: first primitive; inner: index of the second child (the first follows the node).
    offset: u32,
    /// Primitives in a leaf; 0 for an inner node.
    count: u32,
    /// Inner node: the split axis (its first child holds the lower side).
    axis: u8,
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
    /// Index into the scene's materials.
    pub material: u32,
}

/// The scene's primitives and their hierarchy.
pub struct Bvh {
    prims: Vec<Primitive>,
    nodes: Vec<Node>,
    /// Per-corner shading normals and texture coordinates of triangles that have them.
    corner_attrs: Vec<CornerAttrs>,
}

impl Bvh {
    /// Builds the hierarchy over every shape of the scene (rectangles become two triangles).
    pub fn build(scene: &Scene) -> Self {
        let mut prims = Vec::new();
        let mut corner_attrs = Vec::new();
        for o in &scene.objects {
            let material = o.material as u32;
            match &o.shape {
                Shape::Sphere { center, radius } => {
                    prims.push(Primitive::Sphere { center: *center, radius: *radius, material })
                }
                Shape::Rectangle { p0, e1, e2 } => {
                    let attrs = NO_ATTRS;
                    prims.push(Primitive::Triangle { v0: *p0, e1: *e1, e2: *e1 + *e2, material, attrs });
                    prims.push(Primitive::Triangle { v0: *p0, e1: *e1 + *e2, e2: *e2, material, attrs });
                }
                Shape::Mesh { positions, triangles, normals, uvs } => {
                    for (k, t) in triangles.iter().enumerate() {
                        let [a, b, c] = t.map(|i| positions[i as usize]);
                        if (b - a).cross(c - a).length_squared() > 0.0 {
                            let n = normals
                                .get(k)
                                .filter(|n| n.iter().all(|n| n.is_finite() && n.length_squared() > 0.0))
                                .copied();
                            let uv = uvs.get(k).filter(|uv| uv.iter().all(|t| t.is_finite())).copied();
                            let attrs = if n.is_some() || uv.is_some() {
                                corner_attrs.push(CornerAttrs { normals: n, uvs: uv });
                                (corner_attrs.len() - 1) as u32
                            } else {
                                NO_ATTRS
                            };
                            prims.push(Primitive::Triangle { v0: a, e1: b - a, e2: c - a, material, attrs });
                        }
                    }
                }
            }
        }
        let nodes;
        (prims, nodes) = build::build(prims);
        Bvh { prims, nodes, corner_attrs }
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
        self.traverse(o, d, &mut t_max, true, |prim, t_max| {
            if let Some(t) = self.prims[prim].intersect(o, d, t_min, *t_max) {
                *t_max = t;
                best = Some(prim);
            }
            false
        });
        let prim = best?;
        let point = o + t_max * d;
        let mut uv = None;
        let (normal, shading, material) = match self.prims[prim] {
            Primitive::Sphere { center, radius, material } => {
                let n = ((point - center) / radius).normalize();
                (n, n, material)
            }
            Primitive::Triangle { v0, e1, e2, material, attrs } => {
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
                        (n, shading, material)
                    }
                    None => (n, n, material),
                }
            }
        };
        Some(Hit { t: t_max, point, normal, shading_normal: shading, uv, material })
    }

    /// True if anything blocks o + t·d for t ∈ (t_min, t_max).
    pub fn occluded(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        let mut hit = false;
        let mut t_max = t_max;
        self.traverse(o, d, &mut t_max, false, |prim, t_max| {
            hit = self.prims[prim].intersect(o, d, t_min, *t_max).is_some();
            hit
        });
        hit
    }

    /// Visits the primitives of every leaf the ray's box test lets through; `visit` may shrink
    /// `t_max` and returns true to stop.
    #[inline]
    fn traverse(
        &self,
        o: Vec3,
        d: Vec3,
        t_max: &mut f32,
        near_first: bool,
        mut visit: impl FnMut(usize, &mut f32) -> bool,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inv_d = d.recip();
        // Left uninitialised: zeroing the stack per ray is a noticeable share of a render of
        // simple scenes.
        let mut stack = [const { MaybeUninit::<u32>::uninit() }; 128];
        stack[0].write(0);
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            // SAFETY: entries below `sp` were all written (the root above, children below).
            let index = unsafe { stack[sp].assume_init() };
            let node = self.nodes[index as usize];
            if !node.bounds.hit(o, inv_d, *t_max) {
                continue;
            }
            if node.count > 0 {
                for prim in node.offset as usize..(node.offset + node.count) as usize {
                    if visit(prim, t_max) {
                        return;
                    }
                }
            } else {
                // The near child on top (visited next): the first child holds the lower side of
                // the split axis. The build bounds the depth (median splits past depth 40), so
                // the stack cannot overflow.
                debug_assert!(sp + 2 <= stack.len());
                let (near, far) = if (d[node.axis as usize] < 0.0) == near_first {
                    (node.offset, index + 1)
                } else {
                    (index + 1, node.offset)
                };
                stack[sp].write(far);
                stack[sp + 1].write(near);
                sp += 2;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, Object};
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
        for k in 0..2000 {
            let f = k as f32;
            let o = Vec3::new(-3.0 + (f * 0.37) % 20.0, -2.0 + (f * 0.11) % 16.0, -5.0);
            let d = Vec3::new((f * 0.013).sin() * 0.3, (f * 0.029).cos() * 0.3, 1.0).normalize();
            let brute =
                bvh.prims.iter().filter_map(|p| p.intersect(o, d, 1e-4, f32::INFINITY)).fold(f32::INFINITY, f32::min);
            let hit = bvh.intersect(o, d, 1e-4, f32::INFINITY).map_or(f32::INFINITY, |h| h.t);
            assert_eq!(hit, brute, "ray {k}");
            assert_eq!(bvh.occluded(o, d, 1e-4, 50.0), brute < 50.0, "ray {k}");
            hits += usize::from(brute.is_finite());
        }
        assert!(hits > 300 && hits < 1900, "{hits} of 2000 rays hit: the test would miss some failures");
    }
}
