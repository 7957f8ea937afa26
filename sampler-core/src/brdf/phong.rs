//! Modified Phong (Lafortune & Willems 1994): a diffuse part plus a normalised cos^n lobe about
//! the mirror direction. Accurate up to exponents of 1e6: 1 − cos α is formed from |r − ω|²
//! instead of 1 − r·ω, and cos^n as exp(n·log1p(−δ)).

use super::{Brdf, BrdfDraw, BrdfSample, pick_lobe};
use crate::cone::Cone;
use crate::env::luminance;
use crate::sampling::{
    TWO_PI, basis_around, reflect_z, sin_cos_2pi, square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf,
};
use core::f32::consts::FRAC_1_PI;

/// Largest f32 below 1.
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;
use glam::{Vec2, Vec3};

/// f = kd/π + ks·(n+2)/(2π)·cos^n α, α the angle between ωi and the mirror of ωo.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    /// Diffuse reflectance.
    pub kd: Vec3,
    /// Specular reflectance of the lobe.
    pub ks: Vec3,
    /// Exponent n of the cos^n lobe.
    pub exponent: f32,
}

impl Phong {
    /// A Phong BRDF; the exponent is clamped to [0, 1e7].
    #[must_use]
    pub fn new(kd: Vec3, ks: Vec3, exponent: f32) -> Self {
        let exponent = if exponent.is_nan() { 0.0 } else { exponent.clamp(0.0, 1e7) };
        Self { kd, ks, exponent }
    }

    /// cos^n α with δ = 1 − cos α given accurately.
    #[inline]
    fn lobe(&self, r: Vec3, wi: Vec3) -> f32 {
        if r.dot(wi) <= 0.0 {
            return 0.0;
        }
        let delta = 0.5 * (r - wi).length_squared();
        libm::expf(self.exponent * libm::log1pf(-delta.min(1.0)))
    }

    fn lobe_weights(&self) -> [f32; 3] {
        [luminance(self.kd), luminance(self.ks), 0.0]
    }

    /// A direction from the lobe mixture (diffuse ∝ cos, specular ∝ cos^n about the mirror).
    fn sample_direction(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let mut ux = u.x;
        let lobe = pick_lobe(self.lobe_weights(), &mut ux)?;
        if lobe == 0 {
            return Some(square_to_cosine_hemisphere(Vec2::new(ux, u.y)));
        }
        // 1 − cos α = −expm1(ln(1−u)/(n+1)), exact for huge n.
        let one_minus_cos = (-libm::expm1f(libm::logf(1.0 - ux) / (self.exponent + 1.0))).clamp(0.0, 2.0);
        let cos_a = 1.0 - one_minus_cos;
        let sin_a = libm::sqrtf((one_minus_cos * (2.0 - one_minus_cos)).max(0.0));
        let (sin_phi, cos_phi) = sin_cos_2pi(u.y);
        let r = reflect_z(wo);
        let (s, t) = basis_around(r);
        Some((s * (sin_a * cos_phi) + t * (sin_a * sin_phi) + r * cos_a).normalize())
    }
}

impl Brdf for Phong {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let spec = (self.exponent + 2.0) / TWO_PI * self.lobe(reflect_z(wo), wi);
        (self.kd * FRAC_1_PI + self.ks * spec) * wi.z
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        let wi = self.sample_direction(wo, u)?;
        let (value, pdf) = self.eval_pdf(wo, wi);
        (pdf > 0.0).then_some(BrdfSample { wi, value, pdf })
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if wo.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        // One evaluation of the lobe cosⁿα for both.
        let lobe = self.lobe(reflect_z(wo), wi);
        let value = if wi.z > 0.0 {
            let spec = (self.exponent + 2.0) / TWO_PI * lobe;
            (self.kd * FRAC_1_PI + self.ks * spec) * wi.z
        } else {
            Vec3::ZERO
        };
        let w = self.lobe_weights();
        let total = w[0] + w[1];
        if total.is_nan() || total <= 0.0 {
            return (value, 0.0);
        }
        let diffuse = square_to_cosine_hemisphere_pdf(wi);
        let spec = (self.exponent + 1.0) / TWO_PI * lobe;
        (value, (w[0] * diffuse + w[1] * spec) / total)
    }

    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        let w = self.lobe_weights();
        let total = w[0] + w[1];
        if wo.z <= 0.0 || total.is_nan() || total <= 0.0 {
            return 0;
        }
        // Per view, once: the mirror frame, the normalisations and the lobe choice.
        let p_diffuse = w[0] / total;
        let r = reflect_z(wo);
        let (s, t) = basis_around(r);
        let kd = luminance(self.kd) * FRAC_1_PI;
        let ks = luminance(self.ks) * ((self.exponent + 2.0) / TWO_PI);
        let inv_n1 = 1.0 / (self.exponent + 1.0);
        for (p, o) in u.iter().zip(out.iter_mut()) {
            let (wi, lobe) = if p.x < p_diffuse {
                let wi = square_to_cosine_hemisphere(Vec2::new((p.x / p_diffuse).min(ONE_BELOW), p.y));
                (wi, self.lobe(r, wi))
            } else {
                let ux = ((p.x - p_diffuse) / (1.0 - p_diffuse)).clamp(0.0, ONE_BELOW);
                let ln = libm::logf(1.0 - ux);
                let one_minus_cos = (-libm::expm1f(ln * inv_n1)).clamp(0.0, 2.0);
                let cos_a = 1.0 - one_minus_cos;
                let sin_a = libm::sqrtf((one_minus_cos * (2.0 - one_minus_cos)).max(0.0));
                let (sin_phi, cos_phi) = sin_cos_2pi(p.y);
                let wi = (s * (sin_a * cos_phi) + t * (sin_a * sin_phi) + r * cos_a).normalize();
                // cosⁿα = (1 − u)^(n/(n+1)): no need to evaluate the lobe again.
                let lobe = if cos_a > 0.0 { libm::expf(ln * self.exponent * inv_n1) } else { 0.0 };
                (wi, lobe)
            };
            *o = BrdfDraw { wi, value: (kd + ks * lobe) * wi.z.max(0.0) };
        }
        u.len().min(out.len())
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        let w = self.lobe_weights();
        let total = w[0] + w[1];
        if total.is_nan() || total <= 0.0 {
            return 0.0;
        }
        let diffuse = square_to_cosine_hemisphere_pdf(wi);
        let spec = (self.exponent + 1.0) / TWO_PI * self.lobe(reflect_z(wo), wi);
        (w[0] * diffuse + w[1] * spec) / total
    }

    fn is_diffuse(&self) -> bool {
        luminance(self.ks) == 0.0
    }

    /// cosθi and cos α at their largest over the cone.
    /// √(2/(n+2)): the angle at which the lobe cosᵑ falls to about 1/e; π/2 without a specular
    /// lobe.
    fn lobe_width(&self) -> f32 {
        if self.is_diffuse() { core::f32::consts::FRAC_PI_2 } else { libm::sqrtf(2.0 / (self.exponent + 2.0)) }
    }

    fn has_cone_bounds(&self) -> bool {
        true
    }

    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        let (kd, ks) = (luminance(self.kd) * FRAC_1_PI, luminance(self.ks) * ((self.exponent + 2.0) / TWO_PI));
        let r = reflect_z(wo);
        for (o, c) in out.iter_mut().zip(cones) {
            let cos_i = c.max_cos(Vec3::Z);
            *o = if wo.z > 0.0 && cos_i > 0.0 {
                let cos_a = c.max_cos(r);
                let lobe = if cos_a > 0.0 { libm::expf(self.exponent * libm::logf(cos_a)) } else { 0.0 };
                (kd + ks * lobe) * cos_i
            } else {
                0.0
            };
        }
    }

    /// The lobe (n+2)/(2π)·cosⁿα integrates to (n+2)/(n+1) over its hemisphere; cosθi ≤ 1.
    fn reflectance_bound(&self, wo: Vec3) -> Option<f32> {
        let spec = luminance(self.ks) * (self.exponent + 2.0) / (self.exponent + 1.0);
        Some(if wo.z > 0.0 { luminance(self.kd) + spec } else { 0.0 })
    }
}
