//! An [`IntensityProfile`] placed on a light, as UsdLux's ShapingAPI places an IES profile: the
//! profile's vertical angle 0 along the light's primary axis (its local −Z), the horizontal angle
//! measured about that axis from the light's local +X towards +Y, both of the direction from the
//! lit point back to the light (as Pixar's HdEmbree, the schema's reference renderer, evaluates
//! it: θ = acos(w.z), φ = atan2(w.y, w.x) of that direction in the light's frame). The
//! vertical angle is rescaled by `shaping:ies:angleScale` as the schema defines it:
//!
//! - angleScale > 0: θ_ies = θ / angleScale;
//! - angleScale = 0: θ_ies = θ;
//! - angleScale < 0: θ_ies = (θ − π) / −angleScale + π;
//!
//! clamped to [0, π]. The profile's intensity multiplies the light's emission, divided by the
//! profile's mean intensity when `shaping:ies:normalize` is on.

use super::profile::IntensityProfile;
use super::{LightError, unit};
use core::f32::consts::PI;
use glam::Vec3;

/// A profile in a light's frame, with its angle scale and the factor on its intensities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrientedProfile {
    profile: &'static IntensityProfile<'static>,
    /// The light's local +X and +Y, perpendicular to the axis and to each other.
    x: Vec3,
    y: Vec3,
    angle_scale: f32,
    scale: f32,
}

impl OrientedProfile {
    /// `profile` about the unit `axis`, its horizontal angle 0 towards `x` and 90° towards `y`
    /// (any lengths; made perpendicular to the axis), its vertical angles rescaled by
    /// `angle_scale`, its intensities divided by its mean when `normalize` (a profile of mean 0
    /// then emits nothing).
    pub fn new(
        profile: &'static IntensityProfile<'static>,
        axis: Vec3,
        x: Vec3,
        y: Vec3,
        angle_scale: f32,
        normalize: bool,
    ) -> Result<Self, LightError> {
        if !angle_scale.is_finite() {
            return Err(LightError::NotFinite);
        }
        let x = unit(x - axis * axis.dot(x))?;
        let y = unit(y - axis * axis.dot(y) - x * x.dot(y))?;
        let mean = profile.mean_intensity();
        let scale = if !normalize {
            1.0
        } else if mean > 0.0 {
            1.0 / mean
        } else {
            0.0
        };
        Ok(Self { profile, x, y, angle_scale, scale })
    }

    /// The profile.
    #[must_use]
    pub fn profile(&self) -> &'static IntensityProfile<'static> {
        self.profile
    }

    /// The profile's vertical angle for the angle `theta` from the light's axis.
    #[inline]
    #[must_use]
    pub fn ies_theta(&self, theta: f32) -> f32 {
        let s = self.angle_scale;
        let t = if s > 0.0 {
            theta / s
        } else if s < 0.0 {
            (theta - PI) / -s + PI
        } else {
            theta
        };
        t.clamp(0.0, PI)
    }

    /// The angle from the light's axis whose profile angle is `ies` (the inverse of
    /// [`OrientedProfile::ies_theta`] where it is one to one).
    #[must_use]
    pub fn light_theta(&self, ies: f32) -> f32 {
        let s = self.angle_scale;
        let t = if s > 0.0 {
            ies * s
        } else if s < 0.0 {
            PI + (ies - PI) * -s
        } else {
            ies
        };
        t.clamp(0.0, PI)
    }

    /// The factor on the emission leaving along the unit `emitted` at the angle `theta` from
    /// the axis.
    #[inline]
    #[must_use]
    pub fn factor(&self, theta: f32, emitted: Vec3) -> f32 {
        let phi = match self.profile.symmetry() {
            super::HorizontalSymmetry::Rotational => 0.0,
            _ => libm::atan2f(-emitted.dot(self.y), -emitted.dot(self.x)),
        };
        self.scale * self.profile.eval(self.ies_theta(theta), phi)
    }

    /// The angle from the axis beyond which the profile sends nothing.
    #[must_use]
    pub fn extent(&self) -> f32 {
        let lit = self.profile.lit_extent();
        if lit >= PI { PI } else { self.light_theta(lit) }
    }

    /// The angles from the axis where the factor's mean over directions about the axis has a
    /// kink: the profile's vertical angles, rescaled.
    pub fn knots(&self) -> impl Iterator<Item = f32> + '_ {
        self.profile.vertical().iter().map(|&v| self.light_theta(v))
    }

    /// The factor's mean over the directions about the axis at angles in the piece of
    /// [`OrientedProfile::knots`] around `mid`, as a function of the angle (linear there).
    pub fn mean_over_phi(&self, mid: f32) -> impl Fn(f32) -> f32 + '_ {
        let v = self.profile.vertical();
        let at = self.ies_theta(mid);
        let inside = at >= v[0] && at <= v[v.len() - 1];
        let k = self.profile.vertical_segment(at.clamp(v[0], v[v.len() - 1]));
        let (m0, m1) =
            if inside { (self.profile.mean_over_phi(k), self.profile.mean_over_phi(k + 1)) } else { (0.0, 0.0) };
        let (a, b, scale) = (v[k], v[k + 1], if inside { self.scale } else { 0.0 });
        move |theta| {
            let t = ((self.ies_theta(theta) - a) / (b - a)).clamp(0.0, 1.0);
            scale * (m0 + t * (m1 - m0))
        }
    }
}
