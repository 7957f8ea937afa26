//! Direct light from the scene's lights besides the environment, at the shading points of a
//! pixel: the core's balance-heuristic pairs of a light sample and a BRDF sample
//! (`sampler_core::estimator::lights`), or light samples alone where every light is a delta
//! light. Each shading point takes its run of the pixel's own sequences for the two techniques,
//! as the environment's estimators do with theirs; rays go through the BVH, where area lights'
//! surfaces are primitives.

use crate::render::primary::{Hit, shading_point};
use crate::render::shade::Run;
use crate::render::{Context, Counters};
use crate::trace::bvh::{Bvh, Surface};
use sampler_core::estimator::lights::{FirstHit, LightRays, LightSet, brdf_sample, light_sample};
use sampler_core::glam::{DVec2, DVec3, Vec3};
use sampler_core::light::Light;
use sampler_core::points::sobol02;
use sampler_core::rng::hash_combine;

/// Samples per sequence batch.
const BATCH: usize = 16;

/// Visibility samples per shading point for the environment and for the other lights: the
/// whole budget for whichever the scene has, and where it has both, the options' share of it
/// for the lights (rounded, at least one sample each).
pub(crate) fn budgets(ctx: &Context<'_, '_>) -> (usize, usize) {
    let budget = (ctx.options.spp / ctx.options.shading_points.max(1)).max(1);
    match (ctx.env.is_some(), ctx.lights.is_some()) {
        (true, true) => {
            let lights = ((ctx.options.light_share * budget as f64).round() as usize).clamp(1, budget.max(2) - 1);
            ((budget - lights).max(1), lights)
        }
        (true, false) => (budget, 0),
        (false, true) => (0, budget),
        (false, false) => (0, 0),
    }
}

/// The rays of one shading point, through the scene's hierarchy, counted.
struct SceneRays<'a> {
    bvh: &'a Bvh,
    set: &'a LightSet<'a>,
    origin: Vec3,
    shadows: bool,
    traced: u64,
}

impl LightRays for SceneRays<'_> {
    fn unoccluded(&mut self, dir: Vec3, distance: f32) -> bool {
        if !self.shadows {
            return true;
        }
        self.traced += 1;
        !self.bvh.occluded(self.origin, dir, 0.0, distance)
    }

    fn first_hit(&mut self, dir: Vec3) -> FirstHit {
        if !self.shadows {
            return nearest_light(self.set, self.origin, dir);
        }
        self.traced += 1;
        match self.bvh.intersect(self.origin, dir, 0.0, f32::INFINITY).map(|h| h.surface) {
            None => FirstHit::Escapes,
            Some(Surface::Emitter(index)) => FirstHit::Emitter(index),
            Some(Surface::Material(_)) => FirstHit::Blocked,
        }
    }
}

/// Without shadows, the light whose surface the ray meets first, nothing else occluding.
fn nearest_light(set: &LightSet<'_>, origin: Vec3, dir: Vec3) -> FirstHit {
    let mut nearest = (f32::INFINITY, FirstHit::Escapes);
    for (index, light) in set.lights().iter().enumerate().filter(|(_, l)| l.surface().is_some()) {
        if let Some(hit) = light.eval(origin, dir).filter(|h| h.distance < nearest.0) {
            nearest = (hit.distance, FirstHit::Emitter(index));
        }
    }
    nearest.1
}

/// The sum over `hits` of each shading point's estimate of the lights' direct light from
/// `budget` visibility samples; `run_of` gives each hit's run of the pixel's sequences.
pub(crate) fn shade_lights(
    ctx: &Context<'_, '_>,
    set: &LightSet<'_>,
    hits: &[Hit],
    run_of: impl Fn(&Hit) -> Run,
    budget: usize,
    counters: &mut Counters,
) -> DVec3 {
    let mut sum = DVec3::ZERO;
    for hit in hits {
        let sp = shading_point(ctx.scene, hit);
        let mut rays = SceneRays { bvh: ctx.bvh, set, origin: hit.origin, shadows: ctx.options.shadows, traced: 0 };
        let Run { seed, block } = run_of(hit);
        let pairs = set.has_area_lights();
        let n = if pairs { (budget / 2).max(1) } else { budget.max(1) };
        let (mut light_points, mut brdf_points) = ([DVec2::ZERO; BATCH], [DVec2::ZERO; BATCH]);
        let mut estimate = DVec3::ZERO;
        let mut done = 0;
        while done < n {
            let m = (n - done).min(BATCH);
            let first = (block * n + done) as u32;
            sobol02(hash_combine(seed, 5), first, &mut light_points[..m]);
            if pairs {
                sobol02(hash_combine(seed, 6), first, &mut brdf_points[..m]);
            }
            for k in 0..m {
                estimate += light_sample(set, hit.origin, &sp, light_points[k], pairs, &mut rays);
                if pairs {
                    estimate += brdf_sample(set, hit.origin, &sp, brdf_points[k].as_vec2(), &mut rays);
                }
            }
            done += m;
        }
        sum += estimate / n as f64;
        counters.shadow_rays += rays.traced;
    }
    sum
}
