//! The build's probes of B: B·cos at a cell's centre (at its corners where that is 0), for the
//! empty cells the counts say are dim, the leaves under [`Leaves::Probed`](super::Leaves) and
//! the refinement's children. The cells of one node are probed side by side, four lanes of
//! the BRDF's [`eval_luminance_x4`](crate::brdf::Brdf::eval_luminance_x4), each lane bit for bit
//! the one-at-a-time probe; so are the four corners of a cell whose centre reads 0.

use super::quadtree::{EVAL_EMPTY_FROM, TreeBuilder};
use crate::cell::Cell;
use glam::{Vec2, Vec4};

impl<F, G, const NODES: usize, const CORNERS: usize> TreeBuilder<'_, '_, F, G, NODES, CORNERS>
where
    F: FnMut(Vec2) -> f32,
    G: FnMut(Vec4, Vec4) -> Vec4,
{
    /// B at the centres of the children of `cell` (whose samples `bounds` splits, `n` of them)
    /// that the build probes, side by side (`probe4`): the empty children where the counts are
    /// strong evidence (n ≥ [`EVAL_EMPTY_FROM`]) and, with probed leaves, the children that are
    /// leaves of one sample. +∞ (unknown) for the others.
    pub(super) fn probe_children(&mut self, cell: Cell, n: usize, bounds: &[usize; 5]) -> [f32; 4] {
        let mut out = [f32::INFINITY; 4];
        let empty = |c: usize| bounds[c + 1] == bounds[c];
        let any_empty = empty(0) || empty(1) || empty(2) || empty(3);
        if self.bilinear || !(self.probe_leaves || (n >= EVAL_EMPTY_FROM && any_empty)) {
            return out;
        }
        let mut which = [0usize; 4];
        let mut cells = [cell; 4];
        let mut count = 0;
        for c in 0..4 {
            let samples = bounds[c + 1] - bounds[c];
            if (samples == 0 && n >= EVAL_EMPTY_FROM) || (samples == 1 && self.probe_leaves) {
                (which[count], cells[count]) = (c, cell.child(c));
                count += 1;
            }
        }
        if count == 1 {
            out[which[0]] = self.probe(cells[0]);
        } else if count > 1 {
            let probes = self.probe4(&cells[..count]);
            for k in 0..count {
                out[which[k]] = probes[k];
            }
        }
        out
    }

    /// B·cos at the centre of `cell`; where that is 0 (e.g. below the
    /// surface), the largest of its four corners (inset by 1/64 of the cell), so that a cell
    /// straddling the horizon is not zeroed. NaN reads as unknown (+∞: keep the count fill).
    pub(super) fn probe(&mut self, cell: Cell) -> f32 {
        let centre = read_probe((self.eval)(at(cell, 0.5, 0.5)));
        if centre > 0.0 { centre } else { self.probe_corners(cell) }
    }

    /// [`probe`](Self::probe) of up to four cells (`cells[k]` into lane k), their centres
    /// evaluated side by side.
    pub(super) fn probe4(&mut self, cells: &[Cell]) -> [f32; 4] {
        let centres: [Vec2; 4] = core::array::from_fn(|k| at(cells[k.min(cells.len() - 1)], 0.5, 0.5));
        let (u, v) = lanes(centres);
        let centre = (self.eval4)(u, v).to_array().map(read_probe);
        let mut out = [0.0f32; 4];
        for (k, &cell) in cells.iter().enumerate() {
            out[k] = if centre[k] > 0.0 { centre[k] } else { self.probe_corners(cell) };
        }
        out
    }

    /// The largest reading of B·cos at the four corners of `cell`, inset by 1/64 of the cell,
    /// evaluated side by side (each lane bit for bit the scalar evaluation, in the same order).
    fn probe_corners(&mut self, cell: Cell) -> f32 {
        let (a, b) = (1.0 / 64.0, 63.0 / 64.0);
        let (u, v) = lanes([at(cell, a, a), at(cell, b, a), at(cell, a, b), at(cell, b, b)]);
        (self.eval4)(u, v).to_array().into_iter().map(read_probe).fold(0.0, f32::max)
    }
}

/// The point (s, t) of `cell` in units of its side.
#[inline(always)]
fn at(cell: Cell, s: f32, t: f32) -> Vec2 {
    let (Cell { x, y, .. }, inv) = (cell, cell.side());
    Vec2::new((x as f32 + s) * inv, (y as f32 + t) * inv)
}

/// Four points' coordinates in lanes.
#[inline(always)]
fn lanes(p: [Vec2; 4]) -> (Vec4, Vec4) {
    (Vec4::from_array(p.map(|q| q.x)), Vec4::from_array(p.map(|q| q.y)))
}

/// A probe's reading of B·cos: NaN is unknown (+∞), negative is 0.
#[inline(always)]
fn read_probe(v: f32) -> f32 {
    if v.is_nan() { f32::INFINITY } else { v.max(0.0) }
}
