//! Elementary warps used by the BRDF samplers, each with its density.

use core::f32::consts::{FRAC_1_PI, PI};
use glam::{Vec2, Vec3, Vec4};

/// Uniform point of the unit square → uniform point of the unit disk (Shirley–Chiu concentric).
#[inline]
#[must_use]
pub fn square_to_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let a = 2.0 * u.x - 1.0;
    let b = 2.0 * u.y - 1.0;
    if a == 0.0 && b == 0.0 {
        return Vec2::ZERO;
    }
    // φ/2π ∈ [−⅛, ⅜]: the polynomial sincos needs a non-negative turn.
    let (r, turn) = if a.abs() > b.abs() { (a, 0.125 * (b / a)) } else { (b, 0.25 - 0.125 * (a / b)) };
    let (s, c) = sin_cos_2pi(if turn < 0.0 { turn + 1.0 } else { turn });
    Vec2::new(r * c, r * s)
}

#[cfg(test)]
mod sincos_tests {
    use super::*;

    #[test]
    fn sin_cos_2pi_x4_is_sin_cos_2pi() {
        let bits = |(s, c): (f32, f32)| (s.to_bits(), c.to_bits());
        for i in 0..=(1 << 16) {
            let u = (i as f32 / 65_536.0).min(1.0 - f32::EPSILON / 2.0);
            let (s, c) = sin_cos_2pi_x4(Vec4::new(u, 0.0, 0.25, u * 0.5));
            for (k, v) in [u, 0.0, 0.25, u * 0.5].into_iter().enumerate() {
                assert_eq!(bits((s[k], c[k])), bits(sin_cos_2pi(v)), "{v}");
            }
        }
    }

    #[test]
    fn sin_cos_2pi_is_accurate() {
        for i in 0..=100_000 {
            let u = i as f32 / 100_000.0;
            let (s, c) = sin_cos_2pi(u);
            let a = 2.0 * core::f64::consts::PI * u as f64;
            assert!((s as f64 - libm::sin(a)).abs() < 3e-7 && (c as f64 - libm::cos(a)).abs() < 3e-7, "{u}");
        }
    }
}

/// Cosine-weighted direction on the +z hemisphere.
#[inline]
#[must_use]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_uniform_disk_concentric(u);
    let z = libm::sqrtf((1.0 - d.length_squared()).max(0.0));
    Vec3::new(d.x, d.y, z)
}

/// [`square_to_cosine_hemisphere`] for four points (`ux`, `uy` their coordinates), bit for bit:
/// the concentric map's branches by selects. Returns the directions' x, y and z.
#[inline]
#[must_use]
pub fn square_to_cosine_hemisphere_x4(ux: Vec4, uy: Vec4) -> [Vec4; 3] {
    let sp = Vec4::splat;
    let (a, b) = (sp(2.0) * ux - sp(1.0), sp(2.0) * uy - sp(1.0));
    let wide = a.abs().cmpgt(b.abs());
    let r = Vec4::select(wide, a, b);
    let turn = Vec4::select(wide, sp(0.125) * (b / a), sp(0.25) - sp(0.125) * (a / b));
    let (s, c) = sin_cos_2pi_x4(Vec4::select(turn.cmplt(Vec4::ZERO), turn + sp(1.0), turn));
    let centre = a.cmpeq(Vec4::ZERO) & b.cmpeq(Vec4::ZERO);
    let (x, y) = (Vec4::select(centre, Vec4::ZERO, r * c), Vec4::select(centre, Vec4::ZERO, r * s));
    let z = crate::mapping::sqrt4((sp(1.0) - (x * x + y * y)).max(Vec4::ZERO));
    [x, y, z]
}

/// Density of [`square_to_cosine_hemisphere`] with respect to solid angle.
#[inline]
#[must_use]
pub fn square_to_cosine_hemisphere_pdf(v: Vec3) -> f32 {
    if v.z > 0.0 { v.z * FRAC_1_PI } else { 0.0 }
}

/// Uniform direction in the cone about +z whose half-angle θmax has 1 − cos θmax =
/// `one_minus_cos` (density 1/(2π·one_minus_cos)): 1 − cos θ = u.x·(1 − cos θmax), and the
/// sine from (1 − cos θ)(1 + cos θ), which keeps its precision where cos θ rounds to 1 (the
/// sun's cone is 4.6 mrad wide).
#[inline]
#[must_use]
pub fn square_to_uniform_cone(u: Vec2, one_minus_cos: f32) -> Vec3 {
    let t = u.x * one_minus_cos;
    let sin_theta = libm::sqrtf((t * (2.0 - t)).max(0.0));
    let (s, c) = sin_cos_2pi(u.y);
    Vec3::new(sin_theta * c, sin_theta * s, 1.0 - t)
}

/// Mirror direction of `v` about the +z axis in local coordinates.
#[inline]
#[must_use]
pub fn reflect_z(v: Vec3) -> Vec3 {
    Vec3::new(-v.x, -v.y, v.z)
}

/// Mirror direction of `v` about the unit vector `m`.
#[inline]
#[must_use]
pub fn reflect(v: Vec3, m: Vec3) -> Vec3 {
    2.0 * v.dot(m) * m - v
}

/// 2π
pub const TWO_PI: f32 = 2.0 * PI;

/// (sin 2πu, cos 2πu) for u ∈ [0, 1], by octant reduction and Taylor polynomials on
/// [−π/4, π/4] (abs. error < 2e-7): cheaper than libm's sinf + cosf, and bit for bit
/// [`sin_cos_2pi_x4`]'s results (tested).
#[inline]
#[must_use]
pub fn sin_cos_2pi(u: f32) -> (f32, f32) {
    // Quadrant q and remainder w ∈ [−¼, ¼) of a quarter turn.
    let x = 4.0 * u;
    let q = (x + 0.5) as i32; // round to nearest quarter (u ≥ 0)
    let w = (x - q as f32) * (0.5 * PI);
    let w2 = w * w;
    let s = w * (1.0 + w2 * (-1.0 / 6.0 + w2 * (1.0 / 120.0 + w2 * (-1.0 / 5040.0 + w2 * (1.0 / 362_880.0)))));
    let c = 1.0 + w2 * (-0.5 + w2 * (1.0 / 24.0 + w2 * (-1.0 / 720.0 + w2 * (1.0 / 40_320.0))));
    match q & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// [`sin_cos_2pi`] for four values, bit for bit (the quadrant by selects instead of a match).
#[inline]
#[must_use]
pub fn sin_cos_2pi_x4(u: Vec4) -> (Vec4, Vec4) {
    let sp = Vec4::splat;
    let x = sp(4.0) * u;
    // The quarter turn (`as i32` of a non-negative value is its truncation) and its index mod 4.
    let q = (x + sp(0.5)).trunc();
    let w = (x - q) * sp(0.5 * PI);
    let w2 = w * w;
    let s = w
        * (sp(1.0)
            + w2 * (sp(-1.0 / 6.0) + w2 * (sp(1.0 / 120.0) + w2 * (sp(-1.0 / 5040.0) + w2 * sp(1.0 / 362_880.0)))));
    let c = sp(1.0) + w2 * (sp(-0.5) + w2 * (sp(1.0 / 24.0) + w2 * (sp(-1.0 / 720.0) + w2 * sp(1.0 / 40_320.0))));
    let r = q - sp(4.0) * (q * sp(0.25)).trunc();
    let (odd, high) = ((r - sp(2.0) * (r * sp(0.5)).trunc()).cmpgt(Vec4::ZERO), r.cmpge(sp(2.0)));
    // Quadrants 0–3: (s, c), (c, −s), (−s, −c), (−c, s).
    let (sin, cos) = (Vec4::select(odd, c, s), Vec4::select(odd, s, c));
    (Vec4::select(high, -sin, sin), Vec4::select(odd ^ high, -cos, cos))
}

/// An orthonormal frame whose third axis is the unit vector `a`, as `(s, t)`.
#[inline]
#[must_use]
pub fn basis_around(a: Vec3) -> (Vec3, Vec3) {
    let f = crate::frame::Frame::from_normal(a);
    (f.s, f.t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The four-wide cosine warp is the scalar one's bits, on a grid that includes the centre,
    /// the diagonals and the edges.
    #[test]
    fn cosine_hemisphere_x4_is_the_scalar_warp() {
        let n = 64;
        let grid = |i: usize| Vec2::new((i % (n + 1)) as f32, (i / (n + 1)) as f32) / n as f32;
        for first in (0..(n + 1) * (n + 1) - 3).step_by(4) {
            let quad: [Vec2; 4] = core::array::from_fn(|k| grid(first + k));
            let [x, y, z] = square_to_cosine_hemisphere_x4(
                Vec4::new(quad[0].x, quad[1].x, quad[2].x, quad[3].x),
                Vec4::new(quad[0].y, quad[1].y, quad[2].y, quad[3].y),
            );
            for (k, u) in quad.iter().enumerate() {
                let v = square_to_cosine_hemisphere(*u);
                assert_eq!([x[k], y[k], z[k]].map(f32::to_bits), v.to_array().map(f32::to_bits), "{u}");
            }
        }
    }

    #[test]
    fn cosine_hemisphere_stays_on_top() {
        for i in 0..=16 {
            for j in 0..=16 {
                let v = square_to_cosine_hemisphere(Vec2::new(i as f32 / 16.0, j as f32 / 16.0));
                assert!(v.z >= 0.0 && (v.length() - 1.0).abs() < 1e-5);
            }
        }
    }
}
