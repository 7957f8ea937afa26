//! Traversal of the eight-wide nodes with a fixed stack: closest hit visits the children a ray
//! meets nearest first and skips those that start beyond the best hit so far; occlusion tests
//! leaf children as soon as their box is met and stops at the first blocker.

use super::wide::{LEAF, NodeRay, WIDTH, WideNode};
use std::mem::MaybeUninit;

/// Stack entries: a node descends at most one binary level per wide level, the binary build
/// bounds its depth (median splits past depth 40), and each level leaves at most seven
/// entries behind.
const STACK: usize = 512;

/// Visits the primitives of every leaf whose box `ray` meets within `t_max`, nearest box
/// first; `visit(first, count, t_max)` tests a leaf's primitives and may shrink `t_max`.
#[inline(always)]
pub(super) fn closest(
    nodes: &[WideNode],
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

/// True when `test(first, count)` finds a blocker in a leaf whose box `ray` meets within
/// `t_max`.
#[inline(always)]
pub(super) fn any(nodes: &[WideNode], ray: &impl NodeRay, t_max: f32, mut test: impl FnMut(u32, u32) -> bool) -> bool {
    if nodes.is_empty() {
        return false;
    }
    let mut stack = [const { MaybeUninit::<u32>::uninit() }; STACK];
    let mut sp = 0;
    let mut index = 0;
    loop {
        let node = &nodes[index as usize];
        let (mut mask, _) = ray.hit(node, t_max);
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
