//! A triangular area light, the face of a mesh light. Two samplers: uniform in the solid angle
//! it subtends (spherical triangles, [`super::spherical_triangle`]) or uniform on its area
//! converted to solid angle. [`TriangleSampling::default`] is the measured choice.

use super::spherical_triangle::SphericalTriangle;
use super::tilted_integral::TiltedGrid;
use super::{
    Emission, Light, LightError, LightHit, LightSample, Shaping, area_sample, area_to_solid_angle, checked_rgb,
    emitted, finite,
};
use glam::{Vec2, Vec3};

/// How a [`TriangleLight`] draws directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TriangleSampling {
    /// Uniform on the area, converted to solid angle (d²/(|cos| A)).
    Area,
    /// Uniform in the solid angle the triangle subtends where it is at least `min_solid_angle`
    /// sr from the shading point, uniform on the area elsewhere.
    SolidAngle {
        /// Below this solid angle (sr) the triangle is sampled by area.
        min_solid_angle: f32,
    },
}

impl Default for TriangleSampling {
    /// Solid-angle sampling where the triangle subtends at least 0.01 sr, area sampling below:
    /// close triangles gain much from solid-angle sampling (area sampling's density varies with
    /// d²/cos over them), and distant ones, where both are nearly uniform in solid angle, save
    /// the spherical construction's trigonometry (docs/tuning.md, "Light samplers").
    fn default() -> Self {
        Self::SolidAngle { min_solid_angle: 0.01 }
    }
}

/// A triangle `v0 v1 v2` emitting on its front side (normal (v1 − v0) × (v2 − v0)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleLight {
    v: [Vec3; 3],
    normal: Vec3,
    area: f32,
    emission: Emission,
    sampling: TriangleSampling,
    /// The emitted power, computed with the emission (a shaped face's is an integral).
    power: Vec3,
}

/// Slack of the barycentric hit test that admits the rounding of points drawn on the edges.
const EDGE_SLACK: f32 = 1e-5;

impl TriangleLight {
    /// The triangle `v` (counter-clockwise seen from its front) emitting `radiance` (RGB).
    pub fn new(v: [Vec3; 3], radiance: Vec3) -> Result<Self, LightError> {
        for p in v {
            finite(p)?;
        }
        let cross = (v[1] - v[0]).cross(v[2] - v[0]);
        let len = cross.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(LightError::ZeroArea);
        }
        let emission = Emission { radiance: checked_rgb(radiance)?, two_sided: false, shaping: Shaping::NONE };
        let (normal, area) = (cross / len, 0.5 * len);
        let power = emission.power_facing(area, normal);
        Ok(Self { v, normal, area, emission, sampling: TriangleSampling::default(), power })
    }

    /// Both sides emit.
    #[must_use]
    pub fn is_two_sided(&self) -> bool {
        self.emission.two_sided
    }

    /// The same triangle drawing directions by `sampling`.
    #[must_use]
    pub fn with_sampling(self, sampling: TriangleSampling) -> Self {
        Self { sampling, ..self }
    }

    /// The same triangle, emitting on both sides when `two_sided`.
    #[must_use]
    pub fn with_two_sided(self, two_sided: bool) -> Self {
        self.with_emission(Emission { two_sided, ..self.emission })
    }

    /// The same triangle emitting `emission`, its power recomputed.
    fn with_emission(self, emission: Emission) -> Self {
        Self { emission, power: emission.power_facing(self.area, self.normal), ..self }
    }

    /// The same triangle, its radiance shaped by `shaping` about the shaping's own axis (for a
    /// mesh light, the light's primary axis rather than this face's normal).
    #[must_use]
    pub fn with_shaping(self, shaping: Shaping) -> Self {
        self.with_emission(Emission { shaping, ..self.emission })
    }

    /// [`TriangleLight::with_shaping`] for a profiled `shaping` whose integrals over the faces of
    /// one mesh come from its `grid` (built once for them all) rather than from the profile.
    #[must_use]
    pub fn with_shaping_on_grid(self, shaping: Shaping, grid: &TiltedGrid<'_>) -> Self {
        let emission = Emission { shaping, ..self.emission };
        let tilted = shaping.profile().is_some() && shaping.axis().dot(self.normal) < 1.0 - 1e-7;
        if !tilted {
            return self.with_emission(emission);
        }
        let power = emission.radiance * self.area * grid.integral_about(self.normal, emission.two_sided);
        Self { emission, power, ..self }
    }

    /// How its radiance falls off away from the shaping axis.
    #[must_use]
    pub fn shaping(&self) -> &Shaping {
        &self.emission.shaping
    }

    /// The triangle's surface.
    #[must_use]
    pub fn surface(&self) -> super::LightSurface {
        super::LightSurface::Triangle(self.v)
    }

    /// Area in square units.
    #[must_use]
    pub fn area(&self) -> f32 {
        self.area
    }

    fn lit_from(&self, p: Vec3) -> bool {
        let side = (p - self.v[0]).dot(self.normal);
        side > 0.0 || (self.emission.two_sided && side < 0.0)
    }

    /// The spherical triangle from `p` when the sampling setting says to sample by solid angle.
    fn spherical(&self, p: Vec3) -> Option<SphericalTriangle> {
        match self.sampling {
            TriangleSampling::Area => None,
            TriangleSampling::SolidAngle { min_solid_angle } => {
                SphericalTriangle::new(p, self.v).filter(|t| t.solid_angle() >= min_solid_angle as f64)
            }
        }
    }

    /// The distance along the unit `dir` from `p` to the triangle (Möller–Trumbore), if the
    /// ray meets it.
    fn intersect(&self, p: Vec3, dir: Vec3) -> Option<f32> {
        let (e1, e2) = (self.v[1] - self.v[0], self.v[2] - self.v[0]);
        let h = dir.cross(e2);
        let inv = 1.0 / e1.dot(h);
        let s = p - self.v[0];
        let b1 = s.dot(h) * inv;
        let q = s.cross(e1);
        let b2 = dir.dot(q) * inv;
        let t = e2.dot(q) * inv;
        let inside = b1 >= -EDGE_SLACK && b2 >= -EDGE_SLACK && b1 + b2 <= 1.0 + EDGE_SLACK;
        (inside && t > 0.0 && t.is_finite()).then_some(t)
    }
}

impl Light for TriangleLight {
    fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        if !self.lit_from(p) {
            return None;
        }
        if let Some(tri) = self.spherical(p) {
            let dir = tri.sample(u);
            // The distance to the triangle's plane along the drawn direction.
            let n = self.normal.as_dvec3();
            let distance = ((self.v[0].as_dvec3() - p.as_dvec3()).dot(n) / dir.dot(n)) as f32;
            let pdf = (1.0 / tri.solid_angle()) as f32;
            let ok = distance > 0.0 && distance.is_finite();
            let dir = dir.as_vec3();
            let radiance = self.emission.towards(dir);
            return ok.then_some(LightSample { dir, distance, radiance, pdf, delta: false });
        }
        // Uniform barycentrics by the square-root warp.
        let su = libm::sqrtf(u.x);
        let q = self.v[0] + (u.y * su) * (self.v[1] - self.v[0]) + (su * (1.0 - u.y)) * (self.v[2] - self.v[0]);
        area_sample(p, q, self.normal, self.area, |dir| self.emission.towards(dir))
    }

    fn pdf(&self, p: Vec3, dir: Vec3) -> f32 {
        if !self.lit_from(p) {
            return 0.0;
        }
        let Some(t) = self.intersect(p, dir) else { return 0.0 };
        match self.spherical(p) {
            Some(tri) => (1.0 / tri.solid_angle()) as f32,
            None => area_to_solid_angle(t, dir.dot(self.normal), self.area),
        }
    }

    fn eval(&self, p: Vec3, dir: Vec3) -> Option<LightHit> {
        let distance = self.intersect(p, dir)?;
        emitted(&self.emission, -dir.dot(self.normal), dir).map(|radiance| LightHit { radiance, distance })
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn power(&self, _scene_radius: f32) -> Vec3 {
        self.power
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_samplers_land_on_the_triangle() {
        let v = [Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)];
        let light = TriangleLight::new(v, Vec3::ONE).unwrap();
        // Front normal +z: lit from above.
        let p = Vec3::new(0.2, 0.3, 1.5);
        for sampling in [TriangleSampling::Area, TriangleSampling::default()] {
            let light = light.with_sampling(sampling);
            for i in 0..64 {
                let u = Vec2::new((i % 8) as f32 / 8.0 + 0.01, (i / 8) as f32 / 8.0 + 0.04);
                let s = light.sample(p, u).unwrap();
                let t = light.intersect(p, s.dir).unwrap_or(f32::NAN);
                assert!((t - s.distance).abs() < 1e-4 * s.distance, "{sampling:?} {u}");
                assert!((light.pdf(p, s.dir) - s.pdf).abs() <= 1e-3 * s.pdf, "{sampling:?} {u}");
            }
        }
        assert!(light.sample(Vec3::new(0.2, 0.3, 0.5), Vec2::splat(0.5)).is_none());
        assert_eq!(TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::X * 2.0], Vec3::ONE), Err(LightError::ZeroArea));
    }
}
