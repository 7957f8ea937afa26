//! Camera rays' nearest hits, eight rays from one point to a register, among the lone leaf's
//! primitives.

use super::{LANES, and3, cross, dot, load8, sphere_quadratic, splat3, sub3};
use crate::trace::bvh::leaf::LanePrim;
use core::arch::x86_64::*;
use sampler_core::glam::Vec3;

/// The nearest hits of eight rays from `origin` along `dirs` (a row per coordinate) in
/// (`t_min`, ∞): per lane the distance and the index into `prims` of the primitive hit (`u32::MAX`
/// where none is). The primitives are met in order and a nearer hit replaces an earlier only
/// where strictly nearer, as the blocks' lanes are met in `Bvh::intersect`, with the blocks'
/// exact tests (`Block::triangles`, `Block::spheres`): the same hit, bit for bit.
#[target_feature(enable = "avx2")]
pub(in crate::trace::bvh) fn closest(
    prims: &[LanePrim],
    origin: Vec3,
    dirs: [&[f32; LANES]; 3],
    t_min: f32,
) -> ([f32; LANES], [u32; LANES]) {
    let (o, d) = (splat3(origin), dirs.map(|r| load8(r)));
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
pub(super) fn triangle_nearest(
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
    let s = sub3(o, v0);
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
pub(super) fn sphere_nearest(
    center: [__m256; 3],
    r2: __m256,
    o: [__m256; 3],
    d: [__m256; 3],
    t_min: __m256,
    t_max: __m256,
) -> (__m256, __m256) {
    let sign_bit = _mm256_set1_ps(-0.0);
    let [b, disc, c] = sphere_quadratic(center, r2, o, d);
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
    use super::super::test_scenes::{numbers, scene_of, small_scene};
    use crate::scene::Shape;
    use crate::trace::bvh::{Bvh, Hit};
    use sampler_core::glam::Vec3;

    /// Asserts that the batch finds every ray's (from `o` along `dirs`, t ∈ (t_min, ∞)) hit as
    /// `Bvh::intersect` does, bit for bit; returns how many hit.
    fn assert_batch_hits(bvh: &Bvh, o: Vec3, dirs: &[Vec3], t_min: f32, what: &str) -> usize {
        if std::is_x86_feature_detected!("avx2") {
            assert!(bvh.lanes.is_some(), "{what}: the lanes serve a lone leaf");
        }
        let key = |h: &Option<Hit>| {
            h.map(|h| {
                (h.t.to_bits(), h.point.to_array().map(f32::to_bits), h.normal.to_array().map(f32::to_bits), h.surface)
            })
        };
        let mut found = vec![None; dirs.len()];
        bvh.intersect_from(o, dirs, t_min, &mut found);
        for (k, (d, got)) in dirs.iter().zip(&found).enumerate() {
            let want = bvh.intersect(o, *d, t_min, f32::INFINITY);
            assert_eq!(key(got), key(&want), "{what}, origin {o}, ray {k} along {d}");
        }
        found.iter().filter(|h| h.is_some()).count()
    }

    #[test]
    fn eight_rays_to_a_register_find_the_nearest_hits_as_one_ray_at_a_time() {
        let mut next = numbers(0x9e37_79b9_7f4a_7c15);
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
                hits += assert_batch_hits(&bvh, o, &dirs, t_min, &format!("scene {seed}"));
            }
        }
        assert!(hits > 3000, "{hits} hits: too few to test the lanes");
    }

    #[test]
    fn of_equal_distances_the_first_primitive_wins_as_one_ray_at_a_time() {
        // Each shape twice, the copy of another material: the same distances, and the hit must
        // be the surface met first in the leaf, as `Bvh::intersect` meets it.
        let sphere = Shape::Sphere { center: Vec3::new(0.0, 0.0, 2.0), radius: 1.0 };
        let square = Shape::Rectangle { p0: Vec3::new(-2.0, -2.0, 4.0), e1: Vec3::X * 4.0, e2: Vec3::Y * 4.0 };
        let bvh = Bvh::build(&scene_of(vec![(sphere.clone(), 0), (square.clone(), 1), (sphere, 1), (square, 0)]));
        let mut next = numbers(7);
        let dirs: Vec<Vec3> = (0..801).map(|_| Vec3::new(next() * 0.6, next() * 0.6, 1.0).normalize()).collect();
        let hits = assert_batch_hits(&bvh, Vec3::ZERO, &dirs, 0.0, "doubled shapes");
        assert!(hits > 500, "{hits} of {} hit", dirs.len());
    }
}
