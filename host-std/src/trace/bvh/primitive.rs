//! The primitives rays meet: spheres and triangles, each with its bounding box and its exact
//! intersection distance.

use sampler_core::glam::Vec3;

/// One intersectable primitive.
#[derive(Clone, Copy, Debug)]
pub enum Primitive {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
        /// What it is the surface of: a [`super::Surface`] as an id.
        surface: u32,
    },
    /// v0 and two edges; the front face is normalize(e1 × e2).
    Triangle {
        /// A vertex.
        v0: Vec3,
        /// The edge from `v0` to the second vertex.
        e1: Vec3,
        /// The edge from `v0` to the third vertex.
        e2: Vec3,
        /// What it is the surface of: a [`super::Surface`] as an id.
        surface: u32,
        /// Index into the corner attributes, or `NO_ATTRS` (face normal, no texture
        /// coordinates).
        attrs: u32,
    },
}

impl Primitive {
    /// The corners (min, max) of the primitive's bounding box.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let b = self.aabb();
        (b.min, b.max)
    }

    pub(crate) fn aabb(&self) -> Aabb {
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
    pub(crate) min: Vec3,
    pub(crate) max: Vec3,
}

impl Aabb {
    pub(crate) const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    pub(crate) fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    pub(crate) fn area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}
