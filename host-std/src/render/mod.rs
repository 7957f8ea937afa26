//! Rendering an image whose materials are already planned: rayon over 16×16 tiles
//! ([`tiles`]), each pixel through the pipeline of [`pixel`] (camera ray, intersection,
//! shading point, light samples, the pixel's mean), samplers built and kept by
//! [`sampler_cache`], the environment's light sampled by [`shade`] as each material's
//! [`strategy`] says, the other lights' by `shade_lights`.
//! Depends on `light`, `scene` and `trace`; `plan` decides the strategies and calls in here.
//!
//! Every pixel is seeded from (seed, pixel index), so the image depends only on the scene, the
//! options, the plans and the seed, never on the thread count or on which thread rendered
//! which tile. Each pixel gets P shading points (primary rays jittered uniformly inside the
//! pixel: a box filter) and each shading point spp/P visibility samples.

pub mod brdf_samples;
pub mod crop;
pub mod pixel;
pub mod plane_products;
pub(crate) mod primary;
pub mod product_arena;
pub mod sampler_cache;
pub mod shade;
mod shade_cuts;
mod shade_lights;
pub mod strategy;
pub mod tiles;
pub use shade_cuts::Lightcuts;
pub(crate) use shade_lights::budgets;
pub(crate) mod wavefront;

use crate::light::map_buffer::{MapBuffer, PYRAMID_LINE_START};
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use crate::trace::camera::Camera;
use sampler_core::cone::Cone;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::lights::LightSet;
use std::ops::AddAssign;
use strategy::{MaterialPlan, Strategy};

/// How pixels are sampled: the budget, the seed and what is traced.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Visibility samples per pixel.
    pub spp: usize,
    /// Primary rays (shading points) per pixel; divides `spp`.
    pub shading_points: usize,
    /// The seed every pixel's sequences derive from.
    pub seed: u64,
    /// Show a progress bar on stderr (after the first second).
    pub progress: bool,
    /// Trace shadow rays (false: every direction counts as visible — unshadowed direct light,
    /// to tell the error that visibility adds from the error of sampling light × BRDF).
    pub shadows: bool,
    /// With an environment and other lights, the share of a shading point's visibility samples
    /// spent on the other lights.
    pub light_share: f64,
}

/// What every pixel of a render reads.
#[derive(Clone, Copy)]
pub struct Context<'a, 'e> {
    /// The scene.
    pub scene: &'a Scene,
    /// Its BVH.
    pub bvh: &'a Bvh,
    /// The environment light, if the scene has one.
    pub env: Option<&'a EnvHierarchy<'e>>,
    /// The scene's other lights, if any emits.
    pub lights: Option<&'a LightSet<'a>>,
    /// The summed-area table of `env`, built when a material is sampled two-stage.
    pub sat: Option<&'a [f64]>,
    /// The cell cones of the two-level product's coarse levels, built when a material is
    /// sampled with it.
    pub cones: Option<&'a CellCones>,
    /// Structured importance sampling's strata of `env`, built when a material is shaded
    /// with them.
    pub strata: Option<&'a [sampler_core::sis::Stratum]>,
    /// Lightcuts' tree, when the method is Lightcuts: it then shades the environment and the
    /// lights it holds at every shading point, in place of the environment's estimators.
    pub lightcuts: Option<&'a Lightcuts<'a>>,
    /// The pyramids of the planes whose materials sample the plane product, where any does.
    pub planes: Option<&'a plane_products::PlaneProducts>,
    /// The camera.
    pub camera: &'a Camera,
    /// How pixels are sampled.
    pub options: &'a Options,
    /// Per material, how it is shaded.
    pub plans: &'a [MaterialPlan],
}

/// What a render (or a pixel) did, counted.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Shading points shaded (primary hits on a surface that reflects light to the viewer).
    pub shading_points: u64,
    /// Shadow rays traced.
    pub shadow_rays: u64,
    /// Primary rays traced.
    pub camera_rays: u64,
    /// Pixel values that came out NaN or infinite and were set to 0.
    pub non_finite: u64,
}

impl AddAssign for Counters {
    fn add_assign(&mut self, other: Self) {
        self.shading_points += other.shading_points;
        self.shadow_rays += other.shadow_rays;
        self.camera_rays += other.camera_rays;
        self.non_finite += other.non_finite;
    }
}

/// The cell cones the two-level product reads: of its coarse level, and under extended light
/// of its finer one for the lobes that draw from it ([`strategy::TWO_LEVEL_FINE_LEVEL`]).
pub struct CellCones {
    coarse: Vec<Cone>,
    /// Empty under a sun, or where the map is no finer than the coarse level.
    fine: Vec<Cone>,
}

impl CellCones {
    /// The cones a lobe of width `lobe_width` (`Brdf::lobe_width`) draws from.
    #[must_use]
    pub fn for_lobe(&self, lobe_width: f32) -> &[Cone] {
        let fine = !self.fine.is_empty() && strategy::FINE_CELL_LOBES.contains(&lobe_width);
        if fine { &self.fine } else { &self.coarse }
    }
}

/// The cell cones the two-level product reads, built when a plan needs it: of
/// [`strategy::TWO_LEVEL_LEVEL`] and, where the light is `extended` rather than a sun, of
/// [`strategy::TWO_LEVEL_FINE_LEVEL`] (each clamped to the map's finest level).
#[must_use]
pub fn two_level_cones(env: &EnvHierarchy<'_>, plans: &[MaterialPlan], extended: bool) -> Option<CellCones> {
    let of_level = |level: u32| {
        let mut cones = vec![Cone::default(); sampler_core::cone::cell_count(level.min(env.finest_level()))];
        sampler_core::cone::build_cell_cones(&mut cones);
        cones
    };
    plans.iter().any(|p| p.strategy.is_two_level()).then(|| {
        let coarse = of_level(strategy::TWO_LEVEL_LEVEL);
        let finer = extended && env.finest_level() > strategy::TWO_LEVEL_LEVEL;
        CellCones { coarse, fine: if finer { of_level(strategy::TWO_LEVEL_FINE_LEVEL) } else { Vec::new() } }
    })
}

/// The MIS-compensated pyramid of `env` ([`EnvHierarchy::compensated`]), built when a plan
/// samples MIS, two-level-MIS (whose cells it compensates) or the plane product (MIS off its
/// planes), or `auto`'s pilot may choose them, and `env` has none attached; `None` also where nothing of the map stands above its
/// mean (the plain pyramid then serves MIS).
#[must_use]
pub fn compensated_pyramid(env: &EnvHierarchy<'_>, plans: &[MaterialPlan], pilot: bool) -> Option<MapBuffer<f32>> {
    let mis = pilot
        || plans.iter().any(|p| {
            matches!(p.strategy, Strategy::Mis { .. } | Strategy::TwoLevelMis { .. } | Strategy::PlaneProduct)
        });
    if !mis || env.has_compensated() {
        return None;
    }
    let mut out = MapBuffer::new(sampler_core::env::pyramid_len(env.finest_level()), PYRAMID_LINE_START);
    env.compensate_into(&mut out).expect("a view's own pyramid has its level's length").then_some(out)
}

/// The summed-area table two-stage sampling reads, built when a plan needs it.
#[must_use]
pub fn summed_area_table(env: &EnvHierarchy<'_>, plans: &[MaterialPlan]) -> Option<Vec<f64>> {
    plans.iter().any(|p| p.strategy == Strategy::TwoStage).then(|| {
        let mut sat = vec![0.0f64; sampler_core::two_stage::sat_len(env.finest_level())];
        sampler_core::two_stage::build_sat(env, &mut sat);
        sat
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::brdf_samples::BrdfSamples;
    use crate::scene::Bsdf;
    use sampler_core::brdf::Lambert;
    use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};

    #[test]
    fn the_compensated_pyramid_is_built_only_where_mis_may_sample() {
        let rgb: Vec<[f32; 3]> = (0..16).map(|i| [i as f32; 3]).collect();
        let mut pyramid = vec![0.0; pyramid_len(2)];
        build_pyramid(2, &rgb, &mut pyramid).unwrap();
        let env = EnvHierarchy::new(2, &pyramid, &rgb).unwrap();
        let bsdf = Bsdf::Diffuse(Lambert::new(sampler_core::glam::Vec3::ONE));
        let plan = |strategy| MaterialPlan::new(strategy, &bsdf, BrdfSamples::default());
        let (env_only, mis) = ([plan(Strategy::Env)], [plan(Strategy::Env), plan(Strategy::Mis { env_share: 0.5 })]);
        assert!(compensated_pyramid(&env, &env_only, false).is_none());
        let two_level_mis = [plan(Strategy::TwoLevelMis { two_level_share: 0.5 })];
        assert!(compensated_pyramid(&env, &two_level_mis, false).is_some(), "two-level-MIS compensates its cells");
        let built = compensated_pyramid(&env, &mis, false).expect("a MIS plan");
        assert!(compensated_pyramid(&env, &env_only, true).is_some(), "auto's pilot may choose MIS");
        let attached = env.with_compensated(&built).unwrap();
        assert!(compensated_pyramid(&attached, &mis, true).is_none(), "one is attached already");
    }
}
