//! Lambertian diffuse reflection.

use super::{Brdf, BrdfDraw, BrdfSample};
use crate::cone::Cone;
use crate::env::luminance;
use crate::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf, square_to_cosine_hemisphere_x4};
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3, Vec4};

/// f = albedo / π, sampled ∝ cosθ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    /// Reflectance per channel, in [0, 1] for energy conservation.
    pub albedo: Vec3,
}

impl Lambert {
    /// A Lambertian BRDF of the given albedo.
    #[must_use]
    pub fn new(albedo: Vec3) -> Self {
        Self { albedo }
    }

    /// [`Brdf::sample`] of up to four points at once into `out` (lane j `None` where
    /// `below[j]`: its view is below the surface): the warp's bits are the scalar ones
    /// (`square_to_cosine_hemisphere_x4`), and the density and value are `sample`'s products.
    #[inline]
    fn draws_x4(&self, us: &[Vec2], below: [bool; 4], out: &mut [Option<BrdfSample>]) {
        let [x, y, z] = square_to_cosine_hemisphere_x4(lanes(us, |p| p.x), lanes(us, |p| p.y));
        let pdf = z * Vec4::splat(FRAC_1_PI);
        for (j, o) in out.iter_mut().take(us.len()).enumerate() {
            *o = (!below[j] && pdf[j] > 0.0).then(|| BrdfSample {
                wi: Vec3::new(x[j], y[j], z[j]),
                value: self.albedo * pdf[j],
                pdf: pdf[j],
            });
        }
    }
}

impl Brdf for Lambert {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        self.albedo * (FRAC_1_PI * wi.z)
    }

    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = square_to_cosine_hemisphere(u);
        let pdf = square_to_cosine_hemisphere_pdf(wi);
        (pdf > 0.0).then(|| BrdfSample { wi, value: self.eval(wo, wi), pdf })
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 { 0.0 } else { square_to_cosine_hemisphere_pdf(wi) }
    }

    fn sample_many(&self, wo: Vec3, u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        if wo.z <= 0.0 {
            out.iter_mut().zip(u).for_each(|(o, _)| *o = None);
            return;
        }
        for (us, os) in u.chunks(4).zip(out.chunks_mut(4)) {
            self.draws_x4(us, [false; 4], os);
        }
    }

    fn sample_many_views(&self, wo: &[Vec3], u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        for ((ws, us), os) in wo.chunks(4).zip(u.chunks(4)).zip(out.chunks_mut(4)) {
            let below = core::array::from_fn(|j| ws.get(j).is_none_or(|w| w.z <= 0.0));
            self.draws_x4(&us[..us.len().min(ws.len())], below, os);
        }
    }

    fn sample_batch(&self, wo: Vec3, u: &[Vec2], out: &mut [BrdfDraw]) -> usize {
        if wo.z <= 0.0 {
            return 0;
        }
        // Four at a time: the same bits as one by one (`square_to_cosine_hemisphere_x4`).
        let scale = Vec4::splat(luminance(self.albedo) * FRAC_1_PI);
        for (us, os) in u.chunks(4).zip(out.chunks_mut(4)) {
            let [x, y, z] = square_to_cosine_hemisphere_x4(lanes(us, |p| p.x), lanes(us, |p| p.y));
            let value = scale * z.max(Vec4::ZERO);
            for (j, o) in os.iter_mut().take(us.len()).enumerate() {
                *o = BrdfDraw { wi: Vec3::new(x[j], y[j], z[j]), value: value[j] };
            }
        }
        u.len().min(out.len())
    }

    fn is_diffuse(&self) -> bool {
        true
    }

    fn has_cone_bounds(&self) -> bool {
        true
    }

    fn cone_bounds(&self, wo: Vec3, cones: &[Cone], out: &mut [f32]) {
        let scale = if wo.z > 0.0 { luminance(self.albedo) * FRAC_1_PI } else { 0.0 };
        for (o, c) in out.iter_mut().zip(cones) {
            *o = scale * c.max_cos(Vec3::Z).max(0.0);
        }
    }

    fn reflectance_bound(&self, wo: Vec3) -> Option<f32> {
        Some(if wo.z > 0.0 { luminance(self.albedo) } else { 0.0 })
    }
}

/// One coordinate of up to four points in lanes, the missing lanes zero.
#[inline]
fn lanes(us: &[Vec2], coordinate: impl Fn(Vec2) -> f32) -> Vec4 {
    let at = |j: usize| us.get(j).map_or(0.0, |p| coordinate(*p));
    Vec4::new(at(0), at(1), at(2), at(3))
}
