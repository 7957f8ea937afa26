//! The borrowed view over a caller-owned pyramid: its nodes relative to the mean, radiance
//! lookups and the env-only density; the map's orientation is in `frame.rs`.

use super::pyramid::{EnvError, check_lengths, level_offset, pyramid_index};
use super::texel_cdf::TexelCdf;
use crate::cell::{Cell, morton2};
use crate::mapping::{SPHERE_AREA, texel_of};
use crate::prefetch::prefetch;
use glam::{Mat3, Vec2, Vec3};

/// 1 / the pyramid's mean importance (its root), or 0 for a black map.
pub(super) fn inverse_mean(pyramid: &[f32]) -> Result<f32, EnvError> {
    let mean = pyramid[0];
    if !mean.is_finite() || mean < 0.0 {
        return Err(EnvError::NotSanitized);
    }
    let inv_mean = if mean > 0.0 { 1.0 / mean } else { 0.0 };
    Ok(if inv_mean.is_finite() { inv_mean } else { 0.0 })
}

/// Borrowed view over a sanitized environment pyramid, with an optional world rotation.
#[derive(Clone, Copy, Debug)]
pub struct EnvHierarchy<'a> {
    pub(crate) finest: u32,
    pub(crate) pyramid: &'a [f32],
    pub(super) radiance: &'a [[f32; 3]],
    /// 1 / mean importance, or 0 for a black map.
    pub(super) inv_mean: f32,
    tint: Vec3,
    pub(super) world_to_map: Mat3,
    pub(super) map_to_world: Mat3,
    /// The texel table env-only sampling uses instead of the descent, when attached.
    pub(crate) cdf: Option<TexelCdf<'a>>,
    /// The MIS-compensated pyramid ([`compensate_pyramid`](super::compensate_pyramid)) and its
    /// `inv_mean`, when attached.
    pub(super) compensated: Option<(&'a [f32], f32)>,
    /// How MIS weighs this view's samples against BRDF samples.
    pub(super) mis_heuristic: super::MisHeuristic,
}

impl<'a> EnvHierarchy<'a> {
    /// A view over `pyramid` (filled by [`build_pyramid`](super::build_pyramid)) and the finest-level `radiance`.
    pub fn new(finest: u32, pyramid: &'a [f32], radiance: &'a [[f32; 3]]) -> Result<Self, EnvError> {
        check_lengths(finest, radiance.len(), pyramid.len())?;
        Ok(Self {
            finest,
            pyramid,
            radiance,
            inv_mean: inverse_mean(pyramid)?,
            tint: Vec3::ONE,
            world_to_map: Mat3::IDENTITY,
            map_to_world: Mat3::IDENTITY,
            cdf: None,
            compensated: None,
            mis_heuristic: super::MisHeuristic::Balance,
        })
    }

    /// Samples env-only through `cdf` (built by [`build_texel_cdf`](super::build_texel_cdf)
    /// from this pyramid) instead of descending the pyramid: [`sample`](Self::sample),
    /// [`sample_many`](Self::sample_many), [`pdf_square`](Self::pdf_square) and
    /// [`pdf`](Self::pdf) then follow the table's quantized density. The product samplers keep
    /// descending the pyramid below their leaves.
    pub fn with_texel_cdf(mut self, cdf: TexelCdf<'a>) -> Result<Self, EnvError> {
        if cdf.finest_level() != self.finest {
            return Err(EnvError::WrongLength {
                buffer: "texel table",
                expected: super::texel_cdf_len(self.finest),
                found: super::texel_cdf_len(cdf.finest_level()),
            });
        }
        self.cdf = Some(cdf);
        Ok(self)
    }

    /// The texel table env-only sampling uses, if one is attached.
    #[inline]
    #[must_use]
    pub fn texel_cdf(&self) -> Option<&TexelCdf<'a>> {
        self.cdf.as_ref()
    }

    /// Orients the map: `map_to_world` takes directions of the map's own frame (the frame
    /// [`square_to_sphere`](crate::mapping::square_to_sphere) works in) to world space. Must be a rotation.
    #[must_use]
    pub fn with_rotation(mut self, map_to_world: Mat3) -> Self {
        self.map_to_world = map_to_world;
        self.world_to_map = map_to_world.transpose();
        self
    }

    /// Multiplies every radiance lookup (e.g. a light's colour × intensity). Sampling
    /// densities are unaffected.
    #[must_use]
    pub fn with_tint(mut self, tint: Vec3) -> Self {
        self.tint = tint;
        self
    }

    /// Finest level `K` (the map is `2^K × 2^K`).
    #[inline]
    #[must_use]
    pub fn finest_level(&self) -> u32 {
        self.finest
    }

    /// Side length of the finest level in texels.
    #[inline]
    #[must_use]
    pub fn resolution(&self) -> u32 {
        1 << self.finest
    }

    /// True when the map is black everywhere: nothing to sample, every estimate is 0.
    #[inline]
    #[must_use]
    pub fn is_black(&self) -> bool {
        self.inv_mean == 0.0
    }

    /// Mean importance of a node (a cell of level ≤ K), relative to the whole map's mean (so
    /// the map averages to 1 whatever its absolute scale).
    #[inline]
    #[must_use]
    pub fn node_relative(&self, node: Cell) -> f32 {
        self.pyramid[pyramid_index(node)] * self.inv_mean
    }

    /// [`node_relative`](Self::node_relative) of the node of `level` whose Morton index within
    /// its level is `morton`, for callers that carry it down a descent.
    #[inline]
    #[must_use]
    pub fn node_relative_at(&self, level: u32, morton: usize) -> f32 {
        self.pyramid[level_offset(level) + morton] * self.inv_mean
    }

    /// The 16 grandchildren of a node of level < K − 1, as stored
    /// (not relative to the mean: for ratios), in the Morton order of
    /// [`crate::warp::choose_grandchild`] — one cache line.
    #[inline]
    #[must_use]
    pub fn grandchildren_raw(&self, node: Cell) -> &[f32; 16] {
        let base = level_offset(node.level + 2) + 16 * node.morton();
        self.pyramid[base..base + 16].try_into().expect("16 grandchildren")
    }

    /// The four children of a node of level < K, relative to the mean,
    /// in [`child_offset`](crate::warp::child_offset) order.
    #[inline]
    #[must_use]
    pub fn children_relative(&self, node: Cell) -> [f32; 4] {
        self.children_relative_at(node.level, node.morton())
    }

    /// [`children_relative`](Self::children_relative) of the node of `level` whose Morton
    /// index within its level is `morton`, for callers that carry it down a descent.
    #[inline]
    #[must_use]
    pub fn children_relative_at(&self, level: u32, morton: usize) -> [f32; 4] {
        let base = level_offset(level + 1) + 4 * morton;
        let q = &self.pyramid[base..base + 4];
        let s = self.inv_mean;
        [q[0] * s, q[1] * s, q[2] * s, q[3] * s]
    }

    /// Asks the memory system for the 16 grandchildren of the node of `level` whose Morton
    /// index within its level is `morton` (what [`children_relative_at`](Self::children_relative_at)
    /// of its children reads), ahead of reading them: a hint that changes no result, and nothing
    /// where the node has no grandchildren in the map.
    #[inline]
    pub fn prefetch_grandchildren_at(&self, level: u32, morton: usize) {
        if level + 2 <= self.finest {
            let base = level_offset(level + 2) + 16 * morton;
            if let Some(block) = self.pyramid.get(base..base + 16) {
                prefetch(block);
            }
        }
    }

    /// How peaked the lighting is at a scale: the largest node of `level` (clamped to the
    /// finest) relative to the mean — 1 for a constant map, and in the hundreds for a sky with
    /// a sun at level 5 (cells ~6.4° wide). A cheap test of whether sampling the lighting can
    /// pay.
    #[must_use]
    pub fn peak(&self, level: u32) -> f32 {
        let level = level.min(self.finest);
        let n = 1u32 << level;
        let mut max = 0.0f32;
        for y in 0..n {
            for x in 0..n {
                max = max.max(self.node_relative(Cell::new(level, x, y)));
            }
        }
        if max.is_finite() { max } else { f32::MAX }
    }

    /// Mean importance (relative) of the region covered by a quadtree cell at any depth:
    /// below the finest level a cell lies inside one texel.
    #[inline]
    #[must_use]
    pub fn cell_relative(&self, cell: Cell) -> f32 {
        if cell.level <= self.finest {
            self.node_relative(cell)
        } else {
            self.node_relative(cell.ancestor(self.finest))
        }
    }

    /// Finest-level texel containing a point of the square.
    #[inline]
    #[must_use]
    pub fn texel_at(&self, uv: Vec2) -> (u32, u32) {
        texel_of(uv, self.resolution())
    }

    /// RGB radiance of a finest-level texel (tint applied).
    #[inline]
    #[must_use]
    pub fn radiance_texel(&self, x: u32, y: u32) -> Vec3 {
        let i = y as usize * self.resolution() as usize + x as usize;
        Vec3::from_array(self.radiance[i]) * self.tint
    }

    /// RGB radiance arriving from world direction `dir` (nearest texel).
    #[inline]
    #[must_use]
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.radiance_at(self.square_of(dir))
    }

    /// RGB radiance at a point of the square (nearest texel): for samplers that drew the point,
    /// no round trip through the direction.
    #[inline]
    #[must_use]
    pub fn radiance_at(&self, uv: Vec2) -> Vec3 {
        let (x, y) = self.texel_at(uv);
        self.radiance_texel(x, y)
    }

    /// Asks the memory system for what [`radiance_texel`](Self::radiance_texel) and
    /// [`pdf_square`](Self::pdf_square) read at texel (x, y) ([`texel_at`](Self::texel_at)),
    /// ahead of reading it: a hint that changes no result.
    #[inline(always)]
    pub fn prefetch_texel(&self, x: u32, y: u32) {
        self.prefetch_radiance(x, y);
        match &self.cdf {
            Some(cdf) => cdf.prefetch(morton2(x, y)),
            None => {
                let node = pyramid_index(Cell::new(self.finest, x, y));
                prefetch(&self.pyramid[node..=node]);
            }
        }
    }

    /// Asks the memory system for what [`radiance_texel`](Self::radiance_texel) reads at
    /// texel (x, y) alone: for a sampler's own draws, whose density comes with the draw.
    #[inline(always)]
    pub fn prefetch_radiance(&self, x: u32, y: u32) {
        let i = y as usize * self.resolution() as usize + x as usize;
        prefetch(&self.radiance[i..=i]);
    }

    /// Env-only density per unit area of the square at `uv` (mean 1 over the square): the
    /// texel table's where one is attached, else the texel's importance relative to the mean.
    #[inline]
    #[must_use]
    pub fn pdf_square(&self, uv: Vec2) -> f32 {
        let (x, y) = self.texel_at(uv);
        match &self.cdf {
            Some(cdf) => cdf.relative(morton2(x, y)),
            None => self.node_relative(Cell::new(self.finest, x, y)),
        }
    }

    /// The importance of the finest-level texel at `uv` relative to the map's mean: the
    /// pyramid's env-only density, which the product samplers continue below their leaves.
    #[inline]
    #[must_use]
    pub fn texel_relative(&self, uv: Vec2) -> f32 {
        let (x, y) = self.texel_at(uv);
        self.node_relative(Cell::new(self.finest, x, y))
    }

    /// Env-only density with respect to solid angle of world direction `dir`.
    #[inline]
    #[must_use]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        self.pdf_square(self.square_of(dir)) / SPHERE_AREA
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{build_pyramid, luminance};

    #[test]
    fn children_are_the_next_level_and_average_to_the_parent() {
        let mut rgb = [[0.0f32; 3]; 64];
        for (i, t) in rgb.iter_mut().enumerate() {
            *t = [(i * 7 % 11) as f32, 1.0, (i % 5) as f32];
        }
        let mut p = [0.0f32; 85];
        build_pyramid(3, &rgb, &mut p).unwrap();
        let e = EnvHierarchy::new(3, &p, &rgb).unwrap();
        for l in 0..3u32 {
            for y in 0..(1u32 << l) {
                for x in 0..(1u32 << l) {
                    let c = e.children_relative(Cell::new(l, x, y));
                    let at = |dx, dy| e.node_relative(Cell::new(l + 1, 2 * x + dx, 2 * y + dy));
                    assert_eq!(c, [at(0, 0), at(1, 0), at(0, 1), at(1, 1)]);
                    let mean = 0.25 * c.iter().sum::<f32>();
                    assert!((mean - e.node_relative(Cell::new(l, x, y))).abs() <= 1e-6 * mean);
                }
            }
        }
        // The finest level reads back the row-major input.
        assert_eq!(e.node_relative(Cell::new(3, 5, 2)) / e.inv_mean, luminance(Vec3::from_array(rgb[2 * 8 + 5])));
    }

    #[test]
    fn huge_radiance_does_not_overflow_the_mean() {
        let rgb = [[3.0e38f32; 3]; 4];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &rgb, &mut p).unwrap();
        assert!(p[0].is_finite());
        let env = EnvHierarchy::new(1, &p, &rgb).unwrap();
        assert!((env.node_relative(Cell::new(1, 1, 1)) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn peak_measures_how_concentrated_the_light_is() {
        // 8×8 map: constant → 1; one texel 64× brighter than the others.
        let mut rgb = [[1.0f32; 3]; 64];
        let mut p = [0.0f32; 85];
        build_pyramid(3, &rgb, &mut p).unwrap();
        assert!((EnvHierarchy::new(3, &p, &rgb).unwrap().peak(5) - 1.0).abs() < 1e-6);
        rgb[9] = [64.0; 3];
        build_pyramid(3, &rgb, &mut p).unwrap();
        let env = EnvHierarchy::new(3, &p, &rgb).unwrap();
        // Mean (63 + 64)/64; at level 3 the bright texel is its own block, at level 1 it
        // shares a block with 15 others.
        let mean = 127.0 / 64.0;
        assert!((env.peak(5) - 64.0 / mean).abs() < 1e-4);
        assert!((env.peak(1) - (15.0 + 64.0) / 16.0 / mean).abs() < 1e-4);
        assert!((env.peak(0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn wrong_lengths_are_errors() {
        let rgb = [[0.0f32; 3]; 4];
        let p = [0.0f32; 4];
        assert!(matches!(EnvHierarchy::new(1, &p, &rgb), Err(EnvError::WrongLength { .. })));
        let p = [f32::NAN; 5];
        assert_eq!(EnvHierarchy::new(1, &p, &rgb).unwrap_err(), EnvError::NotSanitized);
    }
}
