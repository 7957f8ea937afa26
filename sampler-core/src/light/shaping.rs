//! How a light's emission falls off with the angle from its primary axis: UsdLux's ShapingAPI
//! cone and focus, as the schema defines them. With θ the angle between the axis and the
//! direction the light leaves in,
//!
//! - the cone: 0 where θ > cutoff; where θ lies in [start, cutoff] with start = cutoff·(1 −
//!   softness), the factor 1 − smoothstep(θ; start, cutoff); 1 below start;
//! - the focus: f = |cos θ|^focus and the RGB factor lerp(f, focusTint, 1) = tint + f·(1 − tint).
//!
//! and, where the light carries an IES profile ([`Shaping::with_profile`]), the profile's
//! intensity towards the direction ([`OrientedProfile`]; the cone and focus multiply it, as
//! HdEmbree applies them). The radiance (or intensity) a light sends along a direction is its
//! unshaped value times [`Shaping::factor`]. The samplers keep drawing as unshaped lights do (their densities do not
//! change); the factor enters the value, so the estimates stay unbiased.

use super::oriented_profile::OrientedProfile;
use super::{LightError, checked_rgb, unit};
use core::f32::consts::{FRAC_PI_2, PI};
use glam::Vec3;

/// A ShapingAPI cone and focus about an axis; [`Shaping::NONE`] leaves emission unchanged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shaping {
    axis: Vec3,
    cutoff: f32,
    start: f32,
    focus: f32,
    tint: Vec3,
    profile: Option<OrientedProfile>,
    /// Some direction's emission changes (kept so that unshaped lights test one flag).
    active: bool,
}

/// Simpson intervals per smooth piece of the factor in [`Shaping::integral`].
const SIMPSON_STEPS: usize = 64;

/// Simpson intervals per piece between a profile's vertical angles (many pieces, each narrow).
const PROFILE_SIMPSON_STEPS: usize = 32;

impl Shaping {
    /// No shaping: every direction keeps the full emission.
    pub const NONE: Self =
        Self { axis: Vec3::Z, cutoff: PI, start: PI, focus: 0.0, tint: Vec3::ONE, profile: None, active: false };

    /// The emission about the world `axis` (any length) cut off beyond `cone_angle` radians
    /// (≥ π: no cutoff), softened over the fraction `softness` of the cone (clamped to [0, 1]),
    /// focused by `focus` (< 0 is 0) towards the tint `focus_tint` (RGB, ≥ 0) off the axis.
    pub fn new(axis: Vec3, cone_angle: f32, softness: f32, focus: f32, focus_tint: Vec3) -> Result<Self, LightError> {
        let finite = cone_angle.is_finite() && softness.is_finite() && focus.is_finite();
        if !finite {
            return Err(LightError::NotFinite);
        }
        let cutoff = cone_angle.clamp(0.0, PI);
        let start = cutoff * (1.0 - softness.clamp(0.0, 1.0));
        let (focus, tint) = (focus.max(0.0), checked_rgb(focus_tint)?);
        let active = cutoff < PI || (focus > 0.0 && tint != Vec3::ONE);
        Ok(Self { axis: unit(axis)?, cutoff, start, focus, tint, profile: None, active })
    }

    /// The same shaping times an IES profile placed on the light ([`OrientedProfile::new`]:
    /// its horizontal angle 0 towards `x`, 90° towards `y`, rescaled by `angle_scale`, divided
    /// by its mean when `normalize`).
    pub fn with_profile(
        self,
        profile: &'static super::IntensityProfile<'static>,
        x: Vec3,
        y: Vec3,
        angle_scale: f32,
        normalize: bool,
    ) -> Result<Self, LightError> {
        let oriented = OrientedProfile::new(profile, self.axis, x, y, angle_scale, normalize)?;
        Ok(Self { profile: Some(oriented), active: true, ..self })
    }

    /// The IES profile, if the light carries one.
    #[must_use]
    pub fn profile(&self) -> Option<&OrientedProfile> {
        self.profile.as_ref()
    }

    /// The angle from the axis beyond which nothing is emitted: the cone's cutoff, or less
    /// where the profile sends nothing further out.
    #[must_use]
    pub fn emission_extent(&self) -> f32 {
        self.profile.map_or(self.cutoff, |p| self.cutoff.min(p.extent()))
    }

    /// The shaping changes no direction's emission.
    #[must_use]
    pub fn is_none(&self) -> bool {
        !self.active
    }

    /// The unit axis.
    #[must_use]
    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// The cone's half-angle in radians (π: no cutoff).
    #[must_use]
    pub fn cutoff(&self) -> f32 {
        self.cutoff
    }

    /// Where the soft band of the cone begins, in radians from the axis.
    #[must_use]
    pub fn soft_start(&self) -> f32 {
        self.start
    }

    /// The factor (RGB) on the emission leaving along the unit `emitted`.
    #[inline]
    #[must_use]
    pub fn factor(&self, emitted: Vec3) -> Vec3 {
        if self.is_none() {
            return Vec3::ONE;
        }
        let cos = self.axis.dot(emitted).clamp(-1.0, 1.0);
        let theta = libm::acosf(cos);
        let base = self.factor_at(theta, cos);
        match &self.profile {
            Some(p) if base != Vec3::ZERO => base * p.factor(theta, emitted),
            _ => base,
        }
    }

    /// The cone and focus factor at the angle `theta` from the axis, whose cosine is `cos`
    /// (without a profile, which depends on the direction about the axis too).
    pub(super) fn factor_at_angle(&self, theta: f32, cos: f32) -> Vec3 {
        self.factor_at(theta, cos)
    }

    /// The factor at the angle `theta` from the axis, whose cosine is `cos`.
    fn factor_at(&self, theta: f32, cos: f32) -> Vec3 {
        if theta > self.cutoff {
            return Vec3::ZERO;
        }
        let cone = if theta > self.start {
            let t = ((theta - self.start) / (self.cutoff - self.start)).clamp(0.0, 1.0);
            1.0 - t * t * (3.0 - 2.0 * t)
        } else {
            1.0
        };
        let focused = if self.focus > 0.0 { libm::powf(cos.abs(), self.focus) } else { 1.0 };
        (self.tint + focused * (Vec3::ONE - self.tint)) * cone
    }

    /// ∫ factor(ω) w(ω) dω over the sphere, with w = 1 (`cosine` false: a point's or a sphere's
    /// power over its unshaped one times 4π) or w = |cos θ| on the front hemisphere, and on both
    /// when `two_sided` (a flat emitter's power over its unshaped one times π per side). The
    /// integrand is smooth between the soft start, 90° and a profile's vertical angles; Simpson's
    /// rule runs over each piece, the profile entering through its exact mean about the axis.
    #[must_use]
    pub fn integral(&self, cosine: bool, two_sided: bool) -> Vec3 {
        let extent = self.emission_extent();
        let end = if cosine && !two_sided { extent.min(FRAC_PI_2) } else { extent };
        let mut total = Vec3::ZERO;
        let mut fixed = [self.start, FRAC_PI_2];
        if fixed[0] > fixed[1] {
            fixed.swap(0, 1);
        }
        let (mut a, mut fi) = (0.0f32, 0);
        let mut knots = self.profile.as_ref().map(|p| p.knots().peekable());
        while a < end {
            let mut b = end;
            while fi < fixed.len() && fixed[fi] <= a + 1e-6 {
                fi += 1;
            }
            if fi < fixed.len() {
                b = b.min(fixed[fi]);
            }
            if let Some(k) = knots.as_mut() {
                while k.next_if(|&t| t <= a + 1e-6).is_some() {}
                if let Some(&t) = k.peek() {
                    b = b.min(t);
                }
            }
            total += self.piece_integral(a, b, cosine);
            a = b;
        }
        total * (2.0 * PI)
    }

    /// Simpson's rule for ∫ factor's mean about the axis · w · sin θ dθ over [a, b], a piece on
    /// which it is smooth.
    fn piece_integral(&self, a: f32, b: f32, cosine: bool) -> Vec3 {
        let mid = 0.5 * (a + b);
        let mean = self.profile.as_ref().map(|p| p.mean_over_phi(mid));
        let weight = |theta: f32| {
            let (s, c) = (libm::sinf(theta), libm::cosf(theta));
            let w = if cosine { c.abs() } else { 1.0 };
            let profile = mean.as_ref().map_or(1.0, |m| m(theta));
            self.factor_at(theta, c) * (w * s * profile)
        };
        let steps = if self.profile.is_some() { PROFILE_SIMPSON_STEPS } else { SIMPSON_STEPS };
        let h = (b - a) / steps as f32;
        let mut sum = weight(a) + weight(b);
        for k in 1..steps {
            sum += weight(a + k as f32 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * (h / 3.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cone_cuts_and_softens_as_the_schema_says() {
        let s = Shaping::new(Vec3::NEG_Z, 40f32.to_radians(), 0.5, 0.0, Vec3::ZERO).unwrap();
        let at = |deg: f32| {
            let t = deg.to_radians();
            s.factor(Vec3::new(libm::sinf(t), 0.0, -libm::cosf(t))).x
        };
        assert_eq!(at(10.0), 1.0);
        assert_eq!(at(41.0), 0.0);
        // Halfway through the band [20°, 40°] the smoothstep is ½.
        assert!((at(30.0) - 0.5).abs() < 1e-4, "{}", at(30.0));
        assert!((at(25.0) - (1.0 - 0.15625)).abs() < 1e-3, "{}", at(25.0));
        let hard = Shaping::new(Vec3::Z, 0.5, 0.0, 0.0, Vec3::ZERO).unwrap();
        assert_eq!(hard.factor(Vec3::Z), Vec3::ONE);
        assert!(Shaping::new(Vec3::Z, PI, 0.3, 0.0, Vec3::ZERO).unwrap().is_none());
        assert_eq!(Shaping::new(Vec3::ZERO, 1.0, 0.0, 0.0, Vec3::ONE), Err(LightError::DegenerateDirection));
    }

    #[test]
    fn focus_is_a_cosine_power_towards_the_tint() {
        let s = Shaping::new(Vec3::Z, PI, 0.0, 3.0, Vec3::new(0.0, 0.5, 1.0)).unwrap();
        let d = Vec3::new(0.6, 0.0, 0.8);
        let f = 0.8f32.powi(3);
        assert!((s.factor(d) - Vec3::new(f, 0.5 + 0.5 * f, 1.0)).length() < 1e-5);
        // |cos|: a sphere's focus lights behind it too.
        assert!((s.factor(-d) - s.factor(d)).length() < 1e-6);
        // ∫ cos^n dω over the sphere = 4π/(n+1).
        assert!((s.integral(false, false).x - 4.0 * PI / 4.0).abs() < 1e-4);
        // ∫ cos^n · cos dω over the hemisphere = 2π/(n+2).
        assert!((s.integral(true, false).x - 2.0 * PI / 5.0).abs() < 1e-4);
        assert!((Shaping::NONE.integral(true, true).x - 2.0 * PI).abs() < 1e-4);
    }
}
