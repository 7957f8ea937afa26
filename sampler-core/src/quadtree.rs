//! The per-shading-point quadtree: BRDF samples in the equal-area square, subdivided until each
//! leaf holds one sample, with the product B̃·L computed in the same (single) traversal.
//!
//! * Points are quantised to 24 bits per axis and sorted by Morton code, so every node is a
//!   contiguous run of samples and its four children split that run by the next two bits.
//! * A leaf with samples takes the mean of their B·cos (luminance) — one sample unless the depth
//!   cap or the node capacity stopped the split (e.g. coincident samples).
//! * An empty leaf takes the mean of its non-empty siblings: a piecewise-constant guess from its
//!   neighbourhood instead of 0, so the product does not starve regions between samples.
//!   (Regions where even that is 0 are covered by the sampler's defensive mixture.)
//! * Each node stores B̃'s mean and the product's mean, with the environment taken relative to its
//!   own mean; the combine rule is the plain average ([`ProductKind::Quadtree`]) or the Haar
//!   wavelet product ([`ProductKind::Wavelet`], see `wavelet.rs`).

use crate::env::EnvHierarchy;
use crate::warp::child_offset;
use crate::wavelet::haar_product_mean;
use heapless::Vec;

/// Bits per axis of the quantised square coordinates; also the largest possible depth.
pub const COORD_BITS: u32 = 24;

/// One node of the product tree.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Node {
    /// Index of the first of four consecutive children; 0 marks a leaf (the root is never a
    /// child).
    pub child: u32,
    /// Mean of the product B̃ · (L / mean L) over the node.
    pub product: f32,
    /// Mean of B̃ over the node (the piecewise-constant value at a leaf).
    pub btilde: f32,
}

impl Node {
    #[inline]
    #[must_use]
    pub fn is_leaf(&self) -> bool {
        self.child == 0
    }
}

/// How internal nodes combine their children.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ProductKind {
    /// Average of the four children's products (Clarberg & Akenine-Möller 2008).
    #[default]
    Quadtree,
    /// Product of the nonstandard Haar expansions of B̃ and L (wavelet importance sampling,
    /// Clarberg et al. 2005). Equal to `Quadtree` in exact arithmetic: a cross-check.
    Wavelet,
}

/// 24-bit fixed-point coordinates of a point of the square.
#[inline]
#[must_use]
pub fn quantize(u: f32) -> u32 {
    let max = (1u32 << COORD_BITS) - 1;
    ((u * (1u32 << COORD_BITS) as f32) as u32).min(max)
}

/// Interleaves two 24-bit coordinates (x in the even bits).
#[inline]
#[must_use]
pub fn morton(x: u32, y: u32) -> u64 {
    spread(x) | (spread(y) << 1)
}

#[inline]
fn spread(v: u32) -> u64 {
    let mut x = v as u64 & 0xFFFF_FFFF;
    x = (x | (x << 16)) & 0x0000_FFFF_0000_FFFF;
    x = (x | (x << 8)) & 0x00FF_00FF_00FF_00FF;
    x = (x | (x << 4)) & 0x0F0F_0F0F_0F0F_0F0F;
    x = (x | (x << 2)) & 0x3333_3333_3333_3333;
    (x | (x << 1)) & 0x5555_5555_5555_5555
}

/// Sort key: Morton code in the high 48 bits, sample index in the low 16.
#[inline]
#[must_use]
pub fn sort_key(u: f32, v: f32, index: usize) -> u64 {
    (morton(quantize(u), quantize(v)) << 16) | index as u64
}

/// The child digit (dx + 2·dy) of a key at `depth` (the split from depth to depth + 1).
#[inline]
fn digit(key: u64, depth: u32) -> usize {
    ((key >> (16 + 2 * (COORD_BITS - 1 - depth))) & 3) as usize
}

/// Builds the tree over `keys` (sorted) whose sample values are `values[key & 0xFFFF]`.
pub(crate) struct TreeBuilder<'b, 'e, const NODES: usize> {
    pub keys: &'b [u64],
    pub values: &'b [f32],
    pub env: &'b EnvHierarchy<'e>,
    pub nodes: &'b mut Vec<Node, NODES>,
    pub max_depth: u32,
    pub kind: ProductKind,
}

impl<const NODES: usize> TreeBuilder<'_, '_, NODES> {
    /// Builds the whole tree; the root is node 0. Returns false when there are no samples.
    pub fn build(&mut self) -> bool {
        self.nodes.clear();
        if self.keys.is_empty() {
            return false;
        }
        let _ = self.nodes.push(Node::default());
        let root_env = self.env.cell_relative(0, 0, 0);
        self.node(0, 0, 0, 0, root_env, 0, self.keys.len());
        true
    }

    /// Fills node `index` covering cell `(x, y)` at `depth` and samples `lo..hi` (non-empty);
    /// returns its (B̃ mean, product mean). Fields are written in place: building a `Node` on
    /// the stack and copying it back costs a failed store-forward per node.
    /// `env` is the environment's relative mean over the cell (fetched by the parent).
    #[allow(clippy::too_many_arguments)]
    fn node(
        &mut self,
        index: usize,
        depth: u32,
        x: u32,
        y: u32,
        env: f32,
        lo: usize,
        hi: usize,
    ) -> (f32, f32) {
        let room = self.nodes.len() + 4 <= NODES;
        if hi - lo == 1 || depth >= self.max_depth || !room {
            let sum: f32 = self.keys[lo..hi]
                .iter()
                .map(|k| self.values[(k & 0xFFFF) as usize])
                .sum();
            let b = sum / (hi - lo) as f32;
            let product = b * env;
            set(&mut self.nodes[index], 0, b, product);
            return (b, product);
        }
        let first = self.nodes.len();
        for _ in 0..4 {
            let _ = self.nodes.push(Node::default());
        }
        // Split lo..hi by the next two Morton bits: the run is sorted, so counting each digit
        // gives the child boundaries (cheaper than three binary searches for the short runs
        // that make up most of the tree).
        // Register accumulators (an array of counters would chain through memory).
        let (mut below1, mut below2, mut below3) = (0usize, 0usize, 0usize);
        for &k in &self.keys[lo..hi] {
            let d = digit(k, depth);
            below1 += usize::from(d < 1);
            below2 += usize::from(d < 2);
            below3 += usize::from(d < 3);
        }
        let bounds = [lo, lo + below1, lo + below2, lo + below3, hi];
        // The environment over the four children: one 2×2 block of the pyramid (or the texel
        // containing them, below the finest level).
        let l = if depth < self.env.finest_level() {
            self.env.children_relative(depth, x, y)
        } else {
            [env; 4]
        };
        let mut b = [0.0f32; 4];
        let mut p = [0.0f32; 4];
        let (mut sum_b, mut filled) = (0.0f32, 0u32);
        for c in 0..4 {
            if bounds[c + 1] > bounds[c] {
                let (dx, dy) = child_offset(c);
                let (cx, cy) = (2 * x + dx, 2 * y + dy);
                (b[c], p[c]) =
                    self.node(first + c, depth + 1, cx, cy, l[c], bounds[c], bounds[c + 1]);
                sum_b += b[c];
                filled += 1;
            }
        }
        let fill = sum_b / filled as f32;
        for c in 0..4 {
            if bounds[c + 1] == bounds[c] {
                b[c] = fill;
                p[c] = fill * l[c];
                set(&mut self.nodes[first + c], 0, fill, p[c]);
            }
        }
        let product = match self.kind {
            ProductKind::Quadtree => 0.25 * ((p[0] + p[1]) + (p[2] + p[3])),
            ProductKind::Wavelet => haar_product_mean(b, l, p),
        };
        set(&mut self.nodes[index], first as u32, fill, product);
        (fill, product)
    }
}

#[inline(always)]
fn set(n: &mut Node, child: u32, btilde: f32, product: f32) {
    n.child = child;
    n.btilde = btilde;
    n.product = product;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton_interleaves_x_in_even_bits() {
        assert_eq!(morton(1, 0), 1);
        assert_eq!(morton(0, 1), 2);
        assert_eq!(morton(0b11, 0b01), 0b0111);
        let top = 1u32 << 23;
        let k = sort_key(0.75, 0.25, 5);
        assert_eq!(digit(k, 0), 1); // right, bottom
        assert_eq!(digit(k, 1), 3); // 0.75 = 0.11b, 0.25 = 0.01b
        assert_eq!(morton(top, top) >> 46, 3);
    }

    #[test]
    fn quantize_clamps() {
        assert_eq!(quantize(1.0), (1 << 24) - 1);
        assert_eq!(quantize(-0.5), 0);
        assert_eq!(quantize(f32::NAN), 0);
        assert_eq!(quantize(0.5), 1 << 23);
    }
}
