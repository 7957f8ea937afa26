//! How many light samples each shading point takes under an environment, where the MIS
//! methods' rule allows a choice: its two pairs, or four. A pixel's error is its footprint's
//! (edges, a sun's glint, integrated only by its shading points) plus its light's (falling with
//! every sample); a shading point costs about two shadow rays. Where the light's noise dominates
//! — glossy lobes under extended light — four pairs per point spend the time on what pays; where
//! the footprint's does — a sun's glints and hard shadows — they starve it (docs/tuning.md,
//! "Shading points per pixel"). Neither wins on every scene, so a pilot measures the scene:
//! paired renders of a few tiles with each split (`plan::paired`), scored by variance × cost.
//!
//! The pilot renders at an eighth of the render's samples per pixel (at least 32): the
//! footprint's share of the error falls with spp faster than the light's (stratified shading
//! points), so a split that wins there wins at the render's spp too, and the pilot's four
//! renders of 5% of the pixels cost a few per cent of the render.

use crate::cpu_time::{cpu_seconds_since, process_cpu_time};
use crate::plan::carrier::point_cost;
use crate::plan::method::Lighting;
use crate::plan::paired::{PilotCandidate, paired_scores, pilot_tiles};
use crate::plan::{Method, Settings, ShadingPoints};
use crate::render::crop::Crop;
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use sampler_core::env::EnvHierarchy;
use std::time::Instant;

/// Samples per pixel from which the pilot runs: below, its renders (at least
/// [`MIN_PILOT_SPP`]) would cost more than a quarter of the render's samples per pixel, and the
/// rule's split stands.
pub const MIN_SPP: usize = 128;

/// The pilot's samples per pixel are the render's over this (at least [`MIN_PILOT_SPP`]).
pub const PILOT_SPP_DIVISOR: usize = 8;

/// Share of the frame's pixels each of the pilot's renders covers: a few tiles decide wrongly
/// where a scene's error sits in its edges and glints (docs/tuning.md, "Shading points per pixel").
pub const PILOT_SHARE: f64 = 0.05;

/// The fewest tiles a pilot decides from: on a smaller frame the rule's split stands, since a
/// few tiles miss the glints and edges that decide it (three tiles chose wrongly on two of six
/// scenes; docs/tuning.md, "Shading points per pixel").
pub const MIN_PILOT_TILES: usize = 8;

/// The fewest samples per pixel the pilot renders with: four shading points at four pairs.
pub const MIN_PILOT_SPP: usize = 32;

/// What the pilot measured and chose.
#[derive(Clone, Copy, Debug)]
pub struct SplitChoice {
    /// Light samples per shading point the render takes.
    pub samples_per_point: usize,
    /// The candidates: the rule's samples per point and twice as many.
    pub candidates: [usize; 2],
    /// Their variance × cost at the pilot's spp (lower is better).
    pub scores: [f64; 2],
    /// Samples per pixel of the pilot's renders.
    pub pilot_spp: usize,
    /// Pixels of each of the pilot's renders.
    pub pixels: usize,
    /// Wall-clock seconds of the pilot.
    pub seconds: f64,
    /// CPU seconds of the pilot, every thread's (`None` where the platform does not say).
    pub cpu_seconds: Option<f64>,
}

/// The split for `settings` (its method, spp and seed) on `scene` lit by `env`, where `points`
/// leaves it to the rule and the rule allows a choice; `None` otherwise (the rule's split).
/// `env` is the view the render samples, its compensated pyramid attached where the render
/// reads one ([`Prepass`](crate::plan::prepass::Prepass)), so that the pilot's renders do not
/// build it again.
#[must_use]
pub fn choose(
    scene: &Scene,
    bvh: &Bvh,
    env: Option<&EnvHierarchy<'_>>,
    settings: &Settings,
    points: ShadingPoints,
) -> Option<SplitChoice> {
    let rule = settings.method.samples_per_point_under(Lighting::of(env.is_some(), scene.lights.len()));
    let applies = points == ShadingPoints::Rule
        && env.is_some()
        && scene.lights.is_empty()
        && settings.spp >= MIN_SPP
        && matches!(settings.method, Method::Mis | Method::ProductMis | Method::TwoLevelMis | Method::Auto);
    if !applies {
        return None;
    }
    let tiles = pilot_tiles(scene.camera.width as usize, scene.camera.height as usize, PILOT_SHARE);
    if tiles.len() < MIN_PILOT_TILES {
        return None;
    }
    let (start, cpu_start) = (Instant::now(), process_cpu_time());
    let candidates = [rule, 2 * rule];
    let pilot_spp = (settings.spp / PILOT_SPP_DIVISOR).max(MIN_PILOT_SPP);
    let candidate = |v: usize| PilotCandidate {
        scene,
        env,
        settings: Settings {
            spp: pilot_spp,
            shading_points: ShadingPoints::PerPoint(v).resolve(settings.method, pilot_spp, Lighting::OneKind),
            ..*settings
        },
        point_cost: point_cost(settings.method),
    };
    let scored = paired_scores(bvh, &candidates.map(candidate), &tiles, 0x5b11_7000);
    let scores: [f64; 2] = scored.try_into().expect("two splits");
    let samples_per_point = if scores[1] < scores[0] { candidates[1] } else { candidates[0] };
    let cpu_seconds = cpu_seconds_since(cpu_start);
    let pixels = tiles.iter().map(Crop::area).sum();
    Some(SplitChoice {
        samples_per_point,
        candidates,
        scores,
        pilot_spp,
        pixels,
        seconds: start.elapsed().as_secs_f64(),
        cpu_seconds,
    })
}

/// Shading points per pixel for a render of `settings` where `choice` is the pilot's (if it ran).
#[must_use]
pub fn shading_points(
    choice: Option<&SplitChoice>,
    points: ShadingPoints,
    settings: &Settings,
    lighting: Lighting,
) -> usize {
    let points = choice.map_or(points, |c| ShadingPoints::PerPoint(c.samples_per_point));
    points.resolve(settings.method, settings.spp, lighting)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::environment::{EnvSource, Environment, Placement};
    use crate::light::lights::LightOptions;
    use crate::render::brdf_samples::BrdfSamples;

    fn settings(method: Method, spp: usize) -> Settings {
        Settings {
            method,
            spp,
            shading_points: 1,
            brdf_samples: BrdfSamples::PerLobe,
            seed: 5,
            progress: false,
            shadows: true,
            lights: LightOptions::default(),
        }
    }

    #[test]
    fn the_pilot_runs_only_where_the_rule_leaves_a_choice_and_repeats_it() {
        let source = EnvSource::Constant { level: 5 };
        let env = Environment::build(&source, Placement::default()).unwrap();
        let hierarchy = env.hierarchy();
        let mut scene = crate::scene::builtin::scene();
        (scene.camera.width, scene.camera.height) = (224, 192);
        let bvh = Bvh::build(&scene);
        let run = |method, spp, points, env| choose(&scene, &bvh, env, &settings(method, spp), points);
        let some = Some(&hierarchy);
        assert!(run(Method::Mis, 64, ShadingPoints::Rule, some).is_none(), "below MIN_SPP");
        assert!(run(Method::Mis, 128, ShadingPoints::Given(16), some).is_none(), "--shading-points forces P");
        assert!(run(Method::Env, 128, ShadingPoints::Rule, some).is_none(), "one sample per point");
        assert!(run(Method::Mis, 128, ShadingPoints::Rule, None).is_none(), "no environment");
        let mut small = scene.clone();
        (small.camera.width, small.camera.height) = (160, 90);
        let small_settings = settings(Method::Mis, 128);
        assert!(choose(&small, &bvh, some, &small_settings, ShadingPoints::Rule).is_none(), "too few tiles");
        let (a, b) = (
            run(Method::Mis, 128, ShadingPoints::Rule, some).unwrap(),
            run(Method::Mis, 128, ShadingPoints::Rule, some).unwrap(),
        );
        assert_eq!((a.samples_per_point, a.scores, a.pixels), (b.samples_per_point, b.scores, b.pixels));
        assert_eq!((a.candidates, a.pilot_spp, a.pixels), ([4, 8], 32, 8 * 16 * 16));
        assert!(a.scores.iter().all(|s| s.is_finite() && *s > 0.0), "{:?}", a.scores);
        let best = if a.scores[1] < a.scores[0] { 8 } else { 4 };
        assert_eq!(a.samples_per_point, best);
        let s = settings(Method::Mis, 128);
        assert_eq!(shading_points(Some(&a), ShadingPoints::Rule, &s, Lighting::OneKind), 128 / best);
        assert_eq!(shading_points(None, ShadingPoints::Rule, &s, Lighting::OneKind), 32);
    }
}
