//! The per-shading-point quadtree: BRDF samples in the equal-area square, subdivided until each
//! leaf holds one sample, with the product B̃·L computed in the same (single) traversal.
//!
//! * Points are quantised to 24 bits per axis and sorted by Morton code, so every node is a
//!   contiguous run of samples and its four children split that run by the next two bits.
//! * A leaf with samples takes the mean of their B·cos (luminance) — one sample unless the depth
//!   cap or the node capacity stopped the split (e.g. coincident samples) — or, with
//!   [`Leaves::Probed`], B at its centre where that is larger.
//! * An empty leaf takes its non-empty siblings' mean shrunk by the sample counts (see
//!   `TreeBuilder::node`): a guess from its neighbourhood instead of 0, so the product does not
//!   starve the regions between samples of a smooth lobe, yet small where many samples chose
//!   a sibling (the chain above a needle lobe). Regions where B̃ is still 0 are covered by the
//!   sampler's defensive mixture.
//! * Optionally (`refine_share`, product-MIS's preset) leaves holding more than that share of
//!   the product's mass are split further, B probed at each new child's centre: the samples
//!   place leaves where B is large, the refinement where B̃·L is (a sun in a lobe's tail).
//! * Each node stores B̃'s mean and the product's mean, with the environment taken relative to its
//!   own mean, and beside it (in `branches`) the probability that the warp picks it among its
//!   siblings, computed where the siblings' products are (a descent multiplies them); the combine rule is the plain average ([`ProductKind::Quadtree`]) or the Haar
//!   wavelet product ([`ProductKind::Wavelet`], see `wavelet.rs`). What B̃ is in a leaf is
//!   [`Leaves`]; the combinations that exist are the variants of [`ProductKind`].

use super::arena::branch_probabilities;
use super::keys::digit;
pub use super::keys::{COORD_BITS, morton, quantize, sort_key, sort_keys};
pub use super::params::{Leaves, ProductKind};
use crate::bilinear::{self, Corners};
use crate::cell::Cell;
use crate::env::EnvHierarchy;
use crate::wavelet::haar_product_mean;
use glam::{Vec2, Vec4};
use heapless::Vec;

/// Prior count α of the add-α smoothing that gives empty leaves their B̃ (see
/// `TreeBuilder::node`): the best value on every non-needle case of the efficiency set
/// (tests/integration/efficiency.rs; docs/perf.md#per-sample-variance).
pub const FILL_PRIOR: f32 = 2.0;

/// Samples in a parent from which an empty child's B̃ also looks at B at its centre.
pub const EVAL_EMPTY_FROM: usize = 4;

/// More than the rounding error that subnormal products can add to a subtree's mass over the
/// depth cap's levels (each ≤ 2⁻¹⁴⁹): `refine` passes by a subtree only when its mass is this
/// far below the limit.
const SUBNORMAL_SLACK: f32 = 1e-36;

/// Samples in a node from which its split searches for its children's bounds instead of counting.
const SEARCH_FROM: usize = 32;
const _: () = assert!(SEARCH_FROM <= 255, "split packs its counts in bytes");

/// One node of the product tree. In C's layout: the AVX2 descent (`lanes_avx2.rs`) reads a
/// node's four children as one row of eight 32-bit words.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Node {
    /// Index of the first of four consecutive children; 0 marks a leaf (the root is never a
    /// child).
    pub child: u32,
    /// Mean of the product B̃ · (L / mean L) over the node. (B̃ itself is not kept: the
    /// density is the product of branch probabilities, see `ProductSampler::pdf_square`.)
    pub product: f32,
}

impl Node {
    /// True for a leaf (no children).
    #[inline]
    #[must_use]
    pub fn is_leaf(&self) -> bool {
        self.child == 0
    }
}

/// Builds the tree over `keys` (sorted) whose sample values are `values[key & 0xFFFF]`;
/// `eval(uv)` gives B·cos (luminance) at a point of the square and `eval4(u, v)` at four, their
/// coordinates in lanes (each lane bit for bit `eval` of its point), for the cells whose B is
/// probed.
pub(crate) struct TreeBuilder<'b, 'e, F, G, const NODES: usize, const CORNERS: usize>
where
    F: FnMut(Vec2) -> f32,
    G: FnMut(Vec4, Vec4) -> Vec4,
{
    pub keys: &'b [u64],
    pub values: &'b [f32],
    pub env: &'b EnvHierarchy<'e>,
    pub nodes: &'b mut Vec<Node, NODES>,
    /// Per node, its branch probability among its siblings (`branch_probabilities`; at least
    /// NODES long).
    pub branches: &'b mut [f64],
    pub max_depth: u32,
    /// Internal nodes by the Haar wavelet product instead of the average.
    pub wavelet: bool,
    pub eval: F,
    pub eval4: G,
    /// Also probe B at the centre of every leaf that holds samples (see `node`).
    pub probe_leaves: bool,
    /// Split leaves holding more than this share of the product's mass, B probed at each new
    /// child's centre (see `refine`); 0 turns it off.
    pub refine_share: f32,
    /// B̃ bilinear in each leaf between B at its corners (`corners[i]` for node i, every node),
    /// instead of constant: the samples then only decide where to split.
    pub bilinear: bool,
    pub corners: &'b mut Vec<Corners, CORNERS>,
}

impl<F, G, const NODES: usize, const CORNERS: usize> TreeBuilder<'_, '_, F, G, NODES, CORNERS>
where
    F: FnMut(Vec2) -> f32,
    G: FnMut(Vec4, Vec4) -> Vec4,
{
    /// Builds the whole tree; the root is node 0. Returns false when there are no samples.
    pub fn build(&mut self) -> bool {
        self.nodes.clear();
        self.corners.clear();
        if self.keys.is_empty() {
            return false;
        }
        let _ = self.nodes.push(Node::default());
        if self.bilinear {
            let w = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE].map(|p| self.eval_at(p));
            let _ = self.corners.push(w);
        }
        let root_env = self.env.cell_relative(Cell::ROOT);
        let (_, total) = self.node(0, Cell::ROOT, 0, root_env, 0, self.keys.len());
        if self.refine_share > 0.0 && total > 0.0 && total.is_finite() {
            self.refine(0, Cell::ROOT, root_env, self.refine_share * total);
        }
        true
    }

    /// Splits every leaf whose mass (mean product × area) exceeds `limit`, children's B̃
    /// probed at their centres, recursively; returns the node's (possibly new) product mean.
    ///
    /// Why: the BRDF samples place leaves where B is large, but the product's mass also sits
    /// where L is large — a sun in the lobe's tail lands in a coarse tail leaf whose B̃ is one
    /// sample's value from elsewhere in the leaf, off by orders of magnitude at the sun, and
    /// every product sample of the sun then carries that ratio B/B̃. Splitting the heavy leaves
    /// brings B̃ close to B where the light is.
    fn refine(&mut self, index: usize, cell: Cell, env: f32, limit: f32) -> f32 {
        let (node, depth) = (self.nodes[index], cell.level);
        // A node's mass: its mean over the cell times the cell's area 4^-depth.
        let mass = node.product * f32::from_bits((127 - 2 * depth.min(63)) << 23);
        // A subtree no heavier than the limit holds no leaf above it, and passing it by leaves
        // its products as they are: a node's mass is the sum of its children's (non-negative
        // terms, whose float sum is never below any one of them, scaled by powers of two),
        // up to the rounding of subnormal products, which `SUBNORMAL_SLACK` covers. NaN and ∞
        // never pass, and reach their leaves.
        if mass + SUBNORMAL_SLACK <= limit {
            return node.product;
        }
        // Not below the map's finest level: there L is one texel's, and where B varies faster
        // than that the samples have split already.
        let deepest = self.max_depth.min(self.env.finest_level());
        if node.is_leaf() && (mass <= limit || depth >= deepest || self.nodes.len() + 4 > NODES) {
            return node.product;
        }
        let l = if depth < self.env.finest_level() { self.env.children_relative(cell) } else { [env; 4] };
        let first = if node.is_leaf() {
            let first = self.push_children(index, cell);
            let probes = if self.bilinear { [0.0; 4] } else { self.probe4(&[0, 1, 2, 3].map(|c| cell.child(c))) };
            for (c, probe) in probes.into_iter().enumerate() {
                let b = if self.bilinear {
                    bilinear::mean(&self.corners[first + c])
                } else {
                    // NaN (unknown) keeps the parent's B̃.
                    if probe.is_finite() { probe } else { node.product / env.max(f32::MIN_POSITIVE) }
                };
                set(&mut self.nodes[first + c], 0, b * l[c]);
            }
            first
        } else {
            node.child as usize
        };
        let mut p = [0.0f32; 4];
        for (c, pc) in p.iter_mut().enumerate() {
            *pc = self.refine(first + c, cell.child(c), l[c], limit);
        }
        let product = 0.25 * ((p[0] + p[1]) + (p[2] + p[3]));
        set(&mut self.nodes[index], first as u32, product);
        self.branches[first..first + 4].copy_from_slice(&branch_probabilities(p));
        product
    }

    /// Fills node `index` covering `cell` and samples `lo..hi` (non-empty); returns its (B̃
    /// mean, product mean). Fields are written in place: building a `Node` on the stack and
    /// copying it back costs a failed store-forward per node. `env` is the environment's
    /// relative mean over the cell (fetched by the parent), `code` the cell's Morton index
    /// within its level (carried down: a child's is 4·code + c; its high bits may be lost below
    /// the levels a 32-bit `usize` holds, where the map has no level to look up).
    #[allow(clippy::too_many_arguments)]
    fn node(&mut self, index: usize, cell: Cell, code: usize, env: f32, lo: usize, hi: usize) -> (f32, f32) {
        let room = self.nodes.len() + 4 <= NODES;
        if hi - lo == 1 || cell.level >= self.max_depth || !room {
            return self.leaf(index, cell, env, lo, hi);
        }
        // The children's environment blocks, which their own splits read: the loads miss the
        // caches at large maps, and asking now overlaps them with this node's work.
        self.env.prefetch_grandchildren_at(cell.level, code);
        let first = self.push_children(index, cell);
        let bounds = self.split(cell.level, lo, hi);
        // The environment over the four children: one 2×2 block of the pyramid (or the texel
        // containing them, below the finest level).
        let l = if cell.level < self.env.finest_level() {
            self.env.children_relative_at(cell.level, code)
        } else {
            [env; 4]
        };
        let probes = self.probe_children(cell, hi - lo, &bounds);
        let mut b = [0.0f32; 4];
        let mut p = [0.0f32; 4];
        let (mut sum_b, mut filled) = (0.0f32, 0u32);
        for c in 0..4 {
            if bounds[c + 1] == bounds[c] + 1 && !self.bilinear {
                // A leaf of one sample (most leaves) without the call.
                (b[c], p[c]) = self.sample_leaf(first + c, l[c], bounds[c], probes[c]);
                sum_b += b[c];
                filled += 1;
            } else if bounds[c + 1] > bounds[c] {
                (b[c], p[c]) = self.node(first + c, cell.child(c), (code << 2) | c, l[c], bounds[c], bounds[c + 1]);
                sum_b += b[c];
                filled += 1;
            }
        }
        // Empty children. With n samples over k non-empty children, add-α smoothing of the
        // counts gives an empty child (0 + α)/(n/k + α) of a non-empty child's density:
        // fill = b̄·αk/(n + αk). Two samples in two children: 2b̄/3 (little evidence; a smooth
        // BRDF keeps most of it). But counts cannot tell a tail of 1e-2 from one of 1e-5, and
        // the chain of cells above a needle lobe (n = 256, k = 1) would still hand each empty
        // sibling ~1% of the lobe's mass, which a brighter sky there multiplies. So where the
        // counts are strong evidence (n ≥ 4) B itself is probed in the cell (`probe`) and the
        // smaller of the two is kept — a few dozen evaluations per shading point.
        let n = (hi - lo) as f32;
        let count_fill = sum_b * FILL_PRIOR / (n + filled as f32 * FILL_PRIOR);
        for c in 0..4 {
            if bounds[c + 1] == bounds[c] {
                let fill = if self.bilinear {
                    bilinear::mean(&self.corners[first + c])
                } else if hi - lo >= EVAL_EMPTY_FROM {
                    count_fill.min(probes[c])
                } else {
                    count_fill
                };
                b[c] = fill;
                p[c] = fill * l[c];
                set(&mut self.nodes[first + c], 0, p[c]);
            }
        }
        let mean_b = 0.25 * ((b[0] + b[1]) + (b[2] + b[3]));
        let product = if self.wavelet { haar_product_mean(b, l, p) } else { 0.25 * ((p[0] + p[1]) + (p[2] + p[3])) };
        set(&mut self.nodes[index], first as u32, product);
        self.branches[first..first + 4].copy_from_slice(&branch_probabilities(p));
        (mean_b, product)
    }

    /// Makes node `index` (covering `cell`, samples `lo..hi`) a leaf; returns its (B̃, product).
    fn leaf(&mut self, index: usize, cell: Cell, env: f32, lo: usize, hi: usize) -> (f32, f32) {
        if self.bilinear {
            let b = bilinear::mean(&self.corners[index]);
            set(&mut self.nodes[index], 0, b * env);
            return (b, b * env);
        }
        let sum: f32 = self.keys[lo..hi].iter().map(|k| self.values[(k & 0xFFFF) as usize]).sum();
        let mut b = sum / (hi - lo) as f32;
        // With `probe_leaves`, B at the leaf's centre too, the larger kept (NaN reads as
        // unknown): a sample can sit on the dim side of its leaf, and a B̃ that understates
        // the leaf makes B/B̃ large wherever the light sends the product's samples in it,
        // while one that overstates it only spends a few samples (docs/tuning.md#product-mis-preset).
        if self.probe_leaves {
            let probe = self.probe(cell);
            if probe.is_finite() {
                b = b.max(probe);
            }
        }
        let product = b * env;
        set(&mut self.nodes[index], 0, product);
        (b, product)
    }

    /// [`leaf`](Self::leaf) of the one sample `keys[at]` without bilinear leaves; `probe` is B
    /// at the leaf's centre where leaves are probed (`probe_children`).
    #[inline(always)]
    fn sample_leaf(&mut self, index: usize, env: f32, at: usize, probe: f32) -> (f32, f32) {
        let sum: f32 = core::iter::once(self.values[(self.keys[at] & 0xFFFF) as usize]).sum();
        let mut b = sum / 1.0;
        if self.probe_leaves && probe.is_finite() {
            b = b.max(probe);
        }
        let product = b * env;
        set(&mut self.nodes[index], 0, product);
        (b, product)
    }

    /// The bounds of the four children's runs within `lo..hi` (a node at `depth`): the run is
    /// sorted by the next two Morton bits' digit, so three binary searches find them in a long
    /// run, and counting the digits in a short one (most of the tree's runs, where a scan costs
    /// less than the searches' unpredictable branches).
    fn split(&self, depth: u32, lo: usize, hi: usize) -> [usize; 5] {
        if hi - lo >= SEARCH_FROM {
            let run = &self.keys[lo..hi];
            let below = |d: usize| lo + run.partition_point(|&k| digit(k, depth) < d);
            return [lo, below(1), below(2), below(3), hi];
        }
        // Three counters packed in the bytes of one register (a run here is shorter than
        // `SEARCH_FROM` ≤ 255):
        // digit d adds one to the counts of "below d + 1", …, "below 3", i.e. 0x010101 >> 8d.
        let mut packed = 0u32;
        for &k in &self.keys[lo..hi] {
            packed += 0x01_0101 >> (8 * digit(k, depth));
        }
        let count = |byte: u32| ((packed >> (8 * byte)) & 0xFF) as usize;
        let (below1, below2, below3) = (count(2), count(1), count(0));
        [lo, lo + below1, lo + below2, lo + below3, hi]
    }
}

impl<F, G, const NODES: usize, const CORNERS: usize> TreeBuilder<'_, '_, F, G, NODES, CORNERS>
where
    F: FnMut(Vec2) -> f32,
    G: FnMut(Vec4, Vec4) -> Vec4,
{
    /// Appends the four children of node `index` (covering `cell`) and, for a bilinear
    /// B̃, their corner values: the parent's corners, B at the four edge midpoints and at the
    /// centre — five evaluations, shared by the children so that B̃ is continuous across them.
    fn push_children(&mut self, index: usize, cell: Cell) -> usize {
        let Cell { level: depth, x, y } = cell;
        let first = self.nodes.len();
        let _ = self.nodes.extend_from_slice(&[Node::default(); 4]);
        if self.bilinear {
            let w = self.corners[index];
            let inv = 1.0 / (1u64 << depth) as f32;
            let mut at = |s: f32, t: f32| self.eval_at(Vec2::new((x as f32 + s) * inv, (y as f32 + t) * inv));
            let (b, l, c, r, t) = (at(0.5, 0.0), at(0.0, 0.5), at(0.5, 0.5), at(1.0, 0.5), at(0.5, 1.0));
            for q in [[w[0], b, l, c], [b, w[1], c, r], [l, c, w[2], t], [c, r, t, w[3]]] {
                let _ = self.corners.push(q);
            }
        }
        first
    }

    /// B·cos at a point of the square for a bilinear corner: NaN or negative reads as 0 (the
    /// defensive mixture covers what B̃ misses), infinity as the largest finite value.
    fn eval_at(&mut self, uv: Vec2) -> f32 {
        let v = (self.eval)(uv);
        if v.is_nan() || v <= 0.0 { 0.0 } else { v.min(f32::MAX) }
    }
}

#[inline(always)]
fn set(n: &mut Node, child: u32, product: f32) {
    n.child = child;
    n.product = product;
}
