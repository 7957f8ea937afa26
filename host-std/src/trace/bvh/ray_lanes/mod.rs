//! Rays eight to an AVX2 register: against the primitives of a scene that is one leaf, and
//! camera rays through the tree as a packet (`packet.rs`).
//!
//! A leaf's blocks test one ray against four primitives at once (`leaf.rs`); a scene of a few
//! primitives fills those lanes poorly (a rectangle's two triangles, three spheres: five of
//! eight lanes) and pays the block's set-up per ray. Here a lane is a ray and a primitive is
//! splat, so every lane does work, and the primitives' data stays in registers for eight rays.
//! Each lane repeats the block's operations for its primitive in their order, so a ray's answer
//! is the one the block test gives, bit for bit: `ahead.rs` answers shadow rays over t ∈ (0, ∞)
//! as `Block::occludes` does, `closest.rs` finds camera rays' nearest hits as `Bvh::intersect`
//! does, and `packet.rs` tests a leaf's primitives the same way against a packet's rays.

mod ahead;
mod closest;
mod packet;

pub(super) use ahead::blocked_ahead;
pub(super) use closest::closest;
pub(super) use packet::closest_packet;

use super::Primitive;
use super::leaf::{Block, LanePrim, NONE};
use core::arch::x86_64::*;
use sampler_core::glam::Vec3;

/// Rays per register.
pub(super) const LANES: usize = super::rays_ahead::BLOCK;

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

/// Eight f32 into a register.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn load8(r: &[f32; LANES]) -> __m256 {
    // SAFETY: `r` is eight readable f32s; the load has no alignment requirement.
    unsafe { _mm256_loadu_ps(r.as_ptr()) }
}

/// a − b per lane and coordinate.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn sub3(a: [__m256; 3], b: [__m256; 3]) -> [__m256; 3] {
    [_mm256_sub_ps(a[0], b[0]), _mm256_sub_ps(a[1], b[1]), _mm256_sub_ps(a[2], b[2])]
}

/// A sphere's quadratic t² − 2bt + c = 0 along rays from `o` along `d`, as the leaf's blocks
/// set it up (`Block::sphere_roots`): b (the closest approach's distance), the discriminant
/// r² − |f + b·d|² (robust where the ray passes far from the centre) and c = |f|² − r², with f
/// the origin less the centre.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn sphere_quadratic(center: [__m256; 3], r2: __m256, o: [__m256; 3], d: [__m256; 3]) -> [__m256; 3] {
    let f = sub3(o, center);
    let b = _mm256_xor_ps(dot(f, d), _mm256_set1_ps(-0.0));
    let perp = [
        _mm256_add_ps(f[0], _mm256_mul_ps(b, d[0])),
        _mm256_add_ps(f[1], _mm256_mul_ps(b, d[1])),
        _mm256_add_ps(f[2], _mm256_mul_ps(b, d[2])),
    ];
    let disc = _mm256_sub_ps(r2, dot(perp, perp));
    let c = _mm256_sub_ps(dot(f, f), r2);
    [b, disc, c]
}

/// Scenes for the lanes' tests.
#[cfg(test)]
mod test_scenes {
    use crate::scene::{Bsdf, Material, Object, Scene, Shape};
    use sampler_core::brdf::Lambert;
    use sampler_core::glam::Vec3;

    /// A fixed stream of numbers in [−1, 1) (xorshift64) from `state`.
    pub(super) fn numbers(mut state: u64) -> impl FnMut() -> f32 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        }
    }

    /// A scene of `shapes`, each with its material (two Lambertian materials, 0 and 1).
    pub(super) fn scene_of(shapes: Vec<(Shape, usize)>) -> Scene {
        let objects = shapes.into_iter().map(|(shape, material)| Object { shape, material }).collect();
        let material = Material::new(Bsdf::Diffuse(Lambert::new(Vec3::ONE)), false);
        Scene { objects, materials: vec![material.clone(), material], ..crate::scene::builtin::scene() }
    }

    /// A scene of one leaf: spheres and rectangles about the origin, some overlapping.
    pub(super) fn small_scene(seed: u64, spheres: usize, rectangles: usize) -> Scene {
        let mut next = numbers(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
        let mut v = || Vec3::new(next(), next(), next());
        let mut shapes = Vec::new();
        for _ in 0..spheres {
            shapes.push((Shape::Sphere { center: v(), radius: 0.2 + 0.3 * v().x.abs() }, 0));
        }
        for _ in 0..rectangles {
            shapes.push((Shape::Rectangle { p0: v() * 1.5, e1: v() * 2.0, e2: v() * 2.0 }, 0));
        }
        scene_of(shapes)
    }
}
