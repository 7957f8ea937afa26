//! The BRDF interface any engine can implement, and the built-in materials.
//!
//! All directions are unit vectors in the local shading frame (normal = +z) pointing away from
//! the surface. `eval` returns BRDF × cosθ_i (the integrand's material part), so that
//! `eval / pdf` is the weight of a sample. Surfaces are one-sided: when `wo.z ≤ 0` nothing is
//! reflected and nothing is sampled.

mod carpaint;
mod carpaint_x4;
mod conductor;
mod ggx_x4;
mod lambert;
pub mod microfacet;
mod phong;

pub use carpaint::CarPaint;
pub use conductor::RoughConductor;
pub use lambert::Lambert;
pub use phong::Phong;

use crate::cone::Cone;
use crate::env::luminance;
use glam::{Vec2, Vec3};

/// A direction drawn by a BRDF's own importance sampler.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrdfSample {
    /// Sampled incident direction (local frame). May lie below the surface, where `value` is 0.
    pub wi: Vec3,
    /// BRDF × cosθ_i at `wi` (RGB).
    pub value: Vec3,
    /// Density with respect to solid angle; > 0.
    pub pdf: f32,
}

/// A direction drawn for building B̃: luminances only.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BrdfDraw {
    /// Sampled incident direction (local frame).
    pub wi: Vec3,
    /// Luminance of BRDF × cosθ_i at `wi`.
    pub value: f32,
}

/// A reflectance model that can be evaluated, importance-sampled, and whose sampling density
/// can be evaluated for any direction (needed for MIS and for the product's guard).
pub trait Brdf {
    /// BRDF × cosθ_i. Zero when `wo` or `wi` is below the surface.
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3;

    /// Draws `wi` from the sampling density of [`Brdf::pdf`] using `u ∈ [0,1)²`. `None` when
    /// nothing can be sampled (e.g. `wo` below the surface).
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample>;

    /// Density of [`Brdf::sample`] at `wi` with respect to solid angle (over the whole sphere).
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// [`Brdf::eval`] and [`Brdf::pdf`] at once, bit for bit the same values: MIS needs both at
    /// every direction the other technique drew, and they share most of their work (for GGX the
    /// half vector, D and G1(ωo)) — and behind `dyn Brdf` one call instead of two.
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        (self.eval(wo, wi), self.pdf(wo, wi))
    }

    /// [`Brdf::sample`] for every point of `u` (`out[k]` from `u[k]`, as many as both hold),
    /// bit for bit; implementations may draw several at once (the GGX conductor: four lanes).
    fn sample_many(&self, wo: Vec3, u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        for (o, p) in out.iter_mut().zip(u) {
            *o = self.sample(wo, *p);
        }
    }

    /// [`Brdf::eval_pdf`] for every direction of `wi` (as many as both hold), bit for bit.
    fn eval_pdf_many(&self, wo: Vec3, wi: &[Vec3], out: &mut [(Vec3, f32)]) {
        for (o, w) in out.iter_mut().zip(wi) {
            *o = self.eval_pdf(wo, *w);
        }
    }

    /// Draws one direction per point of `u` like [`Brdf::sample`], for building B̃: writes
    /// each successful draw's direction and the luminance of BRDF × cos into `out`, and returns how many were written (≤ `u.len()` ≤
    /// `out.len()`). One call per shading point, so implementations can hoist what depends only
    /// on `wo`, and skip the RGB work.
    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        let mut n = 0;
        for p in u {
            if let Some(s) = self.sample(wo, *p) {
                out[n] = BrdfDraw { wi: s.wi, value: luminance(s.value) };
                n += 1;
            }
        }
        n
    }

    /// True when the BRDF is so smooth (e.g. Lambert) that product sampling cannot beat plain
    /// environment sampling by much; hosts may pick the cheaper sampler.
    fn is_diffuse(&self) -> bool {
        false
    }

    /// Angular width in radians, roughly, of the BRDF's sharpest lobe that reflects anything:
    /// GGX α, Phong √(2/(n+2)), π/2 for a diffuse BRDF. Hosts scale by it how far a shading
    /// point may move before a sampler built at another no longer fits, and which sampler to
    /// pick. The default is π/2 for a diffuse BRDF and 0 otherwise: a BRDF that does not say
    /// is taken to be as sharp as a mirror, which never reuses a sampler it should not.
    fn lobe_width(&self) -> f32 {
        if self.is_diffuse() { core::f32::consts::FRAC_PI_2 } else { 0.0 }
    }

    /// True when [`Brdf::cone_bounds`] gives true upper bounds; the two-level product
    /// ([`crate::two_level`]) otherwise estimates its weights by evaluation and floors them.
    fn has_cone_bounds(&self) -> bool {
        false
    }

    /// Upper bounds of the luminance of [`Brdf::eval`] over cones of incident directions (local
    /// frame): `out[k] ≥ luminance(eval(wo, ωi))` for every ωi of `cones[k]` (as many as both
    /// hold), as tight as is cheap. A BRDF that implements it says so by
    /// [`Brdf::has_cone_bounds`]; the default writes +∞, the bound that always holds.
    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        let _ = wo;
        out.iter_mut().zip(cones).for_each(|(o, _)| *o = f32::INFINITY);
    }

    /// An upper bound of the directional reflectance ∫ luminance(eval(wo, ωi)) dωi, or `None`.
    /// The two-level product caps each cell's B̃ at this over the cell's solid angle: a needle
    /// lobe's peak is far above its mean over a cell, and uncapped it would draw samples away
    /// from a sun the lobe's tail reflects.
    fn reflectance_bound(&self, wo: Vec3) -> Option<f32> {
        let _ = wo;
        None
    }
}

impl<B: Brdf + ?Sized> Brdf for &B {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        (**self).eval(wo, wi)
    }
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        (**self).sample(wo, u)
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        (**self).pdf(wo, wi)
    }
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        (**self).eval_pdf(wo, wi)
    }
    fn sample_many(&self, wo: Vec3, u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        (**self).sample_many(wo, u, out)
    }
    fn eval_pdf_many(&self, wo: Vec3, wi: &[Vec3], out: &mut [(Vec3, f32)]) {
        (**self).eval_pdf_many(wo, wi, out)
    }
    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        (**self).sample_batch(wo, u, out)
    }
    fn is_diffuse(&self) -> bool {
        (**self).is_diffuse()
    }
    fn lobe_width(&self) -> f32 {
        (**self).lobe_width()
    }
    fn has_cone_bounds(&self) -> bool {
        (**self).has_cone_bounds()
    }
    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        (**self).cone_bounds(wo, cones, out)
    }
    fn reflectance_bound(&self, wo: Vec3) -> Option<f32> {
        (**self).reflectance_bound(wo)
    }
}

/// Chooses one of up to three lobes with probability ∝ `weights`, rescaling `u` so that it is
/// again uniform in [0, 1). Returns `None` when no weight is positive.
#[inline]
pub(crate) fn pick_lobe(weights: [f32; 3], u: &mut f32) -> Option<usize> {
    let total = weights[0] + weights[1] + weights[2];
    if total.is_nan() || total <= 0.0 || total.is_infinite() {
        return None;
    }
    let last = (0..3).rev().find(|&k| weights[k] > 0.0)?;
    let mut acc = 0.0;
    for (k, &w) in weights.iter().enumerate() {
        let p = w / total;
        if p > 0.0 && (*u < acc + p || k == last) {
            *u = ((*u - acc) / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
            return Some(k);
        }
        acc += p;
    }
    None
}
