//! Planning a render: the methods (`--method`), `auto`'s rules and its pilot, and [`render`],
//! which resolves the method per material, runs the pilot where `auto` asks for one, and
//! renders ([`render_crop`]: a part of the frame, planned as the whole frame is). Calls down
//! into `render`, never the reverse.

pub mod budget;
pub mod candidates;
pub mod carrier;
mod decision;
pub mod method;
pub mod pace;
pub mod paired;
pub mod pilot;
pub mod prepass;
pub mod rules;
pub mod split;
pub mod time_model;

pub use budget::ShadingPoints;
pub use method::Method;

use crate::cpu_time::{cpu_seconds_since, process_cpu_time};
use crate::light::baselines::{LightcutTable, sis_strata};
use crate::light::lights::{LightOptions, LightTable};
use crate::light::map_buffer::MapBuffer;
use crate::render::brdf_samples::BrdfSamples;
use crate::render::crop::Crop;
use crate::render::plane_products::{PlaneProducts, on_planes_only};
use crate::render::strategy::{MaterialPlan, Strategy};
use crate::render::tiles::render_tiles;
use crate::render::{Context, Lightcuts, Options, budgets, compensated_pyramid, summed_area_table, two_level_cones};
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use crate::trace::camera::Camera;
use pilot::PilotResult;
use sampler_core::env::EnvHierarchy;
use std::time::Instant;

/// What to render and how.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// How the light is sampled.
    pub method: Method,
    /// Visibility samples per pixel.
    pub spp: usize,
    /// Primary rays (shading points) per pixel; divides `spp`.
    pub shading_points: usize,
    /// BRDF samples that build each material's product samplers.
    pub brdf_samples: BrdfSamples,
    /// The seed every pixel's sequences derive from.
    pub seed: u64,
    /// Show a progress bar on stderr (after the first second).
    pub progress: bool,
    /// Trace shadow rays (false: every direction counts as visible — unshadowed direct light,
    /// to tell the error that visibility adds from the error of sampling light × BRDF).
    pub shadows: bool,
    /// How the lights besides the environment are sampled.
    pub lights: LightOptions,
}

impl Settings {
    /// How pixels are sampled, the method aside.
    #[must_use]
    pub fn options(&self) -> Options {
        Options {
            spp: self.spp,
            shading_points: self.shading_points,
            seed: self.seed,
            progress: self.progress,
            shadows: self.shadows,
            light_share: self.lights.share,
        }
    }
}

/// A rendered image and what it took.
pub struct Rendered {
    /// Width in pixels (the crop's).
    pub width: usize,
    /// Height in pixels (the crop's).
    pub height: usize,
    /// Where the pixels are in the frame (the whole frame unless cropped).
    pub crop: Crop,
    /// Linear RGB, rows top to bottom.
    pub pixels: Vec<[f32; 3]>,
    /// Wall clock of the render, `auto`'s pilot included.
    pub render_seconds: f64,
    /// CPU time of the render, every thread's (`None` where the platform does not say).
    pub render_cpu_seconds: Option<f64>,
    /// Shading points shaded (a crop counts every pixel of the render tiles it meets).
    pub shading_points: u64,
    /// Shadow rays traced.
    pub shadow_rays: u64,
    /// Primary rays traced.
    pub camera_rays: u64,
    /// Pixel values that came out NaN or infinite and were set to 0 (should stay 0).
    pub non_finite: u64,
    /// `auto`: what its pilot measured per material (empty for the other methods).
    pub pilot: Vec<PilotResult>,
    /// `auto`: seconds of the pilot, included in `render_seconds`.
    pub pilot_seconds: f64,
    /// `auto`: every material's plan by name, in material order, whether the rules or the
    /// pilot chose it (empty for the other methods).
    pub auto_plans: Vec<String>,
    /// `auto`: every material's light samples per shading point from the environment, in
    /// material order — fewer than the render's for a plan costlier per sample, more where the
    /// material keeps pace with costlier ones (`plan::pace`); empty for the other methods.
    pub auto_samples: Vec<usize>,
}

impl Rendered {
    /// `auto`: per material, in material order, its index, its plan's name, its light samples
    /// per shading point and what the pilot measured where one ran for it (`None`: the rules
    /// chose alone).
    pub fn auto_choices(&self) -> impl Iterator<Item = (usize, &str, usize, Option<&PilotResult>)> {
        let pilot = |m: usize| self.pilot.iter().find(|r| r.material == m);
        let plans = self.auto_plans.iter().zip(&self.auto_samples).enumerate();
        plans.map(move |(m, (plan, &samples))| (m, plan.as_str(), samples, pilot(m)))
    }

    /// Adds a pilot's time, run before the render and part of its cost, to the render's.
    pub fn add_pilot(&mut self, seconds: f64, cpu_seconds: Option<f64>) {
        self.render_seconds += seconds;
        self.render_cpu_seconds = self.render_cpu_seconds.zip(cpu_seconds).map(|(r, p)| r + p);
    }
}

/// The lights of the seed's baselines, built for a render that uses them, and what building
/// them took.
struct Baselines {
    strata: Option<Vec<sampler_core::sis::Stratum>>,
    cuts: Option<LightcutTable>,
    seconds: f64,
    cpu_seconds: Option<f64>,
}

impl Baselines {
    fn build(scene: &Scene, env: Option<&EnvHierarchy<'_>>, settings: &Settings) -> Self {
        let (start, cpu_start) = (Instant::now(), process_cpu_time());
        let strata = match (settings.method, env) {
            (Method::Sis, Some(e)) => Some(sis_strata(e, settings.lights.sis_lights)),
            _ => None,
        };
        let cuts = (settings.method == Method::Lightcuts).then(|| LightcutTable::new(env, &scene.lights));
        let cpu_seconds = cpu_seconds_since(cpu_start);
        Self { strata, cuts, seconds: start.elapsed().as_secs_f64(), cpu_seconds }
    }
}

/// Renders the scene. `env` is `None` when the scene has no environment light.
pub fn render(scene: &Scene, bvh: &Bvh, env: Option<&EnvHierarchy<'_>>, settings: &Settings) -> Rendered {
    let frame = Crop::full(scene.camera.width as usize, scene.camera.height as usize);
    render_crop(scene, bvh, env, settings, frame)
}

/// `auto` and product-MIS resolve their plan per material once, knowing how peaked the
/// lighting is: the peak (`f32::MAX` where the method does not read it) and every material's plan.
fn material_plans(scene: &Scene, env: Option<&EnvHierarchy<'_>>, settings: &Settings) -> (f32, Vec<MaterialPlan>) {
    let env_peak = match env {
        Some(e) if settings.method.reads_env_peak() => e.peak(5),
        _ => f32::MAX,
    };
    let plans = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let strategy = match settings.method {
                Method::Auto if rules::samples_plane_product(&m.bsdf, on_planes_only(scene, i), env_peak) => {
                    Strategy::PlaneProduct
                }
                method => method.strategy(&m.bsdf, env_peak),
            };
            MaterialPlan::new(strategy, &m.bsdf, settings.brdf_samples)
        })
        .collect();
    (env_peak, plans)
}

/// The MIS-compensated pyramid a render of `settings` samples (`None` where it samples none),
/// built once so that a pilot's renders and the render share it through
/// [`EnvHierarchy::with_compensated`] instead of each building its own. Like the map's own
/// pyramid it is the map's preprocessing, outside the render's time.
#[must_use]
pub fn compensation(scene: &Scene, env: &EnvHierarchy<'_>, settings: &Settings) -> Option<MapBuffer<f32>> {
    let (_, plans) = material_plans(scene, Some(env), settings);
    compensated_pyramid(env, &plans, settings.method == Method::Auto)
}

/// Renders the pixels of `crop` (inside the frame), bit for bit the same pixels of the whole
/// frame's render: everything is planned from the whole frame (`auto`'s pilot too).
pub fn render_crop(
    scene: &Scene,
    bvh: &Bvh,
    env: Option<&EnvHierarchy<'_>>,
    settings: &Settings,
    crop: Crop,
) -> Rendered {
    let (env_peak, plans) = material_plans(scene, env, settings);
    // MIS's env samples draw from the compensated pyramid, built only where MIS may sample.
    let compensated = env.and_then(|e| compensated_pyramid(e, &plans, settings.method == Method::Auto));
    let env_view = env.map(|e| match &compensated {
        Some(c) => e.with_compensated(c).expect("built from this view's pyramid"),
        None => *e,
    });
    let env = env_view.as_ref();
    // The summed-area table exists only for the strategy that reads it.
    let sat = env.and_then(|e| summed_area_table(e, &plans));
    let cones = env.and_then(|e| two_level_cones(e, &plans, env_peak < rules::SUN_PEAK));
    let planes = env.and_then(|e| {
        PlaneProducts::of_scene(scene, e.finest_level(), |m| plans[m].strategy == Strategy::PlaneProduct)
    });
    let camera = Camera::new(&scene.camera);
    let options = settings.options();
    let baselines = Baselines::build(scene, env, settings);
    let cut_tree = baselines.cuts.as_ref().map(|t| Lightcuts { tree: t.tree(), error: settings.lights.lightcut_error });
    // Under Lightcuts the standard estimator keeps the lights its tree does not hold.
    let scene_lights = baselines.cuts.as_ref().map_or(&scene.lights[..], |t| &t.rest[..]);
    let light_table = LightTable::new(scene_lights, bvh.bounding_radius(), settings.lights.selection);
    let lights = light_table.as_ref().map(LightTable::set);
    let ctx = Context {
        scene,
        bvh,
        env,
        lights: lights.as_ref(),
        sat: sat.as_deref(),
        cones: cones.as_ref(),
        strata: baselines.strata.as_deref(),
        lightcuts: cut_tree.as_ref(),
        planes: planes.as_ref(),
        camera: &camera,
        options: &options,
        plans: &plans,
    };
    // `auto` gives each material its plan's equal-cost budget (`plan::candidates`).
    let equal_cost: Vec<MaterialPlan>;
    let ctx = if settings.method == Method::Auto {
        let env_budget = budgets(&ctx).0;
        equal_cost = plans.iter().map(|p| candidates::at_equal_cost(*p, env_budget)).collect();
        Context { plans: &equal_cost, ..ctx }
    } else {
        ctx
    };
    // Timed from here: `auto`'s pilot is part of its cost.
    let start = Instant::now();
    let cpu_start = process_cpu_time();
    let (chosen, pilot) = match (settings.method, env) {
        (Method::Auto, Some(e)) => {
            let (chosen, measured) = pace::auto_plans(&ctx, e, env_peak);
            (Some(chosen), measured)
        }
        _ => (None, Vec::new()),
    };
    // A two-level plan the pilot chose reads the cell cones, which the rules' plans did not build.
    let plans = chosen.as_deref().unwrap_or(ctx.plans);
    let pilot_cones = match (env, ctx.cones) {
        (Some(e), None) => two_level_cones(e, plans, env_peak < rules::SUN_PEAK),
        _ => None,
    };
    let pilot_seconds = start.elapsed().as_secs_f64();
    let (auto_plans, auto_samples) = match settings.method {
        Method::Auto => {
            let v = budgets(&ctx).0;
            let samples = plans.iter().map(|p| p.env_budget.unwrap_or(v)).collect();
            (plans.iter().map(|p| method::strategy_name(p.strategy)).collect(), samples)
        }
        _ => (Vec::new(), Vec::new()),
    };
    let image = render_tiles(&Context { plans, cones: ctx.cones.or(pilot_cones.as_ref()), ..ctx }, crop, start);
    // The baselines' lights are built per render: their build is part of their cost.
    let render_seconds = start.elapsed().as_secs_f64() + baselines.seconds;
    let render_cpu_seconds = cpu_seconds_since(cpu_start).zip(baselines.cpu_seconds).map(|(r, b)| r + b);
    let c = image.counters;
    Rendered {
        width: image.width,
        height: image.height,
        crop: image.crop,
        pixels: image.pixels,
        render_seconds,
        render_cpu_seconds,
        shading_points: c.shading_points,
        shadow_rays: c.shadow_rays,
        camera_rays: c.camera_rays,
        non_finite: c.non_finite,
        pilot,
        pilot_seconds,
        auto_plans,
        auto_samples,
    }
}
