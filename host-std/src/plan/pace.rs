//! `auto`'s budgets for the materials whose plan costs no more than plain MIS: more samples where
//! the other materials' plans make the image costlier, so that those materials do not fall
//! behind MIS at equal time.
//!
//! `auto` compares with MIS over the whole image's time. A material whose plan costs more per
//! shading point than MIS's (a product, the plane product with its pyramid's build, MIS 3:1 or
//! env-only sampling, whose env samples cost more than BRDF samples) takes time from every other
//! pixel, and so does the pilot: where another material's plan is plain MIS, that material has
//! MIS's error at MIS's samples but the costlier image's time, and falls behind MIS at equal
//! time by the image's cost over MIS's (docs/perf.md, "The products against MIS at equal
//! time"). With the cheap materials at `k` × their samples, the costly ones at a mean time `c̄`
//! per shading point (MIS's 1) and the pilot's time `o`, a cheap material's error at the image's
//! time is `(f k + (1 − f) c̄ + o) / k` of MIS's, `f` the cheap materials' share of the shading
//! points: `k = c̄ + o / (1 − f)` brings it to MIS's. That slows the image little where the cheap
//! materials are few and too much where they hold most of it, so the budgets are paced only
//! while the image slows by at most [`MAX_SLOWDOWN`]. The times are a fixed model
//! ([`time_per_point`]) and the shares the centre rays' hits, so that the budgets, and the
//! image, depend only on the scene, the settings and the seed.

use crate::plan::carrier::POINT_COST;
use crate::plan::pilot::{self, MAX_SCANNED, PilotResult};
use crate::plan::time_model::{PLANE_BUILD_COST, time_per_point};
use crate::render::strategy::{MaterialPlan, Strategy};
use crate::render::{Context, budgets};
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::BATCH;

/// The most the cheap materials' extra samples may slow the image, by the time model: each
/// costlier material's lead over MIS at equal time shrinks by as much.
pub const MAX_SLOWDOWN: f64 = 1.05;

/// `auto`'s plans for the render `ctx` (whose plans are the rules'): the pilot's choice
/// ([`pilot::choose`]), the cheap materials paced ([`keep_pace`]); and what the pilot measured.
pub(crate) fn auto_plans(
    ctx: &Context<'_, '_>,
    env: &EnvHierarchy<'_>,
    env_peak: f32,
) -> (Vec<MaterialPlan>, Vec<PilotResult>) {
    let scanned = pilot::material_pixels(ctx);
    let choice = pilot::choose(ctx, env, env_peak, &scanned);
    let hits: Vec<usize> = scanned.iter().map(Vec::len).collect();
    let fixed = FixedCosts::of(ctx, env, &choice.plans, &hits, choice.cost);
    (keep_pace(&choice.plans, &hits, budgets(ctx).0, fixed), choice.results)
}

/// Work a render does once, each as a share of MIS's time for the pixels it is spread over.
#[derive(Clone, Copy, Debug, Default)]
pub struct FixedCosts {
    /// The plane pyramids' build, over the plane product's pixels (part of its cost).
    pub plane_build: f64,
    /// The pilot's renders, over every pixel that meets a surface.
    pub pilot: f64,
}

impl FixedCosts {
    /// The fixed costs of the render `ctx` under `plans`, from each material's `hits` among the
    /// scanned pixels and the pilot's work (`pilot`, in pixels of the render under MIS). Each
    /// plane normal's pyramid is counted once (one side of a plane is seen; a room's opposite
    /// walls build both sides and count one).
    fn of(ctx: &Context<'_, '_>, env: &EnvHierarchy<'_>, plans: &[MaterialPlan], hits: &[usize], pilot: f64) -> Self {
        let frame = ctx.camera.width as usize * ctx.camera.height as usize;
        let to_frame = frame as f64 / frame.clamp(1, MAX_SCANNED) as f64;
        let v = budgets(ctx).0.max(1) as f64;
        // MIS's time for a pixel, in MIS samples: its shading points' own part and samples.
        let mis_pixel = ctx.options.shading_points.max(1) as f64 * (POINT_COST + v);
        let on_planes: usize =
            plans.iter().zip(hits).filter(|(p, _)| p.strategy == Strategy::PlaneProduct).map(|(_, &n)| n).sum();
        let build = ctx
            .planes
            .map_or(0.0, |p| p.len().div_ceil(2) as f64 * (1u64 << (2 * env.finest_level())) as f64 * PLANE_BUILD_COST);
        let share = |work: f64, pixels: usize| {
            let time = pixels as f64 * to_frame * mis_pixel;
            if time > 0.0 { work / time } else { 0.0 }
        };
        let all: usize = hits.iter().sum();
        Self { plane_build: share(build, on_planes), pilot: share(pilot * mis_pixel, all) }
    }
}

/// `plans` with each plan that costs no more than MIS per shading point at `samples_per_point`
/// samples given as many more as keep it level with MIS at the image's time (the module's `k`),
/// rounded up to a whole budget the wavefront draws in one batch — unless the budgets so paced slow the
/// image by more than [`MAX_SLOWDOWN`]. `hits` holds each material's hits among the scanned
/// pixels. The costlier plans are unchanged.
#[must_use]
pub fn keep_pace(
    plans: &[MaterialPlan],
    hits: &[usize],
    samples_per_point: usize,
    fixed: FixedCosts,
) -> Vec<MaterialPlan> {
    let v = samples_per_point.max(1);
    let times = |plans: &[MaterialPlan]| -> Vec<f64> {
        let time = |p: &MaterialPlan| {
            let build = if p.strategy == Strategy::PlaneProduct { fixed.plane_build } else { 0.0 };
            time_per_point(p.strategy, p.env_budget.unwrap_or(v), v) + build
        };
        plans.iter().map(time).collect()
    };
    let before = times(plans);
    let Some(k) = pace(&before, hits, fixed.pilot) else { return plans.to_vec() };
    let paced: Vec<MaterialPlan> = plans
        .iter()
        .zip(&before)
        .map(
            |(p, &t)| {
                if t > 1.0 { *p } else { MaterialPlan { env_budget: Some(paced_budget(p.strategy, v, k)), ..*p } }
            },
        )
        .collect();
    // The image's time, by the model, relative to MIS's.
    let image = |times: &[f64]| {
        let all: usize = hits.iter().sum();
        let shading: f64 = times.iter().zip(hits).map(|(t, &n)| t * n as f64).sum();
        shading / all.max(1) as f64 + fixed.pilot
    };
    if image(&times(&paced)) > MAX_SLOWDOWN * image(&before) { plans.to_vec() } else { paced }
}

/// The factor on the cheap plans' samples from each material's time per shading point
/// (`times`, MIS's 1), its `hits`, and the pilot's time (`pilot`, a share of MIS's for the
/// image): `None` where no plan costs more than MIS.
fn pace(times: &[f64], hits: &[usize], pilot: f64) -> Option<f64> {
    let (mut all, mut costly, mut time) = (0.0, 0.0, 0.0);
    for (&t, &n) in times.iter().zip(hits) {
        all += n as f64;
        if t > 1.0 {
            (costly, time) = (costly + n as f64, time + n as f64 * t);
        }
    }
    (costly > 0.0).then(|| time / costly + pilot * all / costly)
}

/// At least `k` × `v` samples, rounded up to what `strategy` spends whole (pairs for plain MIS),
/// at most what the wavefront draws in one batch (and never fewer than `v`).
fn paced_budget(strategy: Strategy, v: usize, k: f64) -> usize {
    let whole = match strategy {
        Strategy::Mis { env_share: 0.5 } => 2,
        _ => 1,
    };
    // The guard keeps a product that rounds above a whole number (10 × 1.1) from counting as
    // the next one.
    let b = (v as f64 * k / whole as f64 - 1e-9).ceil() as usize * whole;
    b.min(BATCH * whole).max(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(strategy: Strategy, env_budget: Option<usize>) -> MaterialPlan {
        MaterialPlan { strategy, reuse_cosine: 1.0, brdf_samples: 16, env_budget }
    }

    fn budgets(plans: &[MaterialPlan]) -> Vec<Option<usize>> {
        plans.iter().map(|p| p.env_budget).collect()
    }

    const MIS: Strategy = Strategy::Mis { env_share: 0.5 };
    const TWO_LEVEL: Strategy = Strategy::TwoLevelMis { two_level_share: 0.5 };

    #[test]
    fn cheap_plans_keep_pace_with_the_costly_ones_and_nothing_else_moves() {
        let (mis, brdf, plane) =
            (plan(MIS, Some(8)), plan(Strategy::Brdf, Some(8)), plan(Strategy::PlaneProduct, None));
        // Without a costlier plan nothing changes.
        let cheap = [mis, brdf];
        assert_eq!(budgets(&keep_pace(&cheap, &[10, 90], 8, FixedCosts::default())), budgets(&cheap));
        // A plane product on nine tenths of the pixels: the cheap plans take its time in
        // samples, its pyramid's build included.
        let paced =
            |build: f64| keep_pace(&[mis, brdf, plane], &[5, 5, 90], 8, FixedCosts { plane_build: build, pilot: 0.0 });
        for build in [0.0, 0.2] {
            let k = time_per_point(Strategy::PlaneProduct, 8, 8) + build;
            let p = paced(build);
            assert_eq!(p[1].env_budget, Some((8.0 * k).ceil() as usize), "{build}");
            assert_eq!(p[0].env_budget, Some(2 * (4.0 * k).ceil() as usize), "MIS pairs stay whole");
            assert_eq!((p[2].strategy, p[2].env_budget), (plane.strategy, plane.env_budget));
        }
        assert_ne!(paced(0.0)[1].env_budget, paced(0.2)[1].env_budget, "the build counts");
    }

    #[test]
    fn the_pilot_s_time_is_made_up_over_the_costly_share() {
        // A tenth cheap at MIS's time, the rest at 1.3, the pilot 3% of MIS's time.
        let k = pace(&[1.0, 1.3], &[10, 90], 0.03).unwrap();
        assert!((k - (1.3 + 0.03 / 0.9)).abs() < 1e-12, "{k}");
        assert_eq!(pace(&[1.0, 0.8], &[50, 50], 0.03), None, "nothing costlier than MIS");
        // A material without hits weighs nothing.
        assert_eq!(pace(&[1.0, 1.3, 2.0], &[10, 90, 0], 0.0), Some(1.3));
    }

    #[test]
    fn pacing_stops_where_the_rounded_budgets_slow_the_image_too_much() {
        // Two-level-MIS at four samples per point costs ~1.59× MIS; plain MIS's four samples
        // become eight. With a tenth of the image cheap the image slows by ~1.04, with 12% by
        // just over 1.05 (the unrounded k would pass there).
        let (mis, two_level) = (plan(MIS, Some(4)), plan(TWO_LEVEL, Some(4)));
        let at = |cheap: usize| keep_pace(&[mis, two_level], &[cheap, 100 - cheap], 4, FixedCosts::default());
        assert_eq!(at(10)[0].env_budget, Some(8));
        assert_eq!(at(12)[0].env_budget, Some(4));
        let t = time_per_point(TWO_LEVEL, 4, 4);
        let (before, rounded) = (0.12 + 0.88 * t, 0.12 * time_per_point(MIS, 8, 4) + 0.88 * t);
        assert!(rounded / before > MAX_SLOWDOWN && (0.12 * t + 0.88 * t) / before < MAX_SLOWDOWN);
    }

    #[test]
    fn budgets_round_up_to_whole_batches_and_never_fall() {
        assert_eq!(paced_budget(Strategy::Brdf, 10, 1.1), 11, "10 × 1.1 is 11, not 12");
        assert_eq!(paced_budget(MIS, 4, 1.26), 6);
        assert_eq!(paced_budget(Strategy::Brdf, 12, 1.5), BATCH, "one batch at most");
        assert_eq!(paced_budget(MIS, 24, 1.5), 2 * BATCH);
        assert_eq!(paced_budget(Strategy::Brdf, 20, 1.5), 20, "never fewer than the render's");
    }
}
