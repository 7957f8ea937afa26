//! Product samples four at a time ([`ProductSampler::sample_many`]): the descents through the
//! tree, then on through the environment's levels, run side by side with branch-free choices,
//! so that one descent's loads and arithmetic overlap the others' instead of each waiting on
//! its own mispredicted branches (one branch per level and axis, each a coin flip). The
//! environment's `sample_many` does the same for env-only sampling.

use crate::env::WarpLane;
use crate::mapping::SPHERE_AREA;
use crate::quadtree::{COORD_BITS, Node, quantize};
use crate::sampler::{DirectionSample, ProductSampler, branch_probability};
use crate::warp::{ONE_MINUS_EPSILON, child_offset, choose_child_branchless, point_in_cell};
use glam::{DVec2, Vec2};

/// One descent through the product tree.
#[derive(Clone, Copy, Default)]
struct TreeLane {
    /// The node the descent is at (a copy: its leaf test needs no load).
    node: Node,
    depth: u32,
    x: u32,
    y: u32,
    /// Probability of the path so far (the product of the branch probabilities).
    path: f64,
    xi: DVec2,
    /// Drawn by the defensive environment part of the mixture: no tree descent.
    defensive: bool,
    /// Still descending the tree.
    in_tree: bool,
    /// False once the descent met a node without mass.
    alive: bool,
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
        for (us, os) in u.chunks(4).zip(out.chunks_mut(4)) {
            let n = us.len().min(os.len());
            let mut tree = [TreeLane::default(); 4];
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
            let mut below = [WarpLane::default(); 4];
            for (e, t) in below.iter_mut().zip(&tree[..n]) {
                *e = WarpLane::new(t.depth, t.x, t.y, t.xi);
                e.alive = t.alive;
            }
            self.env.warp_down_lanes(&mut below[..n]);
            for ((o, t), e) in os.iter_mut().zip(&tree[..n]).zip(&below[..n]) {
                *o = self.finish(t, e);
            }
        }
    }

    /// Advances every lane still in the tree one level per round until all reach a leaf.
    fn descend_tree(&self, lanes: &mut [TreeLane]) {
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
                lane.path *= branch_probability(mass, k);
                let (dx, dy) = child_offset(k);
                lane.node = c[k];
                (lane.depth, lane.x, lane.y) = (lane.depth + 1, 2 * lane.x + dx, 2 * lane.y + dy);
            }
            if !busy {
                return;
            }
        }
    }

    /// The sample at the end of a tree descent `t` and the environment descent `e` below it,
    /// with its density as [`sample`](Self::sample) computes it.
    fn finish(&self, t: &TreeLane, e: &WarpLane) -> Option<DirectionSample> {
        if !t.alive || !e.alive {
            return None;
        }
        let (uv, pdf_square) = if t.defensive {
            let uv = point_in_cell(e.x, e.y, self.env.finest_level(), e.xi);
            (uv, self.pdf_square(uv))
        } else {
            // Below a leaf finer than the map the env lane did not move: (e.x, e.y, e.xi) are
            // the leaf's.
            let (uv, product, texel) = self.land(t.path, t.depth, t.x, t.y, (e.x, e.y), e.xi);
            (uv, self.mixture(product, texel))
        };
        Some(DirectionSample { dir: self.env.dir_of(uv), uv, pdf: pdf_square / SPHERE_AREA })
    }
}

/// One descent by a point's bits, for [`ProductSampler::pdf_square_many`].
#[derive(Clone, Copy, Default)]
struct PdfLane {
    node: Node,
    depth: u32,
    x: u32,
    y: u32,
    /// The point's 24-bit coordinates.
    qx: u32,
    qy: u32,
    path: f64,
}

impl ProductSampler<'_, '_> {
    /// [`pdf_square`](Self::pdf_square) at every point of `uv` (into `out`, as many as both
    /// hold), bit for bit: the same branch probabilities multiplied in the same order, four
    /// descents side by side.
    pub fn pdf_square_many(&self, uv: &[Vec2], out: &mut [f32]) {
        let Some(&root) = self.nodes.first() else {
            out.iter_mut().zip(uv).for_each(|(o, uv)| *o = self.pdf_square(*uv));
            return;
        };
        if !self.corners.is_empty() || self.defensive >= 1.0 {
            out.iter_mut().zip(uv).for_each(|(o, uv)| *o = self.pdf_square(*uv));
            return;
        }
        for (us, os) in uv.chunks(4).zip(out.chunks_mut(4)) {
            let n = us.len().min(os.len());
            let mut lanes = [PdfLane::default(); 4];
            for (lane, uv) in lanes.iter_mut().zip(&us[..n]) {
                *lane = PdfLane { node: root, qx: quantize(uv.x), qy: quantize(uv.y), path: 1.0, ..*lane };
            }
            loop {
                let mut busy = false;
                for lane in lanes[..n].iter_mut().filter(|l| !l.node.is_leaf()) {
                    busy = true;
                    let shift = COORD_BITS - 1 - lane.depth;
                    let (dx, dy) = ((lane.qx >> shift) & 1, (lane.qy >> shift) & 1);
                    let k = (dx + 2 * dy) as usize;
                    let first = lane.node.child as usize;
                    let c = &self.nodes[first..first + 4];
                    lane.path *= branch_probability([c[0].product, c[1].product, c[2].product, c[3].product], k);
                    lane.node = c[k];
                    (lane.depth, lane.x, lane.y) = (lane.depth + 1, 2 * lane.x + dx, 2 * lane.y + dy);
                }
                if !busy {
                    break;
                }
            }
            for ((o, l), uv) in os.iter_mut().zip(&lanes[..n]).zip(us) {
                let texel = self.env.pdf_square(*uv);
                *o = self.mixture(self.leaf_density(l.path, l.depth, l.x, l.y, texel), texel);
            }
        }
    }
}
