//! Shadow rays over t ∈ (0, ∞), eight to a register, against the lone leaf's primitives.

use super::{LanePrim, cross, dot, le, load8, lt, sphere_quadratic, splat3, sub3};
use crate::trace::bvh::RaysAhead;
use core::arch::x86_64::*;

/// The lanes (bit k for ray `first + k`) that one of `prims` blocks somewhere on t ∈ (0, ∞).
#[target_feature(enable = "avx2")]
pub(in crate::trace::bvh) fn blocked_ahead(prims: &[LanePrim], rays: &RaysAhead, first: usize) -> u32 {
    let (origin, dir) = rays.block(first);
    let (o, d) = (origin.map(|r| load8(r)), dir.map(|r| load8(r)));
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
    let s = sub3(o, v0);
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
    let [b, disc, c] = sphere_quadratic(center, r2, o, d);
    let zero = _mm256_setzero_ps();
    let real = !lt(disc, zero);
    real & (lt(c, zero) | lt(zero, b)) & 0xff
}

#[cfg(test)]
mod tests {
    use super::super::test_scenes::{numbers, scene_of, small_scene};
    use crate::scene::Shape;
    use crate::trace::bvh::{Bvh, RaysAhead};
    use sampler_core::glam::Vec3;

    /// Asserts that the batch answers every ray (from `o` along `d`) as `Bvh::occluded` does
    /// over (0, ∞); returns how many are blocked.
    fn assert_batch_answers(bvh: &Bvh, rays: &[(Vec3, Vec3)], what: &str) -> usize {
        if std::is_x86_feature_detected!("avx2") {
            assert!(bvh.lanes.is_some(), "{what}: the lanes serve a lone leaf");
        }
        let mut batch = RaysAhead::default();
        rays.iter().for_each(|&(o, d)| batch.push(o, d));
        let mut many = vec![false; rays.len()];
        bvh.occluded_ahead_many(&batch, &mut many);
        for (k, (&(o, d), m)) in rays.iter().zip(&many).enumerate() {
            assert_eq!(*m, bvh.occluded(o, d, 0.0, f32::INFINITY), "{what}, ray {k} from {o} along {d}");
        }
        many.iter().filter(|&&m| m).count()
    }

    #[test]
    fn eight_rays_to_a_register_answer_as_one_ray_at_a_time() {
        let mut next = numbers(0x2545_f491_4f6c_dd1d);
        let (mut blocked, mut total) = (0, 0);
        for (seed, spheres, rectangles) in [(1, 3, 1), (2, 0, 4), (3, 8, 0), (4, 1, 0), (5, 4, 2), (6, 2, 3)] {
            let bvh = Bvh::build(&small_scene(seed, spheres, rectangles));
            assert!(bvh.lone_leaf.is_some(), "scene {seed} should be one leaf");
            // Origins inside and outside the primitives, directions anywhere.
            let mut rays: Vec<(Vec3, Vec3)> = (0..3001)
                .map(|k| {
                    let o = Vec3::new(next(), next(), next()) * if k % 3 == 0 { 0.5 } else { 2.5 };
                    (o, Vec3::new(next(), next(), next()).normalize_or(Vec3::Y))
                })
                .collect();
            for p in bvh.primitives() {
                // Rays from a primitive's own surface (as a shading point's, offset or not).
                let (lo, hi) = p.bounds();
                let o = (lo + hi) * 0.5;
                for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::new(0.3, 0.9, -0.3).normalize()] {
                    let surface = bvh.intersect(o - d * 10.0, d, 0.0, f32::INFINITY).map_or(o, |h| h.point);
                    rays.extend([-1e-4, 0.0, 1e-4].map(|s| (surface + d * s, -d)));
                }
            }
            blocked += assert_batch_answers(&bvh, &rays, &format!("scene {seed}"));
            total += rays.len();
        }
        assert!(blocked > total / 10 && blocked < total * 9 / 10, "{blocked} of {total} blocked: too few either way");
    }

    #[test]
    fn rays_on_the_tests_boundaries_answer_as_one_ray_at_a_time() {
        // A unit sphere at the origin and a 2 × 2 square in the plane x = 3 (two triangles
        // sharing the diagonal from (3, −1, 1) to (3, 1, −1)).
        let sphere = Shape::Sphere { center: Vec3::ZERO, radius: 1.0 };
        let square = Shape::Rectangle { p0: Vec3::new(3.0, -1.0, -1.0), e1: Vec3::Y * 2.0, e2: Vec3::Z * 2.0 };
        let bvh = Bvh::build(&scene_of(vec![(sphere, 0), (square, 0)]));
        let mut rays = Vec::new();
        // From the sphere's surface (c = 0 exactly): leaving, entering, along it.
        for o in [Vec3::X, -Vec3::Y, Vec3::Z] {
            rays.extend([(o, o), (o, -o), (o, o.cross(Vec3::new(0.3, 0.2, 0.1)).normalize())]);
        }
        // Grazing the sphere (discriminant 0 up to rounding), ahead and behind.
        rays.extend([(Vec3::new(-5.0, 1.0, 0.0), Vec3::X), (Vec3::new(5.0, 0.0, 1.0), Vec3::X)]);
        // At the square's corners, edges and shared diagonal (u, v, u + v at 0 or 1 exactly),
        // from the side of the sphere and from behind the square.
        for (y, z) in [(-1.0, -1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, 0.0), (0.0, 1.0), (0.0, 0.0), (0.5, -0.5)] {
            rays.push((Vec3::new(2.0, y, z), Vec3::X));
            rays.push((Vec3::new(4.0, y, z), -Vec3::X));
            rays.push((Vec3::new(3.0, y, z), Vec3::X));
        }
        let blocked = assert_batch_answers(&bvh, &rays, "boundaries");
        assert!(blocked > 5 && blocked < rays.len() - 5, "{blocked} of {} blocked", rays.len());
    }
}
