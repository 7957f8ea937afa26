//! Descents side by side: many points warped [`LANES`] at a time, branch-free within a level, so
//! that one descent's loads and arithmetic overlap the others' instead of each waiting on its
//! own mispredicted branches (one per level and axis, each a coin flip).
//!
//! * [`EnvHierarchy::sample_many`]: env-only samples (`WarpLane`s down the pyramid).
//! * [`ProductSampler::sample_many`]: product samples — the tree first, then the environment's
//!   levels below the leaves with the same `WarpLane`s (and the defensive env samples from the
//!   root).
//! * [`ProductSampler::pdf_square_many`]: product densities, descents side by side by the points' bits.

use crate::env::{EnvHierarchy, level_offset, morton2};
use crate::mapping::SPHERE_AREA;
use crate::quadtree::{COORD_BITS, Node, quantize};
use crate::sampler::{DirectionSample, ProductSampler};
use crate::warp::{
    ONE_MINUS_EPSILON, child_offset, choose_child, choose_child_branchless, choose_grandchild_branchless, point_in_cell,
};
use glam::{DVec2, Vec2, Vec3};

/// Descents advanced side by side: enough that the loads of the map's deep levels, which miss
/// the caches, overlap.
const LANES: usize = 8;

/// One descent of [`EnvHierarchy::warp_down_lanes`]: the node it is at and its point ξ.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WarpLane {
    pub level: u32,
    pub x: u32,
    pub y: u32,
    /// Morton index of (x, y) within its level.
    morton: usize,
    pub xi: DVec2,
    /// False once the descent met a node without mass (or never started).
    pub alive: bool,
}

impl WarpLane {
    /// A descent from node (x, y) of `level` with the point `u` (clamped into [0, 1)²).
    pub(crate) fn new(level: u32, x: u32, y: u32, u: DVec2) -> Self {
        let xi = u.clamp(DVec2::ZERO, DVec2::splat(ONE_MINUS_EPSILON));
        Self { level, x, y, morton: morton2(x, y), xi, alive: true }
    }

    #[inline(always)]
    fn step(&mut self, levels: u32, dx: u32, dy: u32, child: usize) {
        self.level += levels;
        self.x = (self.x << levels) + dx;
        self.y = (self.y << levels) + dy;
        self.morton = (self.morton << (2 * levels)) + child;
    }
}

impl EnvHierarchy<'_> {
    /// Env samples for many points, [`LANES`] descents side by side (each level's loads and
    /// arithmetic of the lanes are independent, so they overlap), branch-free within a level.
    /// The same distribution and pdf as [`sample`](Self::sample); the point within a cell can
    /// differ from it in the last bits (the sides are chosen by a count of prefix sums).
    pub fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        for (us, os) in u.chunks(LANES).zip(out.chunks_mut(LANES)) {
            let n = us.len().min(os.len());
            let mut lanes = [WarpLane::default(); LANES];
            for (lane, u) in lanes.iter_mut().zip(&us[..n]) {
                *lane = WarpLane::new(0, 0, 0, *u);
            }
            self.warp_down_lanes(&mut lanes[..n]);
            // The points and densities, then the directions at once.
            let mut points = [(Vec2::ZERO, 0.0); LANES];
            for (p, lane) in points.iter_mut().zip(&lanes[..n]) {
                *p = self.point_in_texel(lane.x, lane.y, lane.xi);
            }
            let mut dirs = [Vec3::ZERO; LANES];
            self.dirs_of(&points.map(|(uv, _)| uv)[..n], &mut dirs[..n]);
            for (k, (o, lane)) in os.iter_mut().zip(&lanes[..n]).enumerate() {
                let (uv, pdf) = points[k];
                *o = lane.alive.then_some(DirectionSample { dir: dirs[k], uv, pdf });
            }
        }
    }

    /// [`warp_down`](Self::warp_down) for up to a few descents at once, each from its own node,
    /// advanced level by level side by side. A lane that meets a node without mass dies.
    pub(crate) fn warp_down_lanes(&self, lanes: &mut [WarpLane]) {
        if self.is_black() {
            lanes.iter_mut().for_each(|l| l.alive = false);
            return;
        }
        loop {
            let mut busy = false;
            for lane in lanes.iter_mut().filter(|l| l.alive && l.level < self.finest) {
                busy = true;
                if lane.level + 2 <= self.finest {
                    let base = level_offset(lane.level + 2) + 16 * lane.morton;
                    let g: &[f32; 16] = self.pyramid[base..base + 16].try_into().unwrap();
                    match choose_grandchild_branchless(g, &mut lane.xi) {
                        Some((c, gx, gy)) => lane.step(2, gx, gy, c),
                        None => lane.alive = false,
                    }
                } else {
                    let base = level_offset(lane.level + 1) + 4 * lane.morton;
                    let q = &self.pyramid[base..base + 4];
                    match choose_child([q[0], q[1], q[2], q[3]], &mut lane.xi) {
                        Some(c) => {
                            let (dx, dy) = child_offset(c);
                            lane.step(1, dx, dy, c);
                        }
                        None => lane.alive = false,
                    }
                }
            }
            if !busy {
                return;
            }
        }
    }
}

/// One descent through the product tree.
#[derive(Clone, Copy, Default)]
struct TreeLane {
    /// The node the descent is at (a copy: its leaf test needs no load) and its index.
    node: Node,
    index: usize,
    depth: u32,
    x: u32,
    y: u32,
    /// Probability of the path (the leaf's, once there).
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
        for (us, os) in u.chunks(LANES).zip(out.chunks_mut(LANES)) {
            let n = us.len().min(os.len());
            let mut tree = [TreeLane::default(); LANES];
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
            let mut below = [WarpLane::default(); LANES];
            for (e, t) in below.iter_mut().zip(&tree[..n]) {
                *e = WarpLane::new(t.depth, t.x, t.y, t.xi);
                e.alive = t.alive;
            }
            self.env.warp_down_lanes(&mut below[..n]);
            let mut landed = [None; LANES];
            for ((l, t), e) in landed.iter_mut().zip(&tree[..n]).zip(&below[..n]) {
                *l = self.finish(t, e);
            }
            // The defensive samples' densities: the product's descents side by side.
            let (mut points, mut which, mut count) = ([Vec2::ZERO; LANES], [0; LANES], 0);
            for (k, t) in tree[..n].iter().enumerate() {
                if let (true, Some((uv, _))) = (t.defensive, landed[k]) {
                    (points[count], which[count], count) = (uv, k, count + 1);
                }
            }
            let mut densities = [0.0f32; LANES];
            self.pdf_square_many(&points[..count], &mut densities[..count]);
            for (&k, &d) in which[..count].iter().zip(&densities) {
                landed[k] = landed[k].map(|(uv, _)| (uv, d / SPHERE_AREA));
            }
            // The directions at once.
            let mut dirs = [Vec3::ZERO; LANES];
            self.env.dirs_of(&landed.map(|l| l.map_or(Vec2::ZERO, |(uv, _)| uv))[..n], &mut dirs[..n]);
            for (k, o) in os.iter_mut().enumerate().take(n) {
                *o = landed[k].map(|(uv, pdf)| DirectionSample { dir: dirs[k], uv, pdf });
            }
        }
    }

    /// Advances every lane still in the tree one level per round until all reach a leaf.
    fn descend_tree(&self, lanes: &mut [TreeLane]) {
        loop {
            let mut busy = false;
            for lane in lanes.iter_mut().filter(|l| l.in_tree) {
                if lane.node.is_leaf() {
                    (lane.in_tree, lane.path) = (false, self.paths[lane.index]);
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
                let (dx, dy) = child_offset(k);
                (lane.node, lane.index) = (c[k], first + k);
                (lane.depth, lane.x, lane.y) = (lane.depth + 1, 2 * lane.x + dx, 2 * lane.y + dy);
            }
            if !busy {
                return;
            }
        }
    }

    /// The sample's point at the end of a tree descent `t` and the environment descent `e` below
    /// it, with its density (solid angle) as [`sample`](Self::sample) computes it — except for
    /// defensive samples, whose density (0 here) the caller looks up for a batch at once.
    fn finish(&self, t: &TreeLane, e: &WarpLane) -> Option<(Vec2, f32)> {
        if !t.alive || !e.alive {
            return None;
        }
        let (uv, pdf_square) = if t.defensive {
            (point_in_cell(e.x, e.y, self.env.finest_level(), e.xi), 0.0)
        } else {
            // Below a leaf finer than the map the env lane did not move: (e.x, e.y, e.xi) are
            // the leaf's.
            let (uv, product, texel) = self.land(t.path, t.depth, t.x, t.y, (e.x, e.y), e.xi);
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
    depth: u32,
    x: u32,
    y: u32,
    /// The point's 24-bit coordinates.
    qx: u32,
    qy: u32,
}

impl ProductSampler<'_, '_> {
    /// [`pdf_square`](Self::pdf_square) at every point of `uv` (into `out`, as many as both
    /// hold), bit for bit: the same leaves and their path probabilities, [`LANES`] descents side by
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
                *lane = PdfLane { node: root, qx: quantize(uv.x), qy: quantize(uv.y), ..*lane };
            }
            loop {
                let mut busy = false;
                for lane in lanes[..n].iter_mut().filter(|l| !l.node.is_leaf()) {
                    busy = true;
                    let shift = COORD_BITS - 1 - lane.depth;
                    let (dx, dy) = ((lane.qx >> shift) & 1, (lane.qy >> shift) & 1);
                    let k = (dx + 2 * dy) as usize;
                    lane.index = lane.node.child as usize + k;
                    lane.node = self.nodes[lane.index];
                    (lane.depth, lane.x, lane.y) = (lane.depth + 1, 2 * lane.x + dx, 2 * lane.y + dy);
                }
                if !busy {
                    break;
                }
            }
            for ((o, l), uv) in os.iter_mut().zip(&lanes[..n]).zip(us) {
                let texel = self.env.pdf_square(*uv);
                *o = self.mixture(self.leaf_density(self.paths[l.index], l.depth, l.x, l.y, texel), texel);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{build_pyramid, pyramid_len};
    use glam::Vec3;

    #[test]
    fn sample_many_draws_what_sample_draws() {
        let mut rgb = [[0.0f32; 3]; 32 * 32];
        for (i, t) in rgb.iter_mut().enumerate() {
            *t = [(i * 7 % 13) as f32, (i % 3) as f32, if i == 300 { 1e6 } else { 0.5 }];
        }
        rgb[17] = [0.0; 3];
        for level in [4u32, 5] {
            let n = 1usize << level;
            let texels = &rgb[..n * n];
            let mut p = [0.0f32; 1365];
            let p = &mut p[..pyramid_len(level)];
            build_pyramid(level, texels, p).unwrap();
            let e = EnvHierarchy::new(level, p, texels).unwrap();
            let mut u = [DVec2::ZERO; 4099];
            crate::points::sobol02(level as u64, 0, &mut u);
            u[3] = DVec2::new(1.0, 0.0); // clamped like `sample` clamps
            let mut out = [None; 4099];
            e.sample_many(&u, &mut out);
            let mut moved = 0;
            for (a, b) in u.iter().zip(&out) {
                let (a, b) = (e.sample(*a).unwrap(), b.unwrap());
                // Same cell; the point inside may differ in the last bits.
                moved += usize::from(e.texel_at(a.uv) != e.texel_at(b.uv));
                assert!((a.uv - b.uv).abs().max_element() < 1e-5, "{a:?} {b:?}");
                assert_eq!(b.pdf, e.pdf_square(b.uv) / SPHERE_AREA);
            }
            assert!(moved <= 2, "{moved} of 4099 in another texel");
        }
        let black = [[0.0f32; 3]; 4];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &black, &mut p).unwrap();
        let mut out = [Some(DirectionSample { dir: Vec3::Z, uv: Vec2::ZERO, pdf: 1.0 }); 5];
        EnvHierarchy::new(1, &p, &black).unwrap().sample_many(&[DVec2::splat(0.5); 5], &mut out);
        assert!(out.iter().all(Option::is_none));
    }
}
