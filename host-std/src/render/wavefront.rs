//! The light samples of all shading points of one material in a group, drawn as one wavefront
//! (`sampler_core::estimator::wavefront`) where the material's sampler is the same at every
//! point — the environment (env, BRDF and MIS sampling) or the pixel's shared product-MIS or
//! two-level-MIS sampler — and each point takes few samples: then each point's estimate is the
//! per-point estimator's ([`shade::shade`]) bit for bit, but the samples of all points are
//! drawn together, and their shadow rays are traced together.

use crate::render::shade::{Run, Sampling};
use crate::trace::bvh::{Bvh, RaysAhead};
use sampler_core::brdf::Brdf;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::wavefront::{Candidate, Technique, WaveSample, Weighting, wavefront};
use sampler_core::estimator::{BATCH, ShadingPoint};
use sampler_core::glam::{DVec2, DVec3, Vec3};
use sampler_core::points::Sobol02;
use sampler_core::rng::hash_combine;

/// How each shading point of a wavefront spends its budget.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Layout {
    /// `n` samples of one technique.
    Single { technique: Technique, n: usize },
    /// `n` pairs, one sample of each technique.
    Pairs { n: usize },
    /// `first` samples of the sampler, then `brdf` of the BRDF, the multi-sample balance
    /// heuristic over them.
    Split { first: usize, brdf: usize },
}

impl Layout {
    /// Samples per shading point.
    fn len(self) -> usize {
        match self {
            Layout::Single { n, .. } => n,
            Layout::Pairs { n } => 2 * n,
            Layout::Split { first, brdf } => first + brdf,
        }
    }
}

/// The wavefront layout of a budget as [`shade::shade`] spends it, where the strategy
/// samples through one sampler for every point and each technique's samples fit one of its
/// batches (larger budgets fill the per-point batches themselves).
fn layout(sampling: &Sampling<'_, '_>, budget: usize) -> Option<Layout> {
    let budget = budget.max(1);
    let split = |share: f64| {
        let (first, brdf) = split_counts(budget, share);
        (first <= BATCH && brdf <= BATCH).then_some(Layout::Split { first, brdf })
    };
    let fits = |n: usize| n <= BATCH;
    match *sampling {
        Sampling::Env => fits(budget).then_some(Layout::Single { technique: Technique::Sampler, n: budget }),
        Sampling::Brdf => fits(budget).then_some(Layout::Single { technique: Technique::Brdf, n: budget }),
        Sampling::Mis { env_share: 0.5, .. } | Sampling::TwoLevelMis { two_level_share: 0.5, .. } => {
            let n = (budget / 2).max(1);
            fits(n).then_some(Layout::Pairs { n })
        }
        Sampling::Mis { env_share: share, .. }
        | Sampling::ProductMis { product_share: share, .. }
        | Sampling::TwoLevelMis { two_level_share: share, .. } => split(share),
        _ => None,
    }
}

/// Whether [`shade_wavefront`] shades a group sampled as `sampling` with `budget` samples per
/// point.
pub(crate) fn fits(sampling: &Sampling<'_, '_>, budget: usize) -> bool {
    layout(sampling, budget).is_some()
}

/// Samples of each technique for a split budget: ⌊share·budget⌉ of the first, the rest of
/// the BRDF, at least one of each (as [`shade::shade`] splits it).
pub(crate) fn split_counts(budget: usize, share: f64) -> (usize, usize) {
    if budget < 2 {
        (1, 1)
    } else {
        let first = ((share * budget as f64).round() as usize).clamp(1, budget - 1);
        (first, budget - first)
    }
}

/// Each technique's share of a split budget of `first` + `brdf` samples, the weights of the
/// multi-sample balance heuristic.
pub(crate) fn split_shares(first: usize, brdf: usize) -> (f32, f32) {
    let total = (first + brdf) as f64;
    ((first as f64 / total) as f32, (brdf as f64 / total) as f32)
}

/// Reused buffers of the wavefronts.
#[derive(Default)]
pub(crate) struct WaveBuffers {
    samples: Vec<WaveSample>,
    candidates: Vec<Candidate>,
    rays: RaysAhead,
    blocked: Vec<bool>,
}

/// What a wavefront's shadow rays need: where each shading point's rays start, and the scene
/// that blocks them (`None` where nothing casts shadows).
pub(crate) struct Shadows<'a> {
    /// Each shading point's ray origin, offset from its surface.
    pub origins: &'a [Vec3],
    /// The scene's hierarchy, or `None` for unshadowed light.
    pub bvh: Option<&'a Bvh>,
}

/// Each shading point's estimate of its direct light into `out`, from `budget` samples drawn
/// as `sampling` says (`runs[k]`: point k's run of its pixel's sequences), if `sampling` draws
/// through one sampler for all of them and the budget is small ([`fits`]). The shadow rays of
/// the samples that need one are traced together ([`Bvh::occluded_ahead_many`]) where the scene
/// answers them in batches, else one by one; returns how many rays it asked for. `None`
/// (nothing done) where the wavefront does not fit.
#[allow(clippy::too_many_arguments)]
pub(crate) fn shade_wavefront(
    sampling: &Sampling<'_, '_>,
    env: &EnvHierarchy<'_>,
    points: &[ShadingPoint<'_, dyn Brdf + '_>],
    runs: &[Run],
    budget: usize,
    buffers: &mut WaveBuffers,
    shadows: Shadows<'_>,
    out: &mut [DVec3],
) -> Option<usize> {
    let layout = layout(sampling, budget)?;
    let weighting = match layout {
        Layout::Single { .. } => Weighting::Single,
        Layout::Pairs { .. } => Weighting::Pairs,
        Layout::Split { first, brdf } => {
            let (sampler, brdf) = split_shares(first, brdf);
            Weighting::Split { sampler, brdf }
        }
    };
    // A pixel's shading points share its sequences, each taking its own run of them.
    let seed = runs.first().map_or(0, |r| r.seed);
    debug_assert!(runs.iter().all(|r| r.seed == seed), "a wavefront is one pixel's");
    let sequences = (Sobol02::new(hash_combine(seed, 1)), Sobol02::new(hash_combine(seed, 2)));
    let per_point = layout.len();
    let total = per_point * runs.len();
    // The buffers only grow: every entry up to `total` is overwritten below.
    let unused = WaveSample { point: 0, technique: Technique::Sampler, u: DVec2::ZERO };
    let samples = at_least(&mut buffers.samples, total, unused);
    for (point, (run, s)) in runs.iter().zip(samples.chunks_exact_mut(per_point)).enumerate() {
        write_samples(layout, point, run.block, sequences, s);
    }
    let candidates = at_least(&mut buffers.candidates, total, Candidate::default());
    match sampling {
        Sampling::ProductMis { sampler, .. } => wavefront(sampler, points, samples, weighting, candidates),
        Sampling::Mis { sampler, .. } => wavefront(sampler, points, samples, weighting, candidates),
        Sampling::TwoLevelMis { sampler, .. } => wavefront(sampler, points, samples, weighting, candidates),
        _ => wavefront(env, points, samples, weighting, candidates),
    }
    // Where the scene answers rays in batches, its rays are traced first and their answers read
    // back in the order the estimates sum their samples; elsewhere each ray is traced as its
    // estimate sums its sample.
    debug_assert_eq!(shadows.origins.len(), runs.len(), "one ray origin per shading point");
    if let Some(bvh) = shadows.bvh.filter(|b| b.batches_rays_ahead()) {
        let bufs = (&mut buffers.rays, &mut buffers.blocked);
        let blocked = trace_batch(bvh, shadows.origins, candidates, per_point, bufs);
        let mut next = 0;
        for (candidates, o) in candidates.chunks(per_point).zip(out.iter_mut()) {
            // Without a branch on the sample (which samples need no ray follows no pattern a
            // predictor finds): a sample without a ray has the value +0, which the next ray's
            // answer leaves +0 (the answers end in one that is not blocked), and a blocked
            // ray's value is cleared to +0 by its bits.
            let mut value = |c: &Candidate| {
                debug_assert!(c.needs_ray || c.value.to_array().iter().all(|v| v.to_bits() == 0));
                let keep = u64::from(!blocked[next]).wrapping_neg();
                next += usize::from(c.needs_ray);
                c.value.to_array().map(|v| f64::from_bits(v.to_bits() & keep)).into()
            };
            *o = reduce(layout, candidates, &mut value);
        }
        debug_assert_eq!(next, blocked.len() - 1, "every answer read");
        return Some(next);
    }
    let mut traced = 0;
    for (origin, (candidates, o)) in shadows.origins.iter().zip(candidates.chunks(per_point).zip(out.iter_mut())) {
        let mut value = |c: &Candidate| {
            if !c.needs_ray {
                return DVec3::ZERO;
            }
            traced += 1;
            let occluded = shadows.bvh.is_some_and(|bvh| bvh.occluded(*origin, c.dir, 0.0, f32::INFINITY));
            if occluded { DVec3::ZERO } else { c.value }
        };
        *o = reduce(layout, candidates, &mut value);
    }
    Some(traced)
}

/// Whether each candidate's shadow ray that `needs_ray` is blocked, in the candidates' order
/// (`per_point` of them per origin), traced as one batch (`rays` and `blocked` reused), and one
/// answer more, not blocked, after the last.
fn trace_batch<'b>(
    bvh: &Bvh,
    origins: &[Vec3],
    candidates: &[Candidate],
    per_point: usize,
    (rays, blocked): (&mut RaysAhead, &'b mut Vec<bool>),
) -> &'b mut [bool] {
    rays.clear_for(candidates.len());
    for (origin, candidates) in origins.iter().zip(candidates.chunks(per_point)) {
        for c in candidates {
            rays.push_if(*origin, c.dir, c.needs_ray);
        }
    }
    let blocked = at_least(blocked, rays.len() + 1, false);
    let (answers, last) = blocked.split_at_mut(rays.len());
    bvh.occluded_ahead_many(rays, answers);
    last[0] = false;
    blocked
}

/// The first `n` entries of `buffer`, grown to hold them (with `fill`) if it is shorter.
fn at_least<T: Copy>(buffer: &mut Vec<T>, n: usize, fill: T) -> &mut [T] {
    if buffer.len() < n {
        buffer.resize(n, fill);
    }
    &mut buffer[..n]
}

/// A shading point's samples into `out` (its [`Layout::len`] entries) in the order its
/// estimate sums them, from its `block` of the pixel's sequences for each technique (the same
/// points [`shade::shade`] draws).
fn write_samples(
    layout: Layout,
    point: usize,
    block: usize,
    (first_seq, brdf_seq): (Sobol02, Sobol02),
    out: &mut [WaveSample],
) {
    let sample = |technique, u| WaveSample { point, technique, u };
    match layout {
        Layout::Single { technique, n } => {
            for (o, u) in out.iter_mut().zip(first_seq.points((block * n) as u32)) {
                *o = sample(technique, u);
            }
        }
        Layout::Pairs { n } => {
            let first = (block * n) as u32;
            let points = first_seq.points(first).zip(brdf_seq.points(first));
            for (o, (u, v)) in out.chunks_exact_mut(2).zip(points) {
                o[0] = sample(Technique::Sampler, u);
                o[1] = sample(Technique::Brdf, v);
            }
        }
        Layout::Split { first, brdf } => {
            let (sampled, brdfs) = out.split_at_mut(first);
            for (o, u) in sampled.iter_mut().zip(first_seq.points((block * first) as u32)) {
                *o = sample(Technique::Sampler, u);
            }
            for (o, u) in brdfs.iter_mut().zip(brdf_seq.points((block * brdf) as u32)) {
                *o = sample(Technique::Brdf, u);
            }
        }
    }
}

/// A member's estimate from its candidates, summed in the order and with the rounding of
/// [`shade::shade`].
fn reduce(layout: Layout, candidates: &[Candidate], value: &mut impl FnMut(&Candidate) -> DVec3) -> DVec3 {
    let mut sum = DVec3::ZERO;
    match layout {
        Layout::Single { n, .. } => {
            candidates.iter().for_each(|c| sum += value(c));
            sum / n as f64
        }
        Layout::Pairs { n } => {
            for pair in candidates.chunks(2) {
                let (a, b) = (value(&pair[0]), value(&pair[1]));
                sum += a + b;
            }
            sum / n as f64
        }
        Layout::Split { first, brdf } => {
            candidates.iter().for_each(|c| sum += value(c));
            sum / (first + brdf) as f64
        }
    }
}
