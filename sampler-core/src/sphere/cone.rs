//! Cones of directions, and the bounding cone of every cell of the equal-area square at one
//! level of the environment's pyramid: the two-level product ([`crate::two_level`]) bounds a
//! BRDF over each cell through its cone ([`crate::brdf::Brdf::cone_bounds`]).

use crate::cell::Cell;
use crate::mapping::square_to_sphere;
use glam::{Vec2, Vec3};

/// The directions within `angle` radians of a unit `axis`, with the angle's cosine and sine.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Unit direction at the cone's centre.
    pub axis: Vec3,
    /// Half-angle θc in radians, in [0, π].
    pub angle: f32,
    /// cos θc.
    pub cos: f32,
    /// sin θc.
    pub sin: f32,
}

impl Default for Cone {
    /// The whole sphere.
    fn default() -> Self {
        Self::new(Vec3::Z, core::f32::consts::PI)
    }
}

impl Cone {
    /// The cone of half-angle `angle` (clamped to [0, π]) about the unit vector `axis`.
    #[must_use]
    pub fn new(axis: Vec3, angle: f32) -> Self {
        let angle = angle.clamp(0.0, core::f32::consts::PI);
        Self { axis, angle, cos: libm::cosf(angle), sin: libm::sinf(angle) }
    }

    /// The same cone with its axis taken through the rows of a rotation (`rows[i]·axis`): how a
    /// cone of the map's frame enters a shading frame.
    #[inline]
    #[must_use]
    pub fn rotated(&self, rows: &[Vec3; 3]) -> Self {
        Self { axis: Vec3::new(rows[0].dot(self.axis), rows[1].dot(self.axis), rows[2].dot(self.axis)), ..*self }
    }

    /// (cos, sin) of the angle between the axis and the unit vector `dir`: the sine from the
    /// cross product, which stays accurate for small angles.
    #[inline]
    #[must_use]
    pub fn cos_sin_to(&self, dir: Vec3) -> (f32, f32) {
        (self.axis.dot(dir).clamp(-1.0, 1.0), self.axis.cross(dir).length().min(1.0))
    }

    /// The cosine of the smallest angle between the unit vector `dir` and a direction of the
    /// cone: cos(max(0, θ − θc)), θ the angle from the axis to `dir`. Negative when the whole
    /// cone lies more than 90° from `dir`.
    #[inline]
    #[must_use]
    pub fn max_cos(&self, dir: Vec3) -> f32 {
        let (c, s) = self.cos_sin_to(dir);
        if c >= self.cos { 1.0 } else { c * self.cos + s * self.sin }
    }

    /// The cosine of the largest angle between the unit vector `dir` and a direction of the
    /// cone: cos(min(π, θ + θc)).
    #[inline]
    #[must_use]
    pub fn min_cos(&self, dir: Vec3) -> f32 {
        let (c, s) = self.cos_sin_to(dir);
        if c <= -self.cos { -1.0 } else { c * self.cos - s * self.sin }
    }
}

/// Cells of one level of the square: `4^level`.
#[inline]
#[must_use]
pub const fn cell_count(level: u32) -> usize {
    1 << (2 * level)
}

/// The level whose cell count is `cells`, if it is a power of four.
#[must_use]
pub fn level_of(cells: usize) -> Option<u32> {
    (cells.is_power_of_two() && cells.trailing_zeros().is_multiple_of(2)).then_some(cells.trailing_zeros() / 2)
}

/// The inverse of [`crate::cell::morton2`]: the cell `(x, y)` at Morton index `m`.
#[inline]
#[must_use]
pub fn morton_cell(m: usize) -> (u32, u32) {
    fn compact(v: u32) -> u32 {
        let mut v = v & 0x5555_5555;
        v = (v | (v >> 1)) & 0x3333_3333;
        v = (v | (v >> 2)) & 0x0F0F_0F0F;
        v = (v | (v >> 4)) & 0x00FF_00FF;
        (v | (v >> 8)) & 0x0000_FFFF
    }
    (compact(m as u32), compact((m >> 1) as u32))
}

/// Points per cell edge at which [`cell_cone`] measures the boundary.
const EDGE_POINTS: u32 = 32;

/// An upper bound of how fast [`square_to_sphere`] moves (radians per unit of the square, in
/// any direction, anywhere): the boundary is measured at discrete points, and between two of
/// them the image cannot stray further than this times half their distance
/// (`cell_cones_contain_their_cells` checks it).
const STRETCH: f32 = 8.0;

/// Extra half-angle that absorbs the rounding of the bounds computed from a cone.
const SLACK: f32 = 1e-3;

/// A cone that contains every direction of `cell`. The image of a cell is a
/// disk-like region that does not reach its axis's antipode, so the angle from the axis is
/// largest on the cell's boundary: measured there at evenly spaced points, plus what
/// can hide between them.
#[must_use]
pub fn cell_cone(cell: Cell) -> Cone {
    let Cell { level, x, y } = cell;
    let size = 1.0 / (1u32 << level) as f32;
    let origin = Vec2::new(x as f32, y as f32) * size;
    let axis = square_to_sphere(origin + Vec2::splat(0.5 * size)).normalize();
    let step = size / EDGE_POINTS as f32;
    let mut widest = 0.0f32;
    for k in 0..=EDGE_POINTS {
        let t = k as f32 * step;
        for p in [Vec2::new(t, 0.0), Vec2::new(t, size), Vec2::new(0.0, t), Vec2::new(size, t)] {
            let d = square_to_sphere(origin + p);
            widest = widest.max(libm::atan2f(axis.cross(d).length(), axis.dot(d)));
        }
    }
    Cone::new(axis, widest + 0.5 * STRETCH * step + SLACK)
}

/// A half-angle within which every direction of a cell of `level` lies around its centre's
/// direction: the equal-area map's stretch bound times half the cell's diagonal, plus the
/// rounding slack. Coarser than [`cell_cone`]'s measured angle, and free to compute.
#[must_use]
pub fn cell_radius_bound(level: u32) -> f32 {
    let size = 1.0 / (1u32 << level) as f32;
    0.5 * STRETCH * core::f32::consts::SQRT_2 * size + SLACK
}

/// Fills `out` (length `4^level`, Morton order like the pyramid's levels) with every cell's
/// [`cell_cone`]. Returns false, writing nothing, when the length is not a power of four.
pub fn build_cell_cones(out: &mut [Cone]) -> bool {
    let Some(level) = level_of(out.len()) else { return false };
    for (m, cone) in out.iter_mut().enumerate() {
        let (x, y) = morton_cell(m);
        *cone = cell_cone(Cell::new(level, x, y));
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::morton2;
    use crate::rng::Pcg32;

    #[test]
    fn morton_cell_inverts_morton2() {
        for m in 0..4096 {
            let (x, y) = morton_cell(m);
            assert_eq!(morton2(x, y), m);
        }
    }

    #[test]
    fn the_mapping_moves_no_faster_than_the_stretch_bound() {
        // Finite differences over a fine grid, in both axes and diagonally.
        let h = 1e-4f32;
        let mut fastest = 0.0f32;
        for j in 0..400 {
            for i in 0..400 {
                let p = Vec2::new((i as f32 + 0.5) / 400.0, (j as f32 + 0.5) / 400.0);
                let d = square_to_sphere(p);
                for e in [Vec2::new(h, 0.0), Vec2::new(0.0, h), Vec2::new(h, h) * core::f32::consts::FRAC_1_SQRT_2] {
                    let q = (p + e).clamp(Vec2::ZERO, Vec2::ONE);
                    let a = libm::atan2f(d.cross(square_to_sphere(q)).length(), d.dot(square_to_sphere(q)));
                    fastest = fastest.max(a / (q - p).length());
                }
            }
        }
        assert!(fastest < STRETCH, "{fastest}");
    }

    #[test]
    fn cell_cones_contain_their_cells() {
        let mut rng = Pcg32::new(1, 2);
        for level in 0..=6u32 {
            let n = 1u32 << level;
            for y in 0..n {
                for x in 0..n {
                    let cone = cell_cone(Cell::new(level, x, y));
                    for _ in 0..64 {
                        let p = (Vec2::new(x as f32, y as f32) + Vec2::new(rng.next_f32(), rng.next_f32())) / n as f32;
                        let d = square_to_sphere(p);
                        let angle = libm::atan2f(cone.axis.cross(d).length(), cone.axis.dot(d));
                        assert!(angle <= cone.angle - 0.5 * SLACK, "level {level} cell ({x}, {y}): {angle} > {cone:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn the_radius_bound_holds_every_direction_of_a_cell_around_its_centre() {
        let mut rng = Pcg32::new(5, 6);
        for level in [2u32, 5, 8, 10, 12] {
            let (n, bound) = (1u32 << level, cell_radius_bound(level));
            for _ in 0..20_000 {
                let (x, y) = (rng.next_u32() % n, rng.next_u32() % n);
                let corner = Vec2::new(x as f32, y as f32);
                let centre = square_to_sphere((corner + Vec2::splat(0.5)) / n as f32);
                // Corners and edges too, where the angle is largest.
                let xi = Vec2::new(rng.next_f32(), rng.next_f32()).map(|v| if v < 0.2 { 0.0 } else { v });
                let d = square_to_sphere((corner + xi) / n as f32);
                let angle = libm::atan2f(centre.cross(d).length(), centre.dot(d));
                assert!(angle <= bound - 0.5 * SLACK, "level {level} cell ({x}, {y}): {angle} > {bound}");
            }
        }
    }

    #[test]
    fn max_and_min_cos_bound_every_direction_of_the_cone() {
        let mut rng = Pcg32::new(3, 4);
        for _ in 0..2000 {
            let axis = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            let cone = Cone::new(axis, rng.next_f32() * 1.5);
            let dir = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            let (hi, lo) = (cone.max_cos(dir), cone.min_cos(dir));
            let frame = crate::frame::Frame::from_normal(axis);
            for _ in 0..32 {
                let (t, phi) = (rng.next_f32() * cone.angle, rng.next_f32() * core::f32::consts::TAU);
                let local = Vec3::new(libm::sinf(t) * libm::cosf(phi), libm::sinf(t) * libm::sinf(phi), libm::cosf(t));
                let c = frame.to_world(local).dot(dir);
                assert!(c <= hi + 1e-5 && c >= lo - 1e-5, "{c} outside [{lo}, {hi}]");
            }
        }
    }
}
