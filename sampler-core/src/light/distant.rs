//! A distant light: a direction and the irradiance on a surface facing it. Of angular diameter
//! 0 it is a delta light; of diameter θ > 0 it is a disc of uniform radiance
//! L = E / (π sin²(θ/2)) over the cone of half-angle θ/2, sampled uniformly in solid angle.

use super::{Light, LightError, LightHit, LightSample, checked_rgb, unit};
use crate::frame::Frame;
use crate::sampling::{TWO_PI, square_to_uniform_cone};
use core::f32::consts::PI;
use glam::{Vec2, Vec3};

/// Angular diameters (radians) below which a distant light is a delta light: its cone's
/// directions would lie within a few f32 roundings of its axis, and no image tells the
/// difference.
pub const MIN_DISTANT_ANGLE: f32 = 1e-4;

/// A light at infinity: the sun, the moon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DistantLight {
    frame: Frame,
    irradiance: Vec3,
    /// Radiance over the cone (0 for a delta light).
    radiance: Vec3,
    /// sin² of the cone's half-angle.
    sin2_max: f32,
    /// 1 − cos of the cone's half-angle, from the half-angle's half so that it stays accurate
    /// for the sun's few milliradians.
    one_minus_cos: f32,
}

impl DistantLight {
    /// Light from the unit direction `direction` (from the scene towards the light), delivering
    /// the irradiance `irradiance` (RGB) on a surface facing it, of full angular diameter
    /// `angle` radians (a delta light below [`MIN_DISTANT_ANGLE`]).
    pub fn new(direction: Vec3, irradiance: Vec3, angle: f32) -> Result<Self, LightError> {
        let axis = unit(direction)?;
        let irradiance = checked_rgb(irradiance)?;
        if !(0.0..PI).contains(&angle) {
            return Err(LightError::BadAngle);
        }
        let half = if angle < MIN_DISTANT_ANGLE { 0.0 } else { 0.5 * angle };
        let sin_half = libm::sinf(half);
        let sin2_max = sin_half * sin_half;
        let s = libm::sinf(0.5 * half);
        let one_minus_cos = 2.0 * s * s;
        let radiance = if sin2_max > 0.0 { irradiance / (PI * sin2_max) } else { Vec3::ZERO };
        if !radiance.is_finite() {
            return Err(LightError::BadRadiance);
        }
        Ok(Self { frame: Frame::from_normal(axis), irradiance, radiance, sin2_max, one_minus_cos })
    }

    /// The unit direction towards the light.
    #[must_use]
    pub fn direction(&self) -> Vec3 {
        self.frame.n
    }

    /// Half the light's angular diameter, radians (0 for a delta light).
    #[must_use]
    pub fn half_angle(&self) -> f32 {
        libm::asinf(libm::sqrtf(self.sin2_max))
    }

    /// The irradiance it delivers to a surface facing it (RGB).
    #[must_use]
    pub fn irradiance(&self) -> Vec3 {
        self.irradiance
    }

    /// The radiance over the light's disc (0 for a delta light).
    #[must_use]
    pub fn radiance(&self) -> Vec3 {
        self.radiance
    }

    /// The unit `dir` lies within the cone: by the sine from the cross product, which stays
    /// accurate where the cosine cannot resolve a small cone. The bound admits the rounding of
    /// the directions [`Light::sample`] draws on the cone's rim.
    fn in_cone(&self, dir: Vec3) -> bool {
        dir.dot(self.frame.n) > 0.0 && self.frame.n.cross(dir).length_squared() <= self.sin2_max * (1.0 + 1e-5)
    }
}

impl Light for DistantLight {
    fn sample(&self, _p: Vec3, u: Vec2) -> Option<LightSample> {
        if self.sin2_max == 0.0 {
            let dir = self.frame.n;
            return Some(LightSample {
                dir,
                distance: f32::INFINITY,
                radiance: self.irradiance,
                pdf: 1.0,
                delta: true,
            });
        }
        let dir = self.frame.to_world(square_to_uniform_cone(u, self.one_minus_cos));
        let pdf = 1.0 / (TWO_PI * self.one_minus_cos);
        Some(LightSample { dir, distance: f32::INFINITY, radiance: self.radiance, pdf, delta: false })
    }

    fn pdf(&self, _p: Vec3, dir: Vec3) -> f32 {
        if self.sin2_max > 0.0 && self.in_cone(dir) { 1.0 / (TWO_PI * self.one_minus_cos) } else { 0.0 }
    }

    fn eval(&self, _p: Vec3, dir: Vec3) -> Option<LightHit> {
        (self.sin2_max > 0.0 && self.in_cone(dir))
            .then_some(LightHit { radiance: self.radiance, distance: f32::INFINITY })
    }

    fn is_delta(&self) -> bool {
        self.sin2_max == 0.0
    }

    fn power(&self, scene_radius: f32) -> Vec3 {
        self.irradiance * (PI * scene_radius * scene_radius)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_delta_light_gives_its_irradiance_along_its_direction() {
        let light = DistantLight::new(Vec3::new(0.0, 3.0, 4.0), Vec3::splat(2.0), 0.0).unwrap();
        let s = light.sample(Vec3::ZERO, Vec2::new(0.5, 0.5)).unwrap();
        assert!(s.delta && light.is_delta() && (s.dir - Vec3::new(0.0, 0.6, 0.8)).length() < 1e-6);
        assert_eq!((s.radiance, s.pdf, light.pdf(Vec3::ZERO, s.dir)), (Vec3::splat(2.0), 1.0, 0.0));
        assert!(light.eval(Vec3::ZERO, s.dir).is_none());
    }

    #[test]
    fn the_suns_cone_keeps_every_sample_inside() {
        let sun = DistantLight::new(Vec3::Z, Vec3::ONE, 0.53f32.to_radians()).unwrap();
        for i in 0..=64 {
            for j in 0..=8 {
                let u = Vec2::new(i as f32 / 64.0, j as f32 / 8.0).min(Vec2::splat(1.0 - f32::EPSILON));
                let s = sun.sample(Vec3::ZERO, u).unwrap();
                assert!((s.dir.length() - 1.0).abs() < 1e-6);
                assert_eq!(sun.pdf(Vec3::ZERO, s.dir), s.pdf, "{u}");
                assert_eq!(sun.eval(Vec3::ZERO, s.dir).unwrap().radiance, s.radiance);
            }
        }
        assert_eq!(DistantLight::new(Vec3::Z, Vec3::ONE, -1.0), Err(LightError::BadAngle));
        assert!(DistantLight::new(Vec3::Z, Vec3::ONE, 0.5 * MIN_DISTANT_ANGLE).unwrap().is_delta());
        assert!(!DistantLight::new(Vec3::Z, Vec3::ONE, MIN_DISTANT_ANGLE).unwrap().is_delta());
        assert_eq!(DistantLight::new(Vec3::ZERO, Vec3::ONE, 0.0), Err(LightError::DegenerateDirection));
    }
}
