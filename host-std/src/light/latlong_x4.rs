//! The lat-long pixels of four points of the equal-area square at once, the same pixels as
//! [`direction_to_latlong`] of [`square_to_sphere`] gives one at a time.
//!
//! Resampling a map into the square looks up several points per texel, and the exact angles
//! (an `atan2` and an `acos` in f64 per point) are most of its time. Here the angles come from
//! f32 polynomials in SIMD lanes, within [`ANGLE_ERROR`] of the exact ones; a point whose angle
//! lies farther than that from every pixel edge is in the pixel the approximation says, and
//! the few points nearer an edge take the exact path. The answer is the exact path's, always.

use super::resample::direction_to_latlong;
use sampler_core::glam::{Vec3, Vec4};
use sampler_core::mapping::square_to_sphere_x4;
use std::f64::consts::PI;

/// A bound on the lanes' angle errors in radians, with a margin of several times the
/// polynomial's truncation and the f32 roundings (each below 1e-6).
const ANGLE_ERROR: f64 = 4e-6;

/// Finds lat-long pixels for a `width × height` map.
pub struct LatLongLookup {
    width: usize,
    height: usize,
    /// Pixels per radian of azimuth and of polar angle.
    per_radian: (f64, f64),
    /// How near a pixel edge (in pixels) an approximate angle must be to take the exact path.
    margin: (f64, f64),
}

impl LatLongLookup {
    /// The lookup for a `width × height` map (both > 0).
    pub fn new(width: usize, height: usize) -> Self {
        let per_radian = (width as f64 / (2.0 * PI), height as f64 / PI);
        Self { width, height, per_radian, margin: (ANGLE_ERROR * per_radian.0, ANGLE_ERROR * per_radian.1) }
    }

    /// The pixels (column, row) of the directions `square_to_sphere` gives for the four points
    /// (`s[k]`, `t[k]`) of the unit square.
    pub fn pixels_x4(&self, s: Vec4, t: Vec4) -> [(usize, usize); 4] {
        let [x, y, z] = square_to_sphere_x4(s, t);
        // Azimuth α = atan2(x, −z) in [0, 2π); polar angle θ = acos(y) = atan2(√((1−y)(1+y)), y),
        // whose argument keeps its relative precision near the poles.
        let alpha = atan2_x4(x, -z);
        let alpha = Vec4::select(alpha.cmplt(Vec4::ZERO), alpha + Vec4::splat(std::f32::consts::TAU), alpha);
        let rho = ((Vec4::ONE - y) * (Vec4::ONE + y)).max(Vec4::ZERO).sqrt();
        let theta = atan2_x4(rho, y);
        let (alpha, theta) = (alpha.to_array(), theta.to_array());
        let (xs, ys, zs) = (x.to_array(), y.to_array(), z.to_array());
        std::array::from_fn(|k| {
            let exact = || direction_to_latlong(Vec3::new(xs[k], ys[k], zs[k]), self.width, self.height);
            if xs[k] == 0.0 {
                return exact(); // the seam's own edge and the poles: signed zeros decide
            }
            let (Some(i), Some(j)) = (
                clear_of_edges(alpha[k] as f64 * self.per_radian.0, self.margin.0, self.width),
                clear_of_edges(theta[k] as f64 * self.per_radian.1, self.margin.1, self.height),
            ) else {
                return exact();
            };
            (i, j)
        })
    }

    /// The pixel of one point of the unit square, by the exact path.
    #[cfg(test)]
    fn pixel(&self, p: sampler_core::glam::Vec2) -> (usize, usize) {
        direction_to_latlong(sampler_core::mapping::square_to_sphere(p), self.width, self.height)
    }
}

/// The pixel index of the coordinate `f` (in pixels) if it lies more than `margin` from
/// every pixel edge and inside `0..n`.
#[inline]
fn clear_of_edges(f: f64, margin: f64, n: usize) -> Option<usize> {
    if !(f > 0.0 && f < n as f64) {
        return None;
    }
    // Truncation is the floor for positive f (and cheaper than `floor` without SSE4.1).
    let i = f as usize;
    let below = f - i as f64;
    (below > margin && 1.0 - below > margin).then_some(i)
}

/// atan2(y, x) in four f32 lanes within about 3e-7 rad: the argument reduced to [0, 1] by
/// symmetry and to [−(√2−1), √2−1] by atan t = π/4 + atan((t−1)/(t+1)), then the odd Taylor
/// series to t¹⁵ (truncation below 4e-8 there).
#[inline]
fn atan2_x4(y: Vec4, x: Vec4) -> Vec4 {
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay.cmpgt(ax);
    let t = ax.min(ay) / ax.max(ay).max(Vec4::splat(f32::MIN_POSITIVE));
    let high = t.cmpgt(Vec4::splat(std::f32::consts::SQRT_2 - 1.0));
    let r = Vec4::select(high, (t - Vec4::ONE) / (t + Vec4::ONE), t);
    let r2 = r * r;
    let mut p = Vec4::splat(-1.0 / 15.0);
    for c in [1.0 / 13.0, -1.0 / 11.0, 1.0 / 9.0, -1.0 / 7.0, 1.0 / 5.0, -1.0 / 3.0, 1.0] {
        p = p * r2 + Vec4::splat(c);
    }
    let mut a = r * p;
    a = Vec4::select(high, a + Vec4::splat(std::f32::consts::FRAC_PI_4), a);
    a = Vec4::select(swap, Vec4::splat(std::f32::consts::FRAC_PI_2) - a, a);
    a = Vec4::select(x.cmplt(Vec4::ZERO), Vec4::splat(std::f32::consts::PI) - a, a);
    // The sign of y; y = ±0 is never asked here (the callers take the exact path there).
    Vec4::select(y.cmplt(Vec4::ZERO), -a, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_find_the_exact_pixels() {
        let mut rng = sampler_core::rng::Pcg32::new(11, 3);
        let mut next = || rng.next_f32();
        for (w, h) in [(1, 1), (2, 1), (7, 3), (1024, 512), (4096, 2048), (16384, 8192)] {
            let lookup = LatLongLookup::new(w, h);
            for k in 0..100_000u32 {
                // Random points, texel corners and centres of squares up to 4096², and the
                // square's edges and diagonals (the poles, the seam, the axes).
                let pick = |j: u32, r: f32| match (k + j) % 4 {
                    0 => r,
                    1 => ((k * 7 + j) % 4097) as f32 / 4096.0,
                    2 => (((k * 13 + j) % 2048) as f32 + 0.5) / 2048.0,
                    _ => [0.0, 0.25, 0.5, 0.75, 1.0][((k + j) % 5) as usize],
                };
                let s = Vec4::from_array(std::array::from_fn(|j| pick(j as u32, next())));
                let t = Vec4::from_array(std::array::from_fn(|j| pick(j as u32 + 1, next())));
                let got = lookup.pixels_x4(s, t);
                for (j, got) in got.iter().enumerate() {
                    let p = sampler_core::glam::Vec2::new(s.to_array()[j], t.to_array()[j]);
                    assert_eq!(*got, lookup.pixel(p), "{w}×{h}: {p:?}");
                }
            }
        }
    }

    #[test]
    fn the_lanes_angles_are_within_the_bound() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let a = k as f64 / 200_000.0 * 2.0 * PI - PI;
            let (y, x) = ((a.sin() * 3.0) as f32, (a.cos() * 3.0) as f32);
            let got = atan2_x4(Vec4::splat(y), Vec4::splat(x)).x as f64;
            worst = worst.max((got - (y as f64).atan2(x as f64)).abs());
        }
        assert!(worst < ANGLE_ERROR / 4.0, "{worst}");
    }
}
