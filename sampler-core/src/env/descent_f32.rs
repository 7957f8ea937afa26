//! Env-only descents in f32: [`choose_grandchild_branchless`]'s two-level step with ξ, the sums
//! and the rescaling in f32, so that eight descents share an AVX2 register
//! (`descent_f32_avx2.rs`). This portable
//! step is the reference the register steps reproduce bit for bit: the same operations in the
//! same order, no fused multiply-adds, so images are the same on every CPU.
//!
//! f32 is enough for env-only sampling, unlike for the product's descents below their leaves:
//! every rounding moves a boundary between sides by a few ulps of the parent's share of ξ, so
//! the texels' probabilities differ from their densities by at most a few 2⁻²⁴ of the map per
//! level, and a side too small to hold any f32 ξ is left out — a side whose mass is below 2⁻²⁴
//! of its prefix (docs/perf.md#env-only-sampling-texel-table-cut-table). The density a sample
//! reports is its texel's, as for every other path. Sums beyond f32's range (masses near
//! `f32::MAX`) take the f64 step.

use super::EnvHierarchy;
use crate::cell::Cell;
use crate::prefetch::prefetch;
use crate::warp::{choose_child_branchless, choose_grandchild_branchless, grandchild_index};
use glam::{DVec2, Vec2};

/// Largest f32 below 1.
pub(super) const ONE_MINUS_EPSILON_F32: f32 = 1.0 - f32::EPSILON / 2.0;

/// Why a side could not be picked in f32.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Refusal {
    /// The weights sum to nothing: no mass below.
    Empty,
    /// The weights' sum overflows f32: the f64 step decides.
    Overflow,
}

/// One env-only descent of [`EnvHierarchy::descend_f32`]: its node and its point ξ in f32.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct DescentF32 {
    pub(super) cell: Cell,
    /// Morton index of the cell within its level.
    pub(super) morton: usize,
    pub(super) xi: Vec2,
    /// False once the descent met a node without mass (or never started).
    pub(super) alive: bool,
}

impl DescentF32 {
    /// A descent from the root with the point `u`, rounded to f32 and clamped into [0, 1)².
    pub(super) fn from_root(u: DVec2) -> Self {
        Self { cell: Cell::ROOT, morton: 0, xi: to_unit_f32(u), alive: true }
    }
}

/// `u` in f32, clamped into [0, 1)² (rounding to nearest keeps the points' order).
#[inline]
pub(super) fn to_unit_f32(u: DVec2) -> Vec2 {
    Vec2::new(u.x as f32, u.y as f32).clamp(Vec2::ZERO, Vec2::splat(ONE_MINUS_EPSILON_F32))
}

/// `pick_branchless` in f32: prefix sums, t = x·total, the side by the count of prefixes t
/// reached; a side without mass that rounding reached gives way to the last side with mass.
/// Returns the side, t's offset into it and its weight.
#[inline(always)]
fn pick_f32<const N: usize>(w: [f32; N], x: f32) -> Result<(usize, f32, f32), Refusal> {
    side_f32(w, x, |prefix, t| (1..N).map(|j| usize::from(t >= prefix[j])).sum::<usize>())
}

/// [`pick_f32`] with a branch per prefix passed, for a descent alone: a predicted branch lets
/// the next level's load start before the arithmetic ends (docs/tuning.md#batched-and-branch-free-sampling).
/// The prefixes do not decrease, so the side is the count's, and the result the same bits.
#[inline(always)]
fn pick_f32_branching<const N: usize>(w: [f32; N], x: f32) -> Result<(usize, f32, f32), Refusal> {
    side_f32(w, x, |prefix, t| {
        let mut i = 0;
        while i + 1 < N && t >= prefix[i + 1] {
            i += 1;
        }
        i
    })
}

/// The prefix sums of `w`, t = x·total and the side `find` gives for them, as [`pick_f32`] says.
#[inline(always)]
fn side_f32<const N: usize>(
    w: [f32; N],
    x: f32,
    find: impl FnOnce(&[f32; 4], f32) -> usize,
) -> Result<(usize, f32, f32), Refusal> {
    let mut prefix = [0.0f32; 4];
    prefix[1] = w[0];
    for i in 2..N {
        prefix[i] = prefix[i - 1] + w[i - 1];
    }
    let total = prefix[N - 1] + w[N - 1];
    if total.is_nan() || total <= 0.0 {
        return Err(Refusal::Empty);
    }
    if total == f32::INFINITY {
        return Err(Refusal::Overflow);
    }
    let t = x * total;
    let mut i = find(&prefix, t);
    if w[i].is_nan() || w[i] <= 0.0 {
        i = (0..N).rev().find(|&j| w[j] > 0.0).ok_or(Refusal::Empty)?;
    }
    Ok((i, t - prefix[i], w[i]))
}

/// A side chooser in f32: (weights, ξ) → (side, ξ's offset into it, its weight).
type PickF32<const N: usize> = fn([f32; N], f32) -> Result<(usize, f32, f32), Refusal>;

/// `v` clamped to [0, 1) (NaN stays NaN, as the register step's blends leave it).
#[inline(always)]
fn clamp_unit_f32(v: f32) -> f32 {
    v.clamp(0.0, ONE_MINUS_EPSILON_F32)
}

/// [`choose_grandchild_branchless`] in f32: the same choice of column then row, ξ rescaled as
/// `(ox / wx, oy / wy)` (two divisions: a product of two small weights would underflow f32).
#[inline(always)]
pub(super) fn choose_grandchild_f32(mass: &[f32; 16], xi: &mut Vec2) -> Option<(usize, u32, u32)> {
    grandchild_f32_by(mass, xi, pick_f32::<4>)
}

/// [`choose_grandchild_f32`] with a branch per prefix passed, for a descent alone: the same bits.
#[inline(always)]
fn choose_grandchild_f32_branching(mass: &[f32; 16], xi: &mut Vec2) -> Option<(usize, u32, u32)> {
    grandchild_f32_by(mass, xi, pick_f32_branching::<4>)
}

/// The column, then the row within it, each by `pick`; see [`choose_grandchild_f32`].
#[inline(always)]
fn grandchild_f32_by(mass: &[f32; 16], xi: &mut Vec2, pick: PickF32<4>) -> Option<(usize, u32, u32)> {
    let at = |x: usize, y: usize| mass[grandchild_index(x as u32, y as u32)];
    let cols: [f32; 4] = core::array::from_fn(|x| (at(x, 0) + at(x, 1)) + (at(x, 2) + at(x, 3)));
    let picked = pick(cols, xi.x).and_then(|(x, ox, wx)| {
        let rows: [f32; 4] = core::array::from_fn(|y| at(x, y));
        pick(rows, xi.y).map(|(y, oy, wy)| (x, ox, wx, y, oy, wy))
    });
    match picked {
        Ok((x, ox, wx, y, oy, wy)) => {
            *xi = Vec2::new(clamp_unit_f32(ox / wx), clamp_unit_f32(oy / wy));
            Some((grandchild_index(x as u32, y as u32), x as u32, y as u32))
        }
        Err(Refusal::Empty) => None,
        Err(Refusal::Overflow) => in_f64(xi, |d| choose_grandchild_branchless(mass, d)),
    }
}

/// [`choose_child_branchless`](crate::warp::choose_child_branchless) in f32, as
/// [`choose_grandchild_f32`]: the last level of a map of odd finest level.
#[inline(always)]
pub(super) fn choose_child_f32(mass: [f32; 4], xi: &mut Vec2) -> Option<usize> {
    let picked = pick_f32([mass[0] + mass[2], mass[1] + mass[3]], xi.x)
        .and_then(|(dx, ox, wx)| pick_f32([mass[dx], mass[dx + 2]], xi.y).map(|(dy, oy, wy)| (dx, ox, wx, dy, oy, wy)));
    match picked {
        Ok((dx, ox, wx, dy, oy, wy)) => {
            *xi = Vec2::new(clamp_unit_f32(ox / wx), clamp_unit_f32(oy / wy));
            Some(dx + 2 * dy)
        }
        Err(Refusal::Empty) => None,
        Err(Refusal::Overflow) => in_f64(xi, |d| choose_child_branchless(mass, d)),
    }
}

/// A step taken in f64 from the f32 point `xi`, the rescaled point rounded back into [0, 1).
#[cold]
fn in_f64<T>(xi: &mut Vec2, step: impl FnOnce(&mut DVec2) -> Option<T>) -> Option<T> {
    let mut d = xi.as_dvec2();
    let out = step(&mut d)?;
    *xi = to_unit_f32(d);
    Some(out)
}

impl EnvHierarchy<'_> {
    /// Warps `xi` from the root down to a finest-level texel ∝ importance, in f32: the single
    /// descent that [`descend_f32`](Self::descend_f32) runs side by side, with the same result
    /// (branching where the lanes count, as a descent alone waits on its loads).
    #[inline]
    pub(super) fn warp_down_f32(&self, xi: &mut Vec2) -> Option<Cell> {
        let (mut cell, mut m) = (Cell::ROOT, 0usize);
        while cell.level + 2 <= self.finest {
            let g: &[f32; 16] = self.nodes_below(cell.level, m).try_into().ok()?;
            let (c, gx, gy) = choose_grandchild_f32_branching(g, xi)?;
            (cell, m) = (cell.grandchild(gx, gy), 16 * m + c);
        }
        if cell.level < self.finest {
            let q = self.nodes_below(cell.level, m);
            cell = cell.child(choose_child_f32([q[0], q[1], q[2], q[3]], xi)?);
        }
        Some(cell)
    }

    /// Env-only descents from the root side by side, in f32: eight to an AVX2 register where
    /// the CPU has it, the same bits as the portable lanes. A black map's lanes all die.
    pub(super) fn descend_f32(&self, lanes: &mut [DescentF32]) {
        if self.is_black() {
            lanes.iter_mut().for_each(|l| l.alive = false);
            return;
        }
        #[cfg(target_arch = "x86_64")]
        self.descend_f32_avx2(lanes);
        self.descend_f32_scalar(lanes);
    }

    /// [`descend_f32`](Self::descend_f32) in scalar arithmetic, the lanes side by side so that
    /// their loads of a level are in flight together.
    pub(super) fn descend_f32_scalar(&self, lanes: &mut [DescentF32]) {
        loop {
            for lane in lanes.iter().filter(|l| l.alive && l.cell.level < self.finest) {
                prefetch(self.nodes_below(lane.cell.level, lane.morton));
            }
            let mut busy = false;
            for lane in lanes.iter_mut().filter(|l| l.alive && l.cell.level < self.finest) {
                busy = true;
                let nodes = self.nodes_below(lane.cell.level, lane.morton);
                if let Ok(g) = <&[f32; 16]>::try_from(nodes) {
                    match choose_grandchild_f32(g, &mut lane.xi) {
                        Some((c, gx, gy)) => {
                            (lane.cell, lane.morton) = (lane.cell.grandchild(gx, gy), 16 * lane.morton + c)
                        }
                        None => lane.alive = false,
                    }
                } else {
                    match choose_child_f32([nodes[0], nodes[1], nodes[2], nodes[3]], &mut lane.xi) {
                        Some(c) => (lane.cell, lane.morton) = (lane.cell.child(c), 4 * lane.morton + c),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::warp::grandchild_probability;

    #[test]
    fn f32_step_follows_the_mass_and_never_picks_an_empty_side() {
        let mut xi = Vec2::new(0.6, 0.3);
        let (c, x, y) = choose_grandchild_f32(&[1.0; 16], &mut xi).unwrap();
        assert_eq!((c, x, y), (2 | 4, 2, 1));
        assert!((xi - Vec2::new(0.4, 0.2)).abs().max_element() < 1e-6);
        for &u in &[0.0, 0.3, ONE_MINUS_EPSILON_F32] {
            let mut m = [0.0f32; 16];
            m[13] = 5.0;
            let mut xi = Vec2::new(u, ONE_MINUS_EPSILON_F32 - u);
            assert_eq!(choose_grandchild_f32(&m, &mut xi).unwrap(), (13, 3, 2));
            assert!((0.0..1.0).contains(&xi.x) && (0.0..1.0).contains(&xi.y));
        }
        assert!(choose_grandchild_f32(&[0.0; 16], &mut Vec2::ZERO.clone()).is_none());
        assert!(choose_child_f32([0.0; 4], &mut Vec2::ZERO.clone()).is_none());
        assert_eq!(choose_child_f32([0.0, 0.0, 0.0, 3.0], &mut Vec2::splat(0.0)), Some(3));
    }

    #[test]
    fn f32_step_picks_in_proportion_to_mass() {
        // A stratified grid of ξ: each grandchild's share is its mass's, to the grid's resolution.
        let mass: [f32; 16] = core::array::from_fn(|i| [0.0, 1.0, 3.5, 0.25][i % 4] * (1 + i / 4) as f32);
        let n = 1024;
        let mut hits = [0usize; 16];
        for i in 0..n {
            for j in 0..n {
                let mut xi = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                hits[choose_grandchild_f32(&mass, &mut xi).unwrap().0] += 1;
                assert!((0.0..1.0).contains(&xi.x) && (0.0..1.0).contains(&xi.y));
            }
        }
        for k in 0..16 {
            let p = grandchild_probability(&mass, k);
            assert!((hits[k] as f64 / (n * n) as f64 - p).abs() < 4.0 / n as f64, "{k}: {hits:?}");
        }
    }

    #[test]
    fn sums_beyond_f32_take_the_f64_step() {
        let mut xi = Vec2::new(0.7, 0.2);
        let (c, x, _) = choose_grandchild_f32(&[f32::MAX; 16], &mut xi).unwrap();
        assert_eq!(x, 2);
        assert_eq!(c & 1, 0);
        assert!((xi.x - 0.8).abs() < 1e-6 && (0.0..1.0).contains(&xi.y));
    }
}
