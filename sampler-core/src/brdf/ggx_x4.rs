//! The GGX conductor four directions at a time: visible-normal sampling and BRDF × cos with its
//! density in `Vec4` lanes (structure of arrays). Every lane is bit for bit what the one-at-a-time
//! code computes — the same IEEE operations in the same order, selects where it branches — so MIS
//! sees the same numbers whichever path drew or evaluated a direction (tests below).

use super::conductor::RoughConductor;
use super::microfacet::Ggx;
use super::{BrdfDraw, BrdfSample, luminance_x4};
use crate::mapping::sqrt4;
use crate::sampling::sin_cos_2pi_x4;
use core::f32::consts::PI;
use glam::{Vec2, Vec3, Vec4};

/// Four directions, one per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dir4 {
    pub x: Vec4,
    pub y: Vec4,
    pub z: Vec4,
}

impl Dir4 {
    /// Lanes from up to four directions (missing ones +z).
    pub(super) fn gather(v: &[Vec3]) -> Self {
        let at = |k: usize| v.get(k).copied().unwrap_or(Vec3::Z);
        let (a, b, c, d) = (at(0), at(1), at(2), at(3));
        Self { x: Vec4::new(a.x, b.x, c.x, d.x), y: Vec4::new(a.y, b.y, c.y, d.y), z: Vec4::new(a.z, b.z, c.z, d.z) }
    }

    /// Lane k's direction. Read through arrays: `Vec4`'s index is a `match`, which a lane
    /// number not known at compile time turns into a jump table, mispredicted lane after lane.
    pub(super) fn lane(&self, k: usize) -> Vec3 {
        Vec3::new(self.x.to_array()[k], self.y.to_array()[k], self.z.to_array()[k])
    }

    /// The same direction in every lane.
    pub(super) fn splat(v: Vec3) -> Self {
        Self { x: Vec4::splat(v.x), y: Vec4::splat(v.y), z: Vec4::splat(v.z) }
    }

    /// `a · self` per lane, as `Vec3::dot` orders it.
    pub(super) fn dot(&self, a: Vec3) -> Vec4 {
        self.dot_lanes(&Self::splat(a))
    }

    /// `a · self` per lane with a lane's own `a`, as `Vec3::dot` orders it.
    pub(super) fn dot_lanes(&self, a: &Self) -> Vec4 {
        a.x * self.x + a.y * self.y + a.z * self.z
    }

    pub(super) fn length_squared(&self) -> Vec4 {
        self.x * self.x + self.y * self.y + self.z * self.z
    }
}

impl Ggx {
    /// [`Ggx::sample_visible_stretched`] for four points.
    pub(super) fn sample_visible_stretched_x4(&self, w: Vec3, ux: Vec4, uy: Vec4) -> Dir4 {
        self.sample_visible_stretched_lanes(&Dir4::splat(w), ux, uy)
    }

    /// [`Ggx::sample_visible_stretched`] for four points, each lane with its own view `w`.
    pub(super) fn sample_visible_stretched_lanes(&self, w: &Dir4, ux: Vec4, uy: Vec4) -> Dir4 {
        let one = Vec4::ONE;
        let a = Vec4::splat(self.alpha());
        let (sin_phi, cos_phi) = sin_cos_2pi_x4(ux);
        let z = (one - uy) * (one + w.z) - w.z;
        let sin_theta = sqrt4((one - z * z).max(Vec4::ZERO).min(one));
        let h = Dir4 { x: sin_theta * cos_phi + w.x, y: sin_theta * sin_phi + w.y, z: z + w.z };
        let m = Dir4 { x: h.x * a, y: h.y * a, z: h.z.max(Vec4::ZERO) };
        let len2 = m.length_squared();
        let ok = len2.cmpgt(Vec4::ZERO) & len2.is_finite_mask();
        let len = sqrt4(len2);
        Dir4 {
            x: Vec4::select(ok, m.x / len, Vec4::ZERO),
            y: Vec4::select(ok, m.y / len, Vec4::ZERO),
            z: Vec4::select(ok, m.z / len, one),
        }
    }

    /// [`Ggx::d`] for four unit microfacet normals.
    pub(super) fn d_x4(&self, m: &Dir4) -> Vec4 {
        let a2 = Vec4::splat(self.alpha() * self.alpha());
        let k = a2 * m.z * m.z + (m.x * m.x + m.y * m.y);
        let d = a2 / (Vec4::splat(PI) * k * k);
        Vec4::select(m.z.cmpgt(Vec4::ZERO) & k.cmpgt(Vec4::ZERO), d, Vec4::ZERO)
    }

    /// [`Ggx::g1`] for four directions.
    pub(super) fn g1_x4(&self, v: &Dir4) -> Vec4 {
        let tan2 = (v.x * v.x + v.y * v.y) / (v.z * v.z);
        let a2 = Vec4::splat(self.alpha() * self.alpha());
        let g = Vec4::splat(2.0) / (Vec4::ONE + sqrt4(Vec4::ONE + a2 * tan2));
        Vec4::select(v.z.cmpgt(Vec4::ZERO), g, Vec4::ZERO)
    }
}

impl RoughConductor {
    /// [`Brdf::eval_pdf`](super::Brdf::eval_pdf) for four directions (`wo.z > 0`, `g1_o` = G1(ωo)):
    /// the scalar factor of BRDF × cos (times `specular`) and the density, per lane.
    fn eval_pdf_x4(&self, wo: Vec3, g1_o: f32, wi: &Dir4) -> (Vec4, Vec4) {
        self.eval_pdf_lanes(&Dir4::splat(wo), Vec4::splat(g1_o), wi)
    }

    /// [`Self::eval_pdf_x4`] with each lane's own view `wo` (`wo.z > 0` in the lanes that
    /// count) and its `g1_o`.
    fn eval_pdf_lanes(&self, wo: &Dir4, g1_o: Vec4, wi: &Dir4) -> (Vec4, Vec4) {
        let g = &self.ggx;
        // The half vector, where it exists.
        let s = Dir4 { x: wo.x + wi.x, y: wo.y + wi.y, z: wo.z + wi.z };
        let len2 = s.length_squared();
        let exists = len2.cmpgt(Vec4::splat(1e-24)) & len2.is_finite_mask();
        let len = sqrt4(len2);
        let h = Dir4 { x: s.x / len, y: s.y / len, z: s.z / len };
        let d = g.d_x4(&h);
        let four_cos_o = Vec4::splat(4.0) * wo.z;
        let value = d * g.g1_x4(wi) * g1_o / four_cos_o;
        let pdf = g1_o * d / four_cos_o;
        let value = Vec4::select(exists & wi.z.cmpgt(Vec4::ZERO), value, Vec4::ZERO);
        let pdf = Vec4::select(exists & h.dot_lanes(wo).cmpgt(Vec4::ZERO), pdf, Vec4::ZERO);
        (value, pdf)
    }

    /// [`Brdf::eval_luminance_x4`](super::Brdf::eval_luminance_x4): `eval`'s scalar factor
    /// D·G1(ωi)·G1(ωo)/(4 cosθo) in lanes, times `specular`, its luminance; +0 where `eval`
    /// returns zero (no half vector, ωi below the surface).
    pub(crate) fn eval_luminance_lanes(&self, wo: Vec3, wi: [Vec4; 3]) -> Vec4 {
        if wo.z <= 0.0 {
            return Vec4::ZERO;
        }
        let g = &self.ggx;
        let wi = Dir4 { x: wi[0], y: wi[1], z: wi[2] };
        let s = Dir4 { x: Vec4::splat(wo.x) + wi.x, y: Vec4::splat(wo.y) + wi.y, z: Vec4::splat(wo.z) + wi.z };
        let len2 = s.length_squared();
        let exists = len2.cmpgt(Vec4::splat(1e-24)) & len2.is_finite_mask();
        let len = sqrt4(len2);
        let h = Dir4 { x: s.x / len, y: s.y / len, z: s.z / len };
        let value = g.d_x4(&h) * g.g1_x4(&wi) * Vec4::splat(g.g1(wo)) / Vec4::splat(4.0 * wo.z);
        let sp = self.specular;
        let lum = luminance_x4(Vec4::splat(sp.x) * value, Vec4::splat(sp.y) * value, Vec4::splat(sp.z) * value);
        Vec4::select(exists & wi.z.cmpgt(Vec4::ZERO), lum, Vec4::ZERO)
    }

    /// [`Brdf::sample`](super::Brdf::sample) for every point of `u` (`out[k]` from `u[k]`), four
    /// at a time.
    pub(crate) fn sample_x4(&self, wo: Vec3, u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        if wo.z <= 0.0 {
            out.iter_mut().for_each(|o| *o = None);
            return;
        }
        let g = &self.ggx;
        // Per view, once.
        let (wo4, w, g1_o) = (Dir4::splat(wo), Dir4::splat(g.stretch(wo)), Vec4::splat(g.g1(wo)));
        for (us, os) in u.chunks(4).zip(out.chunks_mut(4)) {
            self.draws_lanes(&wo4, &w, g1_o, us, [false; 4], os);
        }
    }

    /// [`Brdf::sample_many_views`](super::Brdf::sample_many_views): `out[k]` from `u[k]` seen
    /// from `wo[k]`, four at a time whatever the views.
    pub(crate) fn sample_views_x4(&self, wo: &[Vec3], u: &[Vec2], out: &mut [Option<BrdfSample>]) {
        let g = &self.ggx;
        for ((ws, us), os) in wo.chunks(4).zip(u.chunks(4)).zip(out.chunks_mut(4)) {
            let view = |k: usize| ws.get(k).copied().unwrap_or(Vec3::Z);
            let lanes = |f: &dyn Fn(Vec3) -> f32| Vec4::from_array(core::array::from_fn(|k| f(view(k))));
            let wo4 = Dir4::gather(ws);
            let w = Dir4::gather(&core::array::from_fn::<_, 4, _>(|k| g.stretch(view(k))));
            let g1_o = lanes(&|v| g.g1(v));
            let below = core::array::from_fn(|k| ws.get(k).is_none_or(|v| v.z <= 0.0));
            self.draws_lanes(&wo4, &w, g1_o, &us[..us.len().min(ws.len())], below, os);
        }
    }

    /// Up to four draws into `out` (lane k `None` where `below[k]`), lane k seen from `wo`'s
    /// lane k, its stretched view `w` and G1 `g1_o`.
    #[inline]
    fn draws_lanes(
        &self,
        wo: &Dir4,
        w: &Dir4,
        g1_o: Vec4,
        us: &[Vec2],
        below: [bool; 4],
        out: &mut [Option<BrdfSample>],
    ) {
        let at = |k: usize| us.get(k).copied().unwrap_or(Vec2::ZERO);
        let (ux, uy) = (Vec4::new(at(0).x, at(1).x, at(2).x, at(3).x), Vec4::new(at(0).y, at(1).y, at(2).y, at(3).y));
        let m = self.ggx.sample_visible_stretched_lanes(w, ux, uy);
        // wi = reflect(wo, m), normalised as `Vec3::normalize` does (times 1/length).
        let two_dot = Vec4::splat(2.0) * m.dot_lanes(wo);
        let r = Dir4 { x: two_dot * m.x - wo.x, y: two_dot * m.y - wo.y, z: two_dot * m.z - wo.z };
        let recip = Vec4::ONE / sqrt4(r.length_squared());
        let wi = Dir4 { x: r.x * recip, y: r.y * recip, z: r.z * recip };
        let (value, pdf) = self.eval_pdf_lanes(wo, g1_o, &wi);
        let keep: [bool; 4] = (pdf.cmpgt(Vec4::ZERO) & pdf.is_finite_mask()).into();
        for (k, o) in out.iter_mut().take(us.len()).enumerate() {
            *o = (!below[k] && keep[k]).then(|| BrdfSample {
                wi: wi.lane(k),
                value: self.specular * value[k],
                pdf: pdf[k],
            });
        }
    }

    /// [`Brdf::sample_batch`](super::Brdf::sample_batch) four at a time (`wo.z > 0`, `k` =
    /// luminance(specular)·G1(ωo)/(4 cosθo)): `out[j]` from `u[j]`, bit for bit the scalar draw —
    /// wi = reflect(wo, m) unnormalised, value D(m)·G1(wi)·k.
    pub(crate) fn sample_batch_x4(&self, wo: Vec3, k: f32, u: &[Vec2], out: &mut [BrdfDraw]) {
        let g = &self.ggx;
        let w = g.stretch(wo);
        for (us, os) in u.chunks(4).zip(out.chunks_mut(4)) {
            let at = |j: usize| us.get(j).copied().unwrap_or(Vec2::ZERO);
            let (ux, uy) =
                (Vec4::new(at(0).x, at(1).x, at(2).x, at(3).x), Vec4::new(at(0).y, at(1).y, at(2).y, at(3).y));
            let m = g.sample_visible_stretched_x4(w, ux, uy);
            let two_dot = Vec4::splat(2.0) * m.dot(wo);
            let wi = Dir4 {
                x: two_dot * m.x - Vec4::splat(wo.x),
                y: two_dot * m.y - Vec4::splat(wo.y),
                z: two_dot * m.z - Vec4::splat(wo.z),
            };
            let value = g.d_x4(&m) * g.g1_x4(&wi) * Vec4::splat(k);
            for (j, o) in os.iter_mut().take(us.len()).enumerate() {
                *o = BrdfDraw { wi: wi.lane(j), value: value[j] };
            }
        }
    }

    /// [`Brdf::eval_pdf`](super::Brdf::eval_pdf) for every direction of `wi`, four at a time.
    pub(crate) fn eval_pdf_many_x4(&self, wo: Vec3, wi: &[Vec3], out: &mut [(Vec3, f32)]) {
        if wo.z <= 0.0 {
            out.iter_mut().for_each(|o| *o = (Vec3::ZERO, 0.0));
            return;
        }
        let g1_o = self.ggx.g1(wo);
        for (ws, os) in wi.chunks(4).zip(out.chunks_mut(4)) {
            let (value, pdf) = self.eval_pdf_x4(wo, g1_o, &Dir4::gather(ws));
            for (k, o) in os.iter_mut().take(ws.len()).enumerate() {
                *o = (self.specular * value[k], pdf[k]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::Brdf;
    use crate::env::luminance;
    use crate::rng::Pcg32;
    use crate::sampling::reflect;

    /// The four-wide draws are the one-at-a-time formula's bits: the direction reflected about
    /// the drawn visible normal and D(m)·G1(wi)·k, for smooth to rough lobes and grazing views,
    /// with a batch length that leaves a partial group of four.
    #[test]
    fn batched_draws_are_the_scalar_draws_bit_for_bit() {
        let mut rng = Pcg32::new(9, 9);
        let u: [Vec2; 255] = core::array::from_fn(|_| Vec2::new(rng.next_f32(), rng.next_f32()));
        for alpha in [1e-4, 0.01, 0.1, 0.3, 1.0] {
            let brdf = RoughConductor::new(alpha, Vec3::new(0.9, 0.7, 0.5));
            for wo in [Vec3::Z, Vec3::new(0.3, -0.2, 0.9).normalize(), Vec3::new(0.999, 0.0, 0.01).normalize()] {
                let mut out = [BrdfDraw::default(); 255];
                assert_eq!(brdf.sample_batch(wo, &u, &mut out), u.len());
                let g = &brdf.ggx;
                let k = luminance(brdf.specular) * g.g1(wo) / (4.0 * wo.z);
                for (p, d) in u.iter().zip(&out) {
                    let m = g.sample_visible_stretched(g.stretch(wo), *p);
                    let wi = reflect(wo, m);
                    assert_eq!(d.wi.to_array().map(f32::to_bits), wi.to_array().map(f32::to_bits));
                    assert_eq!(d.value.to_bits(), (g.d(m) * g.g1(wi) * k).to_bits(), "α {alpha}, wo {wo}");
                }
            }
        }
    }
}
