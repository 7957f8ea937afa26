//! Elementary warps used by the BRDF samplers, each with its density.

use core::f32::consts::{FRAC_1_PI, FRAC_PI_4, PI};
use glam::{Vec2, Vec3};

/// Uniform point of the unit square → uniform point of the unit disk (Shirley–Chiu concentric).
#[inline]
#[must_use]
pub fn square_to_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let a = 2.0 * u.x - 1.0;
    let b = 2.0 * u.y - 1.0;
    if a == 0.0 && b == 0.0 {
        return Vec2::ZERO;
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a / b))
    };
    Vec2::new(r * libm::cosf(phi), r * libm::sinf(phi))
}

/// Cosine-weighted direction on the +z hemisphere.
#[inline]
#[must_use]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = square_to_uniform_disk_concentric(u);
    let z = libm::sqrtf((1.0 - d.length_squared()).max(0.0));
    Vec3::new(d.x, d.y, z)
}

/// Density of [`square_to_cosine_hemisphere`] with respect to solid angle.
#[inline]
#[must_use]
pub fn square_to_cosine_hemisphere_pdf(v: Vec3) -> f32 {
    if v.z > 0.0 { v.z * FRAC_1_PI } else { 0.0 }
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
