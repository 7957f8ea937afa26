//! Traversal of the eight-wide nodes with a fixed stack: closest hit visits the children a ray
//! meets nearest first and skips those that start beyond the best hit so far; occlusion tests
//! leaf children as soon as their box is met and stops at the first blocker. `Bvh` runs either
//! in a function compiled for AVX2 where the CPU has it, a node's boxes then tested in one
//! register (`wide_avx2.rs`), else with the two SSE halves (`wide.rs`). As soon as a node's
//! boxes are tested, the cache lines of every child met are asked for (`prefetch.rs`).

use super::Bvh;
use super::leaf::Block;
use super::prefetch::prefetch_child;
use super::wide::{LEAF, NodeRay, RayLanes, WIDTH, WideNode};
use sampler_core::glam::Vec3;
use std::mem::MaybeUninit;

/// Stack entries: a node descends at most one binary level per wide level, the binary build
/// bounds its depth (median splits past depth 40), and each level leaves at most seven
/// entries behind.
const STACK: usize = 512;

impl Bvh {
    /// The nearest hit in the tree, as [`Bvh::closest_in`] for its leaves.
    #[inline(always)]
    pub(super) fn closest_in_tree(&self, o: Vec3, d: Vec3, t_min: f32, t_max: &mut f32, best: &mut Option<usize>) {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the CPU has AVX2.
            return unsafe { self.closest_in_tree_avx2(o, d, t_min, t_max, best) };
        }
        self.closest_along(&RayLanes::new(o, d), o, d, t_min, t_max, best);
    }

    /// [`Bvh::closest_in_tree`] compiled for AVX2, a node's boxes tested in one register.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn closest_in_tree_avx2(&self, o: Vec3, d: Vec3, t_min: f32, t_max: &mut f32, best: &mut Option<usize>) {
        self.closest_along(&super::wide_avx2::RayLanes8::new(o, d), o, d, t_min, t_max, best);
    }

    /// The nearest hit in the tree, its boxes tested by `ray` (the ray o + t·d).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn closest_along(
        &self,
        ray: &impl NodeRay,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: &mut f32,
        best: &mut Option<usize>,
    ) {
        closest(&self.nodes, &self.blocks, ray, t_max, |first, count, t_max| {
            self.closest_in(first, count, o, d, t_min, t_max, best)
        });
    }

    /// Whether a primitive of the tree blocks the ray, as [`Bvh::blocked_in`] for its leaves.
    #[inline(always)]
    pub(super) fn blocked_in_tree(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only where the CPU has AVX2.
            return unsafe { self.blocked_in_tree_avx2(o, d, t_min, t_max) };
        }
        self.blocked_along(&RayLanes::new(o, d), o, d, t_min, t_max)
    }

    /// [`Bvh::blocked_in_tree`] compiled for AVX2, a node's boxes tested in one register.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn blocked_in_tree_avx2(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        self.blocked_along(&super::wide_avx2::RayLanes8::new(o, d), o, d, t_min, t_max)
    }

    /// Whether a primitive of the tree blocks the ray o + t·d, its boxes tested by `ray`.
    #[inline(always)]
    fn blocked_along(&self, ray: &impl NodeRay, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        any(&self.nodes, &self.blocks, ray, t_max, |first, count| self.blocked_in(first, count, o, d, t_min, t_max))
    }
}

/// Visits the primitives of every leaf whose box `ray` meets within `t_max`, nearest box
/// first; `visit(first, count, t_max)` tests a leaf's `blocks` and may shrink `t_max`.
#[inline(always)]
pub(in crate::trace::bvh) fn closest(
    nodes: &[WideNode],
    blocks: &[Block],
    ray: &impl NodeRay,
    t_max: &mut f32,
    mut visit: impl FnMut(u32, u32, &mut f32),
) {
    if nodes.is_empty() {
        return;
    }
    // Left uninitialised: zeroing the stack per ray is a noticeable share of simple scenes.
    let mut stack = [const { MaybeUninit::<(u32, u32, f32)>::uninit() }; STACK];
    let mut sp = 0;
    let mut current = (0, 0);
    loop {
        let (child, count) = current;
        if child & LEAF != 0 {
            visit(child & !LEAF, count, t_max);
        } else {
            let node = &nodes[child as usize];
            let (mut mask, near) = ray.hit(node, *t_max);
            // Sorted farthest first: all but the nearest are pushed in that order, and the
            // nearest is visited next without a trip through the stack.
            let mut order = [(0u32, 0u32, 0.0f32); WIDTH];
            let mut n = 0;
            while mask != 0 {
                let k = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let item = (node.child[k], node.count[k], near[k]);
                prefetch_child(nodes, blocks, item.0, item.1);
                let mut j = n;
                while j > 0 && order[j - 1].2 < item.2 {
                    order[j] = order[j - 1];
                    j -= 1;
                }
                order[j] = item;
                n += 1;
            }
            if n > 0 {
                debug_assert!(sp + n - 1 <= STACK);
                for item in &order[..n - 1] {
                    stack[sp].write(*item);
                    sp += 1;
                }
                current = (order[n - 1].0, order[n - 1].1);
                continue;
            }
        }
        // The nearest entry left that starts within the best hit so far.
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were all written.
            let (child, count, entry) = unsafe { stack[sp].assume_init() };
            if entry <= *t_max {
                current = (child, count);
                break;
            }
        }
    }
}

/// True when `test(first, count)` finds a blocker in the `blocks` of a leaf whose box `ray`
/// meets within `t_max`.
#[inline(always)]
pub(super) fn any(
    nodes: &[WideNode],
    blocks: &[Block],
    ray: &impl NodeRay,
    t_max: f32,
    mut test: impl FnMut(u32, u32) -> bool,
) -> bool {
    if nodes.is_empty() {
        return false;
    }
    let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
    let mut sp = 0;
    let mut index = 0;
    loop {
        let node = &nodes[index as usize];
        let (mut mask, _) = ray.hit(node, t_max);
        // Every child met asked for before the first leaf's test waits on its own lines.
        let mut ahead = mask;
        while ahead != 0 {
            let k = ahead.trailing_zeros() as usize;
            ahead &= ahead - 1;
            prefetch_child(nodes, blocks, node.child[k], node.count[k]);
        }
        // The first inner child met is visited next without a trip through the stack.
        let mut next = None;
        while mask != 0 {
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let child = node.child[k];
            if child & LEAF != 0 {
                if test(child & !LEAF, node.count[k]) {
                    return true;
                }
            } else if next.is_none() {
                next = Some(child);
            } else {
                debug_assert!(sp < STACK);
                stack[sp].write(child);
                sp += 1;
            }
        }
        index = match next {
            Some(child) => child,
            None if sp > 0 => {
                sp -= 1;
                // SAFETY: entries below `sp` were all written.
                unsafe { stack[sp].assume_init() }
            }
            None => return false,
        };
    }
}
