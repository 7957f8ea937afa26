//! Env-only sampling in constant expected time: the finest level's texels, in the pyramid's
//! Morton order, as a cumulative distribution quantized to 2³¹ steps and searched through a
//! guide table (the index-table method, Chen & Asau 1974).
//!
//! The hierarchy's descent makes one two-level choice per step, each with its arithmetic on
//! the critical path of the next load; an env-only sample needs none of the tree's structure,
//! only a texel ∝ importance. Here a sample's first coordinate, as an integer step, finds its
//! bucket of the guide table and then its texel by a binary search that is almost always one
//! or two entries long (over all buckets the ranges add up to the texel count plus the bucket
//! count). Morton order keeps each run of steps a compact patch of the map, so the strata of a
//! (0,2)-net's first coordinate stay compact regions on the sphere; the second coordinate,
//! its bits split between the axes, places the point inside the texel.
//!
//! Each texel with importance > 0 gets at least one step, so env-only sampling reaches every
//! direction the map lights; the density is the texel's share of steps, exactly what is
//! sampled. At most [`CDF_MAX_LEVEL`]: finer maps would spend a visible part of the steps on
//! the floor of one per texel.

use super::pyramid::{EnvError, level_offset, pyramid_len};
use crate::cell::Cell;
use crate::cone::morton_cell;
use crate::mapping::SPHERE_AREA;
use glam::{DVec2, Vec2};

/// Finest level a texel table supports: 4096² texels, at least 128 steps per texel on average.
pub const CDF_MAX_LEVEL: u32 = 12;

/// log2 of the steps of the quantized distribution.
const STEPS_LOG2: u32 = 31;
/// The steps of the quantized distribution: a sample's first coordinate as an integer below it.
const STEPS: u64 = 1 << STEPS_LOG2;

/// Texel-table entries for a finest level: one cumulative end per texel.
#[inline]
#[must_use]
pub const fn texel_cdf_len(finest: u32) -> usize {
    1 << (2 * finest)
}

/// Guide-table entries for a finest level: a bucket per four texels, and an end marker.
#[inline]
#[must_use]
pub const fn texel_guide_len(finest: u32) -> usize {
    (1 << buckets_log2(finest)) + 1
}

const fn buckets_log2(finest: u32) -> u32 {
    if finest == 0 { 0 } else { 2 * finest - 2 }
}

/// Fills `ends` (texel i's cumulative end step, Morton order) and `guide` (bucket j's first
/// texel) from the finest level of a pyramid built by [`build_pyramid`](super::build_pyramid).
/// A black map leaves every entry 0; [`EnvHierarchy::is_black`](super::EnvHierarchy::is_black)
/// then stops sampling before the table is read.
pub fn build_texel_cdf(finest: u32, pyramid: &[f32], ends: &mut [u32], guide: &mut [u32]) -> Result<(), EnvError> {
    check_lengths(finest, ends.len(), guide.len())?;
    if pyramid.len() != pyramid_len(finest) {
        return Err(EnvError::WrongLength { buffer: "pyramid", expected: pyramid_len(finest), found: pyramid.len() });
    }
    let fine = &pyramid[level_offset(finest)..];
    // Weights as integers relative to the largest (exact sums below), and the texels with mass.
    let max = fine.iter().copied().fold(0.0f32, f32::max);
    if !(max.is_finite() && max > 0.0) {
        ends.fill(0);
        guide.fill(0);
        return if max == 0.0 { Ok(()) } else { Err(EnvError::NotSanitized) };
    }
    let scale = (1u64 << 32) as f64 / max as f64;
    let weight = |w: f32| if w > 0.0 { (w as f64 * scale) as u64 } else { 0 };
    let total: u64 = fine.iter().map(|&w| weight(w)).sum();
    let lit = fine.iter().filter(|&&w| w > 0.0).count() as u64;
    // One step per lit texel, the rest in proportion: texel i ends at
    // ⌊Σ_{≤i} w · (STEPS − lit) / Σ w⌋ + (lit texels ≤ i), which reaches STEPS exactly.
    let share = STEPS - lit;
    let (mut sum, mut lit_so_far) = (0u64, 0u64);
    for (e, &w) in ends.iter_mut().zip(fine) {
        sum += weight(w);
        lit_so_far += u64::from(w > 0.0);
        *e = ((sum as u128 * share as u128 / total as u128) as u64 + lit_so_far) as u32;
    }
    fill_guide(finest, ends, guide);
    Ok(())
}

/// Bucket j's entry: the first texel whose end lies past the bucket's first step; the last
/// entry is the texel holding the last step.
fn fill_guide(finest: u32, ends: &[u32], guide: &mut [u32]) {
    let width = STEPS >> buckets_log2(finest);
    let mut texel = 0usize;
    for (j, g) in guide.iter_mut().enumerate() {
        let first_step = (j as u64 * width).min(STEPS - 1);
        while u64::from(ends[texel]) <= first_step {
            texel += 1;
        }
        *g = texel as u32;
    }
}

fn check_lengths(finest: u32, ends: usize, guide: usize) -> Result<(), EnvError> {
    if finest > CDF_MAX_LEVEL {
        return Err(EnvError::TableTooLarge { finest });
    }
    if ends != texel_cdf_len(finest) {
        return Err(EnvError::WrongLength { buffer: "texel table", expected: texel_cdf_len(finest), found: ends });
    }
    if guide != texel_guide_len(finest) {
        return Err(EnvError::WrongLength { buffer: "guide table", expected: texel_guide_len(finest), found: guide });
    }
    Ok(())
}

/// Borrowed view over a texel table and its guide, filled by [`build_texel_cdf`].
#[derive(Clone, Copy, Debug)]
pub struct TexelCdf<'a> {
    finest: u32,
    ends: &'a [u32],
    guide: &'a [u32],
}

impl<'a> TexelCdf<'a> {
    /// A view over tables of a map of finest level `finest`.
    pub fn new(finest: u32, ends: &'a [u32], guide: &'a [u32]) -> Result<Self, EnvError> {
        check_lengths(finest, ends.len(), guide.len())?;
        Ok(Self { finest, ends, guide })
    }

    /// Finest level of the map the tables describe.
    #[inline]
    #[must_use]
    pub fn finest_level(&self) -> u32 {
        self.finest
    }

    /// The texel (Morton index) holding step `step` < 2³¹.
    #[inline]
    #[must_use]
    pub fn texel_of_step(&self, step: u32) -> usize {
        let bucket = (step >> (STEPS_LOG2 - buckets_log2(self.finest))) as usize;
        let (mut lo, mut hi) = (self.guide[bucket] as usize, self.guide[bucket + 1] as usize);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if self.ends[mid] > step {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        lo
    }

    /// The steps texel `morton` holds.
    #[inline]
    #[must_use]
    pub fn steps(&self, morton: usize) -> u32 {
        let start = if morton == 0 { 0 } else { self.ends[morton - 1] };
        self.ends[morton] - start
    }

    /// Env-only density per unit area of the square in texel `morton` (mean 1 over the
    /// square).
    #[inline]
    #[must_use]
    pub fn relative(&self, morton: usize) -> f32 {
        let texels = texel_cdf_len(self.finest) as f64;
        (self.steps(morton) as f64 * (texels / STEPS as f64)) as f32
    }

    /// Asks the memory system for what [`relative`](Self::relative) reads.
    #[inline]
    pub(crate) fn prefetch(&self, morton: usize) {
        crate::prefetch::prefetch(&self.ends[morton.saturating_sub(1)..=morton]);
    }

    /// The point of the square `u` picks and the env-only density there with respect to
    /// solid angle.
    #[inline]
    #[must_use]
    pub fn sample_point(&self, u: DVec2) -> (Vec2, f32) {
        let (_, morton, uv) = self.pick(u);
        (uv, self.relative(morton) / SPHERE_AREA)
    }

    /// The texel a point `u` of [0, 1)² picks and the point inside it (`u.x` picks, the bits
    /// of `u.y` split between the axes place).
    #[inline]
    #[must_use]
    pub fn pick(&self, u: DVec2) -> (Cell, usize, Vec2) {
        let step = ((u.x * STEPS as f64) as u64).min(STEPS - 1) as u32;
        let morton = self.texel_of_step(step);
        let bits = ((u.y * 4_294_967_296.0) as u64).min(u32::MAX as u64) as u32;
        let (ix, iy) = morton_cell(bits as usize);
        let inside = DVec2::new((f64::from(ix) + 0.5) / 65_536.0, (f64::from(iy) + 0.5) / 65_536.0);
        let (x, y) = morton_cell(morton);
        let cell = Cell::new(self.finest, x, y);
        (cell, morton, cell.point(inside))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::morton2;
    use crate::env::build_pyramid_from_importance;

    fn tables(finest: u32, importance: &[f32]) -> (std::vec::Vec<u32>, std::vec::Vec<u32>) {
        let mut p = std::vec![0.0f32; pyramid_len(finest)];
        build_pyramid_from_importance(finest, importance, &mut p).unwrap();
        let mut ends = std::vec![0u32; texel_cdf_len(finest)];
        let mut guide = std::vec![0u32; texel_guide_len(finest)];
        build_texel_cdf(finest, &p, &mut ends, &mut guide).unwrap();
        (ends, guide)
    }

    #[test]
    fn steps_follow_importance_and_every_lit_texel_has_one() {
        let finest = 5;
        let n = 1usize << finest;
        let mut w = std::vec![0.0f32; n * n];
        for (i, v) in w.iter_mut().enumerate() {
            *v = match i % 7 {
                0 => 0.0,
                1 => 1e-30,
                _ => (i % 13) as f32 + 0.5,
            };
        }
        w[100] = 1e9;
        let (ends, guide) = tables(finest, &w);
        let cdf = TexelCdf::new(finest, &ends, &guide).unwrap();
        assert_eq!(*ends.last().unwrap() as u64, STEPS);
        let total: f64 = w.iter().map(|&v| v as f64).sum();
        for (i, &v) in w.iter().enumerate() {
            let k = morton2((i % n) as u32, (i / n) as u32);
            let steps = cdf.steps(k);
            assert_eq!(steps == 0, v == 0.0, "texel {i}");
            let expected = v as f64 / total * STEPS as f64;
            assert!((steps as f64 - expected).abs() <= n as f64 * n as f64 + 1.0, "texel {i}: {steps} vs {expected}");
        }
    }

    #[test]
    fn every_step_finds_the_texel_that_holds_it() {
        let finest = 4;
        let mut w = [0.0f32; 256];
        w[..128].iter_mut().enumerate().for_each(|(i, v)| *v = (i % 5) as f32);
        w[200] = 3.0;
        let (ends, guide) = tables(finest, &w);
        let cdf = TexelCdf::new(finest, &ends, &guide).unwrap();
        let mut rng = crate::rng::Pcg32::new(3, 4);
        for probe in 0..20_000u32 {
            let step = if probe < 256 { ends[probe as usize].saturating_sub(1) } else { rng.next_u32() >> 1 };
            let k = cdf.texel_of_step(step);
            let start = if k == 0 { 0 } else { ends[k - 1] };
            assert!(start <= step && step < ends[k], "step {step} → texel {k} [{start}, {})", ends[k]);
        }
    }

    #[test]
    fn a_point_lands_in_the_texel_it_picks() {
        let finest = 3;
        let w: [f32; 64] = core::array::from_fn(|i| (i % 3) as f32);
        let (ends, guide) = tables(finest, &w);
        let cdf = TexelCdf::new(finest, &ends, &guide).unwrap();
        let mut rng = crate::rng::Pcg32::new(5, 6);
        for _ in 0..10_000 {
            let u = DVec2::new(rng.next_f64(), rng.next_f64());
            let (cell, morton, uv) = cdf.pick(u);
            assert_eq!(cell.morton(), morton);
            assert!(cdf.steps(morton) > 0);
            let n = (1u32 << finest) as f32;
            assert_eq!(((uv.x * n) as u32, (uv.y * n) as u32), (cell.x, cell.y));
        }
    }

    #[test]
    fn wrong_sizes_and_levels_are_errors() {
        let p = [1.0f32; 5];
        let (mut e, mut g) = ([0u32; 4], [0u32; 2]);
        assert!(build_texel_cdf(1, &p, &mut e, &mut g).is_ok());
        assert!(matches!(build_texel_cdf(1, &p, &mut e[..3], &mut g), Err(EnvError::WrongLength { .. })));
        assert!(matches!(build_texel_cdf(1, &p, &mut e, &mut [0u32; 3]), Err(EnvError::WrongLength { .. })));
        assert!(matches!(TexelCdf::new(CDF_MAX_LEVEL + 1, &e, &g), Err(EnvError::TableTooLarge { .. })));
        let black = [0.0f32; 5];
        build_texel_cdf(1, &black, &mut e, &mut g).unwrap();
        assert_eq!(e, [0; 4]);
    }
}
