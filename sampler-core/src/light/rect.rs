//! A rectangular area light, sampled uniformly in the solid angle it subtends (spherical
//! rectangles, [`super::spherical_rect`]) and by area where that solid angle is too small to
//! compute (far and small, or seen edge-on from its own plane's neighbourhood): there every
//! point of it lies in almost the same direction and area sampling is uniform in solid angle too.

use super::spherical_rect::SphericalRect;
use super::{
    Emission, Light, LightError, LightHit, LightSample, Shaping, area_sample, area_to_solid_angle, checked_rgb,
    emitted, finite,
};
use glam::{DVec3, Vec2, Vec3};

/// A rectangle `p0 + s·e1 + t·e2`, s, t ∈ [0, 1], emitting on its front side (normal e1 × e2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RectLight {
    p0: Vec3,
    e1: Vec3,
    e2: Vec3,
    normal: Vec3,
    area: f32,
    emission: Emission,
}

/// Slack, relative to an edge, of the hit test that admits the rounding of points drawn on the
/// rectangle's border.
const EDGE_SLACK: f32 = 1e-5;

impl RectLight {
    /// The rectangle with corner `p0` and perpendicular edges `e1`, `e2` emitting `radiance`
    /// (RGB) towards `e1 × e2`.
    pub fn new(p0: Vec3, e1: Vec3, e2: Vec3, radiance: Vec3) -> Result<Self, LightError> {
        let (p0, e1, e2) = (finite(p0)?, finite(e1)?, finite(e2)?);
        let cross = e1.cross(e2);
        let area = cross.length();
        // Perpendicular edges: |e1·e2| is a small fraction of |e1||e2|.
        let skew = e1.dot(e2).abs();
        if !(area > 0.0 && area.is_finite()) || skew > 1e-4 * e1.length() * e2.length() {
            return Err(LightError::ZeroArea);
        }
        let emission = Emission { radiance: checked_rgb(radiance)?, two_sided: false, shaping: Shaping::NONE };
        Ok(Self { p0, e1, e2, normal: cross / area, area, emission })
    }

    /// Both sides emit.
    #[must_use]
    pub fn is_two_sided(&self) -> bool {
        self.emission.two_sided
    }

    /// The same rectangle, emitting on both sides when `two_sided`.
    #[must_use]
    pub fn with_two_sided(self, two_sided: bool) -> Self {
        Self { emission: Emission { two_sided, ..self.emission }, ..self }
    }

    /// The same rectangle, its radiance shaped by `shaping` (UsdLux's ShapingAPI).
    #[must_use]
    pub fn with_shaping(self, shaping: Shaping) -> Self {
        Self { emission: Emission { shaping, ..self.emission }, ..self }
    }

    /// How its radiance falls off away from the shaping axis.
    #[must_use]
    pub fn shaping(&self) -> &Shaping {
        &self.emission.shaping
    }

    /// The rectangle's surface.
    #[must_use]
    pub fn surface(&self) -> super::LightSurface {
        super::LightSurface::Rect { p0: self.p0, e1: self.e1, e2: self.e2 }
    }

    /// The unit front normal.
    #[must_use]
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// Area in square units.
    #[must_use]
    pub fn area(&self) -> f32 {
        self.area
    }

    /// The side of the plane `p` lies on can receive light.
    fn lit_from(&self, p: Vec3) -> bool {
        let side = (p - self.p0).dot(self.normal);
        side > 0.0 || (self.emission.two_sided && side < 0.0)
    }

    fn spherical(&self, p: Vec3) -> Option<SphericalRect> {
        let (a, b) = (self.e1.as_dvec3(), self.e2.as_dvec3());
        let (la, lb) = (a.length(), b.length());
        // The second axis made exactly perpendicular to the first.
        let y = (b - a * (a.dot(b) / (la * la))).normalize();
        SphericalRect::new(p, self.p0, a / la, y, (la, lb))
    }

    /// The distance along the unit `dir` from `p` to the rectangle, if the ray meets it.
    fn intersect(&self, p: Vec3, dir: Vec3) -> Option<f32> {
        let denom = dir.dot(self.normal);
        let t = (self.p0 - p).dot(self.normal) / denom;
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        let q = p + t * dir - self.p0;
        let s = q.dot(self.e1) / self.e1.length_squared();
        let r = q.dot(self.e2) / self.e2.length_squared();
        let range = -EDGE_SLACK..=1.0 + EDGE_SLACK;
        (range.contains(&s) && range.contains(&r)).then_some(t)
    }
}

impl Light for RectLight {
    fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        if !self.lit_from(p) {
            return None;
        }
        if let Some(rect) = self.spherical(p) {
            let v: DVec3 = rect.sample(u);
            let distance = v.length();
            let dir = (v / distance).as_vec3();
            let pdf = (1.0 / rect.solid_angle()) as f32;
            let radiance = self.emission.towards(dir);
            return Some(LightSample { dir, distance: distance as f32, radiance, pdf, delta: false });
        }
        area_sample(p, self.p0 + u.x * self.e1 + u.y * self.e2, self.normal, self.area, |d| self.emission.towards(d))
    }

    fn pdf(&self, p: Vec3, dir: Vec3) -> f32 {
        if !self.lit_from(p) {
            return 0.0;
        }
        let Some(t) = self.intersect(p, dir) else { return 0.0 };
        match self.spherical(p) {
            Some(rect) => (1.0 / rect.solid_angle()) as f32,
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
        self.emission.power_facing(self.area, self.normal())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_lie_on_the_rectangle_near_and_far() {
        let light =
            RectLight::new(Vec3::new(-1.0, 2.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 3.0), Vec3::ONE)
                .unwrap();
        assert!((light.normal() - Vec3::NEG_Y).length() < 1e-6);
        for p in [Vec3::ZERO, Vec3::new(0.0, 1.999, 1.0), Vec3::new(3e4, -1e5, 2e4), Vec3::new(-5.0, 1.99, 1.5)] {
            for i in 0..64 {
                let u = Vec2::new((i % 8) as f32 / 8.0 + 0.06, (i / 8) as f32 / 8.0 + 0.02);
                let s = light.sample(p, u).unwrap();
                let t = light.intersect(p, s.dir).unwrap_or(f32::NAN);
                assert!((t - s.distance).abs() <= 1e-4 * s.distance, "{p} {u}: {t} vs {s:?}");
                assert!((light.pdf(p, s.dir) - s.pdf).abs() <= 1e-3 * s.pdf, "{p} {u}");
            }
        }
        assert!(light.sample(Vec3::new(0.0, 3.0, 1.0), Vec2::splat(0.5)).is_none());
    }

    #[test]
    fn bad_rectangles_are_refused() {
        let e = RectLight::new(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::ONE);
        assert_eq!(e, Err(LightError::ZeroArea));
        assert_eq!(RectLight::new(Vec3::ZERO, Vec3::X, Vec3::ZERO, Vec3::ONE), Err(LightError::ZeroArea));
        assert_eq!(RectLight::new(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NAN), Err(LightError::BadRadiance));
    }
}
