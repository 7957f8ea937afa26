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
use glam::{Vec2, Vec3, Vec4};

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

    /// [`Brdf::sample`] of each point of `u` seen from its own view (`out[k]` from `wo[k]` and
    /// `u[k]`, as many as all three hold), bit for bit: the draws of many shading points of one
    /// BRDF at once. Implementations may draw across views (Lambert: four lanes); the default
    /// hands each run of equal views to [`Brdf::sample_many`].
    fn sample_many_views(&self, wo: &[Vec3], u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        let n = wo.len().min(u.len()).min(out.len());
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        let mut start = 0;
        while start < n {
            let view = bits(wo[start]);
            let end = start + 1 + wo[start + 1..n].iter().take_while(|w| bits(**w) == view).count();
            self.sample_many(wo[start], &u[start..end], &mut out[start..end]);
            start = end;
        }
    }

    /// [`Brdf::eval_pdf`] for every direction of `wi` (as many as both hold), bit for bit.
    fn eval_pdf_many(&self, wo: Vec3, wi: &[Vec3], out: &mut [(Vec3, f32)]) {
        for (o, w) in out.iter_mut().zip(wi) {
            *o = self.eval_pdf(wo, *w);
        }
    }

    /// The luminance of [`Brdf::eval`] at four directions given in lanes (`wi[0]`, `wi[1]`,
    /// `wi[2]`: their x, y and z), bit for bit `luminance(self.eval(wo, ωk))` in lane k: the
    /// product's build probes B at several cells' centres at once. Implementations may
    /// evaluate the four side by side (the GGX conductor, the car paint).
    fn eval_luminance_x4(&self, wo: Vec3, wi: [Vec4; 3]) -> Vec4 {
        let [x, y, z] = wi;
        Vec4::from_array(core::array::from_fn(|k| luminance(self.eval(wo, Vec3::new(x[k], y[k], z[k])))))
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
    fn sample_many_views(&self, wo: &[Vec3], u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        (**self).sample_many_views(wo, u, out)
    }
    fn eval_pdf_many(&self, wo: Vec3, wi: &[Vec3], out: &mut [(Vec3, f32)]) {
        (**self).eval_pdf_many(wo, wi, out)
    }
    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        (**self).sample_batch(wo, u, out)
    }
    fn eval_luminance_x4(&self, wo: Vec3, wi: [Vec4; 3]) -> Vec4 {
        (**self).eval_luminance_x4(wo, wi)
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

/// [`luminance`] of four RGB values given as their red, green and blue lanes, bit for bit the
/// scalar function in each lane: its weights are read from it (`luminance(Vec3::X)` is the red
/// weight exactly: the other terms add zeros) and summed in its order.
#[inline]
pub(crate) fn luminance_x4(r: Vec4, g: Vec4, b: Vec4) -> Vec4 {
    let w = |axis: Vec3| Vec4::splat(luminance(axis));
    w(Vec3::X) * r + w(Vec3::Y) * g + w(Vec3::Z) * b
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mapping::square_to_sphere;
    use crate::rng::Pcg32;

    /// Every lane of `eval_luminance_x4` is `luminance(eval)` of its direction, bit for bit:
    /// the four-wide GGX conductor and car paint and the default (Lambert, Phong), for smooth
    /// to rough lobes, coloured reflectances, views from the normal to grazing and below the
    /// surface, and directions over the whole sphere, plus the mirror of the view (no half
    /// vector), the horizon and ±0.
    #[test]
    fn four_wide_luminance_is_the_scalar_eval_bit_for_bit() {
        let colour = Vec3::new(0.9, 0.6, 0.2);
        let brdfs: [&dyn Brdf; 9] = [
            &RoughConductor::new(1e-4, colour),
            &RoughConductor::new(0.01, colour),
            &RoughConductor::new(0.3, Vec3::ONE),
            &RoughConductor::new(1.0, colour),
            &CarPaint::default(),
            &CarPaint::new(colour, Vec3::splat(0.5), 0.1, 0.0, 0.01),
            &CarPaint::new(Vec3::splat(0.3), Vec3::ZERO, 0.1, 0.5, 0.05),
            &Lambert::new(colour),
            &Phong::new(Vec3::splat(0.2), colour, 50.0),
        ];
        let mut rng = Pcg32::new(3, 3);
        for brdf in brdfs {
            for wo in [
                Vec3::Z,
                Vec3::new(0.3, -0.2, 0.9).normalize(),
                Vec3::new(0.999, 0.0, 0.01).normalize(),
                Vec3::new(0.2, 0.1, -0.9).normalize(),
            ] {
                let mut dirs: [Vec3; 256] =
                    core::array::from_fn(|_| square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32())));
                dirs[..8].copy_from_slice(&[
                    -wo,
                    wo,
                    Vec3::X,
                    Vec3::new(0.6, 0.8, 0.0),
                    Vec3::new(0.0, 0.0, -0.0),
                    Vec3::Z,
                    -Vec3::Z,
                    Vec3::Y,
                ]);
                for four in dirs.chunks_exact(4) {
                    let lanes = [0, 1, 2].map(|a| Vec4::from_array(core::array::from_fn(|k| four[k][a])));
                    let got = brdf.eval_luminance_x4(wo, lanes);
                    for (k, wi) in four.iter().enumerate() {
                        let want = luminance(brdf.eval(wo, *wi));
                        assert_eq!(got[k].to_bits(), want.to_bits(), "wo {wo}, wi {wi}: {} against {want}", got[k]);
                    }
                }
            }
        }
    }
}
