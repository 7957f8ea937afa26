//! Monte Carlo estimators of direct illumination from the environment, L_o = ∫ L·B·cos·V dω,
//! one sample at a time. Each returns the weighted contribution f·V/p (times an MIS weight where
//! there is one) and the densities it used, so hosts can average, inspect and test them.
//! Visibility is asked only for directions whose unoccluded contribution is non-zero.

use crate::brdf::{Brdf, BrdfSample};
use crate::direction::{DirectionSample, DirectionSampler};
use crate::env::EnvHierarchy;
use crate::frame::Frame;
use crate::mapping::SPHERE_AREA;
use glam::{DVec2, DVec3, Vec2, Vec3};

mod batched;
pub mod lights;
pub mod wavefront;
pub use batched::{BATCH, brdf_many, sampled_many, sampled_mis_many, sampled_mis_split};

/// Answers whether the environment is visible from the shading point in a world direction.
pub trait Visibility {
    /// True when nothing blocks the environment from the shading point in world direction `dir`.
    fn visible(&mut self, dir: Vec3) -> bool;
}

impl<F: FnMut(Vec3) -> bool> Visibility for F {
    fn visible(&mut self, dir: Vec3) -> bool {
        self(dir)
    }
}

/// Where and how a shading point reflects: its frame, the world direction to the viewer and
/// its BRDF.
#[derive(Clone, Copy)]
pub struct ShadingPoint<'b, B: Brdf + ?Sized> {
    /// Shading frame (its normal is the BRDF's +z).
    pub frame: Frame,
    /// World-space unit direction towards the viewer.
    pub wo: Vec3,
    /// The surface's BRDF, evaluated in `frame`'s local coordinates.
    pub brdf: &'b B,
}

impl<B: Brdf + ?Sized> ShadingPoint<'_, B> {
    /// BRDF × cos for a world direction.
    #[inline]
    #[must_use]
    pub fn eval(&self, dir: Vec3) -> Vec3 {
        self.brdf.eval(self.frame.to_local(self.wo), self.frame.to_local(dir))
    }

    /// The BRDF's own sampling density for a world direction.
    #[inline]
    #[must_use]
    pub fn brdf_pdf(&self, dir: Vec3) -> f32 {
        self.brdf.pdf(self.frame.to_local(self.wo), self.frame.to_local(dir))
    }

    /// [`eval`](Self::eval) and [`brdf_pdf`](Self::brdf_pdf) at once ([`Brdf::eval_pdf`]).
    #[inline]
    #[must_use]
    pub fn eval_pdf(&self, dir: Vec3) -> (Vec3, f32) {
        self.brdf.eval_pdf(self.frame.to_local(self.wo), self.frame.to_local(dir))
    }
}

/// One sample's share of an estimate.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Contribution {
    /// World direction sampled (zero when no direction could be drawn).
    pub dir: Vec3,
    /// f·V/p, times the MIS weight for MIS samples — in f64: with radiances near 1e30 and
    /// needle lobes at grazing views, L·B alone exceeds the f32 range.
    pub value: DVec3,
    /// Density (solid angle) of the technique that drew the direction.
    pub pdf: f32,
    /// Density of the other technique at `dir` (MIS only; 0 otherwise).
    pub other_pdf: f32,
}

/// L·B in f64.
#[inline]
pub(crate) fn times(l: Vec3, b: Vec3) -> DVec3 {
    l.as_dvec3() * b.as_dvec3()
}

/// Rec. 709 luminance of an f64 RGB value.
#[inline]
#[must_use]
pub fn luminance64(c: DVec3) -> f64 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

#[inline]
pub(crate) fn weighted(f: DVec3, pdf: f32, vis: &mut impl Visibility, dir: Vec3) -> DVec3 {
    if pdf > 0.0 && f.cmpgt(DVec3::ZERO).any() && vis.visible(dir) { f / pdf as f64 } else { DVec3::ZERO }
}

/// One direction from any sampler of the environment (env-only, the quadtree or two-level
/// product, two-stage): f·V/p.
pub fn sampled<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    u: DVec2,
    vis: &mut impl Visibility,
) -> Contribution {
    sampled_drawn(sampler, sp, sampler.sample(u), vis)
}

/// [`sampled`] with its sample already drawn (e.g. by [`DirectionSampler::sample_many`]).
pub fn sampled_drawn<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    drawn: Option<DirectionSample>,
    vis: &mut impl Visibility,
) -> Contribution {
    let Some(s) = drawn else {
        return Contribution::default();
    };
    let f = times(sampler.env().radiance_at(s.uv), sp.eval(s.dir));
    Contribution { dir: s.dir, value: weighted(f, s.pdf, vis, s.dir), pdf: s.pdf, other_pdf: 0.0 }
}

/// BRDF-only sampling.
pub fn brdf<B: Brdf + ?Sized>(
    env: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    u: DVec2,
    vis: &mut impl Visibility,
) -> Contribution {
    let Some(s) = sp.brdf.sample(sp.frame.to_local(sp.wo), u.as_vec2()) else {
        return Contribution::default();
    };
    let dir = sp.frame.to_world(s.wi);
    let f = times(env.radiance(dir), s.value);
    Contribution { dir, value: weighted(f, s.pdf, vis, dir), pdf: s.pdf, other_pdf: 0.0 }
}

/// Multiple importance sampling of any sampler of the environment with BRDF sampling, balance
/// heuristic, one sample each (Veach 1997): each contributes f·V / (p_sampler + p_brdf), and
/// the sum of the two is the estimate. With the env-only sampler it is plain MIS; with a
/// product, the product keeps its edge where lighting varies and BRDF sampling keeps
/// needle-sharp lobes under smooth lighting as good as they can be.
pub fn sampled_mis<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    u: DVec2,
    u_brdf: Vec2,
    vis: &mut impl Visibility,
) -> [Contribution; 2] {
    sampled_mis_drawn(sampler, sp, sampler.sample(u), u_brdf, vis)
}

/// [`sampled_mis`] with the sampler's direction already drawn.
pub fn sampled_mis_drawn<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    drawn: Option<DirectionSample>,
    u_brdf: Vec2,
    vis: &mut impl Visibility,
) -> [Contribution; 2] {
    mis_with_brdf(sampler.env(), sp, drawn, |uv| sampler.pdf_square(uv), u_brdf, vis)
}

/// MIS (by the view's heuristic, [`EnvHierarchy::mis_heuristic`]) of one direction `drawn`
/// (direction, point of the square, density) by
/// a technique whose density per unit square area is `pdf_square`, and one BRDF sample. The
/// BRDF sample's point of the square is computed once, for its radiance and the other density.
fn mis_with_brdf<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    drawn: Option<DirectionSample>,
    pdf_square: impl Fn(Vec2) -> f32,
    u_brdf: Vec2,
    vis: &mut impl Visibility,
) -> [Contribution; 2] {
    let first = mis_drawn_half(env_h, sp, drawn, vis);
    let Some(s) = sp.brdf.sample(sp.frame.to_local(sp.wo), u_brdf) else { return [first, Contribution::default()] };
    let dir = sp.frame.to_world(s.wi);
    let uv = env_h.square_of(dir);
    [first, mis_brdf_half(env_h, (dir, uv, s), pdf_square(uv) / SPHERE_AREA, vis)]
}

/// The MIS share of a direction drawn by the other technique (direction, point
/// of the square, density).
#[inline]
fn mis_drawn_half<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    drawn: Option<DirectionSample>,
    vis: &mut impl Visibility,
) -> Contribution {
    let Some(d) = drawn else { return Contribution::default() };
    drawn_half(env_h, d, sp.eval_pdf(d.dir), vis)
}

/// [`mis_drawn_half`] with the BRDF × cos and the BRDF's density at the direction evaluated.
#[inline]
pub(crate) fn drawn_half(
    env_h: &EnvHierarchy<'_>,
    DirectionSample { dir, uv, pdf: p }: DirectionSample,
    (b, p_brdf): (Vec3, f32),
    vis: &mut impl Visibility,
) -> Contribution {
    let f = times(env_h.radiance_at(uv), b);
    let pdf = env_h.mis_heuristic().denominator(p, p_brdf);
    Contribution { dir, value: weighted(f, pdf, vis, dir), pdf: p, other_pdf: p_brdf }
}

/// The MIS share of a BRDF sample (world direction, its point of the square, the
/// draw), where the other technique's density is `p_other`.
#[inline]
pub(crate) fn mis_brdf_half(
    env_h: &EnvHierarchy<'_>,
    (dir, uv, s): (Vec3, Vec2, BrdfSample),
    p_other: f32,
    vis: &mut impl Visibility,
) -> Contribution {
    let f = times(env_h.radiance_at(uv), s.value);
    let pdf = env_h.mis_heuristic().denominator(s.pdf, p_other);
    Contribution { dir, value: weighted(f, pdf, vis, dir), pdf: s.pdf, other_pdf: p_other }
}

/// Resampled importance sampling (Talbot et al. 2005): `candidates.len()` candidates from the
/// balance mixture of env and BRDF sampling (each point's x < ½ picks the env, rescaled), each
/// weighted by target/source with target = luminance(L·B·cos) (no visibility); one is kept with
/// probability ∝ weight by a streaming reservoir driven by the single uniform `u_select`, and
/// the estimate is f·V/target × (Σ weights)/M. Unbiased for any M ≥ 1 because the mixture
/// covers every direction where L·B > 0. One visibility query.
pub fn ris<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    candidates: &[DVec2],
    u_select: f64,
    vis: &mut impl Visibility,
) -> Contribution {
    let wo_local = sp.frame.to_local(sp.wo);
    let mut xi = u_select.clamp(0.0, crate::warp::ONE_MINUS_EPSILON);
    let mut total = 0.0f64;
    let mut chosen: Option<(Vec3, DVec3, f64, f32)> = None; // (dir, f, target, source pdf)
    for c in candidates {
        // (direction, its point of the square, BRDF × cos, mixture density)
        let (dir, uv, b, source) = if c.x < 0.5 {
            let u = DVec2::new(2.0 * c.x, c.y);
            match env_h.sample(u) {
                Some(s) => {
                    let (b, p_brdf) = sp.eval_pdf(s.dir);
                    (s.dir, s.uv, b, 0.5 * (s.pdf + p_brdf))
                }
                None => continue,
            }
        } else {
            let u = Vec2::new((2.0 * c.x - 1.0) as f32, c.y as f32);
            match sp.brdf.sample(wo_local, u) {
                Some(s) => {
                    let dir = sp.frame.to_world(s.wi);
                    let uv = env_h.square_of(dir);
                    (dir, uv, s.value, 0.5 * (s.pdf + env_h.pdf_square(uv) / SPHERE_AREA))
                }
                None => continue,
            }
        };
        let f = times(env_h.radiance_at(uv), b);
        let target = luminance64(f);
        if !(target > 0.0 && source > 0.0 && target.is_finite()) {
            continue;
        }
        let w = target / source as f64;
        total += w;
        // Keep this candidate with probability w/total, rescaling ξ to stay uniform.
        let p = w / total;
        if xi < p {
            xi = (xi / p).min(crate::warp::ONE_MINUS_EPSILON);
            chosen = Some((dir, f, target, source));
        } else {
            xi = ((xi - p) / (1.0 - p)).clamp(0.0, crate::warp::ONE_MINUS_EPSILON);
        }
    }
    let Some((dir, f, target, source)) = chosen else { return Contribution::default() };
    let m = candidates.len() as f64;
    let value = if vis.visible(dir) { f * (total / m / target) } else { DVec3::ZERO };
    Contribution { dir, value, pdf: source, other_pdf: 0.0 }
}
