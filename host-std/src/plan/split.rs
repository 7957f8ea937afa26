//! How many light samples each shading point takes under an environment, where the MIS
//! methods' rule allows a choice: its two pairs, or four. A pixel's error is its footprint's
//! (edges, a sun's glint, integrated only by its shading points) plus its light's (falling with
//! every sample); a shading point costs about two shadow rays. Where the light's noise dominates
//! — glossy lobes under extended light — four pairs per point spend the time on what pays; where
//! the footprint's does — a sun's glints and hard shadows — they starve it (docs/tuning.md,
//! "Shading points per pixel"). Under a sun neither wins on every scene, so a pilot measures
//! the scene: paired renders of a few tiles with each split (`plan::paired`), scored by
//! variance × cost. Under extended light (the map's peak below [`SUN_PEAK`]) four pairs won or
//! tied on every scene measured, and the pilot that chose them there cost a few per cent of
//! the render for nothing: there the split is four pairs without a pilot.
//!
//! At the split it chooses, the pilot also renders the MIS methods (not `auto`, whose pilot
//! renders its materials as MIS) with the power heuristic instead of the balance heuristic, and
//! keeps whichever scores lower: neither wins on every map (`sampler_core::env::MisHeuristic`).
//! It does so where most of the map's light stands above its mean ([`POWER_EXCESS_SHARE`]),
//! the maps where the power heuristic can win by more than the pilot costs.
//!
//! The pilot (of the split, or of the heuristic alone under extended light) renders at an
//! eighth of the render's samples per pixel (at least 32): the
//! footprint's share of the error falls with spp faster than the light's (stratified shading
//! points), so a split that wins there wins at the render's spp too, and the pilot's four
//! renders of 5% of the pixels cost a few per cent of the render.

use crate::cpu_time::{cpu_seconds_since, process_cpu_time};
use crate::plan::carrier::point_cost;
use crate::plan::method::Lighting;
use crate::plan::paired::{PilotCandidate, paired_scores, paired_scores_at, pilot_tiles};
use crate::plan::rules::SUN_PEAK;
use crate::plan::{Method, Settings, ShadingPoints};
use crate::render::crop::Crop;
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use sampler_core::env::{EnvHierarchy, MisHeuristic};
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

/// What the pilot's seeds derive from, with the render's seed.
const SALT: u64 = 0x5b11_7000;

/// The least share of the map's light above its mean (`EnvHierarchy::excess_share`) at which
/// the pilot measures the power heuristic: below it, on every map measured, the power
/// heuristic gained at most a few per cent or lost, and the pilot's extra renders and its
/// occasional wrong choice cost more than it could win (docs/perf.md, "MIS heuristic").
pub const POWER_EXCESS_SHARE: f32 = 0.75;

/// What the pilot measured and chose.
#[derive(Clone, Copy, Debug)]
pub struct SplitChoice {
    /// Light samples per shading point the render takes.
    pub samples_per_point: usize,
    /// The candidates: the rule's samples per point and twice as many.
    pub candidates: [usize; 2],
    /// Their variance × cost at the pilot's spp (lower is better), where measured: both under
    /// a sun; under extended light only the chosen split's, and only where the power heuristic
    /// is measured beside it.
    pub scores: [Option<f64>; 2],
    /// The heuristic MIS weighs by in the render.
    pub heuristic: MisHeuristic,
    /// The variance × cost of the chosen split under the power heuristic, where the pilot
    /// measured it (`None` where the heuristic was given, for `auto`, or where the map's light
    /// is not concentrated enough to try it).
    pub power_score: Option<f64>,
    /// Samples per pixel of the pilot's renders.
    pub pilot_spp: usize,
    /// Pixels of each of the pilot's renders (0 where none ran).
    pub pixels: usize,
    /// Wall-clock seconds of the pilot.
    pub seconds: f64,
    /// CPU seconds of the pilot, every thread's (`None` where the platform does not say).
    pub cpu_seconds: Option<f64>,
}

/// The split for `settings` (its method, spp and seed) on `scene` lit by `env`, where `points`
/// leaves it to the rule and the rule allows a choice, and the MIS heuristic where `heuristic`
/// leaves it to the pilot; `None` otherwise (the rule's split, and the heuristic given or the
/// balance heuristic). `env` is the view the render samples, its compensated pyramid attached
/// where the render reads one ([`Prepass`](crate::plan::prepass::Prepass)), so that the
/// pilot's renders do not build it again.
#[must_use]
pub fn choose(
    scene: &Scene,
    bvh: &Bvh,
    env: Option<&EnvHierarchy<'_>>,
    settings: &Settings,
    points: ShadingPoints,
    heuristic: Option<MisHeuristic>,
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
    // The view under the heuristic given (else the balance heuristic), and under the power heuristic.
    let views = [heuristic.unwrap_or_default(), MisHeuristic::Power].map(|h| env.map(|e| e.with_mis_heuristic(h)));
    let candidate = |v: usize, view: usize| PilotCandidate {
        scene,
        env: views[view].as_ref(),
        settings: Settings {
            spp: pilot_spp,
            shading_points: ShadingPoints::PerPoint(v).resolve(settings.method, pilot_spp, Lighting::OneKind),
            ..*settings
        },
        point_cost: point_cost(settings.method),
    };
    let extended = env.is_some_and(|e| e.peak(5) < SUN_PEAK);
    let (mut scores, best) = if extended {
        ([None, None], 1)
    } else {
        let scored = paired_scores(bvh, &candidates.map(|v| candidate(v, 0)), &tiles, SALT);
        (std::array::from_fn(|k| Some(scored[k])), usize::from(scored[1] < scored[0]))
    };
    let samples_per_point = candidates[best];
    // The power heuristic at the chosen split, with its renders' seeds: the same samples,
    // weighed otherwise. Under extended light both heuristics are scored together (one
    // normalisation), as the two splits are under a sun.
    let concentrated = env.and_then(EnvHierarchy::excess_share).is_some_and(|s| s >= POWER_EXCESS_SHARE);
    let mut power_score = None;
    if heuristic.is_none() && settings.method != Method::Auto && concentrated {
        let at_best = |views: &[usize]| {
            let weighed: Vec<PilotCandidate<'_>> = views.iter().map(|&v| candidate(samples_per_point, v)).collect();
            paired_scores_at(bvh, &weighed, &vec![best; views.len()], &tiles, SALT)
        };
        if scores[best].is_some() {
            power_score = Some(at_best(&[1])[0]);
        } else {
            let both = at_best(&[0, 1]);
            (scores[best], power_score) = (Some(both[0]), Some(both[1]));
        }
    }
    let heuristic = match (power_score, scores[best]) {
        (Some(p), Some(b)) if p < b => MisHeuristic::Power,
        _ => heuristic.unwrap_or_default(),
    };
    let measured = scores.iter().any(Option::is_some);
    let cpu_seconds = cpu_seconds_since(cpu_start);
    let pixels = if measured { tiles.iter().map(Crop::area).sum() } else { 0 };
    Some(SplitChoice {
        samples_per_point,
        candidates,
        scores,
        heuristic,
        power_score,
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

    /// A map of level 5 (32², one texel per block `EnvHierarchy::peak(5)` reads): 1 everywhere
    /// but `bright` at one texel, and its plain view.
    fn map_with_one_texel(bright: f32) -> (Vec<[f32; 3]>, Vec<f32>) {
        let level = 5;
        let mut rgb = vec![[1.0f32; 3]; 1 << (2 * level)];
        rgb[300] = [bright; 3];
        let mut pyramid = vec![0.0f32; sampler_core::env::pyramid_len(level)];
        sampler_core::env::build_pyramid(level, &rgb, &mut pyramid).unwrap();
        (rgb, pyramid)
    }

    #[test]
    fn under_a_sun_the_pilot_runs_only_where_the_rule_leaves_a_choice_and_repeats_it() {
        let (rgb, pyramid) = map_with_one_texel(1e4);
        let hierarchy = EnvHierarchy::new(5, &pyramid, &rgb).unwrap();
        assert!(hierarchy.peak(5) >= SUN_PEAK, "a sun");
        let mut scene = crate::scene::builtin::scene();
        (scene.camera.width, scene.camera.height) = (224, 192);
        let bvh = Bvh::build(&scene);
        let run = |method, spp, points, env| choose(&scene, &bvh, env, &settings(method, spp), points, None);
        let some = Some(&hierarchy);
        assert!(run(Method::Mis, 64, ShadingPoints::Rule, some).is_none(), "below MIN_SPP");
        assert!(run(Method::Mis, 128, ShadingPoints::Given(16), some).is_none(), "--shading-points forces P");
        assert!(run(Method::Env, 128, ShadingPoints::Rule, some).is_none(), "one sample per point");
        assert!(run(Method::Mis, 128, ShadingPoints::Rule, None).is_none(), "no environment");
        let mut small = scene.clone();
        (small.camera.width, small.camera.height) = (160, 90);
        let small_settings = settings(Method::Mis, 128);
        assert!(choose(&small, &bvh, some, &small_settings, ShadingPoints::Rule, None).is_none(), "too few tiles");
        let (a, b) = (
            run(Method::Mis, 128, ShadingPoints::Rule, some).unwrap(),
            run(Method::Mis, 128, ShadingPoints::Rule, some).unwrap(),
        );
        assert_eq!((a.samples_per_point, a.scores, a.pixels), (b.samples_per_point, b.scores, b.pixels));
        assert_eq!((a.heuristic, a.power_score), (MisHeuristic::Balance, None), "no excess to weigh");
        assert_eq!((a.candidates, a.pilot_spp, a.pixels), ([4, 8], 32, 8 * 16 * 16));
        let scores = a.scores.map(|s| s.expect("both splits scored"));
        assert!(scores.iter().all(|s| s.is_finite() && *s > 0.0), "{scores:?}");
        let best = if scores[1] < scores[0] { 8 } else { 4 };
        assert_eq!(a.samples_per_point, best);
        let s = settings(Method::Mis, 128);
        assert_eq!(shading_points(Some(&a), ShadingPoints::Rule, &s, Lighting::OneKind), 128 / best);
        assert_eq!(shading_points(None, ShadingPoints::Rule, &s, Lighting::OneKind), 32);
    }

    #[test]
    fn under_extended_light_four_pairs_stand_without_a_pilot() {
        let source = EnvSource::Constant { level: 5 };
        let env = Environment::build(&source, Placement::default()).unwrap();
        let hierarchy = env.hierarchy();
        let (rgb, pyramid) = map_with_one_texel(20.0);
        let patchy = EnvHierarchy::new(5, &pyramid, &rgb).unwrap();
        let mut scene = crate::scene::builtin::scene();
        (scene.camera.width, scene.camera.height) = (224, 192);
        let bvh = Bvh::build(&scene);
        for (view, method) in [(&hierarchy, Method::Mis), (&patchy, Method::Auto), (&patchy, Method::ProductMis)] {
            assert!(view.peak(5) < SUN_PEAK);
            let c = choose(&scene, &bvh, Some(view), &settings(method, 256), ShadingPoints::Rule, None).unwrap();
            assert_eq!(
                (c.samples_per_point, c.scores, c.power_score, c.pixels),
                (8, [None, None], None, 0),
                "{method}"
            );
            let s = settings(method, 256);
            assert_eq!(shading_points(Some(&c), ShadingPoints::Rule, &s, Lighting::OneKind), 32);
        }
    }

    /// A map whose light sits in one bright patch: the pilot measures the power heuristic for
    /// MIS at its chosen split, with that split's seeds, and keeps the better; a heuristic given
    /// stands, and `auto` keeps the balance heuristic.
    #[test]
    fn the_pilot_weighs_the_heuristics_where_the_light_is_concentrated() {
        let level = 5;
        let n = 1usize << level;
        let rgb: Vec<[f32; 3]> =
            (0..n * n).map(|i| if i % n < 4 && i / n < 4 { [200.0; 3] } else { [0.1; 3] }).collect();
        let mut pyramid = vec![0.0f32; sampler_core::env::pyramid_len(level)];
        sampler_core::env::build_pyramid(level, &rgb, &mut pyramid).unwrap();
        let plain = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
        let mut compensated = vec![0.0f32; pyramid.len()];
        assert!(plain.compensate_into(&mut compensated).unwrap());
        let view = plain.with_compensated(&compensated).unwrap();
        assert!(view.excess_share().unwrap() >= POWER_EXCESS_SHARE);
        let mut scene = crate::scene::builtin::scene();
        (scene.camera.width, scene.camera.height) = (224, 192);
        let bvh = Bvh::build(&scene);
        let run = |method, heuristic| {
            choose(&scene, &bvh, Some(&view), &settings(method, 128), ShadingPoints::Rule, heuristic).unwrap()
        };
        let a = run(Method::Mis, None);
        let power = a.power_score.expect("MIS measures the power heuristic");
        assert!(power.is_finite() && power > 0.0);
        assert_eq!((a.samples_per_point, a.scores[0]), (8, None), "extended light: four pairs, unscored");
        let chosen = a.scores[1].expect("the balance heuristic scored beside the power heuristic");
        let expected = if power < chosen { MisHeuristic::Power } else { MisHeuristic::Balance };
        assert_eq!(a.heuristic, expected);
        assert_eq!((a.heuristic, a.power_score), (run(Method::Mis, None).heuristic, Some(power)), "repeatable");
        let given = run(Method::Mis, Some(MisHeuristic::Power));
        assert_eq!((given.heuristic, given.power_score), (MisHeuristic::Power, None), "a given heuristic stands");
        let auto = run(Method::Auto, None);
        assert_eq!(
            (auto.heuristic, auto.power_score),
            (MisHeuristic::Balance, None),
            "auto keeps the balance heuristic"
        );
    }
}
