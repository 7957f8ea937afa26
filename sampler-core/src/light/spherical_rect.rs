//! Uniform sampling of the solid angle a rectangle subtends (Ureña, Fajardo & King, "An
//! Area-Preserving Parametrization for Spherical Rectangles", EGSR 2013). The solid angle is a
//! sum of four angles minus 2π and the first coordinate inverts a sine rule near that sum:
//! both cancel catastrophically for small solid angles, so the computation runs in f64, whose
//! relative error stays small down to [`MIN_SOLID_ANGLE`].

use core::f64::consts::PI;
use glam::{DVec3, Vec2, Vec3};

/// The smallest solid angle (sr) sampled this way: below it the solid angle's f64 rounding
/// exceeds ~1e-6 of its value (docs/tuning.md, "Light samplers", measures it), and the rectangle
/// is small and far enough that area sampling is uniform in solid angle to the same order.
pub const MIN_SOLID_ANGLE: f64 = 1e-8;

/// √(a² + b²): the scene's coordinates are far from f64's overflow, which `libm::hypot` guards
/// against at several times the cost.
#[inline]
fn hypot(a: f64, b: f64) -> f64 {
    libm::sqrt(a * a + b * b)
}

/// The rectangle `p0 + s·e1 + t·e2` seen from a reference point, in the rectangle's frame
/// `(x, y, z)` with z pointing away from the point (z0 < 0).
#[derive(Clone, Copy, Debug)]
pub(super) struct SphericalRect {
    x: DVec3,
    y: DVec3,
    z: DVec3,
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
    z0: f64,
    b0: f64,
    b1: f64,
    k: f64,
    solid_angle: f64,
}

impl SphericalRect {
    /// The rectangle with corner `p0` and perpendicular edges `e1`, `e2` (unit `x`, `y` and
    /// their lengths) seen from `o`; `None` when `o` lies in its plane or the solid angle is
    /// below [`MIN_SOLID_ANGLE`].
    pub(super) fn new(o: Vec3, p0: Vec3, x: DVec3, y: DVec3, lengths: (f64, f64)) -> Option<Self> {
        let mut z = x.cross(y);
        let d = p0.as_dvec3() - o.as_dvec3();
        let (x0, y0, mut z0) = (d.dot(x), d.dot(y), d.dot(z));
        if z0 > 0.0 {
            z0 = -z0;
            z = -z;
        }
        let off_plane = z0 < 0.0;
        if !off_plane {
            return None;
        }
        let (x1, y1) = (x0 + lengths.0, y0 + lengths.1);
        // The unit normals of the planes through `o` and each edge, in closed form.
        let n0 = DVec3::new(0.0, z0, -y0) / hypot(z0, y0);
        let n1 = DVec3::new(-z0, 0.0, x1) / hypot(z0, x1);
        let n2 = DVec3::new(0.0, -z0, y1) / hypot(z0, y1);
        let n3 = DVec3::new(z0, 0.0, -x0) / hypot(z0, x0);
        let angle = |a: DVec3, b: DVec3| libm::acos((-a.dot(b)).clamp(-1.0, 1.0));
        let (g0, g1, g2, g3) = (angle(n0, n1), angle(n1, n2), angle(n2, n3), angle(n3, n0));
        let k = 2.0 * PI - g2 - g3;
        let solid_angle = g0 + g1 - k;
        let ok = solid_angle.is_finite() && solid_angle >= MIN_SOLID_ANGLE;
        ok.then_some(Self { x, y, z, x0, y0, x1, y1, z0, b0: n0.z, b1: n2.z, k, solid_angle })
    }

    /// The solid angle in steradians.
    pub(super) fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// The point of the rectangle for the uniform `u` ∈ [0,1)², relative to the reference point
    /// (world frame): uniformly distributed in solid angle.
    pub(super) fn sample(&self, u: Vec2) -> DVec3 {
        let (u0, u1) = (u.x as f64, u.y as f64);
        // The x coordinate: the sub-rectangle [x0, xu] holds the fraction u0 of the solid angle.
        let au = u0 * self.solid_angle + self.k;
        let (sin_au, cos_au) = (libm::sin(au), libm::cos(au));
        let fu = (cos_au * self.b0 - self.b1) / sin_au;
        let cu = (1.0 / libm::sqrt(fu * fu + self.b0 * self.b0)).copysign(fu).clamp(-1.0, 1.0);
        let xu = -(cu * self.z0) / libm::sqrt((1.0 - cu * cu).max(0.0));
        let xu = if xu.is_nan() { self.x0 } else { xu.clamp(self.x0, self.x1) };
        // The y coordinate: uniform in the sine of the elevation along the line x = xu.
        let d = hypot(xu, self.z0);
        let h0 = self.y0 / hypot(d, self.y0);
        let h1 = self.y1 / hypot(d, self.y1);
        let hv = h0 + u1 * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 { (hv * d) / libm::sqrt(1.0 - hv2) } else { self.y1 };
        xu * self.x + yv.clamp(self.y0, self.y1) * self.y + self.z0 * self.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Van Oosterom & Strackee's solid angle of a triangle, accurate for small ones.
    fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let num = a.dot(b.cross(c)).abs();
        let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        2.0 * libm::atan2(num, den)
    }

    #[test]
    fn solid_angle_is_accurate_near_and_far() {
        let (x, y) = (DVec3::X, DVec3::Y);
        for (o, p0) in [
            (Vec3::new(0.3, 0.2, 1.0), Vec3::ZERO),
            (Vec3::new(0.5, 0.5, 1e-3), Vec3::ZERO),
            (Vec3::new(-3.0, 0.5, 0.01), Vec3::ZERO),
            (Vec3::new(0.5, 0.5, 1e3), Vec3::ZERO),
        ] {
            let r = SphericalRect::new(o, p0, x, y, (1.0, 1.0)).unwrap();
            let c = |s: f64, t: f64| p0.as_dvec3() + DVec3::new(s, t, 0.0) - o.as_dvec3();
            let exact = triangle_solid_angle(c(0.0, 0.0), c(1.0, 0.0), c(1.0, 1.0))
                + triangle_solid_angle(c(0.0, 0.0), c(1.0, 1.0), c(0.0, 1.0));
            assert!((r.solid_angle() - exact).abs() <= 1e-9 * exact, "{o}: {} vs {exact}", r.solid_angle());
        }
        assert!(SphericalRect::new(Vec3::new(0.5, 0.5, 0.0), Vec3::ZERO, x, y, (1.0, 1.0)).is_none());
    }
}
