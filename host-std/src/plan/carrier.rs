//! Which sampler carries a distant light with an angle where the scene has an environment too:
//! its own cone (MIS of a light sample and a BRDF sample, on the lights' share of each shading
//! point's budget) or the environment's map, into which the sun is then rasterised so that the
//! map's samplers — the product among them — see sun × BRDF together
//! (`light::move_distant_lights`). Neither wins everywhere: the map helps near-mirror lobes under
//! the product and hurts diffuse ones, the cone resolves a sun of a few texels better
//! (docs/tuning.md, "A sun in the map or by its cone").
//!
//! `auto` measures it per scene: a pilot renders a few of the frame's tiles (about
//! [`PILOT_SHARE`] of its pixels, at the render's own method, samples per pixel and pixel
//! footprint, so that antialiasing weighs as it does in the render) with each carrier, twice
//! with independent seeds, and scores each carrier by its variance from the pixel pairs'
//! squared differences (relMSE's normalisation, over the mean of all four renders) times its
//! cost: its shadow rays and its shading points at a fixed cost each ([`POINT_COST`]; counted,
//! not timed). The map
//! replaces the cone only where it scores [`MAP_MARGIN`]× better: the cone is the carrier that
//! held or won on whole images at equal time, and a score from a few hundred pixel pairs is good
//! to tens of per cent. The choice depends only on the scene, the settings and the seed, and
//! the pilot's samples are not the render's, so the render stays unbiased.

use crate::cpu_time::{cpu_seconds_since, process_cpu_time};
use crate::light::environment::Environment;
use crate::light::move_distant_lights;
use crate::plan::method::Lighting;
use crate::plan::paired::{PilotCandidate, paired_scores, pilot_tiles};
use crate::plan::{Method, Settings, ShadingPoints};
use crate::render::crop::Crop;
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use sampler_core::light::{Light, SceneLight};
use std::time::Instant;

/// Share of the render's pixels each of the pilot's four renders covers (at least a tile).
pub const PILOT_SHARE: f64 = 0.01;

/// How much better than the cone the map must score to carry the sun.
pub const MAP_MARGIN: f64 = 1.25;

/// A shading point's cost in shadow rays under MIS and the methods without a product
/// (docs/tuning.md, "A sun in the map or by its cone").
pub const POINT_COST: f64 = 2.2;

/// A shading point's cost in shadow rays under product-MIS (its product sampler's share).
pub const PRODUCT_POINT_COST: f64 = 5.5;

/// A shading point's cost in shadow rays under `auto` (its materials' MIS and product-MIS plans).
pub const AUTO_POINT_COST: f64 = 4.6;

/// How a distant light with an angle is sampled (`--distant-carrier`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Carrier {
    /// By its cone, with MIS against BRDF samples.
    Cone,
    /// Rasterised into the environment's map, sampled with it.
    Map,
    /// Whichever of the two a pilot render of the scene measures better.
    Auto,
}

/// What `auto` measured and chose.
#[derive(Clone, Copy, Debug)]
pub struct CarrierChoice {
    /// The carrier the render uses: `Cone` or `Map`.
    pub carrier: Carrier,
    /// The pilot's scores of the cone and the map, variance × cost (lower is better).
    pub scores: [f64; 2],
    /// Pixels of each of the pilot's renders.
    pub pixels: usize,
    /// Wall-clock seconds of the pilot.
    pub seconds: f64,
    /// CPU seconds of the pilot, every thread's (`None` where the platform does not say).
    pub cpu_seconds: Option<f64>,
}

/// True when `scene` has a distant light that the map could carry (one with an angle).
#[must_use]
pub fn has_wide_distant_light(scene: &Scene) -> bool {
    scene.lights.iter().any(|l| matches!(l, SceneLight::Distant(d) if !d.is_delta()))
}

/// Moves the scene's distant lights with an angle into `env` where `carrier` is `Map`.
pub fn apply(carrier: Carrier, lights: &mut Vec<SceneLight>, env: &mut Environment) {
    if carrier == Carrier::Map {
        move_distant_lights(lights, env);
    }
}

/// `auto`'s choice for `scene` lit by `env` (which holds no distant light yet), rendered with
/// `settings` (its seed included) and `points` shading points; `None` where the scene has no
/// distant light with an angle, so nothing to choose.
#[must_use]
pub fn choose(
    scene: &Scene,
    bvh: &Bvh,
    env: &Environment,
    settings: &Settings,
    points: ShadingPoints,
) -> Option<CarrierChoice> {
    if !has_wide_distant_light(scene) {
        return None;
    }
    let (start, cpu_start) = (Instant::now(), process_cpu_time());
    let (width, height) = (scene.camera.width as usize, scene.camera.height as usize);
    let tiles = pilot_tiles(width, height, PILOT_SHARE);
    let mut in_map = Environment {
        level: env.level,
        rgb: env.rgb.clone(),
        pyramid: env.pyramid.clone(),
        map_to_world: env.map_to_world,
        stats: env.stats.clone(),
    };
    let mut map_scene = scene.clone();
    move_distant_lights(&mut map_scene.lights, &mut in_map);
    let (cone_env, map_env) = (env.hierarchy(), in_map.hierarchy());
    let pilot_settings = |scene: &Scene| Settings {
        shading_points: points.resolve(settings.method, settings.spp, Lighting::of(true, scene.lights.len())),
        ..*settings
    };
    let point_cost = point_cost(settings.method);
    let candidates = [
        PilotCandidate { scene, env: Some(&cone_env), settings: pilot_settings(scene), point_cost },
        PilotCandidate { scene: &map_scene, env: Some(&map_env), settings: pilot_settings(&map_scene), point_cost },
    ];
    let scores: [f64; 2] = paired_scores(bvh, &candidates, &tiles, 0xca55_1e55).try_into().expect("two carriers");
    let carrier = if scores[1] * MAP_MARGIN < scores[0] { Carrier::Map } else { Carrier::Cone };
    let cpu_seconds = cpu_seconds_since(cpu_start);
    let pixels = tiles.iter().map(Crop::area).sum();
    Some(CarrierChoice { carrier, scores, pixels, seconds: start.elapsed().as_secs_f64(), cpu_seconds })
}

/// The cost of a shading point (its camera ray, its hit and the samplers set up there) in
/// shadow rays, per method: where the sun moves into the map and the scene has no other light,
/// the shading-point rule gives each point fewer samples and so the image more points
/// (docs/tuning.md, "A sun in the map or by its cone").
pub(crate) fn point_cost(method: Method) -> f64 {
    match method {
        Method::ProductMis => PRODUCT_POINT_COST,
        Method::Auto => AUTO_POINT_COST,
        _ => POINT_COST,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::environment::{EnvSource, Placement};
    use crate::light::lights::LightOptions;
    use crate::render::brdf_samples::BrdfSamples;
    use sampler_core::glam::Vec3;
    use sampler_core::light::DistantLight;

    #[test]
    fn a_pilot_runs_only_for_a_sun_with_an_angle_and_repeats_its_choice() {
        let source = EnvSource::Constant { level: 5 };
        let env = Environment::build(&source, Placement::default()).unwrap();
        let mut scene = crate::scene::builtin::scene();
        (scene.camera.width, scene.camera.height, scene.env) = (24, 20, Some((source, Placement::default())));
        let bvh = Bvh::build(&scene);
        let settings = Settings {
            method: Method::Mis,
            spp: 8,
            shading_points: 1,
            brdf_samples: BrdfSamples::PerLobe,
            seed: 3,
            progress: false,
            shadows: true,
            lights: LightOptions::default(),
        };
        let choose = |scene: &Scene| choose(scene, &bvh, &env, &settings, ShadingPoints::Rule);
        assert!(choose(&scene).is_none(), "no distant light: nothing to choose");
        let sun = |angle| DistantLight::new(Vec3::new(0.3, 1.0, 0.4).normalize(), Vec3::splat(3.0), angle).unwrap();
        scene.lights.push(sun(0.0).into());
        assert!(choose(&scene).is_none(), "a delta light stays a light");
        scene.lights.push(sun(0.02).into());
        let (a, b) = (choose(&scene).unwrap(), choose(&scene).unwrap());
        assert_eq!((a.carrier, a.scores, a.pixels), (b.carrier, b.scores, b.pixels));
        assert!(a.carrier != Carrier::Auto && a.pixels == 16 * 16, "the one tile the pilot renders");
        assert!(a.scores.iter().all(|s| s.is_finite() && *s > 0.0), "{:?}", a.scores);
    }
}
