//! A point light: radiant intensity `I` from one position, shaped into a spot light by a
//! ShapingAPI cone and focus where given; a delta light whose irradiance on a surface facing it
//! at distance d is I·factor(ω)/d².

use super::{Light, LightError, LightHit, LightSample, Shaping, checked_rgb, finite};
use glam::{Vec2, Vec3};

/// A point light, isotropic unless shaped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    position: Vec3,
    intensity: Vec3,
    shaping: Shaping,
}

impl PointLight {
    /// A light at `position` of radiant intensity `intensity` (RGB, W/sr).
    pub fn new(position: Vec3, intensity: Vec3) -> Result<Self, LightError> {
        Ok(Self { position: finite(position)?, intensity: checked_rgb(intensity)?, shaping: Shaping::NONE })
    }

    /// Where the light is.
    #[must_use]
    pub fn position(&self) -> Vec3 {
        self.position
    }

    /// Its radiant intensity (RGB, W/sr) before shaping: along the shaping axis.
    #[must_use]
    pub fn intensity(&self) -> Vec3 {
        self.intensity
    }

    /// The same light, its intensity shaped by `shaping` (a spot light).
    #[must_use]
    pub fn with_shaping(self, shaping: Shaping) -> Self {
        Self { shaping, ..self }
    }

    /// How its intensity falls off away from the shaping axis.
    #[must_use]
    pub fn shaping(&self) -> &Shaping {
        &self.shaping
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
        let dir = d / distance;
        let radiance = self.intensity * self.shaping.factor(-dir) / d2;
        Some(LightSample { dir, distance, radiance, pdf: 1.0, delta: true })
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
        if self.shaping.is_none() {
            return 4.0 * core::f32::consts::PI * self.intensity;
        }
        self.intensity * self.shaping.integral(false, false)
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
