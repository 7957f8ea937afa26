//! A disk-shaped area light: points drawn uniformly on its area (Shirley–Chiu's concentric map,
//! which keeps strata compact) and converted to solid angle, d²/(|cos| A).

use super::{
    Emission, Light, LightError, LightHit, LightSample, Shaping, area_sample, area_to_solid_angle, checked_rgb,
    emitted, finite, unit,
};
use crate::frame::Frame;
use crate::sampling::square_to_uniform_disk_concentric;
use core::f32::consts::PI;
use glam::{Vec2, Vec3};

/// A disk emitting on the side its normal points to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiskLight {
    center: Vec3,
    frame: Frame,
    radius: f32,
    emission: Emission,
}

/// Slack, relative to the radius, of the hit test that admits the rounding of points drawn on
/// the rim.
const RIM_SLACK: f32 = 1e-5;

impl DiskLight {
    /// A disk of centre `center`, front normal `normal` (any length) and radius `radius`
    /// emitting `radiance` (RGB).
    pub fn new(center: Vec3, normal: Vec3, radius: f32, radiance: Vec3) -> Result<Self, LightError> {
        if !radius.is_finite() {
            return Err(LightError::NotFinite);
        }
        if radius <= 0.0 {
            return Err(LightError::ZeroRadius);
        }
        let emission = Emission { radiance: checked_rgb(radiance)?, two_sided: false, shaping: Shaping::NONE };
        Ok(Self { center: finite(center)?, frame: Frame::from_normal(unit(normal)?), radius, emission })
    }

    /// Both sides emit.
    #[must_use]
    pub fn is_two_sided(&self) -> bool {
        self.emission.two_sided
    }

    /// The same disk, emitting on both sides when `two_sided`.
    #[must_use]
    pub fn with_two_sided(self, two_sided: bool) -> Self {
        Self { emission: Emission { two_sided, ..self.emission }, ..self }
    }

    /// The same disk, its radiance shaped by `shaping` (UsdLux's ShapingAPI).
    #[must_use]
    pub fn with_shaping(self, shaping: Shaping) -> Self {
        Self { emission: Emission { shaping, ..self.emission }, ..self }
    }

    /// How its radiance falls off away from the shaping axis.
    #[must_use]
    pub fn shaping(&self) -> &Shaping {
        &self.emission.shaping
    }

    /// The disk's surface.
    #[must_use]
    pub fn surface(&self) -> super::LightSurface {
        super::LightSurface::Disk { center: self.center, normal: self.frame.n, radius: self.radius }
    }

    /// Area πr².
    #[must_use]
    pub fn area(&self) -> f32 {
        PI * self.radius * self.radius
    }

    fn lit_from(&self, p: Vec3) -> bool {
        let side = (p - self.center).dot(self.frame.n);
        side > 0.0 || (self.emission.two_sided && side < 0.0)
    }

    /// The distance along the unit `dir` from `p` to the disk, if the ray meets it.
    fn intersect(&self, p: Vec3, dir: Vec3) -> Option<f32> {
        let t = (self.center - p).dot(self.frame.n) / dir.dot(self.frame.n);
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        let q = p + t * dir - self.center;
        let r2 = self.radius * self.radius * (1.0 + RIM_SLACK);
        (q.length_squared() - q.dot(self.frame.n) * q.dot(self.frame.n) <= r2).then_some(t)
    }
}

impl Light for DiskLight {
    fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        if !self.lit_from(p) {
            return None;
        }
        let d = square_to_uniform_disk_concentric(u) * self.radius;
        let q = self.center + self.frame.s * d.x + self.frame.t * d.y;
        area_sample(p, q, self.frame.n, self.area(), |d| self.emission.towards(d))
    }

    fn pdf(&self, p: Vec3, dir: Vec3) -> f32 {
        if !self.lit_from(p) {
            return 0.0;
        }
        self.intersect(p, dir).map_or(0.0, |t| area_to_solid_angle(t, dir.dot(self.frame.n), self.area()))
    }

    fn eval(&self, p: Vec3, dir: Vec3) -> Option<LightHit> {
        let distance = self.intersect(p, dir)?;
        emitted(&self.emission, -dir.dot(self.frame.n), dir).map(|radiance| LightHit { radiance, distance })
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn power(&self, _scene_radius: f32) -> Vec3 {
        self.emission.power_facing(self.area(), self.frame.n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sided_disk_lights_its_front_only() {
        let disk = DiskLight::new(Vec3::new(0.0, 0.0, 2.0), Vec3::NEG_Z, 0.5, Vec3::ONE).unwrap();
        let s = disk.sample(Vec3::ZERO, Vec2::new(0.2, 0.9)).unwrap();
        assert!((disk.pdf(Vec3::ZERO, s.dir) - s.pdf).abs() < 1e-4 * s.pdf);
        assert!((disk.eval(Vec3::ZERO, s.dir).unwrap().distance - s.distance).abs() < 1e-5);
        let above = Vec3::new(0.0, 0.0, 3.0);
        assert!(disk.sample(above, Vec2::splat(0.5)).is_none() && disk.pdf(above, Vec3::NEG_Z) == 0.0);
        assert!(disk.eval(above, Vec3::NEG_Z).is_none());
        assert!(disk.with_two_sided(true).eval(above, Vec3::NEG_Z).is_some());
        assert_eq!(DiskLight::new(Vec3::ZERO, Vec3::ZERO, 1.0, Vec3::ONE), Err(LightError::DegenerateDirection));
    }
}
