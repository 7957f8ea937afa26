//! Lat-long (equirectangular) → equal-area square.
//!
//! Orientation (the scene format's, the same as USD's DomeLight): for a unit direction d in the
//! map's local frame, `u = atan2(d.x, −d.z)/2π mod 1`, `v = acos(d.y)/π`; the top row is +Y,
//! u = 0 is −Z, u = ¼ is +X, u = ½ is +Z, u = ¾ is −X. Pixel (i, j) covers
//! [i/W, (i+1)/W) × [j/H, (j+1)/H) and is read as a constant (nearest texel). The equal-area
//! square lives in the same local frame: texel (x, y) is the direction `square_to_sphere` gives
//! for its points, x along u, y along v of the square.

use crate::env_io::RgbImage;
use rayon::prelude::*;
use sampler_core::glam::{Vec2, Vec3};
use sampler_core::mapping::square_to_sphere;
use std::f64::consts::PI;

/// Lat-long texel coordinates of a local direction.
#[inline]
pub fn direction_to_latlong(d: Vec3, width: usize, height: usize) -> (usize, usize) {
    let mut u = (d.x.atan2(-d.z) as f64) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = (d.y.clamp(-1.0, 1.0) as f64).acos() / PI;
    let i = ((u * width as f64) as usize).min(width - 1);
    let j = ((v * height as f64) as usize).min(height - 1);
    (i, j)
}

/// Smallest power-of-two level whose texels are no larger than the source's texels at the
/// equator (the largest ones): 4π/N² ≤ 2π²/(W·H), i.e. N ≥ √(2WH/π). 1024×512 → 1024²,
/// 4096×2048 → 4096².
pub fn equal_area_level(width: usize, height: usize) -> u32 {
    let n = (2.0 * width as f64 * height as f64 / PI)
        .sqrt()
        .ceil()
        .max(1.0) as u64;
    n.next_power_of_two()
        .trailing_zeros()
        .min(sampler_core::env::MAX_LEVEL)
}

/// Mean radiance over the sphere of a lat-long image, each row weighted by its solid angle.
pub fn latlong_mean(image: &RgbImage) -> [f64; 3] {
    let (w, h) = (image.width, image.height);
    let mut sum = [0.0f64; 3];
    for j in 0..h {
        let (t0, t1) = (PI * j as f64 / h as f64, PI * (j + 1) as f64 / h as f64);
        let omega = 2.0 * PI / w as f64 * (t0.cos() - t1.cos());
        for t in &image.texels[j * w..(j + 1) * w] {
            for c in 0..3 {
                sum[c] += t[c] as f64 * omega;
            }
        }
    }
    sum.map(|s| s / (4.0 * PI))
}

/// Mean radiance of an equal-area map (all texels have the same solid angle).
pub fn equal_area_mean(texels: &[[f32; 3]]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for t in texels {
        for c in 0..3 {
            sum[c] += t[c] as f64;
        }
    }
    sum.map(|s| s / texels.len() as f64)
}

/// Resamples a lat-long image into a `2^level` equal-area square, averaging `ss × ss`
/// stratified points per texel (accumulated in f64).
pub fn latlong_to_equal_area(image: &RgbImage, level: u32, ss: usize) -> Vec<[f32; 3]> {
    let n = 1usize << level;
    let ss = ss.max(1);
    let mut out = vec![[0.0f32; 3]; n * n];
    out.par_chunks_mut(n).enumerate().for_each(|(y, row)| {
        for (x, texel) in row.iter_mut().enumerate() {
            let mut acc = [0.0f64; 3];
            for sy in 0..ss {
                for sx in 0..ss {
                    let uv = Vec2::new(
                        ((x * ss + sx) as f64 + 0.5) as f32 / (n * ss) as f32,
                        ((y * ss + sy) as f64 + 0.5) as f32 / (n * ss) as f32,
                    );
                    let (i, j) =
                        direction_to_latlong(square_to_sphere(uv), image.width, image.height);
                    let t = image.texels[j * image.width + i];
                    for c in 0..3 {
                        acc[c] += t[c] as f64;
                    }
                }
            }
            let k = 1.0 / (ss * ss) as f64;
            *texel = acc.map(|a| (a * k) as f32);
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_matches_the_scene_format() {
        let (w, h) = (400, 200);
        let at = |d: Vec3| direction_to_latlong(d.normalize(), w, h);
        assert_eq!(at(Vec3::NEG_Z), (0, 100)); // u = 0 on the equator
        assert_eq!(at(Vec3::X), (100, 100)); // u = ¼
        assert_eq!(at(Vec3::Z), (200, 100)); // u = ½
        assert_eq!(at(Vec3::NEG_X), (300, 100)); // u = ¾
        assert_eq!(at(Vec3::Y).1, 0); // top row
        assert_eq!(at(Vec3::NEG_Y).1, 199);
    }

    #[test]
    fn resolution_keeps_the_detail() {
        assert_eq!(equal_area_level(1024, 512), 10);
        assert_eq!(equal_area_level(4096, 2048), 12);
        assert_eq!(equal_area_level(1, 1), 0);
    }

    #[test]
    fn resampling_preserves_the_mean() {
        // A lat-long map with a bright band and a hot pixel.
        let (w, h) = (256, 128);
        let mut texels = vec![[0.1f32, 0.2, 0.3]; w * h];
        for j in 20..30 {
            for i in 0..w {
                texels[j * w + i] = [2.0, 1.0, 0.5];
            }
        }
        texels[64 * w + 77] = [5000.0; 3];
        let image = RgbImage {
            width: w,
            height: h,
            texels,
            sanitized: 0,
        };
        let level = equal_area_level(w, h);
        let ea = latlong_to_equal_area(&image, level, 2);
        let (a, b) = (latlong_mean(&image), equal_area_mean(&ea));
        for c in 0..3 {
            assert!(
                (a[c] / b[c] - 1.0).abs() < 5e-3,
                "channel {c}: {} vs {}",
                a[c],
                b[c]
            );
        }
    }
}
