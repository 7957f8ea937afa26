//! Camera rays' nearest hits, eight rays from one point to a register, among the lone leaf's
//! primitives.

use super::{LANES, LanePrim, and3, cross, dot, splat3};
use core::arch::x86_64::*;
use sampler_core::glam::Vec3;

/// The nearest hits of eight rays from `origin` along `dirs` (a row per coordinate) in
/// (`t_min`, ∞): per lane the distance and the index into `prims` of the primitive hit (`u32::MAX`
/// where none is). The primitives are met in order and a nearer hit replaces an earlier only
/// where strictly nearer, as the blocks' lanes are met in `Bvh::intersect`, with the blocks'
/// exact tests ([`Block::triangles`](super::leaf::Block), [`Block::spheres`](super::leaf::Block)):
/// the same hit, bit for bit.
#[target_feature(enable = "avx2")]
pub(in crate::trace::bvh) fn closest(
    prims: &[LanePrim],
    origin: Vec3,
    dirs: [&[f32; LANES]; 3],
    t_min: f32,
) -> ([f32; LANES], [u32; LANES]) {
    let row = |r: &[f32; LANES]| {
        // SAFETY: `r` is eight readable f32s; the load has no alignment requirement.
        unsafe { _mm256_loadu_ps(r.as_ptr()) }
    };
    let (o, d) = (splat3(origin), dirs.map(row));
    let t_min = _mm256_set1_ps(t_min);
    let mut t_best = _mm256_set1_ps(f32::INFINITY);
    let mut best = _mm256_set1_epi32(-1);
    for (k, p) in prims.iter().enumerate() {
        let (hit, t) = match *p {
            LanePrim::Triangle { v0, e1, e2 } => {
                triangle_nearest(splat3(v0), splat3(e1), splat3(e2), o, d, t_min, t_best)
            }
            LanePrim::Sphere { center, r2 } => sphere_nearest(splat3(center), _mm256_set1_ps(r2), o, d, t_min, t_best),
        };
        // A hit is in (t_min, t_best): strictly nearer than the best so far.
        t_best = _mm256_blendv_ps(t_best, t, hit);
        best = _mm256_blendv_epi8(best, _mm256_set1_epi32(k as i32), _mm256_castps_si256(hit));
    }
    let (mut t, mut ids) = ([0.0f32; LANES], [0u32; LANES]);
    // SAFETY: `t` and `ids` are eight writable 4-byte lanes; the stores have no alignment
    // requirement.
    unsafe {
        _mm256_storeu_ps(t.as_mut_ptr(), t_best);
        _mm256_storeu_si256(ids.as_mut_ptr().cast(), best);
    }
    (t, ids)
}

/// `Block::triangles` of one triangle for eight rays: the lanes hit in (t_min, t_max) (all
/// ones) and their distances.
#[inline]
#[target_feature(enable = "avx2")]
fn triangle_nearest(
    v0: [__m256; 3],
    e1: [__m256; 3],
    e2: [__m256; 3],
    o: [__m256; 3],
    d: [__m256; 3],
    t_min: __m256,
    t_max: __m256,
) -> (__m256, __m256) {
    let (zero, one) = (_mm256_setzero_ps(), _mm256_set1_ps(1.0));
    let p = cross(d, e2);
    let det = dot(e1, p);
    let abs = _mm256_andnot_ps(_mm256_set1_ps(-0.0), det);
    let mut ok = _mm256_cmp_ps::<_CMP_NLT_US>(abs, _mm256_set1_ps(1e-20));
    let inv = _mm256_div_ps(one, det);
    let s = [_mm256_sub_ps(o[0], v0[0]), _mm256_sub_ps(o[1], v0[1]), _mm256_sub_ps(o[2], v0[2])];
    let u = _mm256_mul_ps(dot(s, p), inv);
    ok = and3(ok, _mm256_cmp_ps::<_CMP_LE_OS>(zero, u), _mm256_cmp_ps::<_CMP_LE_OS>(u, one));
    let q = cross(s, e1);
    let v = _mm256_mul_ps(dot(d, q), inv);
    let outside =
        _mm256_or_ps(_mm256_cmp_ps::<_CMP_LT_OS>(v, zero), _mm256_cmp_ps::<_CMP_LT_OS>(one, _mm256_add_ps(u, v)));
    ok = _mm256_andnot_ps(outside, ok);
    let t = _mm256_mul_ps(dot(e2, q), inv);
    ok = and3(ok, _mm256_cmp_ps::<_CMP_LT_OS>(t_min, t), _mm256_cmp_ps::<_CMP_LT_OS>(t, t_max));
    (ok, t)
}

/// `Block::spheres` of one sphere for eight rays: the lanes hit in (t_min, t_max) (all ones)
/// and their distances, the nearer root where it is in the interval, else the farther.
#[inline]
#[target_feature(enable = "avx2")]
fn sphere_nearest(
    center: [__m256; 3],
    r2: __m256,
    o: [__m256; 3],
    d: [__m256; 3],
    t_min: __m256,
    t_max: __m256,
) -> (__m256, __m256) {
    let sign_bit = _mm256_set1_ps(-0.0);
    let f = [_mm256_sub_ps(o[0], center[0]), _mm256_sub_ps(o[1], center[1]), _mm256_sub_ps(o[2], center[2])];
    let b = _mm256_xor_ps(dot(f, d), sign_bit);
    let perp = [
        _mm256_add_ps(f[0], _mm256_mul_ps(b, d[0])),
        _mm256_add_ps(f[1], _mm256_mul_ps(b, d[1])),
        _mm256_add_ps(f[2], _mm256_mul_ps(b, d[2])),
    ];
    let disc = _mm256_sub_ps(r2, dot(perp, perp));
    let c = _mm256_sub_ps(dot(f, f), r2);
    let root = _mm256_or_ps(_mm256_andnot_ps(sign_bit, _mm256_sqrt_ps(disc)), _mm256_and_ps(sign_bit, b));
    let q = _mm256_add_ps(b, root);
    let cq = _mm256_div_ps(c, q);
    let zero = _mm256_setzero_ps();
    let real = _mm256_cmp_ps::<_CMP_NLT_US>(disc, zero);
    // Both roots 0 where q = 0 (NaN q is not 0), then the nearer first.
    let nonzero = _mm256_cmp_ps::<_CMP_NEQ_UQ>(q, zero);
    let (t0, t1) = (_mm256_and_ps(nonzero, q), _mm256_and_ps(nonzero, cq));
    let ordered = _mm256_cmp_ps::<_CMP_LT_OS>(t0, t1);
    let (near, far) = (_mm256_blendv_ps(t1, t0, ordered), _mm256_blendv_ps(t0, t1, ordered));
    let inside = |t| _mm256_and_ps(_mm256_cmp_ps::<_CMP_LT_OS>(t_min, t), _mm256_cmp_ps::<_CMP_LT_OS>(t, t_max));
    let (near_in, far_in) = (inside(near), inside(far));
    let t = _mm256_blendv_ps(far, near, near_in);
    (_mm256_and_ps(real, _mm256_or_ps(near_in, far_in)), t)
}

#[cfg(test)]
mod tests {
    use super::super::test_scenes::small_scene;
    use crate::trace::bvh::Bvh;
    use sampler_core::glam::Vec3;

    #[test]
    fn eight_rays_to_a_register_find_the_nearest_hits_as_one_ray_at_a_time() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut hits = 0;
        for (seed, spheres, rectangles) in [(1, 3, 1), (2, 0, 4), (3, 8, 0), (4, 1, 0), (5, 4, 2), (7, 2, 3)] {
            let bvh = Bvh::build(&small_scene(seed, spheres, rectangles));
            // A camera outside everything, one inside the primitives' spread (some inside a
            // sphere), and one on a primitive's box corner; a near clip of 0 and of 0.5.
            let (lo, hi) = bvh.primitives()[0].bounds();
            for (o, t_min) in
                [(Vec3::new(0.3, 0.4, -6.0), 0.0), (Vec3::new(0.1, -0.2, 0.05), 0.5), (lo, 0.0), (hi, 1e-3)]
            {
                let dirs: Vec<Vec3> =
                    (0..1003).map(|_| Vec3::new(next(), next(), next()).normalize_or(Vec3::Z)).collect();
                let mut found = vec![None; dirs.len()];
                bvh.intersect_from(o, &dirs, t_min, &mut found);
                for (k, (d, got)) in dirs.iter().zip(&found).enumerate() {
                    let want = bvh.intersect(o, *d, t_min, f32::INFINITY);
                    let key = |h: &Option<crate::trace::bvh::Hit>| {
                        h.map(|h| {
                            (
                                h.t.to_bits(),
                                h.point.to_array().map(f32::to_bits),
                                h.normal.to_array().map(f32::to_bits),
                                h.surface,
                            )
                        })
                    };
                    assert_eq!(key(got), key(&want), "scene {seed}, origin {o}, ray {k} along {d}");
                    hits += usize::from(want.is_some());
                }
            }
        }
        assert!(hits > 3000, "{hits} hits: too few to test the lanes");
    }
}
