//! Hints to the memory system for the traversals: the cache lines of a node's or a leaf's
//! children asked for as soon as their boxes are met, so that in a tree larger than the core's
//! caches their misses overlap instead of each visit waiting on its own. A hint only: it never
//! faults, reads nothing and changes no result.

use super::leaf::Block;
use super::wide::{LEAF, WideNode};

/// Asks for the cache lines of a node's child (as `WideNode::child` and `count` hold it): an
/// inner node's, or a leaf's blocks.
#[inline(always)]
pub(super) fn prefetch_child(nodes: &[WideNode], blocks: &[Block], child: u32, count: u32) {
    if child & LEAF != 0 {
        prefetch_blocks(blocks, child & !LEAF, count);
    } else {
        prefetch_node(nodes, child);
    }
}

/// Asks for the cache lines of the blocks `first..first + count`.
#[inline(always)]
fn prefetch_blocks(blocks: &[Block], first: u32, count: u32) {
    if let Some(b) = blocks.get(first as usize..(first + count) as usize) {
        prefetch_lines(b.as_ptr().cast(), size_of_val(b));
    }
}

/// Asks for the cache lines of node `index`.
#[inline(always)]
fn prefetch_node(nodes: &[WideNode], index: u32) {
    if let Some(n) = nodes.get(index as usize) {
        prefetch_lines((n as *const WideNode).cast(), size_of::<WideNode>());
    }
}

/// Asks for every cache line that the `bytes` bytes from `p` touch.
#[inline(always)]
fn prefetch_lines(p: *const u8, bytes: usize) {
    let start = p as usize;
    let mut line = start & !63;
    while line < start + bytes {
        prefetch_line(p.wrapping_add(line.wrapping_sub(start)));
        line += 64;
    }
}

/// Asks for the cache line holding `p`.
#[inline(always)]
fn prefetch_line(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch reads no memory and cannot fault, whatever the address.
    unsafe {
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
