//! The packed mip pyramid of the equal-area map: its layout (levels from the 1×1 root down,
//! Morton order within a level), the luminance it holds, and the checks and builders of the
//! caller-owned buffers.

use crate::cell::Cell;
use glam::Vec3;

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

/// Index of a node in a packed pyramid (Morton order within its level).
#[inline]
#[must_use]
pub fn pyramid_index(node: Cell) -> usize {
    level_offset(node.level) + node.morton()
}

/// Rec. 709 luminance: the scalar importance of an RGB radiance.
#[inline]
#[must_use]
pub fn luminance(c: Vec3) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

/// What can be wrong with the buffers handed to [`EnvHierarchy::new`](super::EnvHierarchy::new) or [`build_pyramid`].
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
    /// A texel table was asked for a finest level above [`CDF_MAX_LEVEL`](super::CDF_MAX_LEVEL).
    TableTooLarge {
        /// The finest level asked for.
        finest: u32,
    },
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
            Self::TableTooLarge { finest } => {
                write!(f, "texel table of level {finest} exceeds the maximum {}", super::CDF_MAX_LEVEL)
            }
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
        pyramid[pyramid_index(Cell::new(finest, (i % n) as u32, (i / n) as u32))] = luminance(Vec3::from_array(*c));
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
        pyramid[pyramid_index(Cell::new(finest, (i % n) as u32, (i / n) as u32))] = *v;
    }
    fill_pyramid(finest, pyramid);
    Ok(())
}

/// Fills levels `finest − 1 … 0` from the finest level: in Morton order the four children of
/// node `i` are `4i .. 4i + 4` of the next level. Accumulated in f64 so that radiances up to
/// f32::MAX do not overflow.
pub(super) fn fill_pyramid(finest: u32, pyramid: &mut [f32]) {
    for level in (0..finest).rev() {
        let (coarse, fine) = pyramid.split_at_mut(level_offset(level + 1));
        let coarse = &mut coarse[level_offset(level)..];
        for (i, c) in coarse.iter_mut().enumerate() {
            let q = &fine[4 * i..4 * i + 4];
            *c = (0.25 * ((q[0] as f64 + q[1] as f64) + (q[2] as f64 + q[3] as f64))) as f32;
        }
    }
}

pub(super) fn check_lengths(finest: u32, rgb: usize, pyramid: usize) -> Result<(), EnvError> {
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
#[cfg(test)]
mod tests {
    use super::*;

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
    fn sanitize_counts_bad_texels() {
        let mut t = [[1.0, f32::NAN, 0.0], [f32::INFINITY, 0.0, 0.0], [-1.0, 2.0, 3.0], [1.0, 2.0, 3.0]];
        assert_eq!(sanitize_rgb(&mut t), 3);
        assert_eq!(t[0], [1.0, 0.0, 0.0]);
        assert_eq!(t[2], [0.0, 2.0, 3.0]);
    }
}
