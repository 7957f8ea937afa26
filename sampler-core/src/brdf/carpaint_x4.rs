//! The car paint's BRDF draws four at a time: the points grouped by the lobe they pick, four
//! directions of one lobe at a time (the coat's or the flakes' visible normals, the base's
//! cosine warp), then the coat, flake and base terms of BRDF × cos in `Vec4` lanes. Every lane
//! is bit for bit the one-at-a-time draw of `CarPaint::sample_batch`: the same IEEE operations
//! in the same order, selects where it branches (tests below).

use super::carpaint::CarPaint;
use super::ggx_x4::Dir4;
use super::microfacet::fresnel_schlick;
use super::{BrdfDraw, luminance_x4};
use crate::env::luminance;
use crate::mapping::sqrt4;
use crate::sampling::square_to_cosine_hemisphere_x4;
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3, Vec4};

/// Schlick's Fresnel (`microfacet::fresnel_schlick`) for four cosines.
fn fresnel_schlick_x4(f0: f32, cos_theta: Vec4) -> Vec4 {
    let c = (Vec4::ONE - cos_theta.max(Vec4::ZERO).min(Vec4::ONE)).max(Vec4::ZERO);
    let c2 = c * c;
    Vec4::splat(f0) + Vec4::splat(1.0 - f0) * c2 * c2 * c
}

/// `reflect(wo, m)` for four normals, as `sampling::reflect` orders it.
fn reflect_x4(wo: Vec3, m: &Dir4) -> Dir4 {
    let two_dot = Vec4::splat(2.0) * m.dot(wo);
    Dir4 {
        x: two_dot * m.x - Vec4::splat(wo.x),
        y: two_dot * m.y - Vec4::splat(wo.y),
        z: two_dot * m.z - Vec4::splat(wo.z),
    }
}

/// What the draws of one view share: each lobe's stretched view and the cumulative lobe
/// probabilities.
struct View {
    wo: Vec3,
    wc: Vec3,
    wf: Vec3,
    p0: f32,
    p1: f32,
}

impl CarPaint {
    /// [`Brdf::sample_batch`](super::Brdf::sample_batch) four at a time: `out[j]` from `u[j]`
    /// (`wo.z > 0` and lobe weights with a positive finite total, which the caller checks).
    /// The points are grouped by the lobe they pick, four directions of one lobe at a time, then
    /// BRDF × cos four at a time in the points' order.
    pub(super) fn sample_batch_x4(&self, wo: Vec3, weights: [f32; 3], u: &[Vec2], out: &mut [BrdfDraw]) {
        let total = weights[0] + weights[1] + weights[2];
        let (c, f) = (&self.coat_ggx, &self.flake_ggx);
        let view = View {
            wo,
            wc: c.stretch(wo),
            wf: f.stretch(wo),
            p0: weights[0] / total,
            p1: (weights[0] + weights[1]) / total,
        };
        // Up to four pending points per lobe.
        let mut pending = [[0usize; 4]; 3];
        let mut count = [0usize; 3];
        for (j, p) in u.iter().enumerate() {
            // The lobe without a branch (the points' lobes follow no pattern a predictor
            // learns): 0 below p0, 1 below p1 (≥ p0), 2 from there; NaN takes 2, as `if` would.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            let lobe = usize::from(!(p.x < view.p0)) + usize::from(!(p.x < view.p1));
            pending[lobe][count[lobe]] = j;
            count[lobe] += 1;
            if count[lobe] == 4 {
                self.draw_directions(&view, lobe, &pending[lobe], u, out);
                count[lobe] = 0;
            }
        }
        for lobe in 0..3 {
            self.draw_directions(&view, lobe, &pending[lobe][..count[lobe]], u, out);
        }
        self.values_x4(wo, out);
    }

    /// The directions of the points `u[j]`, j in `which` (at most four), all of which picked
    /// `lobe`, into `out[j].wi`.
    fn draw_directions(&self, view: &View, lobe: usize, which: &[usize], u: &[Vec2], out: &mut [BrdfDraw]) {
        if which.is_empty() {
            return;
        }
        let sp = Vec4::splat;
        let at = |k: usize| which.get(k).map_or(Vec2::ZERO, |&j| u[j]);
        let (ux, uy) = (Vec4::new(at(0).x, at(1).x, at(2).x, at(3).x), Vec4::new(at(0).y, at(1).y, at(2).y, at(3).y));
        let (p0, p1) = (view.p0, view.p1);
        let wi = match lobe {
            0 => reflect_x4(view.wo, &self.coat_ggx.sample_visible_stretched_x4(view.wc, ux / sp(p0), uy)),
            1 => reflect_x4(
                view.wo,
                &self.flake_ggx.sample_visible_stretched_x4(view.wf, (ux - sp(p0)) / sp(p1 - p0), uy),
            ),
            _ => {
                let x = ((ux - sp(p1)) / sp(1.0 - p1)).min(sp(1.0 - f32::EPSILON / 2.0));
                let [x, y, z] = square_to_cosine_hemisphere_x4(x, uy);
                Dir4 { x, y, z }
            }
        };
        for (k, &j) in which.iter().enumerate() {
            out[j].wi = wi.lane(k);
        }
    }

    /// BRDF × cos (luminance) of every draw's direction into its value, four at a time: the
    /// coat plus the transmitted flakes and base where the half vector exists and wi is above
    /// the surface.
    fn values_x4(&self, wo: Vec3, out: &mut [BrdfDraw]) {
        let sp = Vec4::splat;
        // Per view, once: G1(wo)/(4 cosθo) of both lobes and the coat's transmission towards
        // the viewer.
        let (c, f) = (&self.coat_ggx, &self.flake_ggx);
        let (gc, gf) = (c.g1(wo) / (4.0 * wo.z), f.g1(wo) / (4.0 * wo.z));
        let transmit_o = 1.0 - self.coat * fresnel_schlick(self.coat_f0, wo.z);
        let (flake, base) = (luminance(self.flake), luminance(self.base) * FRAC_1_PI);
        for os in out.chunks_mut(4) {
            let at = |j: usize| os.get(j).map_or(Vec3::Z, |d| d.wi);
            let (a, b, cc, d) = (at(0), at(1), at(2), at(3));
            let wi = Dir4 {
                x: Vec4::new(a.x, b.x, cc.x, d.x),
                y: Vec4::new(a.y, b.y, cc.y, d.y),
                z: Vec4::new(a.z, b.z, cc.z, d.z),
            };
            let s = Dir4 { x: sp(wo.x) + wi.x, y: sp(wo.y) + wi.y, z: sp(wo.z) + wi.z };
            let len2 = s.length_squared();
            let exists = len2.cmpgt(sp(1e-24)) & len2.is_finite_mask();
            let len = sqrt4(len2);
            let h = Dir4 { x: s.x / len, y: s.y / len, z: s.z / len };
            let coat = sp(self.coat) * sp(gc) * fresnel_schlick_x4(self.coat_f0, h.dot(wo)) * c.d_x4(&h) * c.g1_x4(&wi);
            let transmit = sp(transmit_o) * (Vec4::ONE - sp(self.coat) * fresnel_schlick_x4(self.coat_f0, wi.z));
            let value = coat + transmit * (sp(flake) * sp(gf) * f.d_x4(&h) * f.g1_x4(&wi) + sp(base) * wi.z);
            // An array, not `Vec4`'s index: see `Dir4::lane`.
            let value = Vec4::select(exists & wi.z.cmpgt(Vec4::ZERO), value, Vec4::ZERO).to_array();
            for (j, o) in os.iter_mut().enumerate() {
                o.value = value[j];
            }
        }
    }
}

impl CarPaint {
    /// [`Brdf::eval_luminance_x4`](super::Brdf::eval_luminance_x4): `eval`'s coat, flakes and
    /// base in lanes, each term in `eval`'s order, then the luminance of the RGB sum; +0 where
    /// `eval` returns zero (no half vector, ωi below the surface).
    pub(super) fn eval_luminance_lanes(&self, wo: Vec3, wi: [Vec4; 3]) -> Vec4 {
        if wo.z <= 0.0 {
            return Vec4::ZERO;
        }
        let sp = Vec4::splat;
        let (c, f) = (&self.coat_ggx, &self.flake_ggx);
        let wi = Dir4 { x: wi[0], y: wi[1], z: wi[2] };
        let s = Dir4 { x: sp(wo.x) + wi.x, y: sp(wo.y) + wi.y, z: sp(wo.z) + wi.z };
        let len2 = s.length_squared();
        let exists = len2.cmpgt(sp(1e-24)) & len2.is_finite_mask();
        let len = sqrt4(len2);
        let h = Dir4 { x: s.x / len, y: s.y / len, z: s.z / len };
        let four_cos_o = sp(4.0 * wo.z);
        let coat =
            sp(self.coat) * fresnel_schlick_x4(self.coat_f0, h.dot(wo)) * c.d_x4(&h) * c.g1_x4(&wi) * sp(c.g1(wo))
                / four_cos_o;
        let flake = f.d_x4(&h) * f.g1_x4(&wi) * sp(f.g1(wo)) / four_cos_o;
        let transmit = sp(1.0 - self.coat * fresnel_schlick(self.coat_f0, wo.z))
            * (Vec4::ONE - sp(self.coat) * fresnel_schlick_x4(self.coat_f0, wi.z));
        let cos_base = sp(FRAC_1_PI) * wi.z;
        let rgb = |flake_c: f32, base_c: f32| coat + transmit * (sp(flake_c) * flake + sp(base_c) * cos_base);
        let lum = luminance_x4(
            rgb(self.flake.x, self.base.x),
            rgb(self.flake.y, self.base.y),
            rgb(self.flake.z, self.base.z),
        );
        Vec4::select(exists & wi.z.cmpgt(Vec4::ZERO), lum, Vec4::ZERO)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::Brdf;
    use crate::brdf::microfacet::half_vector;
    use crate::rng::Pcg32;
    use crate::sampling::{reflect, square_to_cosine_hemisphere};

    /// One draw as the one-at-a-time formula makes it: the lobe by the point's x, its
    /// direction, then coat + transmission × (flakes + base).
    fn scalar_draw(paint: &CarPaint, wo: Vec3, p: Vec2) -> BrdfDraw {
        let (c, f) = (&paint.coat_ggx, &paint.flake_ggx);
        let w = paint.lobe_weights(wo);
        let total = w[0] + w[1] + w[2];
        let (p0, p1) = (w[0] / total, (w[0] + w[1]) / total);
        let wi = if p.x < p0 {
            reflect(wo, c.sample_visible_stretched(c.stretch(wo), Vec2::new(p.x / p0, p.y)))
        } else if p.x < p1 {
            reflect(wo, f.sample_visible_stretched(f.stretch(wo), Vec2::new((p.x - p0) / (p1 - p0), p.y)))
        } else {
            square_to_cosine_hemisphere(Vec2::new(((p.x - p1) / (1.0 - p1)).min(1.0 - f32::EPSILON / 2.0), p.y))
        };
        let (gc, gf) = (c.g1(wo) / (4.0 * wo.z), f.g1(wo) / (4.0 * wo.z));
        let transmit_o = 1.0 - paint.coat * fresnel_schlick(paint.coat_f0, wo.z);
        let (flake, base) = (luminance(paint.flake), luminance(paint.base) * FRAC_1_PI);
        let value = match half_vector(wo, wi) {
            Some(h) if wi.z > 0.0 => {
                let coat = paint.coat * gc * fresnel_schlick(paint.coat_f0, wo.dot(h)) * c.d(h) * c.g1(wi);
                let transmit = transmit_o * (1.0 - paint.coat * fresnel_schlick(paint.coat_f0, wi.z));
                coat + transmit * (flake * gf * f.d(h) * f.g1(wi) + base * wi.z)
            }
            _ => 0.0,
        };
        BrdfDraw { wi, value }
    }

    /// The four-wide draws are the scalar draws' bits, for the default paint, a paint without
    /// a coat and one without flakes, at normal to grazing views, with a batch length that
    /// leaves a partial group of four.
    #[test]
    fn batched_draws_are_the_scalar_draws_bit_for_bit() {
        let mut rng = Pcg32::new(5, 5);
        let u: [Vec2; 255] = core::array::from_fn(|_| Vec2::new(rng.next_f32(), rng.next_f32()));
        let paints = [
            CarPaint::default(),
            CarPaint::new(Vec3::splat(0.3), Vec3::splat(0.5), 0.1, 0.0, 0.01),
            CarPaint::new(Vec3::splat(0.3), Vec3::ZERO, 0.1, 0.5, 0.05),
        ];
        for paint in paints {
            for wo in [Vec3::Z, Vec3::new(0.3, -0.2, 0.9).normalize(), Vec3::new(0.999, 0.0, 0.01).normalize()] {
                let mut out = [BrdfDraw::default(); 255];
                assert_eq!(paint.sample_batch(wo, &u, &mut out), u.len());
                for (p, d) in u.iter().zip(&out) {
                    let want = scalar_draw(&paint, wo, *p);
                    assert_eq!(d.wi.to_array().map(f32::to_bits), want.wi.to_array().map(f32::to_bits), "{p}");
                    assert_eq!(d.value.to_bits(), want.value.to_bits(), "{paint:?}, wo {wo}, u {p}");
                }
            }
        }
    }
}
