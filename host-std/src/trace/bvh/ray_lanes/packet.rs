//! Camera rays' nearest hits through the tree, eight rays from one point to a register: a
//! packet. A pixel's camera rays leave the camera within its footprint, so they meet nearly the
//! same boxes; the packet descends once for all of them, each node's eight boxes tested for
//! the whole packet in one register by interval arithmetic, and tests a leaf's primitives
//! against its eight rays at once.
//!
//! The packet's box test is conservative: the rays share the origin and, per axis, the sign of
//! the direction, so a slab distance (plane − o)·(1/d) of any of them lies between the ones of
//! the smallest and the largest reciprocal — rounding included, a product rounding monotonically
//! in each factor. A box one ray meets is met by the packet, and no leaf holding a ray's
//! nearest hit is skipped. The primitives are tested with the lone leaf's lane tests, bit for
//! bit the blocks' (`closest.rs`), so each ray's nearest distance is the one it finds alone.
//! Where a ray meets two primitives at exactly its nearest distance, which one a lone ray keeps
//! depends on the order it visits them: such a ray is left to `Bvh::intersect`.
//!
//! This rests on what a lone ray's nearest hit rests on too: a box test admits every hit its
//! leaf's tests find (the box's rounded entry is not beyond a rounded hit inside it). The packet
//! prunes boxes with a bound a few ulps wider than its rays' farthest nearest hit, so a box whose
//! entry rounds just past a hit inside it is still entered.

use super::closest::{sphere_nearest, triangle_nearest};
use super::{LANES, load8, splat3};
use crate::trace::bvh::Bvh;
use crate::trace::bvh::leaf::LanePrim;
use crate::trace::bvh::traverse::closest;
use crate::trace::bvh::wide::{NodeRay, WIDTH, WideNode, near_planes};
use crate::trace::bvh::wide_avx2::{met, plane_row};
use core::arch::x86_64::*;
use sampler_core::glam::Vec3;

/// Eight rays from one origin prepared for the packet's box tests: the origin in all lanes,
/// per axis the smallest and largest reciprocal direction of the packet, and the plane of a box
/// they all meet first.
struct PacketBoxes {
    o: [__m256; 3],
    inv_lo: [__m256; 3],
    inv_hi: [__m256; 3],
    near: [usize; 3],
}

impl PacketBoxes {
    /// The packet of rays from `o` along `dirs`, if their reciprocals are finite and keep one
    /// sign per axis.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn new(o: Vec3, dirs: &[Vec3; LANES]) -> Option<PacketBoxes> {
        let inv = dirs.map(|d| d.recip());
        let near = near_planes(inv[0]);
        if inv.iter().any(|i| !i.is_finite() || near_planes(*i) != near) {
            return None;
        }
        let lo = inv.iter().fold(inv[0], |a, b| a.min(*b));
        let hi = inv.iter().fold(inv[0], |a, b| a.max(*b));
        Some(PacketBoxes { o: splat3(o), inv_lo: splat3(lo), inv_hi: splat3(hi), near })
    }
}

impl NodeRay for PacketBoxes {
    #[inline(always)]
    fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        // SAFETY: a `PacketBoxes` is made only by `new`, which runs where the CPU has AVX2.
        unsafe { packet_hit(self, node, t_max) }
    }
}

/// The children whose boxes some ray of the packet may meet within [0, t_max], and an entry
/// distance no larger than any of theirs: per axis the slab distances at both reciprocals,
/// the smaller one entering and the larger one leaving.
#[inline]
#[target_feature(enable = "avx2")]
fn packet_hit(p: &PacketBoxes, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
    let row = |plane: usize| plane_row(node, plane);
    let mut near = _mm256_setzero_ps();
    let mut far = _mm256_set1_ps(t_max);
    for axis in 0..3 {
        let to_near = _mm256_sub_ps(row(2 * axis + p.near[axis]), p.o[axis]);
        let to_far = _mm256_sub_ps(row(2 * axis + 1 - p.near[axis]), p.o[axis]);
        let (a, b) = (_mm256_mul_ps(to_near, p.inv_lo[axis]), _mm256_mul_ps(to_near, p.inv_hi[axis]));
        near = _mm256_max_ps(_mm256_min_ps(a, b), near);
        let (a, b) = (_mm256_mul_ps(to_far, p.inv_lo[axis]), _mm256_mul_ps(to_far, p.inv_hi[axis]));
        far = _mm256_min_ps(_mm256_max_ps(a, b), far);
    }
    met(near, far)
}

/// The nearest hits of eight rays from `o` along `dirs` in (`t_min`, ∞) through `bvh`'s tree:
/// per ray its distance and primitive (`None` where it hits nothing), and the rays (bit k for
/// ray k) that meet two primitives at their nearest distance, whose answers are to be taken
/// from `Bvh::intersect`. `None` where the rays do not make a packet (a direction with a zero
/// component, or directions of both signs along an axis).
#[target_feature(enable = "avx2")]
pub(in crate::trace::bvh) fn closest_packet(
    bvh: &Bvh,
    o: Vec3,
    dirs: &[Vec3; LANES],
    t_min: f32,
) -> Option<([f32; LANES], [Option<usize>; LANES], u32)> {
    let boxes = PacketBoxes::new(o, dirs)?;
    let rows: [[f32; LANES]; 3] = core::array::from_fn(|a| dirs.map(|d| d[a]));
    let (origin, d) = (splat3(o), rows.each_ref().map(|r| load8(r)));
    let (t_min, infinity) = (_mm256_set1_ps(t_min), _mm256_set1_ps(f32::INFINITY));
    let mut t_best = infinity;
    let mut best = _mm256_set1_epi32(-1);
    // Per ray the distance of its last tie: a tie counts where it is at the final nearest hit.
    let mut t_tie = _mm256_set1_ps(f32::NAN);
    let mut t_max = f32::INFINITY;
    closest(&bvh.nodes, &bvh.blocks, &boxes, &mut t_max, |first, count, t_max| {
        for b in &bvh.blocks[first as usize..(first + count) as usize] {
            for k in 0..4 {
                let (hit, t) = match b.lane(k) {
                    Some(LanePrim::Triangle { v0, e1, e2 }) => {
                        triangle_nearest(splat3(v0), splat3(e1), splat3(e2), origin, d, t_min, infinity)
                    }
                    Some(LanePrim::Sphere { center, r2 }) => {
                        sphere_nearest(splat3(center), _mm256_set1_ps(r2), origin, d, t_min, infinity)
                    }
                    None => continue,
                };
                let nearer = _mm256_and_ps(hit, _mm256_cmp_ps::<_CMP_LT_OS>(t, t_best));
                let tie = _mm256_and_ps(hit, _mm256_cmp_ps::<_CMP_EQ_OQ>(t, t_best));
                t_tie = _mm256_blendv_ps(t_tie, t, tie);
                t_best = _mm256_blendv_ps(t_best, t, nearer);
                let id = _mm256_set1_epi32(b.prim[k] as i32);
                best = _mm256_blendv_epi8(best, id, _mm256_castps_si256(nearer));
            }
        }
        // The farthest of the rays' nearest hits (none is NaN) bounds the boxes still worth
        // entering, a few ulps wider: a box's entry rounds apart from the hits inside it, and
        // a lone ray whose bound was larger when it met such a box entered it.
        let m = _mm256_max_ps(t_best, _mm256_permute2f128_ps::<1>(t_best, t_best));
        let m = _mm256_max_ps(m, _mm256_shuffle_ps::<0b01_00_11_10>(m, m));
        let m = _mm256_max_ps(m, _mm256_shuffle_ps::<0b10_11_00_01>(m, m));
        *t_max = _mm256_cvtss_f32(m) * (1.0 + 8.0 * f32::EPSILON);
    });
    let (mut t, mut ids) = ([0.0f32; LANES], [0i32; LANES]);
    // SAFETY: `t` and `ids` are eight writable 4-byte lanes; the stores need no alignment.
    unsafe {
        _mm256_storeu_ps(t.as_mut_ptr(), t_best);
        _mm256_storeu_si256(ids.as_mut_ptr().cast(), best);
    }
    let ties = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(t_tie, t_best)) as u32;
    Some((t, ids.map(|id| usize::try_from(id).ok()), ties))
}

#[cfg(test)]
mod tests {
    use super::super::test_scenes::{numbers, scene_of};
    use super::*;
    use crate::scene::Shape;
    use crate::trace::bvh::Hit;

    /// A tree: a wavy grid of triangles (twice over one patch, the copy of another material,
    /// so that rays there meet two primitives at one distance), spheres and rectangles.
    fn tree_scene() -> Bvh {
        let n = 40;
        let height = |i: u32, j: u32| 0.15 * ((i as f32 * 0.7).sin() + (j as f32 * 0.45).cos());
        let positions: Vec<Vec3> = (0..=n)
            .flat_map(|j| {
                (0..=n).map(move |i| {
                    Vec3::new(i as f32 / n as f32 * 4.0 - 2.0, height(i, j), j as f32 / n as f32 * 4.0 - 2.0)
                })
            })
            .collect();
        let at = |i: u32, j: u32| j * (n + 1) + i;
        let quads = |range: core::ops::Range<u32>| {
            let mut t = Vec::new();
            for j in range.clone() {
                for i in range.clone() {
                    t.push([at(i, j), at(i, j + 1), at(i + 1, j)]);
                    t.push([at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)]);
                }
            }
            t.into_boxed_slice()
        };
        let mesh = |triangles| Shape::Mesh {
            positions: positions.clone().into_boxed_slice(),
            triangles,
            normals: Box::new([]),
            uvs: Box::new([]),
        };
        let mut shapes = vec![(mesh(quads(0..n)), 0), (mesh(quads(5..30)), 1)];
        let mut next = numbers(0x2545_f491_4f6c_dd1d);
        for _ in 0..12 {
            let c = Vec3::new(next() * 2.0, 0.4 + next().abs(), next() * 2.0);
            shapes.push((Shape::Sphere { center: c, radius: 0.1 + 0.2 * next().abs() }, 0));
        }
        shapes.push((Shape::Rectangle { p0: Vec3::new(-2.0, 0.0, 1.5), e1: Vec3::X * 4.0, e2: Vec3::Y * 1.5 }, 1));
        Bvh::build(&scene_of(shapes))
    }

    fn key(h: &Option<Hit>) -> Option<(u32, [u32; 3], [u32; 3], crate::trace::bvh::Surface)> {
        h.map(|h| {
            (h.t.to_bits(), h.point.to_array().map(f32::to_bits), h.normal.to_array().map(f32::to_bits), h.surface)
        })
    }

    #[test]
    fn packets_find_the_nearest_hits_as_one_ray_at_a_time() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2 on this CPU: packets are never used here");
            return;
        }
        let bvh = tree_scene();
        assert!(bvh.lone_leaf.is_none() && bvh.nodes.len() > 10, "a tree of {} nodes", bvh.nodes.len());
        let mut next = numbers(0x9e37_79b9_7f4a_7c15);
        let (mut hits, mut packets, mut ties) = (0, 0, 0);
        // Pixels' rays: groups about one direction, some of them straddling an axis (no packet),
        // some with a zero component (no packet), one of a remainder of three rays.
        for (g, o) in
            [Vec3::new(0.3, 3.0, -4.5), Vec3::new(-0.2, 1.2, 0.1), Vec3::new(1.9, 0.25, -2.2)].iter().enumerate()
        {
            for pixel in 0..300 {
                let centre = (Vec3::new(next() * 0.8, -0.5 - next().abs(), 0.9 * next()) + Vec3::Z * (g as f32 - 0.5))
                    .normalize();
                let spread = [1e-3, 2e-2, 0.3][pixel % 3];
                let count = if pixel == 7 { 3 } else { 8 + pixel % 17 };
                let mut dirs: Vec<Vec3> =
                    (0..count).map(|_| (centre + spread * Vec3::new(next(), next(), next())).normalize()).collect();
                if pixel % 50 == 1 {
                    dirs[0].x = 0.0;
                }
                let mut found = vec![None; dirs.len()];
                bvh.intersect_from(*o, &dirs, 1e-3, &mut found);
                for (k, (d, got)) in dirs.iter().zip(&found).enumerate() {
                    let want = bvh.intersect(*o, *d, 1e-3, f32::INFINITY);
                    assert_eq!(key(got), key(&want), "origin {o}, pixel {pixel}, ray {k} along {d}");
                    hits += usize::from(want.is_some());
                }
                let mut packet = [dirs[0]; LANES];
                let n = dirs.len().min(LANES);
                packet[..n].copy_from_slice(&dirs[..n]);
                // SAFETY: the CPU has AVX2 (checked above).
                if let Some((_, _, tied)) = unsafe { closest_packet(&bvh, *o, &packet, 1e-3) } {
                    packets += 1;
                    ties += tied.count_ones();
                }
            }
        }
        assert!(hits > 5000, "{hits} hits: too few to test the packets");
        assert!(packets > 500, "{packets} packets: too few rays went together");
        assert!(ties > 20, "{ties} rays met two primitives at their nearest distance: too few to test them");
    }

    #[test]
    fn of_primitives_at_one_distance_a_packet_keeps_the_one_a_lone_ray_keeps() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("no AVX2 on this CPU: packets are never used here");
            return;
        }
        // Overlapping squares in the plane y = 0 with power-of-two sides at dyadic corners:
        // every one a ray meets is at the same distance, bit for bit, and the packet visits
        // their leaves in another order than a lone ray does.
        let mut shapes =
            vec![(Shape::Rectangle { p0: Vec3::new(-2.0, 0.0, -2.0), e1: Vec3::X * 4.0, e2: Vec3::Z * 4.0 }, 0)];
        for k in 0..150u32 {
            let side = 0.5f32.powi(1 + (k % 3) as i32);
            let corner = Vec3::new((k % 24) as f32 / 8.0 - 1.5, 0.0, (k / 24 * 3 % 24) as f32 / 8.0 - 1.5);
            shapes.push((Shape::Rectangle { p0: corner, e1: Vec3::X * side, e2: Vec3::Z * side }, (k % 2) as usize));
        }
        let bvh = Bvh::build(&scene_of(shapes));
        assert!(bvh.lone_leaf.is_none(), "a tree");
        let mut next = numbers(0x5851_f42d_4c95_7f2d);
        let o = Vec3::new(-2.25, 3.0, -2.0);
        let (mut packets, mut tied, mut kept_otherwise) = (0, 0, 0);
        for _ in 0..400 {
            let centre = Vec3::new(0.6 + next() * 0.5, -1.0, 0.6 + next() * 0.5).normalize();
            let dirs: [Vec3; LANES] =
                core::array::from_fn(|_| (centre + 0.1 * Vec3::new(next(), 0.0, next())).normalize());
            let mut found = vec![None; LANES];
            bvh.intersect_from(o, &dirs, 0.0, &mut found);
            // SAFETY: the CPU has AVX2 (checked above).
            let Some((t, best, ties)) = (unsafe { closest_packet(&bvh, o, &dirs, 0.0) }) else {
                continue; // directions on both sides of an axis
            };
            packets += 1;
            for (k, d) in dirs.iter().enumerate() {
                let want = bvh.intersect(o, *d, 0.0, f32::INFINITY);
                assert_eq!(key(&found[k]), key(&want), "ray {k} along {d}");
                if ties & (1 << k) != 0 {
                    tied += 1;
                    let packet = bvh.nearest_of(best[k], o, *d, 0.0, t[k]);
                    kept_otherwise += usize::from(packet.map(|h| h.surface) != want.map(|h| h.surface));
                }
            }
        }
        assert!(packets > 300, "{packets} packets of 400");
        assert!(tied > 1000, "{tied} rays met primitives at one distance: too few");
        assert!(
            kept_otherwise > 20,
            "{kept_otherwise} tied rays: the packet alone keeps the lone ray's surface, so the tie rule goes untested"
        );
    }
}
