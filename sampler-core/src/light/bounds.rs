//! Bounds of a group of lights for many-light sampling (Conty Estevez & Kulla, "Importance
//! sampling of many lights with adaptive tree splitting", HPG 2018; the form pbrt-v4's
//! `LightBounds` documents): a box around them, their total power, and a cone of their emitting
//! normals widened by how far each emits around its normal. From them, an importance for a shading
//! point that never falls below any member's share where that member can light the point: power
//! over squared distance, times the most favourable cosines the bounds allow at the light and at
//! the receiver.

use super::{Light, LightSurface, SceneLight};
use crate::env::luminance;
use glam::Vec3;

/// What many-light sampling knows of a group of lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Corner of the box around the lights' surfaces.
    pub min: Vec3,
    /// Opposite corner.
    pub max: Vec3,
    /// Total power (luminance).
    pub power: f32,
    /// Axis of the cone of emitting normals.
    pub axis: Vec3,
    /// Cosine of the cone's half-angle (−1: every direction).
    pub cos_normals: f32,
    /// Cosine of how far around a normal light leaves (0: a hemisphere, as a one-sided emitter).
    pub cos_emission: f32,
    /// Some member emits on both sides of its surface.
    pub two_sided: bool,
}

/// Radians added to a shaped light's emission spread in its bounds.
const SHAPED_MARGIN: f32 = 1e-3;

/// The cosine of max(0, θa − θb) from the sines and cosines of θa and θb.
#[inline]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b { 1.0 } else { cos_a * cos_b + sin_a * sin_b }
}

/// The sine of max(0, θa − θb).
#[inline]
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b { 0.0 } else { sin_a * cos_b - cos_a * sin_b }
}

fn sin_of(cos: f32) -> f32 {
    libm::sqrtf((1.0 - cos * cos).max(0.0))
}

impl LightBounds {
    /// The bounds of one light; `None` for lights at infinity, which many-light sampling leaves
    /// to its caller, and for lights that emit nothing.
    #[must_use]
    pub fn of(light: &SceneLight) -> Option<Self> {
        let power = luminance(light.power(1.0));
        if !(power > 0.0 && power.is_finite()) {
            return None;
        }
        let every = |min, max| {
            Some(Self { min, max, power, axis: Vec3::Z, cos_normals: -1.0, cos_emission: 0.0, two_sided: false })
        };
        let facing = |points: &[Vec3], normal: Vec3, two_sided: bool| {
            let (min, max) = points.iter().fold((points[0], points[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
            Some(Self { min, max, power, axis: normal, cos_normals: 1.0, cos_emission: 0.0, two_sided })
        };
        let bounds = match (light, light.surface()) {
            (SceneLight::Point(l), _) => every(l.position(), l.position()),
            (SceneLight::Sphere(_), Some(LightSurface::Sphere { center, radius })) => {
                every(center - Vec3::splat(radius), center + Vec3::splat(radius))
            }
            (SceneLight::Rect(l), Some(LightSurface::Rect { p0, e1, e2 })) => {
                facing(&[p0, p0 + e1, p0 + e2, p0 + e1 + e2], l.normal(), l.is_two_sided())
            }
            (SceneLight::Disk(l), Some(LightSurface::Disk { center, normal, radius })) => {
                // The box of the disk: per axis, r·sin of the angle between the axis and the normal.
                let extent = (Vec3::ONE - normal * normal).max(Vec3::ZERO);
                let r = Vec3::new(libm::sqrtf(extent.x), libm::sqrtf(extent.y), libm::sqrtf(extent.z)) * radius;
                facing(&[center - r, center + r], normal, l.is_two_sided())
            }
            (SceneLight::Triangle(l), Some(LightSurface::Triangle(v))) => {
                let normal = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
                facing(&v, normal, l.is_two_sided())
            }
            _ => None,
        };
        bounds.map(|b| b.shaped(light))
    }

    /// These bounds narrowed to a shaped light's cone when it is narrower than a hemisphere:
    /// the emission leaves within `cutoff` of the shaping axis (the cone's, or an IES profile's
    /// last lit angle where that is less), and at full strength within its soft start, so the
    /// importance stays positive wherever the light can shine (the soft band is the emission
    /// spread θe beyond the normals' cone θo, as pbrt-v4 bounds a spot light). A face of a mesh
    /// light is shaped about the light's axis, not its normal: the cone about that axis holds
    /// all it emits on either side, so it replaces the face's hemisphere.
    fn shaped(self, light: &SceneLight) -> Self {
        let Some(shaping) = light.shaping() else { return self };
        let cutoff = shaping.emission_extent();
        if cutoff >= core::f32::consts::FRAC_PI_2 {
            return self;
        }
        let start = shaping.soft_start().min(cutoff);
        // A margin over the band keeps a hard cone (θe = 0, where `importance` would cull
        // every point) and the rounding of the angles on the safe side.
        Self {
            axis: shaping.axis(),
            cos_normals: libm::cosf(start),
            cos_emission: libm::cosf(cutoff - start + SHAPED_MARGIN),
            two_sided: false,
            ..self
        }
    }

    /// The bounds of two groups together.
    #[must_use]
    pub fn union(&self, other: &Self) -> Self {
        let (axis, cos_normals) = cone_union((self.axis, self.cos_normals), (other.axis, other.cos_normals));
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
            power: self.power + other.power,
            axis,
            cos_normals,
            cos_emission: self.cos_emission.min(other.cos_emission),
            two_sided: self.two_sided || other.two_sided,
        }
    }

    /// The centre of the box.
    #[must_use]
    pub fn centre(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// How much light the group can send to the point `p` of shading normal `n` (unit; a
    /// surface that reflects only on the side of `n`): power / d² times the largest cosines the
    /// bounds allow at the lights and at the receiver. 0 only where no member can light `p`.
    #[must_use]
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let centre = self.centre();
        let half_diagonal = 0.5 * (self.max - self.min).length();
        let to_p = p - centre;
        // Not nearer than the box's own size: inside it every distance is possible.
        let d2 = to_p.length_squared().max(half_diagonal * half_diagonal).max(1e-12);
        let d = libm::sqrtf(to_p.length_squared());
        let wi = if d > 0.0 { to_p / d } else { Vec3::Z };
        // The half-angle the box's bounding sphere subtends from p (every direction from inside).
        let (sin_b, cos_b) = if d > half_diagonal {
            let sin2 = (half_diagonal * half_diagonal) / (d * d);
            (libm::sqrtf(sin2), libm::sqrtf((1.0 - sin2).max(0.0)))
        } else {
            (0.0, -1.0)
        };
        // At the lights: the smallest angle between the emitting normals and the way to p.
        let mut cos_w = self.axis.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = sin_of(cos_w);
        let sin_o = sin_of(self.cos_normals);
        let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, self.cos_normals);
        let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, self.cos_normals);
        let cos_light = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
        if cos_light <= self.cos_emission {
            return 0.0;
        }
        // At the receiver: the smallest angle between its normal and a way to the lights.
        let cos_i = -wi.dot(n);
        let cos_receiver = cos_sub_clamped(sin_of(cos_i), cos_i, sin_b, cos_b);
        if cos_receiver <= 0.0 {
            return 0.0;
        }
        (self.power * cos_light * cos_receiver / d2).max(0.0)
    }
}

/// The smallest cone (axis, cos half-angle) holding the cones `a` and `b`.
fn cone_union(a: (Vec3, f32), b: (Vec3, f32)) -> (Vec3, f32) {
    let (theta_a, theta_b) = (libm::acosf(a.1.clamp(-1.0, 1.0)), libm::acosf(b.1.clamp(-1.0, 1.0)));
    let theta_d = libm::acosf(a.0.dot(b.0).clamp(-1.0, 1.0));
    let pi = core::f32::consts::PI;
    if (theta_d + theta_b).min(pi) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(pi) <= theta_b {
        return b;
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= pi {
        return (a.0, -1.0);
    }
    let axis = a.0.cross(b.0);
    if axis.length_squared() < 1e-12 {
        return (a.0, -1.0);
    }
    // a's axis rotated towards b's by θo − θa about their common normal (Rodrigues).
    let k = axis.normalize();
    let theta_r = theta_o - theta_a;
    let (s, c) = (libm::sinf(theta_r), libm::cosf(theta_r));
    let w = a.0 * c + k.cross(a.0) * s + k * k.dot(a.0) * (1.0 - c);
    (w.normalize(), libm::cosf(theta_o))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{PointLight, RectLight};

    #[test]
    fn cones_merge_to_hold_both_and_importance_culls_what_cannot_light() {
        let (axis, cos) = cone_union((Vec3::Z, 1.0), (Vec3::X, 1.0));
        // Both axes within the merged cone.
        assert!(axis.dot(Vec3::Z) >= cos - 1e-5 && axis.dot(Vec3::X) >= cos - 1e-5);
        assert!((libm::acosf(cos) - core::f32::consts::FRAC_PI_4).abs() < 1e-4);
        assert_eq!(cone_union((Vec3::Z, 1.0), (Vec3::NEG_Z, 1.0)).1, -1.0);
        // A rectangle facing down lights the floor below it, not a point above it, and not a
        // floor point whose normal points away.
        let rect = RectLight::new(Vec3::new(0.0, 0.0, 2.0), Vec3::Y, Vec3::X, Vec3::ONE).unwrap();
        let b = LightBounds::of(&rect.into()).unwrap();
        assert!(b.importance(Vec3::new(0.5, 0.5, 0.0), Vec3::Z) > 0.0);
        assert_eq!(b.importance(Vec3::new(0.5, 0.5, 3.0), Vec3::NEG_Z), 0.0);
        assert_eq!(b.importance(Vec3::new(0.5, 0.5, 0.0), Vec3::NEG_Z), 0.0);
        // A point light falls off with distance.
        let point = LightBounds::of(&PointLight::new(Vec3::ZERO, Vec3::ONE).unwrap().into()).unwrap();
        let (near, far) = (point.importance(Vec3::X, Vec3::NEG_X), point.importance(2.0 * Vec3::X, Vec3::NEG_X));
        assert!((near / far - 4.0).abs() < 1e-4);
    }
}
