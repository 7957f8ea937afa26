//! The environment hierarchy: a borrowed view over a caller-owned mip pyramid of the
//! equal-area map.
//!
//! Level `k` is a `2^k × 2^k` grid of scalar importance (luminance) with `x` along `u` and `y`
//! along `v`, stored in Morton (Z) order so that a node's four children are one contiguous
//! 16-byte block and a subtree stays together in memory — the warp touches one cache line per
//! level. Levels are packed from the 1×1 root down to the finest level `K`: level `k` starts at
//! [`level_offset`]`(k)`, node `(x, y)` sits at [`pyramid_index`]; the whole pyramid holds
//! [`pyramid_len`]`(K)` values (4/3 of the finest level). Because every texel of the equal-area
//! map covers the same solid angle, each coarser texel is the plain mean of its four children.
//! RGB radiance for shading is kept at the finest level only, row-major. Lookups are nearest-texel, the same piecewise-constant function the
//! sampling densities are built from, so radiance cancels exactly in the product estimator.

use crate::direction::DirectionSample;
use crate::mapping::{
    SPHERE_AREA, sphere_to_square, sphere_to_square_batch, square_to_sphere, square_to_sphere_batch, texel_of,
};
use crate::warp::{child_offset, choose_child, choose_grandchild, point_in_cell};
use glam::{DVec2, Mat3, Vec2, Vec3};

/// Finest level supported: 2^14 = 16384² texels.
pub const MAX_LEVEL: u32 = 14;

/// Index of the first value of level `k` in a packed pyramid.
#[inline]
#[must_use]
pub const fn level_offset(level: u32) -> usize {
    ((1usize << (2 * level)) - 1) / 3
}

/// Number of values in a packed pyramid whose finest level is `2^finest × 2^finest`.
#[inline]
#[must_use]
pub const fn pyramid_len(finest: u32) -> usize {
    level_offset(finest + 1)
}

/// Index of node `(x, y)` of `level` in a packed pyramid (Morton order within the level).
#[inline]
#[must_use]
pub fn pyramid_index(level: u32, x: u32, y: u32) -> usize {
    level_offset(level) + morton2(x, y)
}

/// Interleaves the bits of two 16-bit coordinates (x in the even bits).
#[inline]
#[must_use]
pub fn morton2(x: u32, y: u32) -> usize {
    fn spread(v: u32) -> u32 {
        let mut v = v & 0xFFFF;
        v = (v | (v << 8)) & 0x00FF_00FF;
        v = (v | (v << 4)) & 0x0F0F_0F0F;
        v = (v | (v << 2)) & 0x3333_3333;
        (v | (v << 1)) & 0x5555_5555
    }
    (spread(x) | (spread(y) << 1)) as usize
}

/// Rec. 709 luminance: the scalar importance of an RGB radiance.
#[inline]
#[must_use]
pub fn luminance(c: Vec3) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

/// What can be wrong with the buffers handed to [`EnvHierarchy::new`] or [`build_pyramid`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvError {
    /// The finest level is larger than [`MAX_LEVEL`].
    TooLarge {
        /// The finest level asked for.
        finest: u32,
    },
    /// A buffer does not have the length its finest level implies.
    WrongLength {
        /// Which buffer (`"pyramid"` or `"radiance"`).
        buffer: &'static str,
        /// The length the finest level implies.
        expected: usize,
        /// The length handed in.
        found: usize,
    },
    /// The pyramid's root is NaN, infinite or negative: the map was not sanitized.
    NotSanitized,
}

impl core::fmt::Display for EnvError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::TooLarge { finest } => {
                write!(f, "environment level {finest} exceeds the maximum {MAX_LEVEL} (16384²)")
            }
            Self::WrongLength { buffer, expected, found } => {
                write!(f, "{buffer} buffer holds {found} values, expected {expected}")
            }
            Self::NotSanitized => write!(f, "environment holds NaN, infinite or negative values"),
        }
    }
}

impl core::error::Error for EnvError {}

/// Replaces NaN, ±Inf and negative components by 0; returns how many texels were changed.
pub fn sanitize_rgb(texels: &mut [[f32; 3]]) -> usize {
    let mut bad = 0;
    for t in texels {
        let mut changed = false;
        for c in t.iter_mut() {
            if !c.is_finite() || *c < 0.0 {
                *c = 0.0;
                changed = true;
            }
        }
        bad += usize::from(changed);
    }
    bad
}

/// Writes the luminance of each RGB texel (row-major, sanitized with [`sanitize_rgb`]) into the
/// finest level of `pyramid` and fills the coarser levels.
pub fn build_pyramid(finest: u32, rgb: &[[f32; 3]], pyramid: &mut [f32]) -> Result<(), EnvError> {
    check_lengths(finest, rgb.len(), pyramid.len())?;
    let n = 1usize << finest;
    for (i, c) in rgb.iter().enumerate() {
        pyramid[pyramid_index(finest, (i % n) as u32, (i / n) as u32)] = luminance(Vec3::from_array(*c));
    }
    fill_pyramid(finest, pyramid);
    Ok(())
}

/// Like [`build_pyramid`] from a row-major scalar importance of the finest level (any
/// non-negative finite weight that is > 0 wherever the radiance is).
pub fn build_pyramid_from_importance(finest: u32, importance: &[f32], pyramid: &mut [f32]) -> Result<(), EnvError> {
    check_lengths(finest, importance.len(), pyramid.len())?;
    let n = 1usize << finest;
    for (i, v) in importance.iter().enumerate() {
        pyramid[pyramid_index(finest, (i % n) as u32, (i / n) as u32)] = *v;
    }
    fill_pyramid(finest, pyramid);
    Ok(())
}

/// Fills levels `finest − 1 … 0` from the finest level: in Morton order the four children of
/// node `i` are `4i .. 4i + 4` of the next level. Accumulated in f64 so that radiances up to
/// f32::MAX do not overflow.
fn fill_pyramid(finest: u32, pyramid: &mut [f32]) {
    for level in (0..finest).rev() {
        let (coarse, fine) = pyramid.split_at_mut(level_offset(level + 1));
        let coarse = &mut coarse[level_offset(level)..];
        for (i, c) in coarse.iter_mut().enumerate() {
            let q = &fine[4 * i..4 * i + 4];
            *c = (0.25 * ((q[0] as f64 + q[1] as f64) + (q[2] as f64 + q[3] as f64))) as f32;
        }
    }
}

fn check_lengths(finest: u32, rgb: usize, pyramid: usize) -> Result<(), EnvError> {
    if finest > MAX_LEVEL {
        return Err(EnvError::TooLarge { finest });
    }
    let texels = 1usize << (2 * finest);
    if rgb != texels {
        return Err(EnvError::WrongLength { buffer: "radiance", expected: texels, found: rgb });
    }
    if pyramid != pyramid_len(finest) {
        return Err(EnvError::WrongLength { buffer: "pyramid", expected: pyramid_len(finest), found: pyramid });
    }
    Ok(())
}

/// Borrowed view over a sanitized environment pyramid, with an optional world rotation.
#[derive(Clone, Copy, Debug)]
pub struct EnvHierarchy<'a> {
    pub(crate) finest: u32,
    pub(crate) pyramid: &'a [f32],
    radiance: &'a [[f32; 3]],
    /// 1 / mean importance, or 0 for a black map.
    inv_mean: f32,
    tint: Vec3,
    world_to_map: Mat3,
    map_to_world: Mat3,
}

impl<'a> EnvHierarchy<'a> {
    /// A view over `pyramid` (filled by [`build_pyramid`]) and the finest-level `radiance`.
    pub fn new(finest: u32, pyramid: &'a [f32], radiance: &'a [[f32; 3]]) -> Result<Self, EnvError> {
        check_lengths(finest, radiance.len(), pyramid.len())?;
        let mean = pyramid[0];
        if !mean.is_finite() || mean < 0.0 {
            return Err(EnvError::NotSanitized);
        }
        let inv_mean = if mean > 0.0 { 1.0 / mean } else { 0.0 };
        let inv_mean = if inv_mean.is_finite() { inv_mean } else { 0.0 };
        Ok(Self {
            finest,
            pyramid,
            radiance,
            inv_mean,
            tint: Vec3::ONE,
            world_to_map: Mat3::IDENTITY,
            map_to_world: Mat3::IDENTITY,
        })
    }

    /// Orients the map: `map_to_world` takes directions of the map's own frame (the frame
    /// [`square_to_sphere`] works in) to world space. Must be a rotation.
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

    /// Mean importance of node `(x, y)` of `level`, relative to the whole map's mean (so the
    /// map averages to 1 whatever its absolute scale).
    #[inline]
    #[must_use]
    pub fn node_relative(&self, level: u32, x: u32, y: u32) -> f32 {
        self.pyramid[pyramid_index(level, x, y)] * self.inv_mean
    }

    /// The 16 grandchildren of node `(x, y)` of `level` (which must be < K − 1), as stored
    /// (not relative to the mean: for ratios), in the Morton order of
    /// [`crate::warp::choose_grandchild`] — one cache line.
    #[inline]
    #[must_use]
    pub fn grandchildren_raw(&self, level: u32, x: u32, y: u32) -> &[f32; 16] {
        let base = level_offset(level + 2) + 16 * morton2(x, y);
        self.pyramid[base..base + 16].try_into().expect("16 grandchildren")
    }

    /// The four children of node `(x, y)` of `level` (which must be < K), relative to the mean,
    /// in [`child_offset`] order.
    #[inline]
    #[must_use]
    pub fn children_relative(&self, level: u32, x: u32, y: u32) -> [f32; 4] {
        let base = level_offset(level + 1) + 4 * morton2(x, y);
        let q = &self.pyramid[base..base + 4];
        let s = self.inv_mean;
        [q[0] * s, q[1] * s, q[2] * s, q[3] * s]
    }

    /// How peaked the lighting is at a scale: the largest node of `level` (clamped to the
    /// finest) relative to the mean — 1 for a constant map, ~700 for a sky with a sun at
    /// level 5 (cells ~6.4° wide). A cheap test of whether sampling the lighting can pay.
    #[must_use]
    pub fn peak(&self, level: u32) -> f32 {
        let level = level.min(self.finest);
        let n = 1u32 << level;
        let mut max = 0.0f32;
        for y in 0..n {
            for x in 0..n {
                max = max.max(self.node_relative(level, x, y));
            }
        }
        if max.is_finite() { max } else { f32::MAX }
    }

    /// Mean importance (relative) of the region covered by a quadtree cell at any depth:
    /// below the finest level a cell lies inside one texel.
    #[inline]
    #[must_use]
    pub fn cell_relative(&self, depth: u32, x: u32, y: u32) -> f32 {
        if depth <= self.finest {
            self.node_relative(depth, x, y)
        } else {
            let sh = depth - self.finest;
            self.node_relative(self.finest, x >> sh, y >> sh)
        }
    }

    /// The rotation taking world directions to the map's frame.
    #[inline]
    #[must_use]
    pub fn world_to_map(&self) -> Mat3 {
        self.world_to_map
    }

    /// World direction → map direction.
    #[inline]
    #[must_use]
    pub fn to_map(&self, world: Vec3) -> Vec3 {
        self.world_to_map * world
    }

    /// Map direction → world direction.
    #[inline]
    #[must_use]
    pub fn to_world(&self, map: Vec3) -> Vec3 {
        self.map_to_world * map
    }

    /// Point of the equal-area square seen in world direction `dir`.
    #[inline]
    #[must_use]
    pub fn square_of(&self, dir: Vec3) -> Vec2 {
        sphere_to_square(self.to_map(dir))
    }

    /// World direction of a point of the square.
    #[inline]
    #[must_use]
    pub fn dir_of(&self, uv: Vec2) -> Vec3 {
        self.to_world(square_to_sphere(uv))
    }

    /// [`dir_of`](Self::dir_of) for every point of `uv` (as many as both hold), four lanes at a
    /// time, bit for bit.
    pub fn dirs_of(&self, uv: &[Vec2], out: &mut [Vec3]) {
        let n = uv.len().min(out.len());
        square_to_sphere_batch(&uv[..n], &mut out[..n]);
        for d in &mut out[..n] {
            *d = self.to_world(*d);
        }
    }

    /// [`square_of`](Self::square_of) for every direction of `dirs` (as many as both hold), four
    /// lanes at a time, bit for bit.
    pub fn squares_of(&self, dirs: &[Vec3], out: &mut [Vec2]) {
        for (ds, os) in dirs.chunks(16).zip(out.chunks_mut(16)) {
            let n = ds.len().min(os.len());
            let mut local = [Vec3::ZERO; 16];
            for (l, d) in local.iter_mut().zip(ds) {
                *l = self.to_map(*d);
            }
            sphere_to_square_batch(&local[..n], &mut os[..n]);
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

    /// Env-only density per unit area of the square at `uv` (mean 1 over the square).
    #[inline]
    #[must_use]
    pub fn pdf_square(&self, uv: Vec2) -> f32 {
        let (x, y) = self.texel_at(uv);
        self.node_relative(self.finest, x, y)
    }

    /// Env-only density with respect to solid angle of world direction `dir`.
    #[inline]
    #[must_use]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        self.pdf_square(self.square_of(dir)) / SPHERE_AREA
    }

    /// Warps `xi` from node `(x, y)` of `level` down to a finest-level texel, ∝ importance.
    /// Returns the texel, or `None` if the node has no mass.
    #[inline]
    pub fn warp_down(&self, level: u32, x: u32, y: u32, xi: &mut DVec2) -> Option<(u32, u32)> {
        // Two levels per step over the 16 grandchildren (one cache line), and raw pyramid
        // values: the choice only needs ratios, so the 1/mean scale is left out.
        let (mut l, mut x, mut y, mut m) = (level, x, y, morton2(x, y));
        while l + 2 <= self.finest {
            let base = level_offset(l + 2) + 16 * m;
            let g: &[f32; 16] = self.pyramid[base..base + 16].try_into().ok()?;
            let (c, gx, gy) = choose_grandchild(g, xi)?;
            (l, x, y, m) = (l + 2, 4 * x + gx, 4 * y + gy, 16 * m + c);
        }
        if l < self.finest {
            let base = level_offset(l + 1) + 4 * m;
            let q = &self.pyramid[base..base + 4];
            let c = choose_child([q[0], q[1], q[2], q[3]], xi)?;
            let (dx, dy) = child_offset(c);
            (x, y) = (2 * x + dx, 2 * y + dy);
        }
        Some((x, y))
    }

    /// Draws a direction with density ∝ importance (env-only sampling through the hierarchy).
    #[inline]
    pub fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        if self.is_black() {
            return None;
        }
        let mut xi = u.clamp(DVec2::ZERO, DVec2::splat(crate::warp::ONE_MINUS_EPSILON));
        let (x, y) = self.warp_down(0, 0, 0, &mut xi)?;
        Some(self.sample_in_texel(x, y, xi))
    }

    /// The sample at point `xi` of finest-level texel (x, y), with its density.
    #[inline]
    pub(crate) fn sample_in_texel(&self, x: u32, y: u32, xi: DVec2) -> DirectionSample {
        let (uv, pdf) = self.point_in_texel(x, y, xi);
        DirectionSample { dir: self.dir_of(uv), uv, pdf }
    }

    /// The point of texel (x, y) at `xi` and the density there (solid angle).
    #[inline]
    pub(crate) fn point_in_texel(&self, x: u32, y: u32, xi: DVec2) -> (Vec2, f32) {
        (point_in_cell(x, y, self.finest, xi), self.node_relative(self.finest, x, y) / SPHERE_AREA)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn batched_directions_and_points_are_bit_identical() {
        let rgb = [[1.0f32; 3]; 16];
        let mut p = [0.0f32; 21];
        build_pyramid(2, &rgb, &mut p).unwrap();
        let e = EnvHierarchy::new(2, &p, &rgb)
            .unwrap()
            .with_rotation(Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.3));
        let mut uv = [Vec2::ZERO; 67];
        for (k, u) in uv.iter_mut().enumerate() {
            *u = Vec2::new((k as f32 * 0.618_034).fract(), (k as f32 * 0.754_877_7).fract());
        }
        let mut dirs = [Vec3::ZERO; 67];
        e.dirs_of(&uv, &mut dirs);
        let mut back = [Vec2::ZERO; 67];
        e.squares_of(&dirs, &mut back);
        for k in 0..uv.len() {
            assert_eq!(dirs[k].to_array().map(f32::to_bits), e.dir_of(uv[k]).to_array().map(f32::to_bits));
            assert_eq!(back[k].to_array().map(f32::to_bits), e.square_of(dirs[k]).to_array().map(f32::to_bits));
        }
    }

    #[test]
    fn pyramid_layout() {
        assert_eq!(pyramid_len(0), 1);
        assert_eq!(pyramid_len(1), 5);
        assert_eq!(pyramid_len(2), 21);
        assert_eq!(level_offset(2), 5);
        let mut p = [0.0f32; 21];
        let fine = [1.0, 2.0, 0.0, 0.0, 3.0, 4.0, 0.0, 0.0, 0.0, 0.0, 8.0, 8.0, 0.0, 0.0, 8.0, 8.0];
        p[5..].copy_from_slice(&fine);
        build_pyramid_from_importance(2, &fine, &mut p).unwrap();
        assert_eq!(&p[1..5], &[2.5, 0.0, 0.0, 8.0]);
        assert_eq!(p[0], 2.625);
    }

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
                    let c = e.children_relative(l, x, y);
                    let at = |dx, dy| e.node_relative(l + 1, 2 * x + dx, 2 * y + dy);
                    assert_eq!(c, [at(0, 0), at(1, 0), at(0, 1), at(1, 1)]);
                    let mean = 0.25 * c.iter().sum::<f32>();
                    assert!((mean - e.node_relative(l, x, y)).abs() <= 1e-6 * mean);
                }
            }
        }
        // The finest level reads back the row-major input.
        assert_eq!(e.node_relative(3, 5, 2) / e.inv_mean, luminance(Vec3::from_array(rgb[2 * 8 + 5])));
    }

    #[test]
    fn huge_radiance_does_not_overflow_the_mean() {
        let rgb = [[3.0e38f32; 3]; 4];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &rgb, &mut p).unwrap();
        assert!(p[0].is_finite());
        let env = EnvHierarchy::new(1, &p, &rgb).unwrap();
        assert!((env.node_relative(1, 1, 1) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sanitize_counts_bad_texels() {
        let mut t = [[1.0, f32::NAN, 0.0], [f32::INFINITY, 0.0, 0.0], [-1.0, 2.0, 3.0], [1.0, 2.0, 3.0]];
        assert_eq!(sanitize_rgb(&mut t), 3);
        assert_eq!(t[0], [1.0, 0.0, 0.0]);
        assert_eq!(t[2], [0.0, 2.0, 3.0]);
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
    fn black_map_samples_nothing() {
        let rgb = [[0.0f32; 3]; 4];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &rgb, &mut p).unwrap();
        let env = EnvHierarchy::new(1, &p, &rgb).unwrap();
        assert!(env.is_black());
        assert!(env.sample(DVec2::splat(0.3)).is_none());
        assert_eq!(env.pdf(Vec3::Z), 0.0);
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
