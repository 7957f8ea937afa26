//! Cells of the dyadic grids over the equal-area square: cell `(x, y)` of level `level` is the
//! square `[x, x + 1) × [y, y + 1) / 2^level`, with `x` along u and `y` along v. The
//! environment's pyramid, the product tree and the two-level product all index by them; a
//! cell's four children are numbered `dx + 2·dy` ([`crate::warp::child_offset`]) and stored in
//! Morton order ([`morton2`]).

use crate::warp::child_offset;
use glam::{DVec2, Vec2};

/// One cell of the `2^level × 2^level` grid over the square.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Cell {
    /// The grid's level: `2^level` cells per side.
    pub level: u32,
    /// Column, along u (`0 .. 2^level`).
    pub x: u32,
    /// Row, along v (`0 .. 2^level`).
    pub y: u32,
}

impl Cell {
    /// The whole square: the only cell of level 0.
    pub const ROOT: Self = Self { level: 0, x: 0, y: 0 };

    /// Cell `(x, y)` of `level`.
    #[inline(always)]
    #[must_use]
    pub const fn new(level: u32, x: u32, y: u32) -> Self {
        Self { level, x, y }
    }

    /// Child `k` (numbered `dx + 2·dy`, [`crate::warp::child_offset`]), one level down.
    #[inline(always)]
    #[must_use]
    pub fn child(self, k: usize) -> Self {
        let (dx, dy) = child_offset(k);
        Self { level: self.level + 1, x: 2 * self.x + dx, y: 2 * self.y + dy }
    }

    /// Grandchild (column `gx`, row `gy`) ∈ [0, 4)², two levels down.
    #[inline(always)]
    #[must_use]
    pub fn grandchild(self, gx: u32, gy: u32) -> Self {
        Self { level: self.level + 2, x: 4 * self.x + gx, y: 4 * self.y + gy }
    }

    /// The cell of `level` (≤ this cell's) that contains this one.
    #[inline(always)]
    #[must_use]
    pub fn ancestor(self, level: u32) -> Self {
        let shift = self.level - level;
        Self { level, x: self.x >> shift, y: self.y >> shift }
    }

    /// Index within its level in Morton order: [`morton2`]`(x, y)`.
    #[inline(always)]
    #[must_use]
    pub fn morton(self) -> usize {
        morton2(self.x, self.y)
    }

    /// 2^−level exactly, without a division: the cell's side (levels ≤ 126).
    #[inline(always)]
    #[must_use]
    pub fn side(self) -> f32 {
        f32::from_bits((127 - self.level) << 23)
    }

    /// 4^level exactly (no_std has no powi): the inverse of the cell's area.
    #[inline(always)]
    #[must_use]
    pub fn inverse_area(self) -> f64 {
        f64::from_bits((1023 + 2 * self.level as u64) << 52)
    }

    /// Places a uniform point `xi` ∈ [0,1)² inside the cell, returning square coordinates that
    /// are guaranteed to lie in it (f32 rounding could otherwise push a point onto the next
    /// cell's edge).
    #[inline]
    #[must_use]
    pub fn point(self, xi: DVec2) -> Vec2 {
        // 2^−level exactly, without a division.
        let inv = f64::from_bits((1023 - self.level as u64) << 52);
        let coord = |i: u32, f: f64| -> f32 {
            let lo = (i as f64 * inv) as f32; // exact: dyadic
            let hi = ((i + 1) as f64 * inv) as f32;
            let c = ((i as f64 + f) * inv) as f32;
            if c >= hi { next_down(hi).max(lo) } else { c.max(lo) }
        };
        Vec2::new(coord(self.x, xi.x), coord(self.y, xi.y))
    }

    /// [`point`](Self::point) of a point with f32 coordinates, in f32 and the same bits: the
    /// sum `i + f` rounds once in either precision (f64 holds more than twice f32's digits, so
    /// rounding through it is rounding once) and the scale by 2^−level is exact, so f32 needs
    /// no widening. For cells of level < 24 (their coordinates exact in f32).
    #[inline]
    #[must_use]
    pub fn point_f32(self, xi: Vec2) -> Vec2 {
        debug_assert!(self.level < 24);
        let inv = f32::from_bits((127 - self.level) << 23);
        let coord = |i: u32, f: f32| -> f32 {
            let lo = i as f32 * inv;
            let hi = (i + 1) as f32 * inv;
            let c = (i as f32 + f) * inv;
            if c >= hi { next_down(hi).max(lo) } else { c.max(lo) }
        };
        Vec2::new(coord(self.x, xi.x), coord(self.y, xi.y))
    }
}

/// Interleaves the bits of two 16-bit coordinates (x in the even bits): a cell's index within
/// its level of the pyramid.
#[inline]
#[must_use]
pub fn morton2(x: u32, y: u32) -> usize {
    // A byte's bits spread by table: two lookups per coordinate where the shifts and masks
    // take four steps.
    #[inline(always)]
    fn spread(v: u32) -> u32 {
        SPREAD_BYTE[(v & 0xFF) as usize] as u32 | (SPREAD_BYTE[((v >> 8) & 0xFF) as usize] as u32) << 16
    }
    (spread(x) | (spread(y) << 1)) as usize
}

/// Each byte's bits moved to the even bits of 16.
static SPREAD_BYTE: [u16; 256] = spread_bytes();

const fn spread_bytes() -> [u16; 256] {
    let mut t = [0u16; 256];
    let mut b = 0;
    while b < 256 {
        let mut v = b as u32;
        v = (v | (v << 4)) & 0x0F0F;
        v = (v | (v << 2)) & 0x3333;
        v = (v | (v << 1)) & 0x5555;
        t[b] = v as u16;
        b += 1;
    }
    t
}

/// The largest f32 below a positive finite `x`.
#[inline]
fn next_down(x: f32) -> f32 {
    if x <= 0.0 { x } else { f32::from_bits(x.to_bits() - 1) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn morton2_interleaves_the_bits() {
        let interleaved = |x: u32, y: u32| {
            (0..16).fold(0usize, |m, b| m | ((x >> b & 1) as usize) << (2 * b) | ((y >> b & 1) as usize) << (2 * b + 1))
        };
        for (x, y) in [(0, 0), (1, 0), (0, 1), (255, 256), (1023, 77), (0xFFFF, 0xFFFF), (0x1_2345, 0xABCD)] {
            assert_eq!(morton2(x, y), interleaved(x & 0xFFFF, y & 0xFFFF), "({x}, {y})");
        }
        for x in (0..0x1_0000).step_by(97) {
            assert_eq!(morton2(x, x ^ 0x5A5A), interleaved(x, x ^ 0x5A5A));
        }
    }

    #[test]
    fn side_is_the_division() {
        for level in 0..=24 {
            let side = Cell::new(level, 0, 0).side();
            assert_eq!(side.to_bits(), (1.0 / (1u64 << level) as f32).to_bits(), "{level}");
        }
    }

    #[test]
    fn children_and_ancestors_are_inverse() {
        let c = Cell::new(3, 5, 2);
        for k in 0..4 {
            assert_eq!(c.child(k).ancestor(3), c);
        }
        assert_eq!(c.child(3), Cell::new(4, 11, 5));
        assert_eq!(c.grandchild(1, 3), Cell::new(5, 21, 11));
        assert_eq!(c.grandchild(1, 3).ancestor(0), Cell::ROOT);
        assert_eq!(Cell::new(1, 1, 1).morton(), 3);
        assert_eq!(c.inverse_area(), 64.0);
    }

    #[test]
    fn f32_points_are_the_f64_points() {
        let mut rng = crate::rng::Pcg32::new(5, 6);
        let edges = [0.0, f32::MIN_POSITIVE, 1e-40, 0.5, 1.0 - f32::EPSILON / 2.0, f32::NAN];
        for level in [0u32, 1, 5, 11, 13, 16, 23] {
            let n = 1u32 << level;
            for k in 0..4000 {
                let (x, y) = (rng.next_u32() & (n - 1), rng.next_u32() & (n - 1));
                let unit = |r: u32| (r >> 8) as f32 * (1.0 / (1u32 << 24) as f32);
                let xi = if k < edges.len() * edges.len() {
                    Vec2::new(edges[k % edges.len()], edges[k / edges.len()])
                } else {
                    Vec2::new(unit(rng.next_u32()), f32::from_bits(rng.next_u32() % 0x3f80_0000))
                };
                let c = Cell::new(level, x, y);
                let (a, b) = (c.point(xi.as_dvec2()), c.point_f32(xi));
                assert_eq!((a.x.to_bits(), a.y.to_bits()), (b.x.to_bits(), b.y.to_bits()), "{c:?} {xi:?}");
            }
        }
    }

    #[test]
    fn points_stay_inside_their_cell() {
        let p = Cell::new(13, 8191, 8191).point(DVec2::splat(crate::warp::ONE_MINUS_EPSILON));
        assert!(p.x < 1.0 && p.y < 1.0);
        assert_eq!(crate::mapping::texel_of(p, 8192), (8191, 8191));
        let p = Cell::new(3, 5, 0).point(DVec2::new(crate::warp::ONE_MINUS_EPSILON, 0.0));
        assert_eq!(crate::mapping::texel_of(p, 8), (5, 0));
    }
}
