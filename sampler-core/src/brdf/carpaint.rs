//! A layered car paint: a Lambertian base and a GGX metallic-flake lobe under a very sharp GGX
//! clear coat with Schlick Fresnel (F0 = 0.04, i.e. η = 1.5). Light that the coat reflects does
//! not reach the base: for coat weight c the base is weighted by (1 − c·F(cosθo))(1 − c·F(cosθi))
//! (c = 0 is a base and flake lobe with no coat at all, as a UsdPreviewSurface without clearcoat).
//! This is the paper's hard case: a wide lobe and a needle-sharp one in one BRDF.

use super::microfacet::{Ggx, HalfVectorCone, fresnel_schlick, half_vector};
use super::{Brdf, BrdfDraw, BrdfSample, pick_lobe};
use crate::cone::Cone;
use crate::env::luminance;
use crate::sampling::{reflect, square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3, Vec4};

/// Lambert base + GGX flakes under a GGX clear coat with Schlick Fresnel (see the module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CarPaint {
    /// Albedo of the Lambertian base.
    pub base: Vec3,
    /// Reflectance of the metallic-flake lobe.
    pub flake: Vec3,
    /// Roughness of the flake lobe.
    pub flake_ggx: Ggx,
    /// Weight c of the clear coat in [0, 1]; 0 removes the coat.
    pub coat: f32,
    /// Roughness of the clear coat.
    pub coat_ggx: Ggx,
    /// Schlick F0 of the clear coat (0.04 from [`CarPaint::new`], i.e. η = 1.5).
    pub coat_f0: f32,
}

impl Default for CarPaint {
    /// A deep blue metallic paint: base (0.01, 0.03, 0.15), flakes (0.1, 0.2, 0.5) at α = 0.25,
    /// coat weight 1 at α = 0.005.
    fn default() -> Self {
        Self::new(Vec3::new(0.01, 0.03, 0.15), Vec3::new(0.1, 0.2, 0.5), 0.25, 1.0, 0.005)
    }
}

impl CarPaint {
    /// A car paint with base albedo, flake reflectance and roughness, coat weight and coat
    /// roughness (GGX α, not squared); the coat's F0 is 0.04.
    #[must_use]
    pub fn new(base: Vec3, flake: Vec3, flake_alpha: f32, coat: f32, coat_alpha: f32) -> Self {
        Self { base, flake, flake_ggx: Ggx::new(flake_alpha), coat, coat_ggx: Ggx::new(coat_alpha), coat_f0: 0.04 }
    }

    /// Sampling weights of (coat, flake, base). The coat gets a share well above its energy
    /// (at least 1/4 of the samples when present): it is needle-sharp, so under a bright light
    /// it dominates a tiny cone that the other lobes would never find.
    pub(super) fn lobe_weights(&self, wo: Vec3) -> [f32; 3] {
        let transmit = 1.0 - self.coat * fresnel_schlick(self.coat_f0, wo.z);
        let flake = transmit * luminance(self.flake);
        let base = transmit * luminance(self.base);
        let coat = if self.coat > 0.0 {
            (self.coat * fresnel_schlick(self.coat_f0, wo.z)).max((flake + base) / 3.0)
        } else {
            0.0
        };
        [coat, flake, base]
    }

    /// A direction from the lobe mixture.
    fn sample_direction(&self, wo: Vec3, u: Vec2) -> Option<Vec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let mut ux = u.x;
        let lobe = pick_lobe(self.lobe_weights(wo), &mut ux)?;
        let u = Vec2::new(ux, u.y);
        Some(match lobe {
            0 => reflect(wo, self.coat_ggx.sample_visible(wo, u)).normalize(),
            1 => reflect(wo, self.flake_ggx.sample_visible(wo, u)).normalize(),
            _ => square_to_cosine_hemisphere(u),
        })
    }
}

impl Brdf for CarPaint {
    /// Diffuse when neither the coat nor the flakes reflect anything.
    fn is_diffuse(&self) -> bool {
        self.coat <= 0.0 && luminance(self.flake) == 0.0
    }

    /// The coat's α where there is a coat, the flakes' otherwise.
    fn lobe_width(&self) -> f32 {
        if self.coat > 0.0 {
            self.coat_ggx.alpha()
        } else if luminance(self.flake) > 0.0 {
            self.flake_ggx.alpha()
        } else {
            core::f32::consts::FRAC_PI_2
        }
    }

    fn has_cone_bounds(&self) -> bool {
        true
    }

    /// Each lobe bounded on its own: the coat's Fresnel at the smallest ωo·h of the cone, the
    /// light entering the base through the coat at most 1 − c·F0.
    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        if wo.z <= 0.0 {
            out.iter_mut().zip(cones).for_each(|(o, _)| *o = 0.0);
            return;
        }
        let (c, f) = (&self.coat_ggx, &self.flake_ggx);
        let transmit = (1.0 - self.coat * fresnel_schlick(self.coat_f0, wo.z)) * (1.0 - self.coat * self.coat_f0);
        let coat = self.coat * luminance(Vec3::ONE) * c.g1(wo) / (4.0 * wo.z);
        let flake = transmit * luminance(self.flake) * f.g1(wo) / (4.0 * wo.z);
        let base = transmit * luminance(self.base) * FRAC_1_PI;
        for (o, cone) in out.iter_mut().zip(cones) {
            let cos_i = cone.max_cos(Vec3::Z);
            *o = if cos_i > 0.0 {
                let h = HalfVectorCone::new(wo, cone);
                let coat =
                    if self.coat > 0.0 { coat * fresnel_schlick(self.coat_f0, h.cos_oh) * c.d_bound(&h) } else { 0.0 };
                coat + flake * f.d_bound(&h) + base * cos_i
            } else {
                0.0
            };
        }
    }

    /// Each GGX lobe reflects at most its weight (F ≤ 1, G1(ωi) ≤ 1), the base its albedo.
    fn reflectance_bound(&self, wo: Vec3) -> Option<f32> {
        if wo.z <= 0.0 {
            return Some(0.0);
        }
        let transmit = (1.0 - self.coat * fresnel_schlick(self.coat_f0, wo.z)) * (1.0 - self.coat * self.coat_f0);
        Some(self.coat * luminance(Vec3::ONE) + transmit * (luminance(self.flake) + luminance(self.base)))
    }

    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let Some(h) = half_vector(wo, wi) else {
            return Vec3::ZERO;
        };
        let (c, f) = (&self.coat_ggx, &self.flake_ggx);
        let coat = self.coat * fresnel_schlick(self.coat_f0, wo.dot(h)) * c.d(h) * c.g1(wi) * c.g1(wo) / (4.0 * wo.z);
        let flake = f.d(h) * f.g1(wi) * f.g1(wo) / (4.0 * wo.z);
        let transmit = (1.0 - self.coat * fresnel_schlick(self.coat_f0, wo.z))
            * (1.0 - self.coat * fresnel_schlick(self.coat_f0, wi.z));
        Vec3::splat(coat) + transmit * (self.flake * flake + self.base * (FRAC_1_PI * wi.z))
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        let wi = self.sample_direction(wo, u)?;
        let (value, pdf) = self.eval_pdf(wo, wi);
        (pdf > 0.0 && pdf.is_finite()).then_some(BrdfSample { wi, value, pdf })
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if wo.z <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        let Some(h) = half_vector(wo, wi) else {
            return (Vec3::ZERO, self.pdf(wo, wi));
        };
        // Each lobe's D(h) and G1(ωo) once for both, multiplied in `eval`'s and `pdf`'s order.
        let (c, f) = (&self.coat_ggx, &self.flake_ggx);
        let (dc, df, gc_o, gf_o) = (c.d(h), f.d(h), c.g1(wo), f.g1(wo));
        let value = if wi.z > 0.0 {
            let coat = self.coat * fresnel_schlick(self.coat_f0, wo.dot(h)) * dc * c.g1(wi) * gc_o / (4.0 * wo.z);
            let flake = df * f.g1(wi) * gf_o / (4.0 * wo.z);
            let transmit = (1.0 - self.coat * fresnel_schlick(self.coat_f0, wo.z))
                * (1.0 - self.coat * fresnel_schlick(self.coat_f0, wi.z));
            Vec3::splat(coat) + transmit * (self.flake * flake + self.base * (FRAC_1_PI * wi.z))
        } else {
            Vec3::ZERO
        };
        let w = self.lobe_weights(wo);
        let total = w[0] + w[1] + w[2];
        if total.is_nan() || total <= 0.0 {
            return (value, 0.0);
        }
        let (coat, flake) =
            if wo.dot(h) > 0.0 { (gc_o * dc / (4.0 * wo.z), gf_o * df / (4.0 * wo.z)) } else { (0.0, 0.0) };
        (value, (w[0] * coat + w[1] * flake + w[2] * square_to_cosine_hemisphere_pdf(wi)) / total)
    }

    fn eval_luminance_x4(&self, wo: Vec3, wi: [Vec4; 3]) -> Vec4 {
        self.eval_luminance_lanes(wo, wi)
    }

    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        let w = self.lobe_weights(wo);
        let total = w[0] + w[1] + w[2];
        if wo.z <= 0.0 || total.is_nan() || total <= 0.0 {
            return 0;
        }
        let n = u.len().min(out.len());
        self.sample_batch_x4(wo, w, &u[..n], &mut out[..n]);
        n
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 {
            return 0.0;
        }
        let w = self.lobe_weights(wo);
        let total = w[0] + w[1] + w[2];
        if total.is_nan() || total <= 0.0 {
            return 0.0;
        }
        let (coat, flake) = match half_vector(wo, wi) {
            Some(h) => (self.coat_ggx.pdf_reflected(wo, h), self.flake_ggx.pdf_reflected(wo, h)),
            None => (0.0, 0.0),
        };
        (w[0] * coat + w[1] * flake + w[2] * square_to_cosine_hemisphere_pdf(wi)) / total
    }
}
