//! Ray intersection: spheres and triangles in a bounding volume hierarchy built with the binned
//! surface-area heuristic (16 bins, up to 4 primitives per leaf), flattened depth-first.

use crate::scene::{Scene, Shape};
use sampler_core::glam::{Vec2, Vec3};
use std::mem::MaybeUninit;

/// One intersectable primitive.
#[derive(Clone, Copy, Debug)]
pub enum Primitive {
    Sphere {
        center: Vec3,
        radius: f32,
        material: u32,
    },
    /// v0 and two edges; the front face is normalize(e1 × e2).
    Triangle {
        v0: Vec3,
        e1: Vec3,
        e2: Vec3,
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
    fn bounds(&self) -> Aabb {
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

    /// Distance along the ray to the nearest hit in (t_min, t_max), if any.
    #[inline]
    fn intersect(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
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
struct Aabb {
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
struct Node {
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
    pub t: f32,
    pub point: Vec3,
    /// Geometric normal, unit, on the front side of the surface.
    pub normal: Vec3,
    /// Interpolated shading normal (the geometric normal where none is given), unit, on the
    /// side of the front face's authored normals.
    pub shading_normal: Vec3,
    /// Interpolated texture coordinates, where the mesh has them.
    pub uv: Option<Vec2>,
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
        let mut bvh = Bvh { prims, nodes: Vec::new(), corner_attrs };
        if !bvh.prims.is_empty() {
            let n = bvh.prims.len();
            let mut centroids: Vec<(Aabb, Vec3)> = bvh
                .prims
                .iter()
                .map(|p| {
                    let b = p.bounds();
                    (b, 0.5 * (b.min + b.max))
                })
                .collect();
            let mut order: Vec<usize> = (0..n).collect();
            bvh.nodes.reserve(2 * n);
            bvh.build_node(&mut centroids, &mut order, 0, n, 0);
            let prims = order.iter().map(|&i| bvh.prims[i]).collect();
            bvh.prims = prims;
        }
        bvh
    }

    /// Recursively builds the node for `order[lo..hi]`; returns its index.
    fn build_node(
        &mut self,
        info: &mut [(Aabb, Vec3)],
        order: &mut [usize],
        lo: usize,
        hi: usize,
        depth: u32,
    ) -> usize {
        let bounds = order[lo..hi].iter().fold(Aabb::EMPTY, |b, &i| b.union(info[i].0));
        let index = self.nodes.len();
        self.nodes.push(Node { bounds, offset: lo as u32, count: (hi - lo) as u32, axis: 0 });
        if hi - lo <= 4 {
            return index;
        }
        let cb = order[lo..hi].iter().fold(Aabb::EMPTY, |b, &i| b.union(Aabb { min: info[i].1, max: info[i].1 }));
        let extent = cb.max - cb.min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        if extent[axis] <= 0.0 {
            return index; // all centroids coincide: keep one leaf
        }
        const BINS: usize = 16;
        let bin_of = |c: Vec3| (((c[axis] - cb.min[axis]) / extent[axis] * BINS as f32) as usize).min(BINS - 1);
        let mut bins = [(Aabb::EMPTY, 0usize); BINS];
        for &i in &order[lo..hi] {
            let b = &mut bins[bin_of(info[i].1)];
            b.0 = b.0.union(info[i].0);
            b.1 += 1;
        }
        // Sweep: cost of splitting after bin k.
        let mut best = (f32::INFINITY, 0);
        for k in 0..BINS - 1 {
            let (l, r) = (&bins[..=k], &bins[k + 1..]);
            let (lb, ln) = l.iter().fold((Aabb::EMPTY, 0), |(b, n), x| (b.union(x.0), n + x.1));
            let (rb, rn) = r.iter().fold((Aabb::EMPTY, 0), |(b, n), x| (b.union(x.0), n + x.1));
            if ln == 0 || rn == 0 {
                continue;
            }
            let cost = lb.area() * ln as f32 + rb.area() * rn as f32;
            if cost < best.0 {
                best = (cost, k);
            }
        }
        let leaf_cost = bounds.area() * (hi - lo) as f32;
        if best.0 >= leaf_cost && hi - lo <= 16 {
            return index;
        }
        // Past depth 40, median splits keep the depth logarithmic (≤ 40 + log₂ n), so the stack of 128
        // always suffices (checked in debug builds).
        let mid = if depth < 40 { lo + partition(&mut order[lo..hi], |&i| bin_of(info[i].1) <= best.1) } else { lo };
        let mid = if mid == lo || mid == hi {
            let m = (lo + hi) / 2;
            order[lo..hi].select_nth_unstable_by(m - lo, |&a, &b| info[a].1[axis].total_cmp(&info[b].1[axis]));
            m
        } else {
            mid
        };
        self.build_node(info, order, lo, mid, depth + 1);
        let right = self.build_node(info, order, mid, hi, depth + 1);
        self.nodes[index].offset = right as u32;
        self.nodes[index].count = 0;
        self.nodes[index].axis = axis as u8;
        index
    }

    /// Number of primitives.
    pub fn primitive_count(&self) -> usize {
        self.prims.len()
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
        // Left uninitialised: zeroing 512 bytes per ray cost 12% of a render of a few spheres.
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

/// Stable-enough partition: elements satisfying `pred` first; returns their count.
fn partition<T>(v: &mut [T], pred: impl Fn(&T) -> bool) -> usize {
    let mut k = 0;
    for i in 0..v.len() {
        if pred(&v[i]) {
            v.swap(i, k);
            k += 1;
        }
    }
    k
}
