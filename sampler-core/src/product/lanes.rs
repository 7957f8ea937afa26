//! Product descents side by side: many points warped [`WARPS`] at a time, branch-free within a
//! level, so that one descent's loads and arithmetic overlap the others' instead of each
//! waiting on its own mispredicted branches.
//!
//! * [`ProductSampler::sample_many`]: product samples — the tree first (four descents to an
//!   AVX2 register where the CPU has it, `lanes_avx2.rs`), then the environment's levels below
//!   the leaves with the environment's own lanes (and the defensive env samples from the root).
//! * [`ProductSampler::pdf_square_many`]: product densities, descents side by side by the points' bits.

use super::quadtree::{COORD_BITS, Node, quantize};
use super::sampler::{DirectionSample, ProductSampler};
use crate::cell::Cell;
use crate::env::{LANES, WarpLane};
use crate::mapping::SPHERE_AREA;
use crate::warp::{ONE_MINUS_EPSILON, choose_child_branchless};
use glam::{DVec2, Vec2, Vec3};

/// Product samples drawn side by side: a renderer's batch (`estimator::BATCH`) in one go, so
/// that the environment's descents below the leaves, whose loads miss the caches at large maps,
/// all have theirs in flight together (twice the environment's own [`LANES`]).
pub(super) const WARPS: usize = 2 * LANES;

/// One descent through the product tree.
#[derive(Clone, Copy, Default)]
pub(super) struct TreeLane {
    /// The node the descent is at (a copy: its leaf test needs no load) and its index.
    pub(super) node: Node,
    pub(super) index: usize,
    /// The node's cell.
    pub(super) cell: Cell,
    /// Probability of the path so far (the leaf's, once there).
    pub(super) path: f64,
    pub(super) xi: DVec2,
    /// Drawn by the defensive environment part of the mixture: no tree descent.
    pub(super) defensive: bool,
    /// Still descending the tree.
    pub(super) in_tree: bool,
    /// False once the descent met a node without mass.
    pub(super) alive: bool,
}

impl ProductSampler<'_, '_> {
    /// [`sample`](Self::sample) for every point of `u` (into `out`, as many as both hold): the
    /// same distribution and densities; a point may move within its texel in the last bits (the
    /// branch-free choices count prefix sums instead of subtracting them one by one).
    pub fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        if !self.corners.is_empty() {
            // The bilinear walk has its own choices; one at a time.
            for (o, u) in out.iter_mut().zip(u) {
                *o = self.sample(*u);
            }
            return;
        }
        let eps = self.defensive as f64;
        let root = self.nodes.first().copied().unwrap_or_default();
        for (us, os) in u.chunks(WARPS).zip(out.chunks_mut(WARPS)) {
            let n = us.len().min(os.len());
            let mut tree = [TreeLane::default(); WARPS];
            for (lane, u) in tree.iter_mut().zip(&us[..n]) {
                let mut xi = u.clamp(DVec2::ZERO, DVec2::splat(ONE_MINUS_EPSILON));
                let defensive = xi.x < eps;
                xi.x = if defensive {
                    (xi.x / eps).min(ONE_MINUS_EPSILON)
                } else {
                    ((xi.x - eps) / (1.0 - eps)).clamp(0.0, ONE_MINUS_EPSILON)
                };
                *lane = TreeLane { node: root, path: 1.0, xi, defensive, in_tree: !defensive, alive: true, ..*lane };
            }
            self.descend_tree(&mut tree[..n]);
            // Below the leaves (or from the root, for defensive samples), the environment's
            // levels, also side by side.
            let mut below = [WarpLane::default(); WARPS];
            for (e, t) in below.iter_mut().zip(&tree[..n]) {
                *e = WarpLane::new(t.cell, t.xi);
                e.alive = t.alive;
            }
            // Each leaf's Morton code, which the lane computed at its start: `finish` reads the
            // leaf's environment by it.
            let leaf_codes = below.map(|e| e.morton);
            self.env.warp_down_lanes(&mut below[..n]);
            let mut landed = [None; WARPS];
            for (k, l) in landed[..n].iter_mut().enumerate() {
                *l = self.finish(&tree[k], &below[k], leaf_codes[k]);
            }
            // The defensive samples' densities: the product's descents side by side.
            let (mut points, mut which, mut count) = ([Vec2::ZERO; WARPS], [0; WARPS], 0);
            for (k, t) in tree[..n].iter().enumerate() {
                if let (true, Some((uv, _))) = (t.defensive, landed[k]) {
                    (points[count], which[count], count) = (uv, k, count + 1);
                }
            }
            let mut densities = [0.0f32; WARPS];
            self.pdf_square_many(&points[..count], &mut densities[..count]);
            for (&k, &d) in which[..count].iter().zip(&densities) {
                landed[k] = landed[k].map(|(uv, _)| (uv, d / SPHERE_AREA));
            }
            // The directions at once.
            let mut dirs = [Vec3::ZERO; WARPS];
            self.env.dirs_of(&landed.map(|l| l.map_or(Vec2::ZERO, |(uv, _)| uv))[..n], &mut dirs[..n]);
            for (k, o) in os.iter_mut().enumerate().take(n) {
                *o = landed[k].map(|(uv, pdf)| DirectionSample { dir: dirs[k], uv, pdf });
            }
        }
    }

    /// Advances every lane still in the tree one level per round until all reach a leaf: four
    /// lanes to a register where the CPU has AVX2 (the same bits), else one at a time.
    fn descend_tree(&self, lanes: &mut [TreeLane]) {
        #[cfg(target_arch = "x86_64")]
        if self.descend_tree_avx2(lanes) {
            return;
        }
        self.descend_tree_scalar(lanes);
    }

    /// [`descend_tree`](Self::descend_tree) in scalar arithmetic, the lanes side by side.
    pub(super) fn descend_tree_scalar(&self, lanes: &mut [TreeLane]) {
        loop {
            let mut busy = false;
            for lane in lanes.iter_mut().filter(|l| l.in_tree) {
                if lane.node.is_leaf() {
                    lane.in_tree = false;
                    continue;
                }
                busy = true;
                let first = lane.node.child as usize;
                let c = &self.nodes[first..first + 4];
                let mass = [c[0].product, c[1].product, c[2].product, c[3].product];
                let Some(k) = choose_child_branchless(mass, &mut lane.xi) else {
                    (lane.in_tree, lane.alive) = (false, false);
                    continue;
                };
                (lane.node, lane.index, lane.cell) = (c[k], first + k, lane.cell.child(k));
                lane.path *= self.branches[first + k];
            }
            if !busy {
                return;
            }
        }
    }

    /// The sample's point at the end of a tree descent `t` and the environment descent `e` below
    /// it, with its density (solid angle) as [`sample`](Self::sample) computes it — except for
    /// defensive samples, whose density (0 here) the caller looks up for a batch at once.
    /// `leaf_code`: the leaf's Morton index within its level (meaningful above the finest).
    fn finish(&self, t: &TreeLane, e: &WarpLane, leaf_code: usize) -> Option<(Vec2, f32)> {
        if !t.alive || !e.alive {
            return None;
        }
        let (uv, pdf_square) = if t.defensive {
            (e.cell.point(e.xi), 0.0)
        } else if t.cell.level < self.env.finest_level() {
            // `land`'s values by the Morton codes the lane carries, the texel's at its end:
            // no code recomputed from a cell.
            let texel = self.env.node_relative_at(e.cell.level, e.morton);
            let leaf_env = self.env.node_relative_at(t.cell.level, leaf_code);
            let product = self.density_below_leaf(t.path, t.cell, leaf_env, texel);
            (e.cell.point(e.xi), self.mixture(product, texel))
        } else {
            // Below a leaf finer than the map the env lane did not move: its cell and point are
            // the leaf's.
            let (uv, product, texel) = self.land(t.path, t.cell, e.cell, e.xi);
            (uv, self.mixture(product, texel))
        };
        Some((uv, pdf_square / SPHERE_AREA))
    }
}

/// One descent by a point's bits, for [`ProductSampler::pdf_square_many`].
#[derive(Clone, Copy, Default)]
struct PdfLane {
    node: Node,
    index: usize,
    cell: Cell,
    /// The point's 24-bit coordinates.
    qx: u32,
    qy: u32,
    /// Probability of the path so far.
    path: f64,
}

impl ProductSampler<'_, '_> {
    /// [`pdf_square`](Self::pdf_square) at every point of `uv` (into `out`, as many as both
    /// hold), bit for bit: the same leaves and their path probabilities, eight descents side by
    /// side.
    pub fn pdf_square_many(&self, uv: &[Vec2], out: &mut [f32]) {
        let Some(&root) = self.nodes.first() else {
            out.iter_mut().zip(uv).for_each(|(o, uv)| *o = self.pdf_square(*uv));
            return;
        };
        if !self.corners.is_empty() || self.defensive >= 1.0 {
            out.iter_mut().zip(uv).for_each(|(o, uv)| *o = self.pdf_square(*uv));
            return;
        }
        for (us, os) in uv.chunks(LANES).zip(out.chunks_mut(LANES)) {
            let n = us.len().min(os.len());
            let mut lanes = [PdfLane::default(); LANES];
            for (lane, uv) in lanes.iter_mut().zip(&us[..n]) {
                *lane = PdfLane { node: root, qx: quantize(uv.x), qy: quantize(uv.y), path: 1.0, ..*lane };
            }
            loop {
                let mut busy = false;
                for lane in lanes[..n].iter_mut().filter(|l| !l.node.is_leaf()) {
                    busy = true;
                    let shift = COORD_BITS - 1 - lane.cell.level;
                    let k = (((lane.qx >> shift) & 1) + 2 * ((lane.qy >> shift) & 1)) as usize;
                    lane.index = lane.node.child as usize + k;
                    lane.node = self.nodes[lane.index];
                    lane.cell = lane.cell.child(k);
                    lane.path *= self.branches[lane.index];
                }
                if !busy {
                    break;
                }
            }
            for ((o, l), uv) in os.iter_mut().zip(&lanes[..n]).zip(us) {
                let texel = self.env.texel_relative(*uv);
                *o = self.mixture(self.leaf_density(l.path, l.cell, texel), texel);
            }
        }
    }
}
