//! Direct illumination from the environment at one shading point, by each strategy, with the
//! same budget: `budget` visibility samples (shadow rays) per shading point. MIS in pairs spends
//! them one per technique, so it takes ⌊budget/2⌋ pairs (at least one).

use crate::render::wavefront::{split_counts, split_shares};
use sampler_core::brdf::Brdf;
use sampler_core::direction::DirectionSampler;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::{self, BATCH, Contribution, ShadingPoint, Visibility};
use sampler_core::glam::{DVec2, DVec3, Vec2, Vec3};
use sampler_core::points::sobol02;
use sampler_core::rng::hash_combine;
use sampler_core::sampler::ProductSampler;
use sampler_core::sis::Stratum;
use sampler_core::two_level::TwoLevelSampler;
use sampler_core::two_stage::TwoStageSampler;

/// Candidates per RIS estimate (each costs an env or BRDF sample and an evaluation, no ray).
pub const RIS_CANDIDATES: usize = 8;

/// Counts the shadow rays a visibility closure traces.
pub struct CountingVisibility<F: FnMut(Vec3) -> bool> {
    /// Whether the light is visible in a direction.
    pub test: F,
    /// Directions tested so far.
    pub rays: u64,
}

impl<F: FnMut(Vec3) -> bool> Visibility for CountingVisibility<F> {
    fn visible(&mut self, dir: Vec3) -> bool {
        self.rays += 1;
        (self.test)(dir)
    }
}

/// What a shading point samples the light with: its strategy, holding the sampler the strategy
/// needs, built. A product sampler or two-stage partition may have been built for another
/// shading point of the same pixel and material (still unbiased: it is a valid density that is
/// positive wherever L > 0).
// The two-stage partition makes one variant large; a `Sampling` lives on the stack for one
// group of shading points, and boxing it would allocate per shading point.
#[allow(clippy::large_enum_variant)]
pub enum Sampling<'s, 'e> {
    /// Env samples only.
    Env,
    /// BRDF samples only.
    Brdf,
    /// MIS of env and BRDF samples (see [`Strategy::Mis`](crate::render::strategy::Strategy::Mis)).
    Mis {
        /// Share of the budget spent on env samples; ½ spends it in pairs.
        env_share: f64,
        /// The environment's view the env samples draw from: its MIS-compensated density
        /// ([`EnvHierarchy::compensated`]).
        sampler: EnvHierarchy<'e>,
    },
    /// Resampled importance sampling.
    Ris,
    /// Product samples (quadtree or wavelet product), the paper's estimator.
    Product(ProductSampler<'s, 'e>),
    /// MIS of product and BRDF samples.
    ProductMis {
        /// The product sampler, possibly shared with other shading points.
        sampler: ProductSampler<'s, 'e>,
        /// Share of the budget spent on product samples.
        product_share: f64,
    },
    /// Two-stage importance sampling through its partition.
    TwoStage(TwoStageSampler<'s, 'e>),
    /// The two-level product, built for this shading point.
    TwoLevel(TwoLevelSampler<'s, 'e>),
    /// MIS of the two-level product and BRDF samples.
    TwoLevelMis {
        /// The two-level sampler.
        sampler: TwoLevelSampler<'s, 'e>,
        /// Share of the budget spent on two-level samples; ½ spends it in pairs.
        two_level_share: f64,
    },
    /// Structured importance sampling: every stratum, as a directional light.
    Sis(&'s [Stratum]),
}

/// Where a shading point's samples come from: the pixel's light-sample seed, and the block of
/// the pixel's sequences this shading point takes (the pixel's shading points together draw one
/// (0,2)-net per technique, stratified over the whole pixel, not per point).
#[derive(Clone, Copy, Debug)]
pub struct Run {
    /// The seed of the pixel's light-sample sequences.
    pub seed: u64,
    /// This shading point's block of them.
    pub block: usize,
}

/// Mean radiance reflected towards `sp.wo` by direct environment light, from `budget`
/// visibility samples drawn as `sampling` says. The MIS strategies with a split spend their
/// share of the budget on their first technique (product or env samples) and the rest on BRDF
/// samples (at least one of each).
pub fn shade<B: Brdf + ?Sized>(
    sampling: &Sampling<'_, '_>,
    env: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    budget: usize,
    run: Run,
    vis: &mut impl Visibility,
) -> DVec3 {
    let budget = budget.max(1);
    match sampling {
        Sampling::ProductMis { sampler, product_share } => shade_split(sampler, sp, budget, *product_share, run, vis),
        Sampling::Mis { env_share, sampler } if *env_share != 0.5 => {
            shade_split(sampler, sp, budget, *env_share, run, vis)
        }
        Sampling::TwoLevelMis { sampler, two_level_share } if *two_level_share != 0.5 => {
            shade_split(sampler, sp, budget, *two_level_share, run, vis)
        }
        Sampling::TwoLevelMis { sampler, .. } => sampled_pairs(sampler, sp, (budget / 2).max(1), run, vis),
        Sampling::TwoLevel(sampler) => sampled_only(sampler, sp, budget, run, vis),
        Sampling::Mis { sampler, .. } => sampled_pairs(sampler, sp, (budget / 2).max(1), run, vis),
        Sampling::Env => sampled_only(env, sp, budget, run, vis),
        Sampling::Brdf => brdf_only(env, sp, budget, run, vis),
        Sampling::Ris => ris(env, sp, budget, run, vis),
        Sampling::Product(sampler) => sampled_only(sampler, sp, budget, run, vis),
        Sampling::TwoStage(sampler) => sampled_only(sampler, sp, budget, run, vis),
        Sampling::Sis(strata) => strata_sum(strata, sp, vis),
    }
}

/// Structured importance sampling's estimate: the sum over the strata of BRDF × cosine ×
/// visibility in the stratum's direction × its irradiance, whatever the budget (one shadow ray
/// per stratum the surface can reflect).
fn strata_sum<B: Brdf + ?Sized>(strata: &[Stratum], sp: &ShadingPoint<'_, B>, vis: &mut impl Visibility) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for s in strata {
        let f = sp.eval(s.dir).as_dvec3() * s.irradiance;
        if f.cmpgt(DVec3::ZERO).any() && f.is_finite() && vis.visible(s.dir) {
            sum += f;
        }
    }
    sum
}

/// The mean of `n` samples of one technique: `batch` gets each batch of this shading point's
/// run of the pixel's (0,2)-sequence, the run's first index and the batch's offset in it, and
/// adds the batch's values to the sum in order. Batches are a power of two long, which keeps
/// each one a (0,2)-net.
fn batched(n: usize, run: Run, mut batch: impl FnMut(&[DVec2], u32, usize, &mut DVec3)) -> DVec3 {
    let first = (run.block * n) as u32;
    let mut points = [DVec2::ZERO; BATCH];
    let mut sum = DVec3::ZERO;
    let mut done = 0;
    while done < n {
        let m = (n - done).min(BATCH);
        sobol02(hash_combine(run.seed, 1), first + done as u32, &mut points[..m]);
        batch(&points[..m], first, done, &mut sum);
        done += m;
    }
    sum / n as f64
}

/// `points` as the f32 points the BRDF samplers take.
fn brdf_points(points: &[DVec2]) -> [Vec2; BATCH] {
    let mut out = [Vec2::ZERO; BATCH];
    for (b, p) in out.iter_mut().zip(points) {
        *b = p.as_vec2();
    }
    out
}

/// BRDF samples only.
fn brdf_only<B: Brdf + ?Sized>(
    env: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    n: usize,
    run: Run,
    vis: &mut impl Visibility,
) -> DVec3 {
    let mut singles = [Contribution::default(); BATCH];
    batched(n, run, |points, _, _, sum| {
        let m = points.len();
        let brdf = brdf_points(points);
        estimator::brdf_many(env, sp, &brdf[..m], vis, &mut singles[..m]);
        for s in &singles[..m] {
            *sum += s.value;
        }
    })
}

/// Resampled importance sampling: per sample, [`RIS_CANDIDATES`] candidates from their own
/// sequence, one chosen by the sample's point.
fn ris<B: Brdf + ?Sized>(
    env: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    n: usize,
    run: Run,
    vis: &mut impl Visibility,
) -> DVec3 {
    batched(n, run, |points, first, done, sum| {
        for (k, u) in points.iter().enumerate() {
            let mut candidates = [DVec2::ZERO; RIS_CANDIDATES];
            sobol02(hash_combine(run.seed, 3 + first as u64 + (done + k) as u64), 0, &mut candidates);
            *sum += estimator::ris(env, sp, &candidates, u.x, vis).value;
        }
    })
}

/// Samples of one sampler of the environment (a product, two-stage), each batch drawn together.
fn sampled_only<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    n: usize,
    run: Run,
    vis: &mut impl Visibility,
) -> DVec3 {
    let mut drawn = [None; BATCH];
    batched(n, run, |points, _, _, sum| {
        let m = points.len();
        sampler.sample_many(points, &mut drawn[..m]);
        for d in &drawn[..m] {
            *sum += estimator::sampled_drawn(sampler, sp, *d, vis).value;
        }
    })
}

/// MIS of a sampler of the environment and BRDF samples in `n` pairs, each batch drawn
/// together.
fn sampled_pairs<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    sampler: &S,
    sp: &ShadingPoint<'_, B>,
    n: usize,
    run: Run,
    vis: &mut impl Visibility,
) -> DVec3 {
    let mut others = [DVec2::ZERO; BATCH];
    let mut pairs = [[Contribution::default(); 2]; BATCH];
    batched(n, run, |points, first, done, sum| {
        let m = points.len();
        sobol02(hash_combine(run.seed, 2), first + done as u32, &mut others[..m]);
        let brdf = brdf_points(&others[..m]);
        estimator::sampled_mis_many(sampler, sp, points, &brdf[..m], vis, &mut pairs[..m]);
        for pair in &pairs[..m] {
            *sum += pair[0].value + pair[1].value;
        }
    })
}

/// MIS at one shading point with the budget split: ⌊share·budget⌉ samples of `first` and the
/// rest BRDF samples (at least one of each; a budget of one still takes one of each), each
/// technique's points this shading point's run of the pixel's (0,2)-sequence for it.
fn shade_split<S: DirectionSampler + ?Sized, B: Brdf + ?Sized>(
    first: &S,
    sp: &ShadingPoint<'_, B>,
    budget: usize,
    share: f64,
    run: Run,
    vis: &mut impl Visibility,
) -> DVec3 {
    let Run { seed, block } = run;
    let (n_p, n_b) = split_counts(budget, share);
    let total = (n_p + n_b) as f64;
    let shares = split_shares(n_p, n_b);
    let mut sum = DVec3::ZERO;
    let (mut done_p, mut done_b) = (0, 0);
    let mut first_points = [DVec2::ZERO; BATCH];
    let mut brdf_points = [DVec2::ZERO; BATCH];
    let mut brdf_points_f32 = [Vec2::ZERO; BATCH];
    // Batches of each technique's points (a power of two keeps each batch a net).
    while done_p < n_p || done_b < n_b {
        let (m_p, m_b) = ((n_p - done_p).min(BATCH), (n_b - done_b).min(BATCH));
        sobol02(hash_combine(seed, 1), (block * n_p + done_p) as u32, &mut first_points[..m_p]);
        sobol02(hash_combine(seed, 2), (block * n_b + done_b) as u32, &mut brdf_points[..m_b]);
        for (b, o) in brdf_points_f32.iter_mut().zip(&brdf_points[..m_b]) {
            *b = o.as_vec2();
        }
        let (u_p, u_b) = (&first_points[..m_p], &brdf_points_f32[..m_b]);
        sum += estimator::sampled_mis_split(first, sp, u_p, u_b, shares, vis);
        (done_p, done_b) = (done_p + m_p, done_b + m_b);
    }
    sum / total
}
