//! Product-tree descents four to a register: [`choose_child_branchless`]'s step for four
//! descents at once in AVX2 (four f64 lanes), with the same operations in the same order — the
//! same children, rescaled points and path probabilities, bit for bit. A descent's ξ stays in
//! registers from the root to its leaf; per level only the lanes' children's masses come in
//! and the chosen child's index goes out, to the lane's node, cell and path. Lanes stop at
//! their leaves one by one; a group steps while any of its lanes is still above one.
//!
//! [`choose_child_branchless`]: crate::warp::choose_child_branchless

use super::lanes::{TreeLane, WARPS};
use super::quadtree::Node;
use super::sampler::ProductSampler;
use crate::env::{clamp_unit, floats, lane_mask};
use core::arch::x86_64::*;

/// Children of a lane that takes no part in a step: no mass.
static EMPTY: [Node; 4] = [Node { child: 0, product: 0.0 }; 4];

/// Lanes per register.
const WIDTH: usize = 4;

const _: () = assert!(size_of::<Node>() == 8, "a row of four children is read as 32 bytes");

/// Groups of four lanes stepped together, level by level, so that one group's loads and
/// divisions overlap the others' arithmetic: a batch of `sample_many`.
const GROUPS: usize = WARPS / WIDTH;

impl ProductSampler<'_, '_> {
    /// Descends `lanes` as [`descend_tree_scalar`](Self::descend_tree_scalar) does, bit for bit,
    /// four lanes to a register; false (and nothing done) where the CPU lacks AVX2.
    pub(super) fn descend_tree_avx2(&self, lanes: &mut [TreeLane]) -> bool {
        if !crate::cpu::has_avx2() {
            return false;
        }
        for chunk in lanes.chunks_mut(WIDTH * GROUPS) {
            // SAFETY: AVX2 is available (checked above).
            unsafe { self.descend_groups(chunk) };
        }
        true
    }

    /// Up to [`GROUPS`] groups of four lanes down to their leaves, a level per round.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[target_feature(enable = "avx2")]
    unsafe fn descend_groups(&self, lanes: &mut [TreeLane]) {
        let mut xi = [[_mm256_setzero_pd(); 2]; GROUPS];
        for (x, four) in xi.iter_mut().zip(lanes.chunks(WIDTH)) {
            *x = load_xi(four);
        }
        loop {
            let mut busy = false;
            for (x, four) in xi.iter_mut().zip(lanes.chunks_mut(WIDTH)) {
                // A lane at a leaf leaves the tree, as in the scalar round.
                let mut active = 0;
                for (k, lane) in four.iter_mut().enumerate().filter(|(_, l)| l.in_tree) {
                    if lane.node.is_leaf() {
                        lane.in_tree = false;
                    } else {
                        active |= 1 << k;
                    }
                }
                if active != 0 {
                    busy = true;
                    self.step(four, active, x);
                }
            }
            if !busy {
                break;
            }
        }
        for (x, four) in xi.iter().zip(lanes.chunks_mut(WIDTH)) {
            store_xi(x, four);
        }
    }

    /// One level of the `active` lanes of `four`, whose ξ is `xi`: each picks a child by the
    /// children's masses (the column by ξ.x, the row within it by ξ.y) and moves to it, or
    /// dies where its children have no mass.
    #[target_feature(enable = "avx2")]
    fn step(&self, four: &mut [TreeLane], active: i32, xi: &mut [__m256d; 2]) {
        let rows: [&[Node; 4]; WIDTH] = core::array::from_fn(|k| match four.get(k) {
            Some(lane) if active & (1 << k) != 0 => {
                let first = lane.node.child as usize;
                self.nodes[first..first + 4].try_into().expect("four children")
            }
            _ => &EMPTY,
        });
        let m = masses(rows);
        let column = pick2([_mm256_add_pd(m[0], m[2]), _mm256_add_pd(m[1], m[3])], xi[0]);
        // The chosen column's two masses.
        let row_masses = [_mm256_blendv_pd(m[0], m[1], column.side), _mm256_blendv_pd(m[2], m[3], column.side)];
        let row = pick2(row_masses, xi[1]);
        // rescale: r = 1/(wx·wy), ξ = (ox·wy·r, oy·wx·r) clamped to [0, 1).
        let r = _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_mul_pd(column.weight, row.weight));
        let nx = clamp_unit(_mm256_mul_pd(_mm256_mul_pd(column.offset, row.weight), r));
        let ny = clamp_unit(_mm256_mul_pd(_mm256_mul_pd(row.offset, column.weight), r));
        let ok = column.ok & row.ok & active;
        let keep = lane_mask(ok);
        xi[0] = _mm256_blendv_pd(xi[0], nx, keep);
        xi[1] = _mm256_blendv_pd(xi[1], ny, keep);
        let (dx, dy) = (_mm256_movemask_pd(column.side), _mm256_movemask_pd(row.side));
        for (k, lane) in four.iter_mut().enumerate().filter(|(k, _)| active & (1 << k) != 0) {
            if ok & (1 << k) == 0 {
                (lane.in_tree, lane.alive) = (false, false);
                continue;
            }
            let c = ((dx >> k) & 1) as usize + 2 * ((dy >> k) & 1) as usize;
            let first = lane.node.child as usize;
            (lane.node, lane.index, lane.cell) = (self.nodes[first + c], first + c, lane.cell.child(c));
            lane.path *= self.branches[first + c];
        }
    }
}

/// The side a [`pick2`] chose per lane, with what the rescaling needs.
struct Picked {
    /// All ones in lanes that chose side 1.
    side: __m256d,
    /// t less the chosen side's prefix.
    offset: __m256d,
    /// The chosen side's weight.
    weight: __m256d,
    /// Lane bits that chose a side (a positive total, and a side with mass).
    ok: i32,
}

/// `pick_branchless::<2>` of four lanes: t = x·(w₀ + w₁), side 1 where t reached w₀ — unless
/// that side has no mass, where the last side with mass is taken instead.
#[inline]
#[target_feature(enable = "avx2")]
fn pick2(w: [__m256d; 2], x: __m256d) -> Picked {
    let zero = _mm256_setzero_pd();
    let p1 = _mm256_add_pd(zero, w[0]);
    let total = _mm256_add_pd(p1, w[1]);
    let t = _mm256_mul_pd(x, total);
    let reached = _mm256_cmp_pd::<_CMP_GE_OQ>(t, p1);
    let (has0, has1) = (_mm256_cmp_pd::<_CMP_GT_OQ>(w[0], zero), _mm256_cmp_pd::<_CMP_GT_OQ>(w[1], zero));
    // The side t fell in, where it has mass; else the last side that has.
    let fell_ok = _mm256_blendv_pd(has0, has1, reached);
    let side = _mm256_blendv_pd(has1, reached, fell_ok);
    let any = _mm256_or_pd(fell_ok, _mm256_or_pd(has0, has1));
    let positive = _mm256_cmp_pd::<_CMP_GT_OQ>(total, zero);
    Picked {
        side,
        offset: _mm256_sub_pd(t, _mm256_blendv_pd(zero, p1, side)),
        weight: _mm256_blendv_pd(w[0], w[1], side),
        ok: _mm256_movemask_pd(_mm256_and_pd(positive, any)),
    }
}

/// Four lanes' rows of four children, child by child: `out[j]` holds child j's mass of
/// lanes 0–3.
#[inline]
#[target_feature(enable = "avx2")]
fn masses(rows: [&[Node; 4]; WIDTH]) -> [__m256d; 4] {
    // SAFETY: `Node` is `repr(C)`, two 32-bit words: a row of four is 32 bytes.
    let load = |r: &[Node; 4]| unsafe { _mm256_loadu_si256(r.as_ptr().cast()) };
    let (a, b, c, d) = (load(rows[0]), load(rows[1]), load(rows[2]), load(rows[3]));
    // Words of a row: child₀, mass₀, child₁, mass₁ | child₂, mass₂, child₃, mass₃; the masses
    // of children 0 and 2, then of 1 and 3, of the four rows.
    let (ab_lo, cd_lo) = (_mm256_unpacklo_epi32(a, b), _mm256_unpacklo_epi32(c, d));
    let (ab_hi, cd_hi) = (_mm256_unpackhi_epi32(a, b), _mm256_unpackhi_epi32(c, d));
    let (mass02, mass13) = (_mm256_unpackhi_epi64(ab_lo, cd_lo), _mm256_unpackhi_epi64(ab_hi, cd_hi));
    let f64s = |v: __m128i| _mm256_cvtps_pd(_mm_castsi128_ps(v));
    let (low, high) = (_mm256_castsi256_si128, _mm256_extracti128_si256::<1>);
    [f64s(low(mass02)), f64s(low(mass13)), f64s(high(mass02)), f64s(high(mass13))]
}

/// The ξ of up to four lanes, x and y each in a register (missing lanes 0).
#[inline]
#[target_feature(enable = "avx2")]
fn load_xi(four: &[TreeLane]) -> [__m256d; 2] {
    let get = |k: usize| four.get(k).map_or(glam::DVec2::ZERO, |l| l.xi);
    let (a, b, c, d) = (get(0), get(1), get(2), get(3));
    [_mm256_setr_pd(a.x, b.x, c.x, d.x), _mm256_setr_pd(a.y, b.y, c.y, d.y)]
}

/// Writes `xi` back into the lanes of `four`.
#[inline]
#[target_feature(enable = "avx2")]
fn store_xi(xi: &[__m256d; 2], four: &mut [TreeLane]) {
    let (xs, ys) = (floats(xi[0]), floats(xi[1]));
    for (k, lane) in four.iter_mut().enumerate() {
        lane.xi = glam::DVec2::new(xs[k], ys[k]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::{Lambert, RoughConductor};
    use crate::cell::Cell;
    use crate::env::{EnvHierarchy, build_pyramid, pyramid_len};
    use crate::frame::Frame;
    use crate::sampler::{ProductArena, ProductParams};
    use crate::warp::ONE_MINUS_EPSILON;
    use glam::{DVec2, Vec3};
    use std::boxed::Box;
    use std::vec;
    use std::vec::Vec;

    /// A smooth map with a 1e7× texel, holes and a denormal-sized texel.
    fn map(level: u32) -> Vec<[f32; 3]> {
        let n = 1usize << (2 * level);
        let mut rgb: Vec<[f32; 3]> = (0..n).map(|i| [(i * 7 % 13) as f32 + 0.5, (i % 3) as f32, 1.0]).collect();
        rgb.iter_mut().enumerate().filter(|(i, _)| (i / 5) % 7 == 0).for_each(|(_, t)| *t = [0.0; 3]);
        rgb[n / 3] = [1e7; 3];
        rgb[n / 2] = [1e-38; 3];
        rgb
    }

    #[test]
    fn four_lanes_in_a_register_descend_the_tree_as_the_scalar_lanes() {
        if !crate::cpu::has_avx2() {
            std::println!("no AVX2 here: the scalar descent is the only one");
            return;
        }
        let level = 7;
        let rgb = map(level);
        let mut p = vec![0.0f32; pyramid_len(level)];
        build_pyramid(level, &rgb, &mut p).unwrap();
        let env = EnvHierarchy::new(level, &p, &rgb).unwrap();
        let mut arena: Box<ProductArena> = Box::default();
        let mut u = vec![DVec2::ZERO; 1031];
        crate::points::sobol02(3, 0, &mut u);
        u[1] = DVec2::new(ONE_MINUS_EPSILON, ONE_MINUS_EPSILON);
        u[2] = DVec2::new(0.0, ONE_MINUS_EPSILON);
        u[3] = DVec2::new(ONE_MINUS_EPSILON, 0.0);
        let (glossy, diffuse) = (RoughConductor::new(0.05, Vec3::ONE), Lambert::new(Vec3::splat(0.5)));
        let views = [Vec3::new(0.3, 0.2, 0.93), Vec3::new(0.99, 0.0, 0.05), Vec3::Z];
        let mut descents = 0;
        for (v, wo) in views.iter().enumerate() {
            for params in [ProductParams::default(), ProductParams::for_mis(64)] {
                let frame = Frame::from_normal(Vec3::new(0.1, 0.2, 1.0).normalize());
                for glossy_lobe in [true, false] {
                    let brdf: &dyn crate::brdf::Brdf = if glossy_lobe { &glossy } else { &diffuse };
                    let s = arena.build(&env, brdf, &frame, wo.normalize(), &params, v as u64).unwrap();
                    let Some(&root) = s.nodes.first() else { continue };
                    // Groups of every size, some lanes out of the tree from the start.
                    for size in [16, 13, 4, 3, 1] {
                        for chunk in u.chunks(size) {
                            let start: Vec<TreeLane> = chunk
                                .iter()
                                .enumerate()
                                .map(|(k, &xi)| {
                                    let out = k % 5 == 4;
                                    let lane = TreeLane {
                                        node: root,
                                        path: 1.0,
                                        xi,
                                        in_tree: !out,
                                        alive: true,
                                        ..Default::default()
                                    };
                                    TreeLane { cell: Cell::ROOT, defensive: out, ..lane }
                                })
                                .collect();
                            let (mut simd, mut scalar) = (start.clone(), start);
                            assert!(s.descend_tree_avx2(&mut simd));
                            s.descend_tree_scalar(&mut scalar);
                            for (a, b) in simd.iter().zip(&scalar) {
                                assert_eq!(
                                    (a.node, a.index, a.cell, a.in_tree, a.alive),
                                    (b.node, b.index, b.cell, b.in_tree, b.alive)
                                );
                                assert_eq!(a.path.to_bits(), b.path.to_bits());
                                assert_eq!((a.xi.x.to_bits(), a.xi.y.to_bits()), (b.xi.x.to_bits(), b.xi.y.to_bits()));
                            }
                            descents += chunk.len();
                        }
                    }
                }
            }
        }
        assert!(descents > 10_000, "the trees were built and descended");
    }
}
