//! Lat-long (equirectangular) maps → the equal-area square, for engines that store their
//! environment as lat-long; allocation-free.
//!
//! Orientation (the scene format's, the same as USD's DomeLight): for a unit direction d in the
//! map's frame, `u = atan2(d.x, −d.z)/2π mod 1`, `v = acos(d.y)/π`; the top row is +Y, u = 0 is
//! −Z, u = ¼ is +X, u = ½ is +Z, u = ¾ is −X. Pixel (i, j) covers [i/W, (i+1)/W) × [j/H,
//! (j+1)/H) and is read as a constant. The square lives in the same frame: texel (x, y) holds
//! the directions [`square_to_sphere`] gives for its points.

use crate::env::MAX_LEVEL;
use crate::estimator::luminance64;
use crate::mapping::{sphere_to_square, square_to_sphere, texel_of};
use core::f64::consts::PI;
use glam::{Vec2, Vec3};

/// Why a lat-long map could not be resampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LatLongError {
    /// The source has no pixels, or not `width × height` of them.
    SourceSize,
    /// The destination does not hold `4^level` texels, or the level exceeds [`MAX_LEVEL`].
    DestinationSize,
}

impl core::fmt::Display for LatLongError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::SourceSize => "the lat-long source does not hold width × height pixels",
            Self::DestinationSize => "the equal-area destination does not hold 4^level texels",
        })
    }
}

impl core::error::Error for LatLongError {}

/// Continuous lat-long coordinates (u, v) ∈ \[0,1)×\[0,1\] of a unit direction (f64: an f32
/// atan2 rounds across pixel edges).
#[must_use]
pub fn direction_to_latlong_uv(d: Vec3) -> (f64, f64) {
    let d = d.as_dvec3();
    let mut u = libm::atan2(d.x, -d.z) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    (u, libm::acos(d.y.clamp(-1.0, 1.0)) / PI)
}

/// The pixel of a `width × height` lat-long map that a unit direction falls in.
#[must_use]
pub fn direction_to_latlong(d: Vec3, width: usize, height: usize) -> (usize, usize) {
    let (u, v) = direction_to_latlong_uv(d);
    (((u * width as f64) as usize).min(width - 1), ((v * height as f64) as usize).min(height - 1))
}

/// Smallest level whose texels are no larger than the source's largest (at the equator):
/// 4π/N² ≤ 2π²/(W·H), i.e. N ≥ √(2WH/π). 1024×512 → 1024², 4096×2048 → 4096².
#[must_use]
pub fn equal_area_level(width: usize, height: usize) -> u32 {
    let n = libm::ceil(libm::sqrt(2.0 * width as f64 * height as f64 / PI)).max(1.0) as u64;
    n.next_power_of_two().trailing_zeros().min(MAX_LEVEL)
}

fn luminance(t: [f32; 3]) -> f64 {
    luminance64(Vec3::from(t).as_dvec3())
}

/// Mean radiance over the sphere of a lat-long map, each row weighted by its solid angle.
#[must_use]
pub fn latlong_mean(src: &[[f32; 3]], width: usize, height: usize) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for (j, row) in src.chunks_exact(width).take(height).enumerate() {
        let omega = row_solid_angle(j, width, height);
        for t in row {
            for c in 0..3 {
                sum[c] += f64::from(t[c]) * omega;
            }
        }
    }
    sum.map(|s| s / (4.0 * PI))
}

/// Solid angle of one pixel of row `j`.
fn row_solid_angle(j: usize, width: usize, height: usize) -> f64 {
    let (t0, t1) = (PI * j as f64 / height as f64, PI * (j + 1) as f64 / height as f64);
    2.0 * PI / width as f64 * (libm::cos(t0) - libm::cos(t1))
}

/// Splat points per pixel side for the bright part of a pixel.
const SPLAT: usize = 8;

/// Resamples a row-major lat-long map into the `2^level` equal-area square `dst`, conserving
/// energy: [`gather_rows`] over every row, then [`splat_excess`].
///
/// A bright source (the sun) can carry most of a map's energy on a few pixels; any
/// point-sampled gather quantises their coverage. So each pixel is split at
/// [`bright_threshold`]: the part up to it is gathered, the excess above it (on at most 1/64 of
/// the sphere) is splatted.
pub fn latlong_to_equal_area(
    src: &[[f32; 3]],
    width: usize,
    height: usize,
    level: u32,
    ss: usize,
    dst: &mut [[f32; 3]],
) -> Result<(), LatLongError> {
    check(src, width, height)?;
    if level > MAX_LEVEL || dst.len() != 1usize << (2 * level) {
        return Err(LatLongError::DestinationSize);
    }
    let threshold = bright_threshold(src, width, height);
    gather_rows(src, width, height, level, ss, threshold, 0, dst)?;
    splat_excess(src, width, height, level, threshold, dst)
}

fn check(src: &[[f32; 3]], width: usize, height: usize) -> Result<(), LatLongError> {
    if width == 0 || height == 0 || src.len() != width * height { Err(LatLongError::SourceSize) } else { Ok(()) }
}

/// The luminance above which a pixel's excess is splatted: 64 × the map's mean.
#[must_use]
pub fn bright_threshold(src: &[[f32; 3]], width: usize, height: usize) -> f64 {
    64.0 * luminance(latlong_mean(src, width, height).map(|c| c as f32))
}

/// A pixel's part up to the threshold (same chromaticity).
fn clamped(t: [f32; 3], threshold: f64) -> [f32; 3] {
    let l = luminance(t);
    if l > threshold && threshold > 0.0 { t.map(|c| (f64::from(c) * threshold / l) as f32) } else { t }
}

/// Gathers the rows `first_row..` of the `2^level` square that `out` holds (whole rows, so
/// hosts can resample bands of rows in parallel): each texel the mean of `ss × ss` stratified
/// points of the source clamped at `threshold`, and of 4 × 4 where those and the texel's
/// corners differ by more than 25%.
#[allow(clippy::too_many_arguments)]
pub fn gather_rows(
    src: &[[f32; 3]],
    width: usize,
    height: usize,
    level: u32,
    ss: usize,
    threshold: f64,
    first_row: usize,
    out: &mut [[f32; 3]],
) -> Result<(), LatLongError> {
    check(src, width, height)?;
    let n = 1usize << level.min(MAX_LEVEL);
    if level > MAX_LEVEL || !out.len().is_multiple_of(n) || first_row + out.len() / n > n {
        return Err(LatLongError::DestinationSize);
    }
    let ss = ss.max(1);
    let lookup = |s: f64, t: f64| {
        let (i, j) = direction_to_latlong(square_to_sphere(Vec2::new(s as f32, t as f32)), width, height);
        clamped(src[j * width + i], threshold)
    };
    let average = |x: usize, y: usize, k: usize| -> [f64; 3] {
        let mut acc = [0.0f64; 3];
        for sy in 0..k {
            for sx in 0..k {
                let p = (((x * k + sx) as f64 + 0.5) / (n * k) as f64, ((y * k + sy) as f64 + 0.5) / (n * k) as f64);
                let t = lookup(p.0, p.1);
                for c in 0..3 {
                    acc[c] += f64::from(t[c]);
                }
            }
        }
        acc.map(|a| a / (k * k) as f64)
    };
    for (i, texel) in out.iter_mut().enumerate() {
        let (x, y) = (i % n, first_row + i / n);
        let mean = average(x, y, ss);
        let l = luminance(mean.map(|c| c as f32));
        let corner = |dx: usize, dy: usize| luminance(lookup((x + dx) as f64 / n as f64, (y + dy) as f64 / n as f64));
        let (lo, hi) = [corner(0, 0), corner(1, 0), corner(0, 1), corner(1, 1)]
            .iter()
            .fold((l, l), |(lo, hi), &c| (lo.min(c), hi.max(c)));
        let mean = if hi > 1.25 * lo && ss < 4 { average(x, y, 4) } else { mean };
        *texel = mean.map(|a| a as f32);
    }
    Ok(())
}

/// Adds to `dst` (the whole `2^level` square) the excess of every pixel above `threshold`:
/// 8 × 8 points per pixel, uniform in solid angle, each carrying 1/64 of the excess energy into
/// the texel it lands in — energy conserved exactly, whatever the coverage.
pub fn splat_excess(
    src: &[[f32; 3]],
    width: usize,
    height: usize,
    level: u32,
    threshold: f64,
    dst: &mut [[f32; 3]],
) -> Result<(), LatLongError> {
    check(src, width, height)?;
    if level > MAX_LEVEL || dst.len() != 1usize << (2 * level) {
        return Err(LatLongError::DestinationSize);
    }
    let n = 1usize << level;
    let texel_solid_angle = 4.0 * PI / (n * n) as f64;
    for j in 0..height {
        let (c0, c1) = (libm::cos(PI * j as f64 / height as f64), libm::cos(PI * (j + 1) as f64 / height as f64));
        let scale = row_solid_angle(j, width, height) / (SPLAT * SPLAT) as f64 / texel_solid_angle;
        for i in 0..width {
            let t = src[j * width + i];
            let c = clamped(t, threshold);
            if c == t {
                continue;
            }
            let excess = [0, 1, 2].map(|k| (f64::from(t[k]) - f64::from(c[k])) * scale);
            for b in 0..SPLAT {
                // Uniform in solid angle: cos θ uniform over the row.
                let cos_t = c0 + (c1 - c0) * (b as f64 + 0.5) / SPLAT as f64;
                let sin_t = libm::sqrt((1.0 - cos_t * cos_t).max(0.0));
                for a in 0..SPLAT {
                    let phi = 2.0 * PI * (i as f64 + (a as f64 + 0.5) / SPLAT as f64) / width as f64;
                    let d = Vec3::new((sin_t * libm::sin(phi)) as f32, cos_t as f32, (-sin_t * libm::cos(phi)) as f32);
                    let (x, y) = texel_of(sphere_to_square(d), n as u32);
                    let e = &mut dst[y as usize * n + x as usize];
                    for k in 0..3 {
                        e[k] += excess[k] as f32;
                    }
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec;

    #[test]
    fn orientation_matches_the_scene_format() {
        let uv = |d: Vec3| direction_to_latlong_uv(d.normalize());
        let close = |(u, v): (f64, f64), (eu, ev): (f64, f64)| (u - eu).abs() < 1e-7 && (v - ev).abs() < 1e-7;
        assert!(close(uv(Vec3::NEG_Z), (0.0, 0.5)));
        assert!(close(uv(Vec3::X), (0.25, 0.5)));
        assert!(close(uv(Vec3::Z), (0.5, 0.5)));
        assert!(close(uv(Vec3::NEG_X), (0.75, 0.5)));
        assert!(uv(Vec3::Y).1 < 1e-7);
        assert!((uv(Vec3::NEG_Y).1 - 1.0).abs() < 1e-7);
    }

    #[test]
    fn resampling_preserves_the_mean_and_checks_sizes() {
        let (w, h) = (256, 128);
        for case in 0..3 {
            let mut src = vec![[0.1f32, 0.2, 0.3]; w * h];
            match case {
                1 => src[64 * w + 77] = [5000.0, 4000.0, 3000.0],
                2 => src[2 * w + 77] = [5000.0, 4000.0, 3000.0],
                _ => {}
            }
            let level = equal_area_level(w, h);
            let mut dst = vec![[0.0f32; 3]; 1 << (2 * level)];
            latlong_to_equal_area(&src, w, h, level, 2, &mut dst).unwrap();
            let a = latlong_mean(&src, w, h);
            for c in 0..3 {
                let b = dst.iter().map(|t| f64::from(t[c])).sum::<f64>() / dst.len() as f64;
                assert!((b / a[c] - 1.0).abs() < 5e-4, "case {case}, channel {c}: {} vs {b}", a[c]);
            }
        }
        let mut dst = vec![[0.0f32; 3]; 15];
        assert_eq!(latlong_to_equal_area(&[[1.0; 3]; 8], 4, 2, 2, 1, &mut dst), Err(LatLongError::DestinationSize));
        assert_eq!(latlong_to_equal_area(&[[1.0; 3]; 7], 4, 2, 2, 1, &mut dst), Err(LatLongError::SourceSize));
    }
}
