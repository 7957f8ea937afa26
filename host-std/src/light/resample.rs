//! Lat-long (equirectangular) → equal-area square.
//!
//! Orientation (the scene format's, the same as USD's DomeLight): for a unit direction d in the
//! map's local frame, `u = atan2(d.x, −d.z)/2π mod 1`, `v = acos(d.y)/π`; the top row is +Y,
//! u = 0 is −Z, u = ¼ is +X, u = ½ is +Z, u = ¾ is −X. Pixel (i, j) covers
//! [i/W, (i+1)/W) × [j/H, (j+1)/H) and is read as a constant (nearest texel). The equal-area
//! square lives in the same local frame: texel (x, y) is the direction `square_to_sphere` gives
//! for its points, x along u, y along v of the square.

use crate::light::image_file::RgbImage;
use crate::light::latlong_x4::LatLongLookup;
use rayon::prelude::*;
use sampler_core::glam::{Vec3, Vec4};
use std::f64::consts::PI;

/// Continuous lat-long coordinates (u, v) ∈ \[0,1)×\[0,1\] of a local direction (f64: an f32
/// atan2 rounds across pixel edges).
#[inline]
pub fn direction_to_latlong_uv(d: Vec3) -> (f64, f64) {
    let d = d.as_dvec3();
    let mut u = atan2(d.x, -d.z) / (2.0 * PI);
    if u < 0.0 {
        u += 1.0;
    }
    let v = d.y.clamp(-1.0, 1.0).acos() / PI;
    (u, v)
}

/// atan2(y, x) within 2 ulp of libm's (Cephes' rational atan on [0, 0.66], the rest by
/// tan(π/4 + a) = (1 + t)/(1 − t) and symmetry); exact on the axes and diagonals. Resampling
/// calls it for every point of every texel, where a correctly rounded atan2 is a large share of
/// the time.
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    const P: [f64; 5] = [
        -8.750_608_600_031_904e-1,
        -1.615_753_718_733_365e1,
        -7.500_855_792_314_705e1,
        -1.228_866_684_490_136e2,
        -6.485_021_904_942_025e1,
    ];
    const Q: [f64; 5] = [
        2.485_846_490_142_306e1,
        1.650_270_098_316_988_5e2,
        4.328_810_604_912_903e2,
        4.853_903_996_359_137e2,
        1.945_506_571_482_614e2,
    ];
    // The low parts of π/4, π/2 and π.
    const PIO4_LO: f64 = 0.5 * 6.123_233_995_736_766e-17;
    const PIO2_LO: f64 = 6.123_233_995_736_766e-17;
    const PI_LO: f64 = 1.224_646_799_147_353_2e-16;
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    if den == 0.0 || den.is_nan() || num.is_nan() {
        return y.atan2(x); // zeros and NaN: libm's conventions
    }
    let mut t = num / den;
    let (mut base, mut lo) = (0.0, 0.0);
    if t > 0.66 {
        (base, lo, t) = (std::f64::consts::FRAC_PI_4, PIO4_LO, (t - 1.0) / (t + 1.0));
    }
    let z = t * t;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    let mut a = base + (t + t * (z * p / q) + lo);
    if swap {
        a = std::f64::consts::FRAC_PI_2 - a + PIO2_LO;
    }
    if x < 0.0 {
        a = std::f64::consts::PI - a + PI_LO;
    }
    a.copysign(y)
}

/// Lat-long texel of a local direction.
#[inline]
pub fn direction_to_latlong(d: Vec3, width: usize, height: usize) -> (usize, usize) {
    let (u, v) = direction_to_latlong_uv(d);
    (((u * width as f64) as usize).min(width - 1), ((v * height as f64) as usize).min(height - 1))
}

/// Smallest power-of-two level whose texels are no larger than the source's texels at the
/// equator (the largest ones): 4π/N² ≤ 2π²/(W·H), i.e. N ≥ √(2WH/π). 1024×512 → 1024²,
/// 4096×2048 → 4096².
pub fn equal_area_level(width: usize, height: usize) -> u32 {
    let n = (2.0 * width as f64 * height as f64 / PI).sqrt().ceil().max(1.0) as u64;
    n.next_power_of_two().trailing_zeros().min(sampler_core::env::MAX_LEVEL)
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

/// Rows of the square resampled together (their shared corners looked up once).
const BAND_ROWS: usize = 16;

/// Resamples a lat-long image into a `2^level` equal-area square, conserving energy.
///
/// A bright source (the sun) can carry most of a map's energy on a few pixels that cover a few
/// texels; any point-sampled *gather* quantises their coverage (a 1-pixel sun loses percents of
/// the map's energy). So each source pixel is split at T = 64 × the map's mean luminance:
/// * the part up to T is gathered: every texel is the mean of `ss × ss` stratified points, and
///   of 4 × 4 where those and the texel's corners disagree by more than 25% (a finer gather
///   costs many times the time for an energy error that is already small);
/// * the excess above T, present on at most 1/64 of the sphere, is splatted: 8 × 8 points per
///   pixel, uniform in solid angle, each carrying 1/64 of the pixel's excess energy into the
///   texel it lands in — energy conserved exactly, whatever the coverage.
pub fn latlong_to_equal_area(image: &RgbImage, level: u32, ss: usize) -> Vec<[f32; 3]> {
    let n = 1usize << level;
    let ss = ss.max(1);
    let lum = |t: [f32; 3]| (0.212_671 * t[0] + 0.715_160 * t[1] + 0.072_169 * t[2]) as f64;
    let mean = latlong_mean(image);
    let threshold = 64.0 * (0.212_671 * mean[0] + 0.715_160 * mean[1] + 0.072_169 * mean[2]);
    // The part of a texel's radiance up to the threshold (same chromaticity).
    let clamped = |t: [f32; 3]| {
        let l = lum(t);
        if l > threshold && threshold > 0.0 { t.map(|c| (c as f64 * threshold / l) as f32) } else { t }
    };
    let pixels = LatLongLookup::new(image.width, image.height);
    // The source texels at four points of the square (coordinates in f64, read as f32).
    let lookup4 = |s: [f64; 4], t: [f64; 4]| {
        let found = pixels.pixels_x4(Vec4::from_array(s.map(|s| s as f32)), Vec4::from_array(t.map(|t| t as f32)));
        found.map(|(i, j)| clamped(image.texels[j * image.width + i]))
    };
    // The mean of k × k stratified points of texel (x, y), row by row.
    let average = |x: usize, y: usize, k: usize| -> [f64; 3] {
        let mut acc = [0.0f64; 3];
        let at = |i: usize| (i as f64 + 0.5) / (n * k) as f64;
        each_point(
            &lookup4,
            k * k,
            |q| (at(x * k + q % k), at(y * k + q / k)),
            |f| {
                for c in 0..3 {
                    acc[c] += f[c] as f64;
                }
            },
        );
        acc.map(|a| a / (k * k) as f64)
    };
    let mut out = vec![[0.0f32; 3]; n * n];
    // Bands of rows, each with its (rows + 1) × (n + 1) texel corners looked up once and shared
    // by the four texels that meet there (instead of four lookups per texel).
    let band = BAND_ROWS.min(n);
    out.par_chunks_mut(n * band).enumerate().for_each(|(b, rows)| {
        let y0 = b * band;
        let (width, count) = (n + 1, (band + 1) * (n + 1));
        let mut corner: Vec<f64> = Vec::with_capacity(count);
        let at = |q: usize| ((q % width) as f64 / n as f64, (y0 + q / width) as f64 / n as f64);
        each_point(&lookup4, count, at, |t| corner.push(lum(t)));
        for (k, texel) in rows.iter_mut().enumerate() {
            let (x, y) = (k % n, y0 + k / n);
            let mean = average(x, y, ss);
            // Contrast across the texel: its points' mean against its corners.
            let m = lum(mean.map(|c| c as f32));
            let at = |dx: usize, dy: usize| corner[(y - y0 + dy) * (n + 1) + x + dx];
            let corners = [at(0, 0), at(1, 0), at(0, 1), at(1, 1)];
            let (lo, hi) = corners.iter().fold((m, m), |(lo, hi), &c| (lo.min(c), hi.max(c)));
            let mean = if hi > 1.25 * lo && ss < 4 { average(x, y, 4) } else { mean };
            *texel = mean.map(|a| a as f32);
        }
    });
    splat_excess(image, n, &clamped, &mut out);
    out
}

/// Calls `visit` with the texel `lookup4` finds at each of the `count` points `at(q)` of the
/// square, in order, looked up four at a time (the last four padded with the last point).
#[inline]
fn each_point(
    lookup4: &impl Fn([f64; 4], [f64; 4]) -> [[f32; 3]; 4],
    count: usize,
    at: impl Fn(usize) -> (f64, f64),
    mut visit: impl FnMut([f32; 3]),
) {
    for first in (0..count).step_by(4) {
        let points: [(f64, f64); 4] = std::array::from_fn(|l| at((first + l).min(count - 1)));
        let found = lookup4(points.map(|p| p.0), points.map(|p| p.1));
        found[..(count - first).min(4)].iter().for_each(|&t| visit(t));
    }
}

/// Adds the radiance that `clamped` cut from the source's bright pixels to the equal-area map
/// `out` (n × n), each pixel's excess spread over 8 × 8 directions uniform in its solid angle:
/// the map keeps the source's energy without the clamp's outliers in single texels' averages.
fn splat_excess(image: &RgbImage, n: usize, clamped: &impl Fn([f32; 3]) -> [f32; 3], out: &mut [[f32; 3]]) {
    const SPLAT: usize = 8;
    let texel_solid_angle = 4.0 * PI / (n * n) as f64;
    let (w, h) = (image.width, image.height);
    let mut energy = vec![[0.0f64; 3]; 0];
    for j in 0..h {
        let (c0, c1) = ((PI * j as f64 / h as f64).cos(), (PI * (j + 1) as f64 / h as f64).cos());
        let pixel_solid_angle = 2.0 * PI / w as f64 * (c0 - c1);
        for i in 0..w {
            let t = image.texels[j * w + i];
            let c = clamped(t);
            if c == t {
                continue;
            }
            if energy.is_empty() {
                energy = vec![[0.0f64; 3]; n * n];
            }
            let excess = [0, 1, 2].map(|k| (t[k] - c[k]) as f64 * pixel_solid_angle / (SPLAT * SPLAT) as f64);
            for b in 0..SPLAT {
                // Uniform in solid angle: cos θ uniform over the row.
                let cos_t = c0 + (c1 - c0) * (b as f64 + 0.5) / SPLAT as f64;
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                for a in 0..SPLAT {
                    let phi = 2.0 * PI * (i as f64 + (a as f64 + 0.5) / SPLAT as f64) / w as f64;
                    // Inverse of direction_to_latlong_uv: u = atan2(x, −z)/2π, v = θ/π.
                    let d = Vec3::new((sin_t * phi.sin()) as f32, cos_t as f32, (-sin_t * phi.cos()) as f32);
                    let (x, y) = sampler_core::mapping::texel_of(sampler_core::mapping::sphere_to_square(d), n as u32);
                    let e = &mut energy[y as usize * n + x as usize];
                    for k in 0..3 {
                        e[k] += excess[k];
                    }
                }
            }
        }
    }
    if !energy.is_empty() {
        for (t, e) in out.iter_mut().zip(&energy) {
            for k in 0..3 {
                t[k] += (e[k] / texel_solid_angle) as f32;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orientation_matches_the_scene_format() {
        let uv = |d: Vec3| direction_to_latlong_uv(d.normalize());
        let close = |(u, v): (f64, f64), (eu, ev): (f64, f64)| (u - eu).abs() < 1e-7 && (v - ev).abs() < 1e-7;
        assert!(close(uv(Vec3::NEG_Z), (0.0, 0.5))); // u = 0 on the equator
        assert!(close(uv(Vec3::X), (0.25, 0.5)));
        assert!(close(uv(Vec3::Z), (0.5, 0.5)));
        assert!(close(uv(Vec3::NEG_X), (0.75, 0.5)));
        assert!(uv(Vec3::Y).1 < 1e-7); // top row is +Y
        assert!((uv(Vec3::NEG_Y).1 - 1.0).abs() < 1e-7);
        assert_eq!(direction_to_latlong(Vec3::new(0.1, 0.2, -1.0).normalize(), 400, 200).0, 6);
    }

    #[test]
    fn atan2_is_within_two_ulp_of_libm() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let ulps = |a: f64, b: f64| (a.to_bits() as i64 - b.to_bits() as i64).unsigned_abs();
        for _ in 0..200_000 {
            let (y, x) = (next(), next());
            for (y, x) in [(y, x), (y * 1e-9, x), (y, x * 1e-9), (y * 1e300, x * 1e300)] {
                assert!(ulps(atan2(y, x), y.atan2(x)) <= 2, "atan2({y}, {x})");
            }
        }
        for y in [0.0, -0.0, 1.0, -1.0, 3.0] {
            for x in [0.0, -0.0, 1.0, -1.0, 3.0] {
                assert_eq!(atan2(y, x).to_bits(), y.atan2(x).to_bits(), "atan2({y}, {x})");
            }
        }
        assert!(atan2(f64::NAN, 1.0).is_nan() && atan2(1.0, f64::NAN).is_nan());
    }

    #[test]
    fn resolution_keeps_the_detail() {
        assert_eq!(equal_area_level(1024, 512), 10);
        assert_eq!(equal_area_level(4096, 2048), 12);
        assert_eq!(equal_area_level(1, 1), 0);
    }

    #[test]
    fn resampling_preserves_the_mean() {
        // Constant, a bright band, a hot pixel on the equator, a hot pixel next to the pole.
        let (w, h) = (256, 128);
        for case in 0..4 {
            let mut texels = vec![[0.1f32, 0.2, 0.3]; w * h];
            match case {
                1 => (20..30).for_each(|j| (0..w).for_each(|i| texels[j * w + i] = [2.0, 1.0, 0.5])),
                2 => texels[64 * w + 77] = [5000.0, 4000.0, 3000.0],
                3 => texels[2 * w + 77] = [5000.0, 4000.0, 3000.0],
                _ => {}
            }
            let image = RgbImage { width: w, height: h, texels, sanitized: 0 };
            let ea = latlong_to_equal_area(&image, equal_area_level(w, h), 2);
            let (a, b) = (latlong_mean(&image), equal_area_mean(&ea));
            for c in 0..3 {
                assert!((b[c] / a[c] - 1.0).abs() < 5e-4, "case {case}, channel {c}: {} vs {}", a[c], b[c]);
            }
        }
    }
}
