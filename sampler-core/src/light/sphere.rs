//! A spherical area light. Seen from outside it fills a cone of directions, sampled uniformly
//! (its density is constant, 1/(2π(1 − cos θmax)) with sin²θmax = r²/d²), and the sampled ray's
//! distance to the sphere follows from the same sines. From inside only a two-sided sphere sends
//! light in: points drawn uniformly on its area, converted to solid angle.

use super::{
    Emission, Light, LightError, LightHit, LightSample, Shaping, area_to_solid_angle, checked_rgb, emitted, finite,
};
use crate::frame::Frame;
use crate::mapping::square_to_sphere;
use crate::sampling::{TWO_PI, square_to_uniform_cone};
use core::f32::consts::PI;
use glam::{Vec2, Vec3};

/// A sphere emitting uniform radiance outwards (and inwards when two-sided).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereLight {
    center: Vec3,
    radius: f32,
    emission: Emission,
}

/// Relative slack of the cone test that admits the rounding of the directions drawn on its rim.
const RIM_SLACK: f32 = 1e-5;

impl SphereLight {
    /// A sphere of centre `center` and radius `radius` emitting `radiance` (RGB) outwards.
    pub fn new(center: Vec3, radius: f32, radiance: Vec3) -> Result<Self, LightError> {
        if !radius.is_finite() {
            return Err(LightError::NotFinite);
        }
        if radius <= 0.0 {
            return Err(LightError::ZeroRadius);
        }
        let emission = Emission { radiance: checked_rgb(radiance)?, two_sided: false, shaping: Shaping::NONE };
        Ok(Self { center: finite(center)?, radius, emission })
    }

    /// Both sides emit.
    #[must_use]
    pub fn is_two_sided(&self) -> bool {
        self.emission.two_sided
    }

    /// The same sphere, emitting on both sides when `two_sided`.
    #[must_use]
    pub fn with_two_sided(self, two_sided: bool) -> Self {
        Self { emission: Emission { two_sided, ..self.emission }, ..self }
    }

    /// The same sphere, its radiance shaped by `shaping` (UsdLux's ShapingAPI).
    #[must_use]
    pub fn with_shaping(self, shaping: Shaping) -> Self {
        Self { emission: Emission { shaping, ..self.emission }, ..self }
    }

    /// How its radiance falls off away from the shaping axis.
    #[must_use]
    pub fn shaping(&self) -> &Shaping {
        &self.emission.shaping
    }

    /// The sphere's surface.
    #[must_use]
    pub fn surface(&self) -> super::LightSurface {
        super::LightSurface::Sphere { center: self.center, radius: self.radius }
    }

    /// Surface area 4πr².
    #[must_use]
    pub fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    /// The cone the sphere fills seen from `p` outside it: (axis towards the centre, distance
    /// to the centre, sin²θmax, 1 − cos θmax); `None` from inside or on the surface.
    fn cone_from(&self, p: Vec3) -> Option<(Vec3, f32, f32, f32)> {
        let w = self.center - p;
        let d2 = w.length_squared();
        let r2 = self.radius * self.radius;
        let outside = d2 > r2;
        if !outside {
            return None;
        }
        let sin2_max = r2 / d2;
        let cos_max = libm::sqrtf((1.0 - sin2_max).max(0.0));
        let d = libm::sqrtf(d2);
        Some((w / d, d, sin2_max, sin2_max / (1.0 + cos_max)))
    }

    /// Where the ray from `p` along the unit `dir` meets the sphere: (near, far) distances, the
    /// near one without cancellation (c/q form); `None` when it misses. `slack` widens the
    /// sphere relatively to admit rays drawn on the rim of its cone.
    fn intersect(&self, p: Vec3, dir: Vec3, slack: f32) -> Option<(f32, f32)> {
        let w = self.center - p;
        let b = w.dot(dir);
        let r2 = self.radius * self.radius;
        // The squared distance from the centre to the ray, from the perpendicular part of w.
        let perp2 = (w - b * dir).length_squared();
        if perp2 > r2 * (1.0 + slack) {
            return None;
        }
        let root = libm::sqrtf((r2 - perp2).max(0.0));
        let far = b + root.copysign(b);
        let near = (w.length_squared() - r2) / far;
        Some(if near < far { (near, far) } else { (far, near) })
    }
}

impl Light for SphereLight {
    fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        if let Some((axis, d, sin2_max, one_minus_cos)) = self.cone_from(p) {
            let local = square_to_uniform_cone(u, one_minus_cos);
            let sin2 = local.x * local.x + local.y * local.y;
            // The near root of |t·dir − w|² = r² with cos θ and the sines: no cancellation.
            let r = self.radius;
            let distance = (d - r) * (d + r) / (d * (local.z + libm::sqrtf((sin2_max - sin2).max(0.0))));
            let dir = Frame::from_normal(axis).to_world(local);
            let pdf = 1.0 / (TWO_PI * one_minus_cos);
            // A sphere too far for its cone to be represented adds nothing f32 can hold.
            let ok = pdf.is_finite() && distance.is_finite();
            return ok.then(|| LightSample { dir, distance, radiance: self.emission.towards(dir), pdf, delta: false });
        }
        if !self.emission.two_sided {
            return None;
        }
        // From inside: a uniform point of the surface (the equal-area map is uniform on the
        // sphere), which faces away from `p`.
        let normal = square_to_sphere(u);
        let to = self.center + self.radius * normal - p;
        let distance = to.length();
        let apart = distance > 0.0;
        if !apart {
            return None;
        }
        let dir = to / distance;
        let pdf = area_to_solid_angle(distance, dir.dot(normal), self.area());
        (pdf > 0.0 && pdf.is_finite()).then_some(LightSample {
            dir,
            distance,
            radiance: self.emission.towards(dir),
            pdf,
            delta: false,
        })
    }

    fn pdf(&self, p: Vec3, dir: Vec3) -> f32 {
        if let Some((axis, _, sin2_max, one_minus_cos)) = self.cone_from(p) {
            let inside = axis.dot(dir) > 0.0 && axis.cross(dir).length_squared() <= sin2_max * (1.0 + RIM_SLACK);
            let pdf = 1.0 / (TWO_PI * one_minus_cos);
            return if inside && pdf.is_finite() { pdf } else { 0.0 };
        }
        if !self.emission.two_sided {
            return 0.0;
        }
        match self.intersect(p, dir, 0.0) {
            Some((_, far)) if far > 0.0 => {
                let normal = (p + far * dir - self.center) / self.radius;
                area_to_solid_angle(far, dir.dot(normal), self.area())
            }
            _ => 0.0,
        }
    }

    fn eval(&self, p: Vec3, dir: Vec3) -> Option<LightHit> {
        let (near, far) = self.intersect(p, dir, RIM_SLACK)?;
        let t = if near > 0.0 { near } else { far };
        let ahead = t > 0.0;
        if !ahead {
            return None;
        }
        let normal = (p + t * dir - self.center) / self.radius;
        // From outside the near hit faces the ray (cos towards it ≥ 0 up to rounding).
        let cos_front = if near > 0.0 { (-dir.dot(normal)).max(f32::MIN_POSITIVE) } else { -dir.dot(normal) };
        emitted(&self.emission, cos_front, dir).map(|radiance| LightHit { radiance, distance: t })
    }

    fn is_delta(&self) -> bool {
        false
    }

    fn power(&self, _scene_radius: f32) -> Vec3 {
        if self.emission.shaping.is_none() {
            return self.emission.power(self.area());
        }
        // Seen along any direction the sphere shows a disk of area πr² whatever the axis: the
        // power is πr²·L·∫ factor dω (4π²r²L unshaped), once per emitting side.
        let sides = if self.emission.two_sided { 2.0 } else { 1.0 };
        self.emission.radiance * (sides * PI * self.radius * self.radius) * self.emission.shaping.integral(false, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_reach_the_surface_and_match_the_ray() {
        let light = SphereLight::new(Vec3::new(1.0, 2.0, 3.0), 0.5, Vec3::ONE).unwrap();
        for p in [Vec3::ZERO, Vec3::new(1.0, 2.0, 3.51), Vec3::new(1e3, -2e3, 0.0)] {
            for i in 0..64 {
                let u = Vec2::new((i % 8) as f32 / 8.0 + 0.03, (i / 8) as f32 / 8.0 + 0.05);
                let s = light.sample(p, u).unwrap();
                let on = p + s.distance * s.dir;
                assert!(((on - light.center).length() - 0.5).abs() < 1e-5 * (1.0 + p.length()), "{p} {u}");
                let hit = light.eval(p, s.dir).unwrap();
                assert!((hit.distance - s.distance).abs() <= 1e-3 * s.distance, "{hit:?} {s:?}");
            }
        }
    }

    #[test]
    fn inside_a_one_sided_sphere_nothing_arrives() {
        let light = SphereLight::new(Vec3::ZERO, 1.0, Vec3::ONE).unwrap();
        let p = Vec3::new(0.2, 0.0, 0.1);
        assert!(light.sample(p, Vec2::splat(0.3)).is_none());
        assert_eq!(light.pdf(p, Vec3::Z), 0.0);
        assert!(light.eval(p, Vec3::Z).is_none());
        let two = light.with_two_sided(true);
        let s = two.sample(p, Vec2::splat(0.3)).unwrap();
        assert!((two.pdf(p, s.dir) - s.pdf).abs() < 1e-4 * s.pdf);
        assert_eq!(SphereLight::new(Vec3::ZERO, 0.0, Vec3::ONE), Err(LightError::ZeroRadius));
        // So far that its cone underflows: nothing to draw, density 0.
        let speck = SphereLight::new(Vec3::new(0.0, 0.0, 1e25), 1.0, Vec3::ONE).unwrap();
        assert!(speck.sample(Vec3::ZERO, Vec2::splat(0.5)).is_none() && speck.pdf(Vec3::ZERO, Vec3::Z) == 0.0);
    }
}
