//! Samples at many shading points at once: a wavefront. Where each shading point takes only a
//! sample or two (many primary rays per pixel, few light samples each), a per-point estimator
//! runs its batched code one lane wide and waits on each lookup of the map in turn. Drawn
//! across the shading points of a wavefront instead, the sampler's descents run side by side,
//! the map's lookups of different samples overlap in the memory system, and the shadow rays
//! are left to the caller to trace together: each sample comes back unshadowed, with the
//! direction its shadow ray tests.
//!
//! The values are those of the per-point estimators, bit for bit: a sample drawn by the
//! sampler is weighted as [`sampled_drawn`](super::sampled_drawn) (alone),
//! [`sampled_mis_many`](super::sampled_mis_many) (in pairs) or
//! [`sampled_mis_split`](super::sampled_mis_split) (a split budget) weigh it, and a BRDF sample
//! as [`brdf_many`](super::brdf_many) or the MIS forms weigh theirs.

use crate::brdf::{Brdf, BrdfSample};
use crate::direction::{DirectionSample, DirectionSampler};
use crate::env::MisHeuristic;
use crate::estimator::{ShadingPoint, times};
use crate::mapping::SPHERE_AREA;
use core::ops::Range;
use glam::{DVec2, DVec3, Vec2, Vec3};

/// Samples drawn together: the sampler's descents and the map's lookups of this many samples
/// are in flight at once.
pub const WAVE: usize = 64;

/// Which technique draws a sample of a wavefront.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// The sampler of the environment (env-only, a product…).
    Sampler,
    /// The shading point's BRDF.
    Brdf,
}

/// One sample of a wavefront: the shading point it belongs to, who draws it, and its point of
/// the unit square.
#[derive(Clone, Copy, Debug)]
pub struct WaveSample {
    /// Index of its shading point in the wavefront's `points`.
    pub point: usize,
    /// The technique that draws it.
    pub technique: Technique,
    /// Its point of [0, 1)².
    pub u: DVec2,
}

/// How the samples of a wavefront are weighted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Weighting {
    /// One technique alone: f/p.
    Single,
    /// One sample of each technique, weighed by the sampler's view's heuristic
    /// ([`MisHeuristic`]): f/(p_sampler + p_brdf) under the balance heuristic.
    Pairs,
    /// The multi-sample heuristic of a split budget, each technique's share of the shading
    /// point's samples scaling its density: f/(c_sampler·p_sampler + c_brdf·p_brdf) under the
    /// balance heuristic.
    Split {
        /// The sampler's share c_sampler.
        sampler: f32,
        /// The BRDF's share c_brdf.
        brdf: f32,
    },
}

/// A sample's contribution before visibility, and the shadow ray it needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Candidate {
    /// World direction of the shadow ray.
    pub dir: Vec3,
    /// f/p times the MIS weight, unshadowed (f64, as [`Contribution::value`](super::Contribution)).
    pub value: DVec3,
    /// Whether the value is non-zero and so needs the shadow ray; where it is false, `value`
    /// is zero and no ray is traced.
    pub needs_ray: bool,
}

impl Candidate {
    /// The candidate of f with density `pdf` in direction `dir` (a ray only where f/p counts).
    #[inline]
    fn new(f: DVec3, pdf: f32, dir: Vec3) -> Self {
        if pdf > 0.0 && f.cmpgt(DVec3::ZERO).any() {
            Self { dir, value: f / pdf as f64, needs_ray: true }
        } else {
            Self { dir, value: DVec3::ZERO, needs_ray: false }
        }
    }
}

/// The candidates of `samples` (`out[k]` from `samples[k]`), at most [`WAVE`] at a time: the
/// sampler's draws in one batch, the BRDF's draws and their points of the square in another,
/// the other technique's densities and the map's radiance looked up for all of them together.
pub fn wavefront<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    points: &[ShadingPoint<'_, B>],
    samples: &[WaveSample],
    weighting: Weighting,
    out: &mut [Candidate],
) {
    // One copy of the wave per heuristic: the choice is made once, not per sample.
    let power = sampler.env().mis_heuristic() == MisHeuristic::Power;
    for (s, o) in samples.chunks(WAVE).zip(out.chunks_mut(WAVE)) {
        let n = s.len().min(o.len());
        if power {
            wave::<S, B, true>(sampler, points, &s[..n], weighting, &mut o[..n]);
        } else {
            wave::<S, B, false>(sampler, points, &s[..n], weighting, &mut o[..n]);
        }
    }
}

/// [`wavefront`] of at most [`WAVE`] samples, MIS weighing by the power heuristic where
/// `POWER`, else by the balance heuristic.
fn wave<S: DirectionSampler + ?Sized, B: Brdf + ?Sized, const POWER: bool>(
    sampler: &S,
    points: &[ShadingPoint<'_, B>],
    samples: &[WaveSample],
    weighting: Weighting,
    out: &mut [Candidate],
) {
    let n = samples.len().min(WAVE);
    let env = sampler.env();
    let heuristic = if POWER { MisHeuristic::Power } else { MisHeuristic::Balance };
    // Each technique's samples in order, split in one pass.
    let (mut u_brdf, mut brdf_points, mut n_brdf) = ([Vec2::ZERO; WAVE], [0usize; WAVE], 0);
    let (mut u_sampler, mut sampler_points, mut n_sampler) = ([DVec2::ZERO; WAVE], [0usize; WAVE], 0);
    for s in &samples[..n] {
        if s.technique == Technique::Brdf {
            (u_brdf[n_brdf], brdf_points[n_brdf]) = (s.u.as_vec2(), s.point);
            n_brdf += 1;
        } else {
            (u_sampler[n_sampler], sampler_points[n_sampler]) = (s.u, s.point);
            n_sampler += 1;
        }
    }
    // The BRDF's draws first, each at its own shading point, and their points of the square:
    // the texels they read (radiance, the sampler's density) are asked for now and reach the
    // outer caches while the sampler's descents below run.
    let mut brdf: [Option<BrdfSample>; WAVE] = [None; WAVE];
    let mut dirs = [Vec3::Z; WAVE];
    draw_brdf(points, &brdf_points[..n_brdf], &u_brdf[..n_brdf], &mut brdf[..n_brdf], &mut dirs[..n_brdf]);
    let mut uvs = [Vec2::ZERO; WAVE];
    env.squares_of(&dirs[..n_brdf], &mut uvs[..n_brdf]);
    // Each sample's texel found once: asked for now, read in the last loops.
    let mut texels_brdf = [(0u32, 0u32); WAVE];
    for (t, uv) in texels_brdf.iter_mut().zip(&uvs[..n_brdf]) {
        *t = env.texel_at(*uv);
        env.prefetch_texel(t.0, t.1);
    }
    // The sampler's draws, all in one batch (its descents side by side).
    let mut drawn = [None; WAVE];
    sampler.sample_many(&u_sampler[..n_sampler], &mut drawn[..n_sampler]);
    // The descents' own loads push the BRDF samples' texels out of the nearest cache: asked
    // for again, they are back in it by the time the lookups below read them.
    if n_sampler > 0 {
        for &(x, y) in &texels_brdf[..n_brdf] {
            env.prefetch_texel(x, y);
        }
    }
    // The draws' radiance is read in the last loop, after the BRDF samples' lookups: asked for
    // now, it arrives meanwhile (their density came with the draw). The environment's own
    // descents asked for it already; the products' did not.
    let mut texels_drawn = [(0u32, 0u32); WAVE];
    for (t, d) in texels_drawn.iter_mut().zip(&drawn[..n_sampler]) {
        if let Some(d) = d {
            *t = env.texel_at(d.uv);
            env.prefetch_radiance(t.0, t.1);
        }
    }
    let mut p_square = [0.0f32; WAVE];
    if weighting != Weighting::Single {
        sampler.pdf_square_many(&uvs[..n_brdf], &mut p_square[..n_brdf]);
    }
    // Under MIS the BRDF's value and density at the sampler's draws, each point's in one call.
    let mut evaluated = [(Vec3::ZERO, 0.0f32); WAVE];
    if weighting != Weighting::Single {
        eval_at_draws(points, &sampler_points[..n_sampler], &drawn[..n_sampler], &mut evaluated[..n_sampler]);
    }
    let mut radiance_brdf = [Vec3::ZERO; WAVE];
    for (r, &(x, y)) in radiance_brdf.iter_mut().zip(&texels_brdf[..n_brdf]) {
        *r = env.radiance_texel(x, y);
    }
    // Every sample's value, in order.
    let (mut i_sampler, mut i_brdf) = (0, 0);
    for (s, o) in samples[..n].iter().zip(out.iter_mut()) {
        *o = match s.technique {
            Technique::Sampler => {
                let k = i_sampler;
                i_sampler += 1;
                drawn[k].map_or(Candidate::default(), |d| {
                    let (x, y) = texels_drawn[k];
                    sampler_candidate(
                        &points[s.point],
                        d,
                        env.radiance_texel(x, y),
                        evaluated[k],
                        (weighting, heuristic),
                    )
                })
            }
            Technique::Brdf => {
                let k = i_brdf;
                i_brdf += 1;
                brdf[k].map_or(Candidate::default(), |b| {
                    brdf_candidate(b, dirs[k], radiance_brdf[k], p_square[k], (weighting, heuristic))
                })
            }
        };
    }
}

/// The BRDF's draws of `u` at `owners`' shading points (`brdf[k]`, its world direction in
/// `dirs[k]`): each sample's view in its point's frame found once per point, and the draws of
/// the points that share one BRDF in one call, which may draw across them.
#[inline(always)]
fn draw_brdf<B: Brdf + ?Sized>(
    points: &[ShadingPoint<'_, B>],
    owners: &[usize],
    u: &[Vec2],
    brdf: &mut [Option<BrdfSample>],
    dirs: &mut [Vec3],
) {
    let mut views = [Vec3::Z; WAVE];
    let mut last: Option<(usize, Vec3)> = None;
    for (view, &owner) in views.iter_mut().zip(owners) {
        *view = match last {
            Some((o, v)) if o == owner => v,
            _ => {
                let sp = &points[owner];
                sp.frame.to_local(sp.wo)
            }
        };
        last = Some((owner, *view));
    }
    let same_brdf = |a: usize, b: usize| core::ptr::addr_eq(points[a].brdf, points[b].brdf);
    for run in runs(owners, same_brdf) {
        let brdf_of = points[owners[run.start]].brdf;
        brdf_of.sample_many_views(&views[run.clone()], &u[run.clone()], &mut brdf[run]);
    }
    for ((d, b), &owner) in dirs.iter_mut().zip(brdf.iter()).zip(owners) {
        if let Some(b) = b {
            *d = points[owner].frame.to_world(b.wi);
        }
    }
}

/// The BRDF × cos and the BRDF's density at the sampler's draws (`evaluated[k]` at `drawn[k]`
/// of `owners[k]`'s shading point), each point's draws in one call.
#[inline(always)]
fn eval_at_draws<B: Brdf + ?Sized>(
    points: &[ShadingPoint<'_, B>],
    owners: &[usize],
    drawn: &[Option<DirectionSample>],
    evaluated: &mut [(Vec3, f32)],
) {
    let mut local = [Vec3::Z; WAVE];
    for run in runs(owners, |a, b| a == b) {
        let sp = &points[owners[run.start]];
        for (l, d) in local[run.clone()].iter_mut().zip(&drawn[run.clone()]) {
            *l = d.map_or(Vec3::Z, |d| sp.frame.to_local(d.dir));
        }
        sp.brdf.eval_pdf_many(sp.frame.to_local(sp.wo), &local[run.clone()], &mut evaluated[run]);
    }
}

/// The ranges of consecutive entries of `owners` whose shading points are the `same` as
/// their run's first's (e.g. the samples of one shading point).
fn runs<'a>(owners: &'a [usize], same: impl Fn(usize, usize) -> bool + 'a) -> impl Iterator<Item = Range<usize>> + 'a {
    let mut start = 0;
    core::iter::from_fn(move || {
        let first = *owners.get(start)?;
        let end = start + 1 + owners[start + 1..].iter().take_while(|&&p| same(first, p)).count();
        let run = start..end;
        start = end;
        Some(run)
    })
}

/// The candidate of the BRDF's draw `b` in world direction `dir`, where the map's radiance is
/// `radiance` and, under MIS (weighed by `heuristic`), the sampler's density in the square is
/// `p_square`.
#[inline(always)]
fn brdf_candidate(
    b: BrdfSample,
    dir: Vec3,
    radiance: Vec3,
    p_square: f32,
    (weighting, heuristic): (Weighting, MisHeuristic),
) -> Candidate {
    let f = times(radiance, b.value);
    let p_other = p_square / SPHERE_AREA;
    let pdf = match weighting {
        Weighting::Single => b.pdf,
        Weighting::Pairs => heuristic.denominator(b.pdf, p_other),
        Weighting::Split { sampler, brdf } => heuristic.denominator(brdf * b.pdf, sampler * p_other),
    };
    Candidate::new(f, pdf, dir)
}

/// The candidate of a direction the sampler drew at `sp`, where the map's radiance is
/// `radiance` and, under MIS, the BRDF × cos and the BRDF's density there are `evaluated`.
#[inline(always)]
fn sampler_candidate<B: Brdf + ?Sized>(
    sp: &ShadingPoint<'_, B>,
    d: DirectionSample,
    radiance: Vec3,
    evaluated: (Vec3, f32),
    (weighting, heuristic): (Weighting, MisHeuristic),
) -> Candidate {
    if weighting == Weighting::Single {
        return Candidate::new(times(radiance, sp.eval(d.dir)), d.pdf, d.dir);
    }
    let (b, p_brdf) = evaluated;
    let pdf = match weighting {
        Weighting::Split { sampler, brdf } => heuristic.denominator(sampler * d.pdf, brdf * p_brdf),
        _ => heuristic.denominator(d.pdf, p_brdf),
    };
    Candidate::new(times(radiance, b), pdf, d.dir)
}
