//! A point light: radiant intensity `I` from one position; a delta light whose irradiance on a
//! surface facing it at distance d is I/d².

use super::{Light, LightError, LightHit, LightSample, checked_rgb, finite};
use glam::{Vec2, Vec3};

/// An isotropic point light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    position: Vec3,
    intensity: Vec3,
}

impl PointLight {
    /// A light at `position` of radiant intensity `intensity` (RGB, W/sr).
    pub fn new(position: Vec3, intensity: Vec3) -> Result<Self, LightError> {
        Ok(Self { position: finite(position)?, intensity: checked_rgb(intensity)? })
    }

    /// Where the light is.
    #[must_use]
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// Its radiant intensity (RGB, W/sr).
    #[must_use]
    pub fn intensity(&self) -> Vec3 {
        self.intensity
    }
}

impl Light for PointLight {
    fn sample(&self, p: Vec3, _u: Vec2) -> Option<LightSample> {
        let d = self.position - p;
        let d2 = d.length_squared();
        if !(d2 > 0.0 && d2.is_finite()) {
            return None;
        }
        let distance = libm::sqrtf(d2);
        Some(LightSample { dir: d / distance, distance, radiance: self.intensity / d2, pdf: 1.0, delta: true })
    }

    fn pdf(&self, _p: Vec3, _dir: Vec3) -> f32 {
        0.0
    }

    fn eval(&self, _p: Vec3, _dir: Vec3) -> Option<LightHit> {
        None
    }

    fn is_delta(&self) -> bool {
        true
    }

    fn power(&self, _scene_radius: f32) -> Vec3 {
        4.0 * core::f32::consts::PI * self.intensity
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn irradiance_falls_with_the_square_of_distance() {
        let light = PointLight::new(Vec3::new(0.0, 0.0, 2.0), Vec3::splat(8.0)).unwrap();
        let s = light.sample(Vec3::ZERO, Vec2::ZERO).unwrap();
        assert_eq!((s.dir, s.distance, s.radiance, s.delta), (Vec3::Z, 2.0, Vec3::splat(2.0), true));
        assert!(light.sample(Vec3::new(0.0, 0.0, 2.0), Vec2::ZERO).is_none());
        assert_eq!(PointLight::new(Vec3::ZERO, Vec3::new(1.0, -1.0, 0.0)), Err(LightError::BadRadiance));
    }
}
