//! Rays eight to an AVX2 register against the primitives of a scene that is one leaf.
//!
//! A leaf's blocks test one ray against four primitives at once (`leaf.rs`); a scene of a few
//! primitives fills those lanes poorly (a rectangle's two triangles, three spheres: five of
//! eight lanes) and pays the block's set-up per ray. Here a lane is a ray and a primitive is
//! splat, so every lane does work, and the primitives' data stays in registers for eight rays.
//! Each lane repeats the block's operations for its primitive in their order, so a ray's answer
//! is the one the block test gives, bit for bit: `ahead.rs` answers shadow rays over t ∈ (0, ∞)
//! as [`Block::occludes`](super::leaf::Block) does, `closest.rs` finds camera rays' nearest hits
//! as `Bvh::intersect` does.

mod ahead;
mod closest;

pub(super) use ahead::blocked_ahead;
pub(super) use closest::closest;

use super::Primitive;
use super::leaf::{Block, NONE};
use core::arch::x86_64::*;
use sampler_core::glam::Vec3;

/// Rays per register.
pub(super) const LANES: usize = super::rays_ahead::BLOCK;

/// A primitive of the lone leaf as the lanes test it.
#[derive(Clone, Copy, Debug)]
pub(super) enum LanePrim {
    /// A vertex and the two edges from it.
    Triangle { v0: Vec3, e1: Vec3, e2: Vec3 },
    /// The centre and the squared radius (rounded as the blocks round it).
    Sphere { center: Vec3, r2: f32 },
}

impl LanePrim {
    /// The lane form of `p`.
    fn of(p: &Primitive) -> Self {
        match *p {
            Primitive::Triangle { v0, e1, e2, .. } => LanePrim::Triangle { v0, e1, e2 },
            Primitive::Sphere { center, radius, .. } => LanePrim::Sphere { center, r2: radius * radius },
        }
    }
}

/// The primitives of a tree that is one leaf, in the order its blocks hold them.
#[derive(Clone, Debug)]
pub(super) struct LoneLeaf {
    /// Each primitive's lane form.
    pub(super) prims: Vec<LanePrim>,
    /// Each primitive's index in the tree's primitives.
    pub(super) ids: Vec<u32>,
}

impl LoneLeaf {
    /// The primitives of `leaf`, the lone leaf's blocks.
    pub(super) fn new(leaf: &[Block], prims: &[Primitive]) -> Self {
        let ids: Vec<u32> = leaf.iter().flat_map(|b| b.prim).filter(|&id| id != NONE).collect();
        Self { prims: ids.iter().map(|&id| LanePrim::of(&prims[id as usize])).collect(), ids }
    }
}

/// a ∧ b ∧ c of three lane masks.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn and3(a: __m256, b: __m256, c: __m256) -> __m256 {
    _mm256_and_ps(_mm256_and_ps(a, b), c)
}

/// A vector splat into three registers.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn splat3(v: Vec3) -> [__m256; 3] {
    [_mm256_set1_ps(v.x), _mm256_set1_ps(v.y), _mm256_set1_ps(v.z)]
}

/// Bit k set where lane k of `a` < lane k of `b` (never for NaN), as `_mm_cmplt_ps`.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn lt(a: __m256, b: __m256) -> u32 {
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OS>(a, b)) as u32
}

/// Bit k set where lane k of `a` ≤ lane k of `b` (never for NaN), as `_mm_cmple_ps`.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn le(a: __m256, b: __m256) -> u32 {
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(a, b)) as u32
}

/// a × b per lane, in the leaf's order of operations.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn cross(a: [__m256; 3], b: [__m256; 3]) -> [__m256; 3] {
    let m = |x, y| _mm256_mul_ps(x, y);
    [
        _mm256_sub_ps(m(a[1], b[2]), m(b[1], a[2])),
        _mm256_sub_ps(m(a[2], b[0]), m(b[2], a[0])),
        _mm256_sub_ps(m(a[0], b[1]), m(b[0], a[1])),
    ]
}

/// a · b per lane, in the leaf's order of operations.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn dot(a: [__m256; 3], b: [__m256; 3]) -> __m256 {
    _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a[0], b[0]), _mm256_mul_ps(a[1], b[1])), _mm256_mul_ps(a[2], b[2]))
}

/// Scenes for the lanes' tests.
#[cfg(test)]
mod test_scenes {
    use crate::scene::{Bsdf, Material, Object, Scene, Shape};
    use sampler_core::brdf::Lambert;
    use sampler_core::glam::Vec3;

    /// A scene of one leaf: spheres and rectangles about the origin, some overlapping.
    pub(super) fn small_scene(seed: u64, spheres: usize, rectangles: usize) -> Scene {
        let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
        let mut next = move || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut v = || Vec3::new(next(), next(), next());
        let mut objects = Vec::new();
        for _ in 0..spheres {
            objects.push(Object { shape: Shape::Sphere { center: v(), radius: 0.2 + 0.3 * v().x.abs() }, material: 0 });
        }
        for _ in 0..rectangles {
            objects
                .push(Object { shape: Shape::Rectangle { p0: v() * 1.5, e1: v() * 2.0, e2: v() * 2.0 }, material: 0 });
        }
        let material = Material::new(Bsdf::Diffuse(Lambert::new(Vec3::ONE)), false);
        Scene { objects, materials: vec![material], ..crate::scene::builtin::scene() }
    }
}
