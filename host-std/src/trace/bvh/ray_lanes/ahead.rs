//! Shadow rays over t ∈ (0, ∞), eight to a register, against the lone leaf's primitives.

use super::{LANES, LanePrim, cross, dot, le, lt, splat3};
use crate::trace::bvh::RaysAhead;
use core::arch::x86_64::*;

/// The lanes (bit k for ray `first + k`) that one of `prims` blocks somewhere on t ∈ (0, ∞).
#[target_feature(enable = "avx2")]
pub(in crate::trace::bvh) fn blocked_ahead(prims: &[LanePrim], rays: &RaysAhead, first: usize) -> u32 {
    let row = |r: &[f32; LANES]| {
        // SAFETY: `r` is eight readable f32s; the load has no alignment requirement.
        unsafe { _mm256_loadu_ps(r.as_ptr()) }
    };
    let (origin, dir) = rays.block(first);
    let (o, d) = (origin.map(row), dir.map(row));
    let mut blocked = 0;
    for p in prims {
        blocked |= match *p {
            LanePrim::Triangle { v0, e1, e2 } => triangle_ahead(splat3(v0), splat3(e1), splat3(e2), o, d),
            LanePrim::Sphere { center, r2 } => sphere_ahead(splat3(center), _mm256_set1_ps(r2), o, d),
        };
        if blocked == 0xff {
            break;
        }
    }
    blocked
}

/// `Block::triangles_hit` of one triangle for eight rays, t ∈ (0, ∞): Möller–Trumbore with u,
/// v and t left multiplied by the determinant.
#[inline]
#[target_feature(enable = "avx2")]
fn triangle_ahead(v0: [__m256; 3], e1: [__m256; 3], e2: [__m256; 3], o: [__m256; 3], d: [__m256; 3]) -> u32 {
    let sign_bit = _mm256_set1_ps(-0.0);
    let p = cross(d, e2);
    let det = dot(e1, p);
    let (sign, scale) = (_mm256_and_ps(sign_bit, det), _mm256_andnot_ps(sign_bit, det));
    let mut ok = !lt(scale, _mm256_set1_ps(1e-20));
    let s = [_mm256_sub_ps(o[0], v0[0]), _mm256_sub_ps(o[1], v0[1]), _mm256_sub_ps(o[2], v0[2])];
    let u = _mm256_xor_ps(dot(s, p), sign);
    let zero = _mm256_setzero_ps();
    ok &= le(zero, u) & le(u, scale);
    let q = cross(s, e1);
    let v = _mm256_xor_ps(dot(d, q), sign);
    ok &= !(lt(v, zero) | lt(scale, _mm256_add_ps(u, v)));
    let t = _mm256_xor_ps(dot(e2, q), sign);
    let (t_min, t_max) = (_mm256_setzero_ps(), _mm256_set1_ps(f32::INFINITY));
    ok &= lt(_mm256_mul_ps(t_min, scale), t) & lt(t, _mm256_mul_ps(t_max, scale));
    ok & 0xff
}

/// `Block::spheres_ahead` of one sphere for eight rays: real roots, and the origin inside
/// (c < 0) or the sphere ahead (b > 0).
#[inline]
#[target_feature(enable = "avx2")]
fn sphere_ahead(center: [__m256; 3], r2: __m256, o: [__m256; 3], d: [__m256; 3]) -> u32 {
    let f = [_mm256_sub_ps(o[0], center[0]), _mm256_sub_ps(o[1], center[1]), _mm256_sub_ps(o[2], center[2])];
    let b = _mm256_xor_ps(dot(f, d), _mm256_set1_ps(-0.0));
    let perp = [
        _mm256_add_ps(f[0], _mm256_mul_ps(b, d[0])),
        _mm256_add_ps(f[1], _mm256_mul_ps(b, d[1])),
        _mm256_add_ps(f[2], _mm256_mul_ps(b, d[2])),
    ];
    let disc = _mm256_sub_ps(r2, dot(perp, perp));
    let c = _mm256_sub_ps(dot(f, f), r2);
    let zero = _mm256_setzero_ps();
    let real = !lt(disc, zero);
    real & (lt(c, zero) | lt(zero, b)) & 0xff
}
#[cfg(test)]
mod tests {
    use super::super::test_scenes::small_scene;
    use crate::trace::bvh::{Bvh, RaysAhead, ShadowRay};
    use sampler_core::glam::Vec3;

    #[test]
    fn eight_rays_to_a_register_answer_as_one_ray_at_a_time() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let (mut blocked, mut total) = (0, 0);
        for (seed, spheres, rectangles) in [(1, 3, 1), (2, 0, 4), (3, 8, 0), (4, 1, 0), (5, 4, 2), (6, 2, 3)] {
            let scene = small_scene(seed, spheres, rectangles);
            let bvh = Bvh::build(&scene);
            assert!(bvh.lone_leaf.is_some(), "scene {seed} should be one leaf");
            if std::is_x86_feature_detected!("avx2") {
                assert!(bvh.lanes.is_some(), "scene {seed}: the lanes serve a lone leaf");
            }
            let mut rays = Vec::new();
            for k in 0..3001 {
                // Origins inside and outside the primitives, directions anywhere; every eighth
                // group has a finite interval, for the one-at-a-time path.
                let o = Vec3::new(next(), next(), next()) * if k % 3 == 0 { 0.5 } else { 2.5 };
                let d = Vec3::new(next(), next(), next()).normalize_or(Vec3::Y);
                let (t_min, t_max) = if (k / 8) % 8 == 7 { (1e-3, 1.5) } else { (0.0, f32::INFINITY) };
                rays.push(ShadowRay { origin: o, dir: d, t_min, t_max });
            }
            for p in bvh.primitives() {
                // Rays from a primitive's own surface (as a shading point's, offset or not).
                let (lo, hi) = p.bounds();
                let o = (lo + hi) * 0.5;
                for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::new(0.3, 0.9, -0.3).normalize()] {
                    let surface = bvh.intersect(o - d * 10.0, d, 0.0, f32::INFINITY).map_or(o, |h| h.point);
                    for s in [-1e-4, 0.0, 1e-4] {
                        rays.push(ShadowRay { origin: surface + d * s, dir: -d, t_min: 0.0, t_max: f32::INFINITY });
                    }
                }
            }
            // The batch of the rays over (0, ∞).
            let ahead: Vec<&ShadowRay> = rays.iter().filter(|r| r.t_min == 0.0).collect();
            let mut batch = RaysAhead::default();
            ahead.iter().for_each(|r| batch.push(r.origin, r.dir));
            let mut many = vec![false; ahead.len()];
            bvh.occluded_ahead_many(&batch, &mut many);
            for (k, (r, m)) in ahead.iter().zip(&many).enumerate() {
                assert_eq!(*m, bvh.occluded(r.origin, r.dir, 0.0, f32::INFINITY), "scene {seed}, ray {k}: {r:?}");
            }
            let mut each = vec![false; rays.len()];
            bvh.occluded_many(&rays, &mut each);
            for (r, e) in rays.iter().zip(&each) {
                assert_eq!(*e, bvh.occluded(r.origin, r.dir, r.t_min, r.t_max));
            }
            blocked += many.iter().filter(|&&m| m).count();
            total += many.len();
        }
        assert!(blocked > total / 10 && blocked < total * 9 / 10, "{blocked} of {total} blocked: too few either way");
    }
}
