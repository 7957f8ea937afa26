//! `auto`'s choice of strategy per material, checked on the scene: a pilot render of a few of
//! each material's pixels with every candidate plan, twice with independent samples, at a
//! quarter of the render's shading points where no candidate builds a product sampler
//! ([`PILOT_SHADING_POINT_DIVISOR`]), each plan at its
//! equal-cost budget of samples per
//! shading point (`plan::candidates`: a plan that costs more per sample takes fewer, so that
//! no material's choice takes time from the others'), scored by variance × cost per shading
//! point — the variance from the pixel pairs' squared differences (relMSE's normalisation),
//! the cost a fixed per-sample weight per plan ([`PLANS`]), not the pilot's clock, so that the
//! choice, and the image, depend only on the scene, the settings and the seed. The pilot's samples are independent of the render's
//! (their own seeds), so choosing from them keeps every pixel's estimate unbiased.
//!
//! The pilot overrides the rules' plan ([`auto_strategy`](crate::plan::rules::auto_strategy))
//! only when another plan scores [`OVERRIDE_MARGIN`]× better, and by [`SEPARATION`] standard
//! errors of the pilot pixels' paired differences: a variance estimate from tens of pixel pairs
//! is dominated by its few brightest pixels and is good to tens of per cent at best, while an
//! env map whose light is unlike the scenes the rules were set on makes a plan win by several
//! times. Plain MIS, the baseline `auto` must never fall behind, replaces the rules' plan by
//! the margin alone. Where the rules' plan is not trusted, the best plan replaces it only
//! where it separates from plain MIS; otherwise MIS does.
//!
//! A pilot cannot see rare large samples it did not draw: BRDF sampling under a sun looks quiet
//! in a pilot that never hit the sun, and then leaves fireflies across the image. So only plans
//! whose sample weights are bounded for the material and lighting compete ([`eligible`]): the
//! MIS plans always (each sample is weighted against a technique that covers the light), env
//! sampling where B·cos is bounded (its weight is B·cos × the map's total power), BRDF sampling
//! where the lighting is (its weight is L × B·cos/p). Each MIS strategy competes with the
//! rules' split and plain MIS (1:1) only: the splits between differ by less than the pilot
//! can tell apart ([`OVERRIDE_MARGIN`]), and every candidate fewer leaves more pixels for the
//! others. Product-MIS and two-level-MIS compete on glossy lobes only: on a diffuse one env
//! sampling draws nearly the product, cheaper, and both products have lost on every diffuse
//! region measured under a sun (docs/perf.md, "The products against MIS at equal time"), so
//! measuring them there only adds to the pilot's cost.
//!
//! Nor can a pilot see the rare pixels where a plan fails. Env-only sampling fails where the
//! bright part of the map is hidden (in a shadow, the sky is lit only by the few samples that
//! miss the sun), and those few pixels carry most of the image's error: a pilot of a few dozen
//! pixels rarely holds one, so it finds env sampling better than it is. Env-only sampling
//! therefore replaces the rules' plan only where it scores [`OVERRIDE_MARGIN`]× better than
//! every plan with BRDF samples too (`plan::decision`; docs/perf.md, "`auto` and its pilot").

use crate::plan::candidates::at_equal_cost;
pub use crate::plan::candidates::{Candidate, PLANS};
use crate::plan::decision::{decide, score};
use crate::plan::method::strategy_name;
use crate::plan::rules::{SMOOTH_LIGHTING_PEAK, auto_env_share, product_share};
use crate::render::pixel::{Scratch, pixel};
use crate::render::strategy::{MaterialPlan, Strategy};
use crate::render::{Context, Options, budgets, two_level_cones};
use crate::scene::Bsdf;
use rayon::prelude::*;
use sampler_core::env::EnvHierarchy;
use sampler_core::points::permutation_element;
use sampler_core::rng::hash_combine;

/// How much better than the rule's plan a plan of no higher cost must score to replace it:
/// above the noise of a score from a few dozen pixel pairs where two plans are alike, below
/// the gaps that cost a render its equal-time error (docs/perf.md, "`auto` and its pilot").
pub const OVERRIDE_MARGIN: f64 = 1.25;

/// How much better than the rule's plan a costlier plan must score to replace it. The rules
/// give the costly product-MIS to the materials where it won the equal-time sweeps; elsewhere
/// it loses on every scene measured (docs/perf.md, "`auto` and its pilot"), and a pilot whose
/// few brightest pixels happened to favour it would spend the render's time where it does not pay.
pub const COSTLIER_OVERRIDE_MARGIN: f64 = 2.0;

/// Ratio of costs per sample from which a plan counts as costlier than the rule's for
/// [`COSTLIER_OVERRIDE_MARGIN`]: product-MIS (1.45× MIS and above) is, two-level-MIS (1.12×)
/// is not — its samples come from a sampler shared as product-MIS's is, and its score already
/// carries its cost.
pub const COSTLIER_FROM: f64 = 1.2;

/// Standard errors by which the rule's plan must score above another's for the other to replace
/// it (`plan::decision`): a one-sided test at about 2% per comparison, on the mean of the pilot
/// pixels' paired differences, so that a score led by a few bright pixels does not decide.
pub const SEPARATION: f64 = 2.0;

/// Share of the render's work (in MIS pixels, the candidates weighted by their cost) the pilot
/// aims to spend, both repetitions of every candidate. A larger pilot costs more than its
/// better choices gain where the rules' plan stands.
pub const PILOT_SHARE: f64 = 0.02;

/// The most the pilot may spend: with fewer than [`MIN_PIXELS`] per material within that, the
/// rules decide alone.
pub const MAX_PILOT_SHARE: f64 = 0.05;

/// Pilot pixels per material, at least: fewer and the scores are noise (the plan changes with
/// the seed).
pub const MIN_PIXELS: usize = 32;

/// Pilot pixels per material, at most: more and the pilot costs too much.
pub const MAX_PIXELS: usize = 64;

/// Largest BRDF × cos peak (per steradian) for which env-only sampling may compete: GGX α ≥
/// 0.14, Phong n ≤ 98 (Lambert: 1/π).
const ENV_ONLY_LOBE_PEAK: f32 = 16.0;

/// A pilot pixel takes 1/this of a render pixel's shading points (at the render's samples per
/// shading point): every plan's variance grows alike, so their scores keep their order, while
/// the pilot's budget buys this many times the pixels — and the pixels, each lit its own way,
/// are what a score's noise comes from.
pub const PILOT_SHADING_POINT_DIVISOR: usize = 4;

/// Shading points of a pilot pixel, at least (the render's, where it has fewer).
const MIN_PILOT_SHADING_POINTS: usize = 4;

/// Pixels looked at (centre rays) to find each material's pilot pixels.
pub(crate) const MAX_SCANNED: usize = 1 << 14;

/// What the pilot measured for one material.
#[derive(Clone, Debug)]
pub struct PilotResult {
    /// The material.
    pub material: usize,
    /// Pilot pixels (each rendered twice per candidate).
    pub pixels: usize,
    /// Per candidate of [`PLANS`]: relative variance × cost per shading point (`None`: not measured or not
    /// trusted — its pilot mean disagrees with the others', the sign of rare large samples it
    /// missed).
    pub scores: Vec<Option<f64>>,
    /// The index into [`PLANS`] chosen.
    pub chosen: usize,
    /// The rules' plan, if it is one of [`PLANS`].
    pub rule: Option<usize>,
}

/// Whether candidate `c` of [`PLANS`] may compete on `bsdf` under a map of peak `env_peak`
/// (`EnvHierarchy::peak(5)`): see the module's note.
#[must_use]
pub fn eligible(c: usize, bsdf: &Bsdf, env_peak: f32) -> bool {
    match PLANS[c].strategy {
        Strategy::Env => {
            // B·cos's peak scale: 1/π diffuse, 1/(πw²) for a lobe of width w — GGX's D at its
            // centre for α = w, Phong's (n+2)/2π for w = √(2/(n+2)).
            let brdf = bsdf.as_brdf();
            let w = brdf.lobe_width();
            let peak =
                if brdf.is_diffuse() { std::f32::consts::FRAC_1_PI } else { 1.0 / (std::f32::consts::PI * w * w) };
            peak <= ENV_ONLY_LOBE_PEAK
        }
        Strategy::Brdf => env_peak < SMOOTH_LIGHTING_PEAK,
        Strategy::Mis { env_share } => env_share == auto_env_share(bsdf, env_peak) || env_share == 0.5,
        Strategy::ProductMis { product_share: share } => {
            !bsdf.as_brdf().is_diffuse() && share == product_share(bsdf, env_peak)
        }
        Strategy::TwoLevelMis { .. } => !bsdf.as_brdf().is_diffuse(),
        Strategy::Product
        | Strategy::Wavelet
        | Strategy::Ris
        | Strategy::TwoStage
        | Strategy::TwoLevel
        | Strategy::Sis
        | Strategy::PlaneProduct
        | Strategy::Lightcuts => false,
    }
}

/// One material's pilot: its candidates' pixel pairs, per candidate (index into [`PLANS`]).
type Measured = Vec<(usize, Vec<[[f64; 3]; 2]>)>;

/// What the pilot chose and what it took.
pub(crate) struct Choice {
    /// One plan per material: the rules' where a material has too few pixels to measure.
    pub plans: Vec<MaterialPlan>,
    /// What was measured, per material measured.
    pub results: Vec<PilotResult>,
    /// The pilot's work in pixels of the render under MIS, by [`PLANS`]' weights.
    pub cost: f64,
}

/// Runs the pilot on the render `ctx` (whose plans are the rules') over each material's
/// `scanned` pixels ([`material_pixels`]).
pub(crate) fn choose(
    ctx: &Context<'_, '_>,
    env: &EnvHierarchy<'_>,
    env_peak: f32,
    scanned: &[Vec<(usize, usize)>],
) -> Choice {
    let defaults = ctx.plans;
    let Some(Tasks { pixels: found, tasks, cost }) = pilot_tasks(ctx, env_peak, scanned) else {
        return Choice { plans: defaults.to_vec(), results: Vec::new(), cost: 0.0 };
    };
    // The two-level candidates read the cell cones, which the rules' plans do not build.
    let env_budget = budgets(ctx).0;
    let plan =
        |m: usize, c: usize| at_equal_cost(MaterialPlan { strategy: PLANS[c].strategy, ..defaults[m] }, env_budget);
    let candidates: Vec<MaterialPlan> = tasks.iter().map(|&(m, c)| plan(m, c)).collect();
    let extended = env_peak < super::rules::SUN_PEAK;
    let cones = if ctx.cones.is_none() { two_level_cones(env, &candidates, extended) } else { None };
    let ctx = &Context { cones: ctx.cones.or(cones.as_ref()), ..*ctx };
    let mut measured: Vec<Measured> = vec![Vec::new(); found.len()];
    for ((m, c), v) in tasks.iter().zip(measure(ctx, env, &found, &tasks)) {
        measured[*m].push((*c, v));
    }
    let mut plans = defaults.to_vec();
    let mut results = Vec::new();
    for (m, pixels) in found.iter().enumerate() {
        if measured[m].is_empty() {
            continue;
        }
        let pairs: Vec<(usize, &[[[f64; 3]; 2]])> = measured[m].iter().map(|(c, v)| (*c, v.as_slice())).collect();
        let scores = score(&pairs, pixels.len(), env_budget);
        let rule = PLANS.iter().position(|p| p.strategy == defaults[m].strategy);
        let Some(chosen) = decide(&scores, rule) else { continue };
        plans[m] = plan(m, chosen);
        let scores = scores.iter().map(|s| s.as_ref().map(|s| s.value)).collect();
        results.push(PilotResult { material: m, pixels: pixels.len(), scores, chosen, rule });
    }
    Choice { plans, results, cost }
}

/// Each material's pixels among up to [`MAX_SCANNED`] of the image's (their centre rays' hits),
/// in a fixed pseudo-random order over the image: the pilot's pixels, and the materials'
/// shares of the image.
pub(crate) fn material_pixels(ctx: &Context<'_, '_>) -> Vec<Vec<(usize, usize)>> {
    let camera = ctx.camera;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut found: Vec<Vec<(usize, usize)>> = vec![Vec::new(); ctx.scene.materials.len()];
    let n = w * h;
    let order_seed = hash_combine(ctx.options.seed, 0x9170) as u32;
    for k in 0..n.min(MAX_SCANNED) {
        let i = permutation_element(k as u32, n as u32, order_seed) as usize;
        let (x, y) = (i % w, i / w);
        let d = camera.direction(x as f32 + 0.5, y as f32 + 0.5);
        let hit = ctx.bvh.intersect(camera.origin, d, camera.near_clip, f32::INFINITY);
        if let Some(material) = hit.and_then(|hit| hit.surface.material()) {
            found[material].push((x, y));
        }
    }
    found
}

/// What the pilot renders.
struct Tasks {
    /// Each material's pilot pixels.
    pixels: Vec<Vec<(usize, usize)>>,
    /// Every (material, candidate) to measure.
    tasks: Vec<(usize, usize)>,
    /// Their work in pixels of the render under MIS.
    cost: f64,
}

/// The pilot's [`Tasks`] over each material's `scanned` pixels (the first of them); `None` when
/// the pilot would cost more than [`MAX_PILOT_SHARE`] of the render.
fn pilot_tasks(ctx: &Context<'_, '_>, env_peak: f32, scanned: &[Vec<(usize, usize)>]) -> Option<Tasks> {
    let (w, h) = (ctx.camera.width as usize, ctx.camera.height as usize);
    let materials = ctx.scene.materials.len();
    let n = w * h;
    // Every (material, candidate) to measure, and the cost of one pilot pixel of all of them,
    // twice.
    let v = samples_per_point(ctx.options);
    let tasks: Vec<(usize, usize)> = (0..materials)
        .filter(|&m| scanned[m].len() >= MIN_PIXELS && ctx.plans[m].strategy != Strategy::PlaneProduct)
        .flat_map(|m| {
            let bsdf = &ctx.scene.materials[m].bsdf;
            (0..PLANS.len()).filter(move |&c| eligible(c, bsdf, env_peak)).map(move |c| (m, c))
        })
        .collect();
    let pilot = pilot_options(ctx.options, &tasks);
    let share = pilot.shading_points as f64 / ctx.options.shading_points.max(1) as f64;
    let cost_per_pixel: f64 = tasks.iter().map(|&(_, c)| 2.0 * PLANS[c].cost_per_point(v) * share).sum();
    let per_material = ((PILOT_SHARE * n as f64 / cost_per_pixel.max(1.0)) as usize).clamp(MIN_PIXELS, MAX_PIXELS);
    if per_material as f64 * cost_per_pixel > MAX_PILOT_SHARE * n as f64 {
        return None;
    }
    let pixels = scanned.iter().map(|f| f[..f.len().min(per_material)].to_vec()).collect();
    Some(Tasks { pixels, tasks, cost: per_material as f64 * cost_per_pixel })
}

/// Renders every task's pixels twice, in parallel, and returns per task its pixel pairs, in a
/// fixed order whatever the thread count (truncating keeps every measured material at ≥
/// [`MIN_PIXELS`]). One job per (task, pixel), so that the threads share the work evenly.
fn measure(
    ctx: &Context<'_, '_>,
    env: &EnvHierarchy<'_>,
    found: &[Vec<(usize, usize)>],
    tasks: &[(usize, usize)],
) -> Vec<Vec<[[f64; 3]; 2]>> {
    let env_budget = budgets(ctx).0;
    let jobs: Vec<(usize, (usize, usize))> =
        tasks.iter().enumerate().flat_map(|(t, &(m, _))| found[m].iter().map(move |&p| (t, p))).collect();
    let rendered: Vec<[[f64; 3]; 2]> = jobs
        .par_iter()
        .map(|&(t, (x, y))| {
            let (m, c) = tasks[t];
            let mut plans: Vec<MaterialPlan> = ctx.plans.to_vec();
            plans[m] = at_equal_cost(MaterialPlan { strategy: PLANS[c].strategy, ..ctx.plans[m] }, env_budget);
            [0u64, 1].map(|rep| {
                let options = Options {
                    seed: hash_combine(ctx.options.seed, 0x9170_0000 + rep),
                    ..pilot_options(ctx.options, tasks)
                };
                let job = Context { env: Some(env), options: &options, plans: &plans, ..*ctx };
                // A fresh scratch: no product sampler carried over from another pixel or
                // repetition (that would correlate the pair).
                let mut scratch = Scratch::new(plans.len(), options.shading_points);
                pixel(&job, x, y, &mut scratch).map(f64::from)
            })
        })
        .collect();
    let mut values: Vec<Vec<[[f64; 3]; 2]>> = vec![Vec::new(); tasks.len()];
    for ((t, _), v) in jobs.iter().zip(rendered) {
        values[*t].push(v);
    }
    values
}

/// How a pilot pixel of a render of `options` is sampled: [`PILOT_SHADING_POINT_DIVISOR`]
/// times fewer shading points (at least [`MIN_PILOT_SHADING_POINTS`]), as many samples each —
/// unless a task measures product-MIS, whose sampler a pilot pixel builds afresh (the image's
/// serves a pixel and its neighbours): fewer shading points would not amortise that build,
/// and the pilot would cost more than its share. Then the render's own shading points.
fn pilot_options(options: &Options, tasks: &[(usize, usize)]) -> Options {
    let p = options.shading_points.max(1);
    let builds = tasks.iter().any(|&(_, c)| matches!(PLANS[c].strategy, Strategy::ProductMis { .. }));
    let divisor = if builds { 1 } else { PILOT_SHADING_POINT_DIVISOR };
    let shading_points = (p / divisor).max(MIN_PILOT_SHADING_POINTS).min(p);
    Options { spp: samples_per_point(options) * shading_points, shading_points, ..*options }
}

/// Light samples per shading point of a render of `options`.
fn samples_per_point(options: &Options) -> usize {
    options.spp / options.shading_points.max(1)
}

/// A candidate's name: the method, and its split where it is not half and half
/// ("mis 3:1" — three env samples to one BRDF sample; "product-mis 3:1").
#[must_use]
pub fn plan_name(candidate: usize) -> String {
    strategy_name(PLANS[candidate].strategy)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn plain_mis_competes_beside_the_rules_split() {
        use sampler_core::brdf::{Lambert, RoughConductor};
        use sampler_core::glam::Vec3;
        let mis = |share: f64| PLANS.iter().position(|p| p.strategy == Strategy::Mis { env_share: share }).unwrap();
        let diffuse = Bsdf::Diffuse(Lambert::new(Vec3::ONE));
        // Extended light: the rules lean on env samples, and plain MIS competes too.
        assert!(eligible(mis(0.75), &diffuse, 21.0) && eligible(mis(0.5), &diffuse, 21.0));
        // Under a sun, and on glossy lobes, the rules' split is plain MIS.
        assert!(!eligible(mis(0.75), &diffuse, 713.0) && eligible(mis(0.5), &diffuse, 713.0));
        let glossy = Bsdf::Conductor(RoughConductor::new(0.01, Vec3::ONE));
        assert!(!eligible(mis(0.75), &glossy, 21.0) && eligible(mis(0.5), &glossy, 21.0));
    }
}
