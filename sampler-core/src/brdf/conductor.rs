//! GGX rough conductor with Fresnel 1, as Mitsuba 3's `roughconductor` with the separable
//! Smith shadowing: f = specular · D(h)·G1(ωi)·G1(ωo) / (4 cosθi cosθo).

use super::microfacet::{Ggx, HalfVectorCone, half_vector};
use super::{Brdf, BrdfDraw, BrdfSample};
use crate::cone::Cone;
use crate::env::luminance;
use crate::sampling::reflect;
use glam::{Vec2, Vec3, Vec4};

/// GGX rough conductor with Fresnel 1 (see the module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughConductor {
    /// The microfacet distribution (its α).
    pub ggx: Ggx,
    /// Reflectance that scales the lobe.
    pub specular: Vec3,
}

impl RoughConductor {
    /// α is the GGX roughness (not squared), clamped to ≥ 1e-4.
    #[must_use]
    pub fn new(alpha: f32, specular: Vec3) -> Self {
        Self { ggx: Ggx::new(alpha), specular }
    }
}

impl Brdf for RoughConductor {
    /// The GGX α.
    fn lobe_width(&self) -> f32 {
        self.ggx.alpha()
    }

    fn has_cone_bounds(&self) -> bool {
        true
    }

    /// specular · D·G1(ωo)/(4 cosθo) with G1(ωi) ≤ 1 and D bounded over the cone's half vectors.
    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        let scale = if wo.z > 0.0 { luminance(self.specular) * self.ggx.g1(wo) / (4.0 * wo.z) } else { 0.0 };
        for (o, c) in out.iter_mut().zip(cones) {
            *o = if scale > 0.0 && c.max_cos(Vec3::Z) > 0.0 {
                scale * self.ggx.d_bound(&HalfVectorCone::new(wo, c))
            } else {
                0.0
            };
        }
    }

    /// With G1(ωi) ≤ 1 the integrand is at most specular × the visible-normal density.
    fn reflectance_bound(&self, wo: Vec3) -> Option<f32> {
        Some(if wo.z > 0.0 { luminance(self.specular) } else { 0.0 })
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let Some(h) = half_vector(wo, wi) else {
            return Vec3::ZERO;
        };
        let g = &self.ggx;
        self.specular * (g.d(h) * g.g1(wi) * g.g1(wo) / (4.0 * wo.z))
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        let wi = self.sample_direction(wo, u)?;
        let (value, pdf) = self.eval_pdf(wo, wi);
        (pdf > 0.0 && pdf.is_finite()).then_some(BrdfSample { wi, value, pdf })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match half_vector(wo, wi) {
            Some(h) => self.ggx.pdf_reflected(wo, h),
            None => 0.0,
        }
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if wo.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let Some(h) = half_vector(wo, wi) else {
            return (Vec3::ZERO, 0.0);
        };
        // One D(h) and G1(ωo) for both, multiplied in `eval`'s and `pdf_reflected`'s order.
        let g = &self.ggx;
        let (d, g1_o) = (g.d(h), g.g1(wo));
        let value = if wi.z > 0.0 { self.specular * (d * g.g1(wi) * g1_o / (4.0 * wo.z)) } else { Vec3::ZERO };
        let pdf = if wo.dot(h) > 0.0 { g1_o * d / (4.0 * wo.z) } else { 0.0 };
        (value, pdf)
    }

    fn sample_many(&self, wo: Vec3, u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        self.sample_x4(wo, u, out);
    }

    fn sample_many_views(&self, wo: &[Vec3], u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        self.sample_views_x4(wo, u, out);
    }

    fn eval_pdf_many(&self, wo: Vec3, wi: &[Vec3], out: &mut [(Vec3, f32)]) {
        self.eval_pdf_many_x4(wo, wi, out);
    }

    fn eval_luminance_x4(&self, wo: Vec3, wi: [Vec4; 3]) -> Vec4 {
        self.eval_luminance_lanes(wo, wi)
    }

    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        if wo.z <= 0.0 {
            return 0;
        }
        // Per view, once: G1(wo)/(4 cosθo). m is the half vector of (wo, wi) by construction:
        // D is evaluated at it without recomputing it.
        let g = &self.ggx;
        let spec = luminance(self.specular);
        let k = spec * g.g1(wo) / (4.0 * wo.z);
        let n = u.len().min(out.len());
        self.sample_batch_x4(wo, k, &u[..n], &mut out[..n]);
        n
    }
}

impl RoughConductor {
    /// Reflection of `wo` about a visible microfacet normal.
    #[inline]
    fn sample_direction(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let m = self.ggx.sample_visible(wo, u);
        Some(reflect(wo, m).normalize())
    }
}
