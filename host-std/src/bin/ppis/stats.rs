//! The stats JSON of `ppis render --stats-json`: timings, counts and what was built. The file
//! lists its keys sorted, so the fields are declared in alphabetical order; scripts (docs/,
//! host-usd/bench/) read them by name.

use crate::render_cmd::{Prepared, RenderArgs};
use host_std::plan::pilot::PilotResult;
use host_std::plan::split::SplitChoice;
use host_std::plan::{Rendered, pilot};
use host_std::scene::Scene;
use sampler_core::env::EnvHierarchy;
use serde::Serialize;
use std::collections::BTreeMap;

/// One render's stats.
#[derive(Serialize)]
pub(crate) struct Stats {
    /// `auto`: per material, in material order, its plan and its pilot's scores (empty otherwise).
    auto_plans: Vec<AutoPlan>,
    /// `--brdf-samples`: every material's K (`null`: each material's from its lobes).
    brdf_samples: Option<u32>,
    /// The process's CPU seconds (every thread) building the BVH.
    bvh_cpu_seconds: Option<f64>,
    bvh_seconds: f64,
    camera_rays: u64,
    /// The pixels rendered, x0, y0, x1, y1 (half-open): `--crop`, or the whole frame.
    crop: [usize; 4],
    env_build_seconds: f64,
    /// The process's CPU seconds (every thread) reading the environment map and building the
    /// equal-area map and its pyramid.
    env_cpu_seconds: Option<f64>,
    env_bytes: Option<usize>,
    env_level: Option<u32>,
    env_map_mean_rgb: Option<[f64; 3]>,
    /// The equal-area map's mean radiance against the source's: the largest relative error
    /// over the channels.
    env_mean_relative_error: Option<f64>,
    /// `EnvHierarchy::peak(5)`, widened to f64 as the file has it.
    env_peak: Option<f64>,
    env_sanitized_texels: Option<usize>,
    env_source_mean_rgb: Option<[f64; 3]>,
    /// The whole frame's size; `width` and `height` are the crop's.
    frame_height: usize,
    frame_width: usize,
    /// The image's height (the crop's).
    height: usize,
    /// The process's CPU seconds (every thread) loading the scene.
    load_cpu_seconds: Option<f64>,
    /// The scene's and the environment's.
    load_seconds: f64,
    method: &'static str,
    non_finite_pixels: u64,
    pilot_seconds: f64,
    /// The environment's build and the BVH's.
    preprocess_seconds: f64,
    primitives: usize,
    /// Every render thread's CPU time (`null` where the platform does not say): the cost per
    /// core on a machine shared with other work.
    render_cpu_seconds: Option<f64>,
    render_seconds: f64,
    scene: String,
    seed: u64,
    shading_points: u64,
    shading_points_per_pixel: u32,
    shadow_rays: u64,
    /// The light samples per shading point the split pilot measured (`null` where it did not run).
    split_pilot: Option<SplitPilot>,
    spp: u32,
    threads: usize,
    /// `--frame` as given (a USD time code), `null` without it.
    time_code: Option<String>,
    unshadowed: bool,
    /// The image's width (the crop's).
    width: usize,
}

/// What the split pilot measured (`plan::split`).
#[derive(Serialize)]
struct SplitPilot {
    /// Light samples per shading point the render took.
    chosen: usize,
    pilot_pixels: usize,
    pilot_spp: usize,
    /// Per candidate samples per shading point, its variance × cost (`null`: not measured —
    /// under extended light the split is the rule's, docs/tuning.md, "Shading points per pixel").
    scores: BTreeMap<usize, Option<f64>>,
    /// The MIS heuristic the render weighed by (`balance` or `power`).
    mis_heuristic: &'static str,
    /// The chosen split's variance × cost under the power heuristic (`null`: not measured).
    power_score: Option<f64>,
}

/// One material's plan under `auto`, and what its pilot measured.
#[derive(Serialize)]
struct AutoPlan {
    material: String,
    /// 0 where no pilot ran for the material (the rules chose alone).
    pilot_pixels: usize,
    plan: String,
    /// Light samples per shading point from the environment (`Rendered::auto_samples`).
    samples_per_point: usize,
    rule_plan: Option<String>,
    /// Per candidate plan by name, its score (`null`: not measured or not trusted).
    scores: BTreeMap<String, Option<f64>>,
}

impl AutoPlan {
    /// Material `m`'s entry: its plan, and the pilot's measurement where one ran (otherwise no
    /// pilot pixels, no scores, and the rules' plan is the plan).
    fn new(scene: &Scene, m: usize, (plan, samples_per_point): (&str, usize), pilot: Option<&PilotResult>) -> Self {
        let material = scene.materials[m].bsdf.label();
        let plan = plan.to_string();
        match pilot {
            Some(r) => AutoPlan {
                material,
                pilot_pixels: r.pixels,
                plan,
                samples_per_point,
                rule_plan: r.rule.map(pilot::plan_name),
                scores: (0..pilot::PLANS.len()).map(|c| (pilot::plan_name(c), r.scores[c])).collect(),
            },
            None => AutoPlan {
                material,
                pilot_pixels: 0,
                rule_plan: Some(plan.clone()),
                plan,
                samples_per_point,
                scores: BTreeMap::new(),
            },
        }
    }
}

impl Stats {
    /// The stats of `image`, rendered from `prepared` as `args` asked.
    pub(crate) fn new(
        args: &RenderArgs,
        prepared: &Prepared,
        hierarchy: Option<&EnvHierarchy<'_>>,
        image: &Rendered,
        shading_points: u32,
        split: Option<&SplitChoice>,
        threads: usize,
    ) -> Self {
        let env = prepared.environment.as_ref();
        let env_load = env.map_or(0.0, |e| e.stats.load_seconds);
        let env_build = env.map_or(0.0, |e| e.stats.build_seconds);
        let scene = &prepared.scene;
        Stats {
            auto_plans: image
                .auto_choices()
                .map(|(m, plan, samples, pilot)| AutoPlan::new(scene, m, (plan, samples), pilot))
                .collect(),
            brdf_samples: args.brdf_samples,
            bvh_cpu_seconds: prepared.cpu_seconds.map(|c| c[2]),
            bvh_seconds: prepared.bvh_seconds,
            camera_rays: image.camera_rays,
            crop: [prepared.crop.x0, prepared.crop.y0, prepared.crop.x1, prepared.crop.y1],
            env_build_seconds: env_build,
            env_cpu_seconds: prepared.cpu_seconds.filter(|_| env.is_some()).map(|c| c[1]),
            env_bytes: env.map(|e| e.stats.bytes),
            env_level: env.map(|e| e.level),
            env_map_mean_rgb: env.map(|e| e.stats.map_mean),
            env_mean_relative_error: env.map(|e| {
                (0..3)
                    .map(|c| (e.stats.map_mean[c] / e.stats.source_mean[c].max(1e-300) - 1.0).abs())
                    .fold(0.0, f64::max)
            }),
            env_peak: hierarchy.map(|h| f64::from(h.peak(5))),
            env_sanitized_texels: env.map(|e| e.stats.sanitized),
            env_source_mean_rgb: env.map(|e| e.stats.source_mean),
            frame_height: scene.camera.height as usize,
            frame_width: scene.camera.width as usize,
            height: image.height,
            load_cpu_seconds: prepared.cpu_seconds.map(|c| c[0]),
            load_seconds: prepared.load_seconds + env_load,
            method: args.method.name(),
            non_finite_pixels: image.non_finite,
            pilot_seconds: image.pilot_seconds,
            preprocess_seconds: env_build + prepared.bvh_seconds,
            primitives: prepared.bvh.primitive_count(),
            render_cpu_seconds: image.render_cpu_seconds,
            render_seconds: image.render_seconds,
            scene: scene.name.clone(),
            seed: args.sampling.seed,
            shading_points: image.shading_points,
            shading_points_per_pixel: shading_points,
            shadow_rays: image.shadow_rays,
            split_pilot: split.map(|c| SplitPilot {
                chosen: c.samples_per_point,
                pilot_pixels: c.pixels,
                pilot_spp: c.pilot_spp,
                scores: c.candidates.into_iter().zip(c.scores).collect(),
                mis_heuristic: crate::render_cmd::heuristic_name(c.heuristic),
                power_score: c.power_score,
            }),
            spp: args.spp,
            threads,
            time_code: args.scene.frame.clone(),
            unshadowed: args.sampling.unshadowed,
            width: image.width,
        }
    }
}
