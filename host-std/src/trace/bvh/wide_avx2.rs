//! A wide node's eight box tests in one AVX2 register: the same operations per lane as the
//! two halves of four (`wide.rs`), so the same answers bit for bit, in half the instructions.
//! A tree's traversal runs in a function compiled for AVX2 (`Bvh::intersect`, `Bvh::occluded`)
//! where the CPU has it.

use super::wide::{NodeRay, WIDTH, WideNode, near_planes};
use core::arch::x86_64::*;
use sampler_core::glam::Vec3;

/// A ray prepared for box tests eight lanes at a time: origin and reciprocal direction in all
/// lanes, and per axis which of a box's two planes it meets first.
pub(super) struct RayLanes8 {
    o: [__m256; 3],
    inv: [__m256; 3],
    near: [usize; 3],
}

impl RayLanes8 {
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn new(o: Vec3, d: Vec3) -> RayLanes8 {
        let inv = d.recip();
        let splat = |v: Vec3| [_mm256_set1_ps(v.x), _mm256_set1_ps(v.y), _mm256_set1_ps(v.z)];
        RayLanes8 { o: splat(o), inv: splat(inv), near: near_planes(inv) }
    }
}

impl NodeRay for RayLanes8 {
    #[inline(always)]
    fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        // SAFETY: a `RayLanes8` is made only by `new`, which runs where the CPU has AVX2.
        unsafe { hit8(self, node, t_max) }
    }
}

/// [`NodeRay::hit`] in one register: per lane `max(lo − o) · inv` over the axes from 0 and
/// `min(hi − o) · inv` from `t_max`, a NaN distance keeping the running value (`maxps` /
/// `minps` with the running value second, as `F4::max_or` / `F4::min_or`), met where near ≤ far.
#[inline]
#[target_feature(enable = "avx2")]
fn hit8(r: &RayLanes8, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
    let mut near = _mm256_setzero_ps();
    let mut far = _mm256_set1_ps(t_max);
    for axis in 0..3 {
        let lo = plane_row(node, 2 * axis + r.near[axis]);
        let hi = plane_row(node, 2 * axis + 1 - r.near[axis]);
        near = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(lo, r.o[axis]), r.inv[axis]), near);
        far = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(hi, r.o[axis]), r.inv[axis]), far);
    }
    met(near, far)
}

/// Plane `plane` of a node's eight boxes in one register.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn plane_row(node: &WideNode, plane: usize) -> __m256 {
    // SAFETY: every row is eight readable f32s; the load needs no alignment.
    unsafe { _mm256_loadu_ps(node.planes[plane].as_ptr()) }
}

/// A node test's answer from its lanes' entry and exit distances: the children met (near ≤
/// far) and the entry distances.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn met(near: __m256, far: __m256) -> (u32, [f32; WIDTH]) {
    let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OS>(near, far)) as u32;
    let mut out = [0.0; WIDTH];
    // SAFETY: `out` is eight writable f32s; the store needs no alignment.
    unsafe { _mm256_storeu_ps(out.as_mut_ptr(), near) };
    (mask, out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::bvh::wide::RayLanes;

    /// A value of a small grid, so that origins fall on box planes and directions have zero
    /// components: the cases whose slab distances are NaN or infinite.
    fn grid(k: u32, salt: u32) -> f32 {
        let h = k.wrapping_mul(0x9E37_79B9).wrapping_add(salt.wrapping_mul(0x85EB_CA6B));
        let h = (h ^ (h >> 15)).wrapping_mul(0x2C1B_3C6D);
        ((h >> 8) % 9) as f32 * 0.5 - 2.0
    }

    #[test]
    fn eight_lanes_give_the_two_halves_answers_bit_for_bit() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2 on this CPU: the eight-lane box test is never used here");
            return;
        }
        let (mut met, mut nan_lanes) = (0, 0);
        for k in 0..4000u32 {
            let mut node = WideNode { planes: [[0.0; WIDTH]; 6], child: [0; WIDTH], count: [0; WIDTH] };
            for lane in 0..WIDTH {
                let salt = k * 64 + lane as u32 * 6;
                for axis in 0..3 {
                    let (a, b) = (grid(salt + 2 * axis as u32, 1), grid(salt + 2 * axis as u32 + 1, 2));
                    node.planes[2 * axis][lane] = a.min(b);
                    node.planes[2 * axis + 1][lane] = a.max(b);
                }
                if lane == (k % 9) as usize {
                    // An empty lane, as `collapse` writes one.
                    for axis in 0..3 {
                        node.planes[2 * axis][lane] = f32::INFINITY;
                        node.planes[2 * axis + 1][lane] = f32::NEG_INFINITY;
                    }
                }
            }
            let o = Vec3::new(grid(k, 3), grid(k, 4), grid(k, 5));
            let mut d = Vec3::new(grid(k, 6), grid(k, 7), grid(k, 8)) * 0.5;
            if k % 5 == 0 {
                d.y = -0.0;
            }
            let t_max = [f32::INFINITY, 2.0, 0.5][(k % 3) as usize];
            for lane in 0..WIDTH {
                for axis in 0..3 {
                    let lo = node.planes[2 * axis][lane];
                    nan_lanes += u32::from(((lo - o[axis]) * d[axis].recip()).is_nan());
                }
            }
            let (mask4, near4) = RayLanes::new(o, d).hit(&node, t_max);
            // SAFETY: the CPU has AVX2 (checked above).
            let (mask8, near8) = unsafe { RayLanes8::new(o, d) }.hit(&node, t_max);
            assert_eq!(mask8, mask4, "ray {k}");
            assert_eq!(near8.map(f32::to_bits), near4.map(f32::to_bits), "ray {k}");
            met += mask4.count_ones();
        }
        assert!(met > 2000, "{met} boxes met: too few to test the lanes");
        assert!(nan_lanes > 500, "{nan_lanes} NaN slab distances: too few to test their rule");
    }
}
