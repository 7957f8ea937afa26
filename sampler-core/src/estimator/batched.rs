//! The MIS estimators for many samples at once: each technique's draws, evaluations and
//! densities in batches of [`BATCH`] (four lanes at a time where the core has lanes), so that
//! the descents and BRDF evaluations of a batch overlap. Any number of samples per call; the
//! scratch of one batch lives on the stack and is a few kilobytes, so a call for a handful of
//! samples (a shading point with a small budget) costs little more than the samples.

use super::{Contribution, ShadingPoint, Visibility, drawn_half, mis_brdf_half, times, weighted};
use crate::brdf::{Brdf, BrdfSample};
use crate::direction::{DirectionSample, DirectionSampler};
use crate::env::EnvHierarchy;
use crate::mapping::SPHERE_AREA;
use glam::{DVec2, DVec3, Vec2, Vec3};

/// Samples per batch: four lanes of four, and no more (a shading point with 16 visibility
/// samples spends 8 pairs; a larger batch only zeroes more scratch per call, which a shading
/// point with few samples pays in full: docs/tuning.md#batched-and-branch-free-sampling).
pub const BATCH: usize = 16;

/// A drawn direction, or none.
type Drawn = Option<DirectionSample>;

/// [`sampled_mis`](super::sampled_mis) for every pair (`out[k]` from `u_sampler[k]` and
/// `u_brdf[k]`, as many as all three hold): the sampler's directions drawn by
/// [`DirectionSampler::sample_many`] and its densities at the BRDF samples by
/// [`DirectionSampler::pdf_square_many`] (four tree descents side by side for the quadtree
/// product: the same values as one pair at a time, up to the last bits of a product sample's
/// point).
pub fn sampled_mis_many<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    u_sampler: &[DVec2],
    u_brdf: &[Vec2],
    vis: &mut impl Visibility,
    out: &mut [[Contribution; 2]],
) {
    let n = u_sampler.len().min(u_brdf.len()).min(out.len());
    for start in (0..n).step_by(BATCH) {
        let end = (start + BATCH).min(n);
        let m = end - start;
        let mut directions = [None; BATCH];
        sampler.sample_many(&u_sampler[start..end], &mut directions[..m]);
        let pdf_square_many = |uv: &[Vec2], p: &mut [f32]| sampler.pdf_square_many(uv, p);
        let (u_b, o) = (&u_brdf[start..end], &mut out[start..end]);
        mis_with_brdf_batch(sampler.env(), sp, &directions[..m], u_b, pdf_square_many, vis, o);
    }
}

/// [`sampled`](super::sampled) for every point of `u` (`out[k]` from `u[k]`): the sampler's
/// directions drawn a batch at a time and the BRDF evaluated likewise.
pub fn sampled_many<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    u: &[DVec2],
    vis: &mut impl Visibility,
    out: &mut [Contribution],
) {
    for (us, os) in u.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
        let n = us.len().min(os.len());
        let mut drawn = [None; BATCH];
        sampler.sample_many(&us[..n], &mut drawn[..n]);
        drawn_many(sampler.env(), sp, &drawn[..n], vis, &mut os[..n]);
    }
}

/// f·V/p of up to [`BATCH`] drawn directions into `out`, the BRDF evaluated at once.
fn drawn_many<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    drawn: &[Drawn],
    vis: &mut impl Visibility,
    out: &mut [Contribution],
) {
    let n = drawn.len().min(out.len()).min(BATCH);
    let evaluated = evaluate_drawn(sp, &drawn[..n]);
    for ((o, d), (b, _)) in out.iter_mut().zip(&drawn[..n]).zip(evaluated) {
        *o = d.map_or(Contribution::default(), |d| {
            let f = times(env_h.radiance_at(d.uv), b);
            Contribution { dir: d.dir, value: weighted(f, d.pdf, vis, d.dir), pdf: d.pdf, other_pdf: 0.0 }
        });
    }
}

/// [`brdf()`](super::brdf) for every point of `u` (`out[k]` from `u[k]`), the BRDF samples
/// drawn and their points of the square found a batch at a time ([`Brdf::sample_many`]: four
/// lanes for GGX): the same values, bit for bit.
pub fn brdf_many<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    u: &[Vec2],
    vis: &mut impl Visibility,
    out: &mut [Contribution],
) {
    for (us, os) in u.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
        let n = us.len().min(os.len());
        let (brdf, _) = brdf_draws(env_h, sp, &us[..n], |_, _| {});
        for (o, b) in os.iter_mut().zip(&brdf[..n]) {
            *o = b.map_or(Contribution::default(), |(dir, uv, s)| {
                let f = times(env_h.radiance_at(uv), s.value);
                Contribution { dir, value: weighted(f, s.pdf, vis, dir), pdf: s.pdf, other_pdf: 0.0 }
            });
        }
    }
}

/// MIS (by the view's heuristic) of up to [`BATCH`] directions drawn by one technique and as many BRDF
/// samples, the BRDF's draws and evaluations batched ([`Brdf::sample_many`],
/// [`Brdf::eval_pdf_many`]: four lanes for GGX) and the other technique's densities at the
/// BRDF samples' points by `pdf_square_many` — bit for bit the values of
/// [`mis_with_brdf`](super::mis_with_brdf) pair by pair.
fn mis_with_brdf_batch<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    drawn: &[Drawn],
    u_brdf: &[Vec2],
    pdf_square_many: impl FnOnce(&[Vec2], &mut [f32]),
    vis: &mut impl Visibility,
    out: &mut [[Contribution; 2]],
) {
    let n = drawn.len().min(u_brdf.len()).min(out.len()).min(BATCH);
    let evaluated = evaluate_drawn(sp, &drawn[..n]);
    let (brdf, p_other) = brdf_draws(env_h, sp, &u_brdf[..n], pdf_square_many);
    for k in 0..n {
        let first = drawn[k].map_or(Contribution::default(), |d| drawn_half(env_h, d, evaluated[k], vis));
        let second =
            brdf[k].map_or(Contribution::default(), |b| mis_brdf_half(env_h, b, p_other[k] / SPHERE_AREA, vis));
        out[k] = [first, second];
    }
}

/// BRDF × cos and the BRDF's density at up to [`BATCH`] drawn directions, four lanes at a time
/// for GGX.
fn evaluate_drawn<B: Brdf + ?Sized>(sp: &ShadingPoint<'_, B>, drawn: &[Drawn]) -> [(Vec3, f32); BATCH] {
    let n = drawn.len().min(BATCH);
    let mut local = [Vec3::Z; BATCH];
    for (l, d) in local.iter_mut().zip(&drawn[..n]) {
        *l = d.map_or(Vec3::Z, |d| sp.frame.to_local(d.dir));
    }
    let mut evaluated = [(Vec3::ZERO, 0.0); BATCH];
    sp.brdf.eval_pdf_many(sp.frame.to_local(sp.wo), &local[..n], &mut evaluated[..n]);
    evaluated
}

/// Up to [`BATCH`] BRDF samples (world direction, point of the square, the draw) and the other
/// technique's density per unit square area at each point, by `pdf_square_many`.
#[allow(clippy::type_complexity)]
fn brdf_draws<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    u_brdf: &[Vec2],
    pdf_square_many: impl FnOnce(&[Vec2], &mut [f32]),
) -> ([Option<(Vec3, Vec2, BrdfSample)>; BATCH], [f32; BATCH]) {
    let n = u_brdf.len().min(BATCH);
    let mut samples = [None; BATCH];
    sp.brdf.sample_many(sp.frame.to_local(sp.wo), &u_brdf[..n], &mut samples[..n]);
    let mut dirs = [Vec3::Z; BATCH];
    for (d, s) in dirs.iter_mut().zip(&samples[..n]) {
        if let Some(s) = s {
            *d = sp.frame.to_world(s.wi);
        }
    }
    let mut uvs = [Vec2::ZERO; BATCH];
    env_h.squares_of(&dirs[..n], &mut uvs[..n]);
    let mut brdf = [None; BATCH];
    for k in 0..n {
        brdf[k] = samples[k].map(|s| (dirs[k], uvs[k], s));
    }
    let mut p_other = [0.0f32; BATCH];
    pdf_square_many(&uvs[..n], &mut p_other[..n]);
    (brdf, p_other)
}

/// Any sampler of the environment (a product, the env-only sampler…) and BRDF sampling in MIS
/// with the budget split unevenly (Veach's multi-sample heuristics): `shares = (c_p, c_b)` are
/// the fractions of the shading point's samples that each technique draws (c_p + c_b = 1), and
/// every sample, whichever technique drew it, weighs f·V / (c_p·p_product + c_b·p_brdf) under
/// the balance heuristic, or by the view's other heuristic with each density scaled by its share
/// ([`MisHeuristic::denominator`](crate::env::MisHeuristic::denominator)). Returns the sum over these points — any number
/// of each technique; the estimate is the sum over all of a shading point's points divided by
/// their count. Unbiased for any split: each technique's density covers what it samples, and
/// together they cover every direction where L·B > 0 (the product through its defensive part).
/// Where a wide lobe meets extended light, product samples are worth more than BRDF samples,
/// and a split towards them lowers the error (docs/tuning.md#budget-splits); with shares (½, ½) and as many
/// points of each it is [`sampled_mis_many`]'s estimate. The sum runs over all of the first
/// technique's samples, then the BRDF's, one by one (the same order and rounding however the
/// points are batched).
pub fn sampled_mis_split<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    first: &S,
    sp: &ShadingPoint<'_, B>,
    u_first: &[DVec2],
    u_brdf: &[Vec2],
    shares: (f32, f32),
    vis: &mut impl Visibility,
) -> DVec3 {
    let mut sum = DVec3::ZERO;
    let env_h = first.env();
    for u in u_first.chunks(BATCH) {
        let mut drawn = [None; BATCH];
        first.sample_many(u, &mut drawn[..u.len()]);
        add_drawn(env_h, sp, &drawn[..u.len()], shares, vis, &mut sum);
    }
    for u in u_brdf.chunks(BATCH) {
        add_brdf(env_h, sp, u, |uv, p| first.pdf_square_many(uv, p), shares, vis, &mut sum);
    }
    sum
}

/// Adds f·V / (c_d·p_drawn + c_b·p_brdf) (the view's heuristic's denominator,
/// [`MisHeuristic::denominator`](crate::env::MisHeuristic::denominator)) of up to [`BATCH`]
/// directions drawn by the first technique to `sum`, one by one (the same order and rounding however the points are batched).
fn add_drawn<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    drawn: &[Drawn],
    (c_d, c_b): (f32, f32),
    vis: &mut impl Visibility,
    sum: &mut DVec3,
) {
    let evaluated = evaluate_drawn(sp, drawn);
    for (d, (b, p_brdf)) in drawn.iter().zip(evaluated) {
        if let Some(DirectionSample { dir, uv, pdf: p }) = *d {
            let pdf = env_h.mis_heuristic().denominator(c_d * p, c_b * p_brdf);
            *sum += weighted(times(env_h.radiance_at(uv), b), pdf, vis, dir);
        }
    }
}

/// Adds f·V / (c_b·p_brdf + c_d·p_drawn) (as [`add_drawn`]) of up to [`BATCH`] BRDF samples to `sum`, the first
/// technique's densities at their points by `pdf_square_many`.
fn add_brdf<B: Brdf + ?Sized>(
    env_h: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    u_brdf: &[Vec2],
    pdf_square_many: impl FnOnce(&[Vec2], &mut [f32]),
    (c_d, c_b): (f32, f32),
    vis: &mut impl Visibility,
    sum: &mut DVec3,
) {
    let (brdf, p_drawn) = brdf_draws(env_h, sp, u_brdf, pdf_square_many);
    for (b, p_square) in brdf[..u_brdf.len().min(BATCH)].iter().zip(p_drawn) {
        if let Some((dir, uv, s)) = *b {
            let p = env_h.mis_heuristic().denominator(c_b * s.pdf, c_d * (p_square / SPHERE_AREA));
            *sum += weighted(times(env_h.radiance_at(uv), s.value), p, vis, dir);
        }
    }
}
