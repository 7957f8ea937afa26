//! Env-only sampling through the hierarchy: a point warped down the pyramid's levels to a
//! texel ∝ importance, then placed uniformly inside it.

use super::EnvHierarchy;
use super::descent_f32::to_unit_f32;
use super::pyramid::level_offset;
use crate::cell::Cell;
use crate::direction::DirectionSample;
use crate::mapping::SPHERE_AREA;
use crate::warp::{choose_child, choose_grandchild};
use glam::{DVec2, Vec2};

impl EnvHierarchy<'_> {
    /// Warps `xi` from `node` down to a finest-level texel, ∝ importance. Returns the texel,
    /// or `None` if the node has no mass.
    #[inline]
    pub fn warp_down(&self, node: Cell, xi: &mut DVec2) -> Option<Cell> {
        // Two levels per step over the 16 grandchildren (one cache line), and raw pyramid
        // values: the choice only needs ratios, so the 1/mean scale is left out.
        let (mut cell, mut m) = (node, node.morton());
        while cell.level + 2 <= self.finest {
            let base = level_offset(cell.level + 2) + 16 * m;
            let g: &[f32; 16] = self.pyramid[base..base + 16].try_into().ok()?;
            let (c, gx, gy) = choose_grandchild(g, xi)?;
            (cell, m) = (cell.grandchild(gx, gy), 16 * m + c);
        }
        if cell.level < self.finest {
            let base = level_offset(cell.level + 1) + 4 * m;
            let q = &self.pyramid[base..base + 4];
            cell = cell.child(choose_child([q[0], q[1], q[2], q[3]], xi)?);
        }
        Some(cell)
    }

    /// Draws a direction with density ∝ importance (env-only sampling through the hierarchy, in
    /// f32 as [`sample_many`](Self::sample_many) does, or through the texel table where one is
    /// attached).
    #[inline]
    pub fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        if self.is_black() {
            return None;
        }
        if let Some(cdf) = &self.cdf {
            let (uv, pdf) = cdf.sample_point(u.clamp(DVec2::ZERO, DVec2::splat(crate::warp::ONE_MINUS_EPSILON)));
            return Some(DirectionSample { dir: self.dir_of(uv), uv, pdf });
        }
        let mut xi = to_unit_f32(u);
        let texel = self.warp_down_f32(&mut xi)?;
        Some(self.sample_in_texel(texel, xi))
    }

    /// The sample at point `xi` of a finest-level texel, with its density (solid angle).
    #[inline]
    fn sample_in_texel(&self, texel: Cell, xi: Vec2) -> DirectionSample {
        let uv = texel.point_f32(xi);
        DirectionSample { dir: self.dir_of(uv), uv, pdf: self.node_relative(texel) / SPHERE_AREA }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::build_pyramid;
    use glam::Vec3;

    #[test]
    fn black_map_samples_nothing() {
        let rgb = [[0.0f32; 3]; 4];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &rgb, &mut p).unwrap();
        let env = EnvHierarchy::new(1, &p, &rgb).unwrap();
        assert!(env.is_black());
        assert!(env.sample(DVec2::splat(0.3)).is_none());
        assert_eq!(env.pdf(Vec3::Z), 0.0);
    }
}
