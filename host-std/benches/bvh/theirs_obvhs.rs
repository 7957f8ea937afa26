//! The `obvhs` crate's compressed-wide BVH (CWBVH, 8 children per node, SIMD node tests) over
//! the same primitives, intersected with our own primitive tests so that only the hierarchy
//! and its traversal differ.

use host_std::trace::bvh::{Bvh, Primitive};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray, RayHit};
use sampler_core::glam::{Vec3, Vec3A};
use std::time::Duration;

/// The hierarchy and the primitives it indexes.
pub struct Obvhs {
    bvh: CwBvh,
    prims: Vec<Primitive>,
}

impl Obvhs {
    /// Builds over `ours`'s primitives with obvhs's medium-quality preset.
    pub fn build(ours: &Bvh) -> Obvhs {
        let prims = ours.primitives().to_vec();
        let boxes: Vec<Aabb> = prims
            .iter()
            .map(|p| {
                let (min, max) = p.bounds();
                Aabb::new(Vec3A::from(min), Vec3A::from(max))
            })
            .collect();
        let bvh =
            obvhs::cwbvh::builder::build_cwbvh(&boxes, obvhs::BvhBuildParams::medium_build(), &mut Duration::default());
        Obvhs { bvh, prims }
    }

    /// The distance to the nearest hit in (t_min, ∞), if any.
    pub fn closest(&self, o: Vec3, d: Vec3, t_min: f32) -> Option<f32> {
        let mut hit = RayHit::none();
        let ray = Ray::new(o.into(), d.into(), t_min, f32::INFINITY);
        let prims = &self.prims;
        let index = &self.bvh.primitive_indices;
        self.bvh
            .ray_traverse(ray, &mut hit, |r, id| {
                prims[index[id] as usize].intersect(o, d, t_min, r.tmax).unwrap_or(f32::INFINITY)
            })
            .then_some(hit.t)
    }

    /// Whether anything blocks the ray in (t_min, ∞).
    pub fn occluded(&self, o: Vec3, d: Vec3, t_min: f32) -> bool {
        let ray = Ray::new(o.into(), d.into(), t_min, f32::INFINITY);
        let prims = &self.prims;
        let index = &self.bvh.primitive_indices;
        !self.bvh.ray_traverse_miss(ray, |r, id| {
            prims[index[id] as usize].intersect(o, d, t_min, r.tmax).unwrap_or(f32::INFINITY)
        })
    }
}
