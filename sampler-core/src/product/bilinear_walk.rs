//! Below a bilinear leaf (`Leaves::Bilinear`): the walk down the environment's levels
//! that weighs each cell by L·B̃ at its centre, for the warp and, replayed by a point's bits,
//! for its density.

use super::arena::branch_probability;
use super::bilinear::{self, BilinearCell, Corners, Masses};
use super::quadtree::{COORD_BITS, quantize};
use super::sampler::ProductSampler;
use crate::cell::Cell;
use crate::warp::{choose_child, choose_grandchild, grandchild_index, grandchild_probability};
use glam::{DVec2, Vec2};

impl ProductSampler<'_, '_> {
    /// Below node `leaf` (cell `at`, reached with probability `path`) with a bilinear B̃: down
    /// the environment's levels by L·B̃ at each cell's centre, then inside the texel (or the
    /// leaf, when it is finer than a texel) ∝ B̃. Returns what `warp_product` does.
    pub(super) fn warp_bilinear(&self, leaf: usize, path: f64, at: Cell, xi: &mut DVec2) -> Option<(Vec2, f64, f32)> {
        let w = &self.corners[leaf];
        let (cell, path) = self.walk_bilinear(w, path, at, |masses, _| match masses {
            Masses::Sixteen(m) => choose_grandchild(m, xi).map(|(k, _, _)| k),
            Masses::Four(m) => choose_child(m, xi),
        })?;
        let corners = bilinear::sub_corners(w, cell.s, cell.t, cell.size);
        let uv = cell.cell.point(bilinear::sample(&corners, *xi));
        let texel = self.env.cell_relative(cell.cell);
        // The density at the point as stored (f32), as `pdf_square` will find it.
        Some((uv, cell.density(path, &corners, uv), texel))
    }

    /// The walk below a bilinear leaf (cell `at`, reached with probability `path`)
    /// down to the finest level: two levels per step over the 16 grandchildren (one cache
    /// line), then one if left, each cell weighed by L·B̃ at its centre. `pick` chooses the
    /// next cell from the masses (`warp_bilinear` by its point, `bilinear_density` by the
    /// bits of `uv`) — one walk, so the warp and its pdf weigh every cell alike. Returns the
    /// final cell and the probability of reaching it; `None` when `pick` finds no mass.
    fn walk_bilinear(
        &self,
        w: &Corners,
        mut path: f64,
        at: Cell,
        mut pick: impl FnMut(Masses<'_>, &BilinearCell) -> Option<usize>,
    ) -> Option<(BilinearCell, f64)> {
        let finest = self.env.finest_level();
        let mut cell = BilinearCell { cell: at, s: 0.0, t: 0.0, size: 1.0 };
        while cell.cell.level + 2 <= finest {
            let mass = self.bilinear_grandchild_masses(w, &cell);
            let k = pick(Masses::Sixteen(&mass), &cell)?;
            path *= grandchild_probability(&mass, k);
            // Morton index → (column, row) of the grandchild.
            let (gx, gy) = ((k & 1 | (k >> 1) & 2) as u32, ((k >> 1) & 1 | (k >> 2) & 2) as u32);
            cell.descend_two(gx, gy);
        }
        if cell.cell.level < finest {
            let mass = self.bilinear_masses(w, &cell);
            let child = pick(Masses::Four(mass), &cell)?;
            path *= branch_probability(mass, child);
            cell.descend(child);
        }
        Some((cell, path))
    }

    /// The environment's 16 grandchildren of `cell` (Morton order, see `choose_grandchild`),
    /// each weighed by B̃ at its centre: B̃ = a + b·s + c·t + d·s·t along each row of four.
    #[inline]
    fn bilinear_grandchild_masses(&self, w: &Corners, cell: &BilinearCell) -> [f32; 16] {
        let g = self.env.grandchildren_raw(cell.cell);
        let (a, b, c, d) = (w[0], w[1] - w[0], w[2] - w[0], (w[3] - w[2]) - (w[1] - w[0]));
        let q = 0.25 * cell.size;
        let centre = |o: f32, i: u32| o + (i as f32 + 0.5) * q;
        let mut mass = [0.0f32; 16];
        for gy in 0..4u32 {
            let t = centre(cell.t, gy);
            let (row, slope) = (a + c * t, b + d * t);
            for gx in 0..4u32 {
                let k = grandchild_index(gx, gy);
                mass[k] = g[k] * (row + slope * centre(cell.s, gx));
            }
        }
        mass
    }

    /// The environment's four children of `cell`, each weighed by B̃ at its centre.
    #[inline]
    fn bilinear_masses(&self, w: &Corners, cell: &BilinearCell) -> [f32; 4] {
        let l = self.env.children_relative(cell.cell);
        let h = 0.25 * cell.size;
        let (s0, s1, t0, t1) = (cell.s + h, cell.s + 3.0 * h, cell.t + h, cell.t + 3.0 * h);
        [
            l[0] * bilinear::bilinear(w, s0, t0),
            l[1] * bilinear::bilinear(w, s1, t0),
            l[2] * bilinear::bilinear(w, s0, t1),
            l[3] * bilinear::bilinear(w, s1, t1),
        ]
    }

    /// The bilinear product's density at `uv` inside node `leaf` (cell `at`, reached with
    /// probability `path`): the walk `warp_bilinear` takes, replayed by `uv`'s bits.
    pub(super) fn bilinear_density(&self, leaf: usize, path: f64, at: Cell, uv: Vec2) -> f64 {
        let w = &self.corners[leaf];
        let (qx, qy) = (quantize(uv.x), quantize(uv.y));
        // The bits of `uv` that choose among the 2^n × 2^n cells below a cell of `level`.
        let bits = |level: u32, n: u32| {
            let shift = COORD_BITS - level - n;
            let mask = (1 << n) - 1;
            ((qx >> shift) & mask, (qy >> shift) & mask)
        };
        let walked = self.walk_bilinear(w, path, at, |masses, b| match masses {
            Masses::Sixteen(_) => {
                let (gx, gy) = bits(b.cell.level, 2);
                Some(grandchild_index(gx, gy))
            }
            Masses::Four(_) => {
                let (dx, dy) = bits(b.cell.level, 1);
                Some((dx + 2 * dy) as usize)
            }
        });
        let Some((cell, path)) = walked else { return 0.0 };
        cell.density(path, &bilinear::sub_corners(w, cell.s, cell.t, cell.size), uv)
    }
}
