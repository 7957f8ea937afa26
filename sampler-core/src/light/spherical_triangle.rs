//! Uniform sampling of the solid angle a triangle subtends (Arvo, "Stratified Sampling of
//! Spherical Triangles", SIGGRAPH 1995). The first coordinate picks the sub-triangle holding the
//! fraction u₀ of the solid angle, the second a point along its far edge's arc. The spherical
//! excess cancels catastrophically for small triangles, so the solid angle comes from Van
//! Oosterom & Strackee's formula and the rest runs in f64.

use glam::{DVec3, Vec2, Vec3};

/// The smallest solid angle (sr) sampled this way, the spherical rectangle's floor: below it a
/// triangle is small and far enough that area sampling is uniform in solid angle to f32's
/// precision ([`TriangleSampling::default`](super::TriangleSampling) switches far earlier).
pub const MIN_SOLID_ANGLE: f64 = 1e-8;

/// A triangle's vertices seen from a reference point, as unit directions.
#[derive(Clone, Copy, Debug)]
pub(super) struct SphericalTriangle {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    /// The interior angle at `a` as (cos, sin).
    alpha: (f64, f64),
    solid_angle: f64,
}

impl SphericalTriangle {
    /// The triangle `v0 v1 v2` seen from `o`; `None` when it is seen edge-on or its solid angle
    /// is below [`MIN_SOLID_ANGLE`].
    pub(super) fn new(o: Vec3, v: [Vec3; 3]) -> Option<Self> {
        let o = o.as_dvec3();
        let [a, b, c] = v.map(|p| (p.as_dvec3() - o).normalize_or_zero());
        let triple = a.dot(b.cross(c)).abs();
        let solid_angle = 2.0 * libm::atan2(triple, 1.0 + a.dot(b) + b.dot(c) + c.dot(a));
        let large_enough = solid_angle >= MIN_SOLID_ANGLE;
        if !large_enough {
            return None;
        }
        // The angle at `a` between the great circles towards `b` and towards `c`.
        // Its cosine and sine straight from the planes' unit normals: no inverse trigonometry.
        let (n_ab, n_ac) = (a.cross(b).normalize_or_zero(), a.cross(c).normalize_or_zero());
        let alpha = (n_ab.dot(n_ac).clamp(-1.0, 1.0), n_ab.cross(n_ac).length().min(1.0));
        let ok = n_ab != DVec3::ZERO && n_ac != DVec3::ZERO && alpha.1 > 0.0;
        ok.then_some(Self { a, b, c, alpha, solid_angle })
    }

    /// The solid angle in steradians.
    pub(super) fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// A unit direction for the uniform `u` ∈ [0,1)², uniformly distributed in solid angle.
    pub(super) fn sample(&self, u: Vec2) -> DVec3 {
        let (a, b, c) = (self.a, self.b, self.c);
        let (cos_alpha, sin_alpha) = self.alpha;
        // The sub-triangle a-b-c' of area u₀·Ω: c' on the arc from a to c (Arvo's eq. for cos b').
        let area = u.x as f64 * self.solid_angle;
        let (s, t) = (
            libm::sin(area) * cos_alpha - libm::cos(area) * sin_alpha,
            libm::cos(area) * cos_alpha + libm::sin(area) * sin_alpha,
        );
        let (uu, vv) = (t - cos_alpha, s + sin_alpha * a.dot(b));
        let q = (((vv * t - uu * s) * cos_alpha - vv) / ((vv * s + uu * t) * sin_alpha)).clamp(-1.0, 1.0);
        let c_perp = (c - c.dot(a) * a).normalize_or_zero();
        let c_hat = q * a + libm::sqrt((1.0 - q * q).max(0.0)) * c_perp;
        // Uniform in solid angle along the arc from b to c': z = cos of the angle from b.
        let z = 1.0 - u.y as f64 * (1.0 - c_hat.dot(b));
        let perp = (c_hat - c_hat.dot(b) * b).normalize_or_zero();
        (z * b + libm::sqrt((1.0 - z * z).max(0.0)) * perp).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_of_the_unit_square_map_to_the_vertices() {
        let v = [Vec3::new(1.0, 0.0, 1.0), Vec3::new(-0.5, 0.8, 1.0), Vec3::new(-0.4, -0.9, 1.0)];
        let t = SphericalTriangle::new(Vec3::ZERO, v).unwrap();
        let dir = |p: Vec3| p.as_dvec3().normalize();
        assert!((t.sample(Vec2::new(0.3, 0.0)) - dir(v[1])).length() < 1e-9);
        assert!((t.sample(Vec2::new(0.0, 1.0)) - dir(v[0])).length() < 1e-6);
        assert!((t.sample(Vec2::new(1.0, 1.0)) - dir(v[2])).length() < 1e-6);
        // An octant subtends 4π/8.
        let octant = SphericalTriangle::new(Vec3::ZERO, [Vec3::X, Vec3::Y, Vec3::Z]).unwrap();
        assert!((octant.solid_angle() - core::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
