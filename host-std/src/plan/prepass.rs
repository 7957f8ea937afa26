//! What a render plans once before its tiles: the MIS-compensated pyramid its env samples draw
//! from (built once, so that the split pilot's renders and the render share it), the light
//! samples per shading point and the MIS heuristic ([`split`]). The split's pilot is part of
//! the render's cost: its time is added to the render's ([`Prepass::charge`]); the pyramid,
//! like the map's own, is the map's preprocessing.

use crate::light::map_buffer::MapBuffer;
use crate::plan::method::Lighting;
use crate::plan::split::{self, SplitChoice};
use crate::plan::{Rendered, Settings, ShadingPoints, compensation, render_crop};
use crate::render::crop::Crop;
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use sampler_core::env::{EnvHierarchy, MisHeuristic};

/// The compensated pyramid, the split, and what they took.
pub struct Prepass {
    /// The compensated pyramid the render's env view carries (`None`: it samples none).
    pub compensated: Option<MapBuffer<f32>>,
    /// The split pilot's choice, where it ran.
    pub split: Option<SplitChoice>,
    /// Shading points per pixel the render takes.
    pub shading_points: usize,
    /// The heuristic MIS weighs by: the one given, else the split pilot's, else the balance
    /// heuristic.
    pub mis_heuristic: MisHeuristic,
}

impl Prepass {
    /// Plans a render of `settings` on `scene` lit by `env` (the plain view), with `points`
    /// shading points or the split the pilot chooses, and MIS weighing by `heuristic` or by
    /// the one the pilot chooses (`None`).
    #[must_use]
    pub fn run(
        scene: &Scene,
        bvh: &Bvh,
        env: Option<&EnvHierarchy<'_>>,
        settings: &Settings,
        points: ShadingPoints,
        heuristic: Option<MisHeuristic>,
    ) -> Self {
        let compensated = env.and_then(|e| compensation(scene, e, settings));
        let mis_heuristic = heuristic.unwrap_or_default();
        let mut prepass = Self { compensated, split: None, shading_points: 1, mis_heuristic };
        let view = env.map(|e| prepass.view(e));
        prepass.split = split::choose(scene, bvh, view.as_ref(), settings, points, heuristic);
        prepass.mis_heuristic = prepass.split.as_ref().map_or(mis_heuristic, |c| c.heuristic);
        let lighting = Lighting::of(env.is_some(), scene.lights.len());
        prepass.shading_points = split::shading_points(prepass.split.as_ref(), points, settings, lighting);
        prepass
    }

    /// `env` with the compensated pyramid attached where there is one, weighing MIS by the
    /// heuristic chosen.
    #[must_use]
    pub fn view<'a>(&'a self, env: &EnvHierarchy<'a>) -> EnvHierarchy<'a> {
        let env = env.with_mis_heuristic(self.mis_heuristic);
        match &self.compensated {
            Some(c) => env.with_compensated(c).expect("built from this view's pyramid"),
            None => env,
        }
    }

    /// Adds the split pilot's time to `image`'s.
    pub fn charge(&self, image: &mut Rendered) {
        if let Some(c) = &self.split {
            image.add_pilot(c.seconds, c.cpu_seconds);
        }
    }
}

/// Renders `crop` of the frame as `settings` ask (their shading points aside), with `points`
/// shading points or the split the pilot chooses, and the MIS heuristic the pilot chooses; the
/// pilot's time is part of the render's.
#[must_use]
pub fn render_planned(
    scene: &Scene,
    bvh: &Bvh,
    env: Option<&EnvHierarchy<'_>>,
    settings: &Settings,
    points: ShadingPoints,
    crop: Crop,
) -> (Rendered, Prepass) {
    let prepass = Prepass::run(scene, bvh, env, settings, points, None);
    let view = env.map(|e| prepass.view(e));
    let settings = Settings { shading_points: prepass.shading_points, ..*settings };
    let mut image = render_crop(scene, bvh, view.as_ref(), &settings, crop);
    prepass.charge(&mut image);
    (image, prepass)
}
