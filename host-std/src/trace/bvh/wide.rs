//! The eight-wide hierarchy that rays traverse: each node holds its eight children's boxes as
//! structure of arrays (one eight-lane row per box plane), so one ray tests all eight at once:
//! in one AVX2 register where the CPU has it (`wide_avx2.rs`), else in two halves of four SIMD
//! lanes ([`super::lanes::F4`], here), with the same bits. It is collapsed from the binary SAH
//! tree (`build.rs`): a node takes its binary children and keeps opening the largest inner one
//! until it has eight, so the boxes are the binary tree's boxes and only the levels between
//! them go. Eight children make the tree half as deep as four do, so a ray pops, loads and
//! branches over fewer nodes.

use super::lanes::F4;
use super::leaf::Block;
use super::{Aabb, Node, Primitive};
use sampler_core::glam::Vec3;

/// A child that is a leaf: the low bits are its first block of primitives.
pub(super) const LEAF: u32 = 1 << 31;
/// A lane with no child (its box is empty, so no ray enters it).
const EMPTY: u32 = u32::MAX;

/// Children per node.
pub(super) const WIDTH: usize = 8;

/// Eight children's boxes and links: four cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct WideNode {
    /// Rows min x, max x, min y, max y, min z, max z; lane k is child k.
    pub(super) planes: [[f32; WIDTH]; 6],
    /// An inner child's node index, or `LEAF | first block`, or `EMPTY`.
    pub(super) child: [u32; WIDTH],
    /// A leaf child's number of blocks (0 for the others).
    pub(super) count: [u32; WIDTH],
}

/// A ray prepared for a wide node's box tests.
pub(super) trait NodeRay {
    /// Which children's boxes of `node` the ray meets within [0, t_max] (bit k for child k)
    /// and an entry distance of each, no larger than the ray's (a packet's: no larger than any
    /// of its rays'). NaN slab distances (a ray in a box's plane) leave the
    /// interval as it is, so such boxes count as met.
    fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]);
}

/// A ray prepared for box tests in two halves of four lanes: origin and reciprocal direction
/// in all lanes, and per axis which of a box's two planes it meets first.
pub(super) struct RayLanes {
    o: [F4; 3],
    inv: [F4; 3],
    /// Row offset (0 or 1) of the near plane of each axis within its pair.
    near: [usize; 3],
}

impl RayLanes {
    pub(super) fn new(o: Vec3, d: Vec3) -> RayLanes {
        let inv = d.recip();
        RayLanes {
            o: [o.x, o.y, o.z].map(F4::splat),
            inv: [inv.x, inv.y, inv.z].map(F4::splat),
            near: near_planes(inv),
        }
    }
}

/// Per axis, the row offset (0 or 1) of the plane of a box that a ray of reciprocal direction
/// `inv` meets first: the sign bit, not a comparison, so that a direction of −0 (reciprocal
/// −∞) meets the max plane first, which keeps empty lanes (min +∞, max −∞) empty.
#[inline(always)]
pub(super) fn near_planes(inv: Vec3) -> [usize; 3] {
    [inv.x, inv.y, inv.z].map(|v| usize::from(v.is_sign_negative()))
}

impl NodeRay for RayLanes {
    #[inline(always)]
    fn hit(&self, node: &WideNode, t_max: f32) -> (u32, [f32; WIDTH]) {
        let (low, near_low) = node.hit_half(self, t_max, 0);
        let (high, near_high) = node.hit_half(self, t_max, 4);
        let mut near = [0.0; WIDTH];
        near[..4].copy_from_slice(&near_low);
        near[4..].copy_from_slice(&near_high);
        (low | high << 4, near)
    }
}

impl WideNode {
    /// [`NodeRay::hit`] for the four children from `first`.
    #[inline(always)]
    fn hit_half(&self, r: &RayLanes, t_max: f32, first: usize) -> (u32, [f32; 4]) {
        let row = |plane: usize| -> &[f32; 4] { self.planes[plane][first..first + 4].try_into().unwrap() };
        let mut near = F4::splat(0.0);
        let mut far = F4::splat(t_max);
        for axis in 0..3 {
            let lo = F4::load(row(2 * axis + r.near[axis]));
            let hi = F4::load(row(2 * axis + 1 - r.near[axis]));
            near = lo.sub(r.o[axis]).mul(r.inv[axis]).max_or(near);
            far = hi.sub(r.o[axis]).mul(r.inv[axis]).min_or(far);
        }
        (near.le_mask(far), near.to_array())
    }
}

/// The blocks (first, count) of the one leaf that is the whole tree, if it is: a ray then
/// tests them without the root's box test, whose answer the primitive tests decide anyway.
pub(super) fn lone_leaf(nodes: &[WideNode]) -> Option<(u32, u32)> {
    match nodes {
        [root] if root.child[0] & LEAF != 0 && root.child[1..].iter().all(|&c| c == EMPTY) => {
            Some((root.child[0] & !LEAF, root.count[0]))
        }
        _ => None,
    }
}

/// The eight-wide nodes over the binary tree `bin` of `prims` (root first, then each subtree
/// depth first), and the blocks of its leaves.
pub(super) fn collapse(bin: &[Node], prims: &[Primitive]) -> (Vec<WideNode>, Vec<Block>) {
    let mut tree = Tree { bin, prims, nodes: Vec::with_capacity(bin.len() / 4 + 1), blocks: Vec::new() };
    if !bin.is_empty() {
        tree.emit(0);
    }
    (tree.nodes, tree.blocks)
}

/// The collapse under way.
struct Tree<'a> {
    bin: &'a [Node],
    prims: &'a [Primitive],
    nodes: Vec<WideNode>,
    blocks: Vec<Block>,
}

impl Tree<'_> {
    /// Appends the node whose children are the binary node `index`'s (or the leaf `index`
    /// alone), opened up to eight, and their subtrees; returns its index.
    fn emit(&mut self, index: usize) -> u32 {
        let children = open(self.bin, index);
        let me = self.nodes.len();
        let empty = Aabb { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };
        let mut node = WideNode { planes: [[0.0; WIDTH]; 6], child: [EMPTY; WIDTH], count: [0; WIDTH] };
        self.nodes.push(node);
        for k in 0..WIDTH {
            let b = children.get(k).map_or(empty, |&c| self.bin[c].bounds);
            for axis in 0..3 {
                node.planes[2 * axis][k] = b.min[axis];
                node.planes[2 * axis + 1][k] = b.max[axis];
            }
            if let Some(&c) = children.get(k) {
                let n = self.bin[c];
                if n.count > 0 {
                    let first = self.blocks.len() as u32;
                    Block::pack(self.prims, n.offset, n.count, &mut self.blocks);
                    assert!(first < LEAF, "too many primitives for the node format");
                    (node.child[k], node.count[k]) = (LEAF | first, self.blocks.len() as u32 - first);
                } else {
                    node.child[k] = self.emit(c);
                }
            }
        }
        self.nodes[me] = node;
        me as u32
    }
}

/// The binary nodes that become one wide node's children: the binary node's two children,
/// the inner one of largest surface area replaced by its two until there are eight (or only
/// leaves), in depth-first order.
fn open(bin: &[Node], index: usize) -> Vec<usize> {
    let node = bin[index];
    if node.count > 0 {
        return vec![index];
    }
    let mut children = vec![index + 1, node.offset as usize];
    while children.len() < WIDTH {
        let widest = (0..children.len())
            .filter(|&k| bin[children[k]].count == 0)
            .max_by(|&a, &b| bin[children[a]].bounds.area().total_cmp(&bin[children[b]].bounds.area()));
        let Some(k) = widest else { break };
        let c = children[k];
        children.splice(k..=k, [c + 1, bin[c].offset as usize]);
    }
    children
}
