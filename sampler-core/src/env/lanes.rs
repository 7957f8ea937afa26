//! Descents side by side: many points warped [`IN_FLIGHT`] at a time, branch-free within a
//! level, so that one descent's loads and arithmetic overlap the others' instead of each
//! waiting on its own mispredicted branches (one per level and axis, each a coin flip).
//! Env-only draws ([`EnvHierarchy::sample_many`]) descend in f32 (`descent_f32.rs`); the
//! product's lanes (`product/lanes.rs`) and the two-level product's continue below their leaves
//! in f64 with the [`WarpLane`]s here.

use super::EnvHierarchy;
use super::descent_f32::DescentF32;
use super::pyramid::level_offset;
use super::texel_cdf::TexelCdf;
use crate::cell::Cell;
use crate::direction::DirectionSample;
use crate::mapping::SPHERE_AREA;
use crate::prefetch::prefetch;
use crate::warp::{ONE_MINUS_EPSILON, child_offset, choose_child, choose_grandchild_branchless};
use glam::{DVec2, Vec2, Vec3};

/// Lookups side by side where each is short (the texel table's) and the products' descents
/// below their leaves, whose trees are walked this many (twice) at a time.
pub(crate) const LANES: usize = 8;

/// Env-only descents [`EnvHierarchy::sample_many`] advances together: the deep levels miss the
/// caches on nearly every read, and only many independent descents, each a chain of dependent
/// loads, keep enough of those misses in flight to cover their latency.
pub(crate) const IN_FLIGHT: usize = 64;

/// One descent of [`EnvHierarchy::warp_down_lanes`]: the node it is at and its point ξ.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WarpLane {
    pub cell: Cell,
    /// Morton index of the cell within its level.
    pub(crate) morton: usize,
    pub xi: DVec2,
    /// False once the descent met a node without mass (or never started).
    pub alive: bool,
}

impl WarpLane {
    /// A descent from `node` with the point `u` (clamped into [0, 1)²).
    pub(crate) fn new(node: Cell, u: DVec2) -> Self {
        let xi = u.clamp(DVec2::ZERO, DVec2::splat(ONE_MINUS_EPSILON));
        Self { cell: node, morton: node.morton(), xi, alive: true }
    }

    #[inline(always)]
    pub(super) fn step(&mut self, levels: u32, dx: u32, dy: u32, child: usize) {
        let c = &mut self.cell;
        (c.level, c.x, c.y) = (c.level + levels, (c.x << levels) + dx, (c.y << levels) + dy);
        self.morton = (self.morton << (2 * levels)) + child;
    }
}

impl EnvHierarchy<'_> {
    /// Env samples for many points, up to 64 descents side by side in f32 (each level's loads
    /// and arithmetic of the lanes are independent, so they overlap), branch-free within a
    /// level: the same samples as [`sample`](Self::sample), bit for bit.
    pub fn sample_many(&self, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        if let Some(cdf) = &self.cdf {
            return self.sample_many_by_table(cdf, u, out);
        }
        // The buffers live across chunks: each chunk writes the entries it reads, so they are
        // not cleared again for every 64 points.
        let mut lanes = [DescentF32::default(); IN_FLIGHT];
        let mut uvs = [Vec2::ZERO; IN_FLIGHT];
        let mut dirs = [Vec3::ZERO; IN_FLIGHT];
        for (us, os) in u.chunks(IN_FLIGHT).zip(out.chunks_mut(IN_FLIGHT)) {
            let n = us.len().min(os.len());
            for (lane, u) in lanes.iter_mut().zip(&us[..n]) {
                *lane = DescentF32::from_root(*u);
            }
            self.descend_f32(&mut lanes[..n]);
            // Callers read the drawn texels' radiance next: asked for now, it arrives while the
            // directions below are computed, instead of one miss after another in the caller's
            // loop (env-only draws have nothing else to overlap it with).
            for lane in lanes[..n].iter().filter(|l| l.alive) {
                self.prefetch_radiance(lane.cell.x, lane.cell.y);
            }
            // The points, then the directions at once.
            for (uv, lane) in uvs.iter_mut().zip(&lanes[..n]) {
                *uv = lane.cell.point_f32(lane.xi);
            }
            self.dirs_of(&uvs[..n], &mut dirs[..n]);
            for (k, (o, lane)) in os.iter_mut().zip(&lanes[..n]).enumerate() {
                // `sample_in_texel`'s density, by the Morton index the descent carried down.
                let pdf = self.node_relative_at(self.finest, lane.morton) / SPHERE_AREA;
                *o = lane.alive.then_some(DirectionSample { dir: dirs[k], uv: uvs[k], pdf });
            }
        }
    }

    /// [`sample_many`](Self::sample_many) through the texel table: every point's texel first,
    /// so that the table's loads of all of them are in flight together, then the directions.
    fn sample_many_by_table(&self, cdf: &TexelCdf<'_>, u: &[DVec2], out: &mut [Option<DirectionSample>]) {
        if self.is_black() {
            out.iter_mut().for_each(|o| *o = None);
            return;
        }
        for (us, os) in u.chunks(LANES).zip(out.chunks_mut(LANES)) {
            let n = us.len().min(os.len());
            let mut points = [(Vec2::ZERO, 0.0f32); LANES];
            for (p, u) in points.iter_mut().zip(&us[..n]) {
                *p = cdf.sample_point(u.clamp(DVec2::ZERO, DVec2::splat(ONE_MINUS_EPSILON)));
            }
            let mut dirs = [Vec3::ZERO; LANES];
            self.dirs_of(&points.map(|(uv, _)| uv)[..n], &mut dirs[..n]);
            for (k, o) in os[..n].iter_mut().enumerate() {
                let (uv, pdf) = points[k];
                *o = Some(DirectionSample { dir: dirs[k], uv, pdf });
            }
        }
    }

    /// [`warp_down`](Self::warp_down) for up to a few descents at once, each from its own node,
    /// advanced level by level side by side. A lane that meets a node without mass dies.
    pub(crate) fn warp_down_lanes(&self, lanes: &mut [WarpLane]) {
        #[cfg(target_arch = "x86_64")]
        self.warp_down_pairs_avx2(lanes);
        self.warp_down_lanes_scalar(lanes);
    }

    /// [`warp_down_lanes`](Self::warp_down_lanes) without AVX2: every step in scalar
    /// arithmetic, the lanes side by side.
    pub(super) fn warp_down_lanes_scalar(&self, lanes: &mut [WarpLane]) {
        if self.is_black() {
            lanes.iter_mut().for_each(|l| l.alive = false);
            return;
        }
        loop {
            // Every lane's next node first, so that their loads are in flight together.
            for lane in lanes.iter().filter(|l| l.alive && l.cell.level < self.finest) {
                prefetch(self.nodes_below(lane.cell.level, lane.morton));
            }
            let mut busy = false;
            for lane in lanes.iter_mut().filter(|l| l.alive && l.cell.level < self.finest) {
                busy = true;
                if lane.cell.level + 2 <= self.finest {
                    let g: &[f32; 16] = self.nodes_below(lane.cell.level, lane.morton).try_into().unwrap();
                    match choose_grandchild_branchless(g, &mut lane.xi) {
                        Some((c, gx, gy)) => lane.step(2, gx, gy, c),
                        None => lane.alive = false,
                    }
                } else {
                    let q = self.nodes_below(lane.cell.level, lane.morton);
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

    /// The nodes a descent at node `morton` of `level`, above the finest level, chooses among
    /// next: its sixteen grandchildren, or its four children one level above the finest.
    #[inline(always)]
    pub(super) fn nodes_below(&self, level: u32, morton: usize) -> &[f32] {
        if level + 2 <= self.finest {
            let base = level_offset(level + 2) + 16 * morton;
            &self.pyramid[base..base + 16]
        } else {
            let base = level_offset(level + 1) + 4 * morton;
            &self.pyramid[base..base + 4]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{build_pyramid, pyramid_len};

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
            for (a, b) in u.iter().zip(&out) {
                let (a, b) = (e.sample(*a).unwrap(), b.unwrap());
                assert_eq!((a.uv, a.pdf, a.dir), (b.uv, b.pdf, b.dir));
                assert_eq!(b.pdf, e.pdf_square(b.uv) / SPHERE_AREA);
            }
        }
        let black = [[0.0f32; 3]; 4];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &black, &mut p).unwrap();
        let mut out = [Some(DirectionSample { dir: Vec3::Z, uv: Vec2::ZERO, pdf: 1.0 }); 5];
        EnvHierarchy::new(1, &p, &black).unwrap().sample_many(&[DVec2::splat(0.5); 5], &mut out);
        assert!(out.iter().all(Option::is_none));
    }
}
