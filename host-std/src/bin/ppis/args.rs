//! The arguments `render`, `info` and `report` share: the scene to load and how to sample it.

use clap::Args;
use host_std::light::lights::{LightOptions, LightSelection};
use host_std::plan::Method;
use host_std::plan::carrier::Carrier;
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::Scene;
use std::path::PathBuf;

/// Largest visibility-sample count per pixel accepted (2^26: converging single techniques on
/// sharp highlights takes millions; pixel counters are u64, per-point indices u32).
pub(crate) const MAX_SPP: i64 = 1 << 26;

#[derive(Args)]
pub(crate) struct SceneArgs {
    /// Scene file: .json (docs/scene-format.md) or USD (.usda, .usdc, .usdz, .usd). Without
    /// it: the embedded default scene.
    pub(crate) scene: Option<PathBuf>,
    /// USD: the camera prim to render through (default: the render settings' camera, else
    /// the stage's first camera).
    #[arg(long)]
    pub(crate) camera: Option<String>,
    /// USD: the RenderSettings prim whose resolution and camera apply (default: the layer's
    /// renderSettingsPrimPath, else the stage's only RenderSettings prim).
    #[arg(long, value_name = "PRIM")]
    pub(crate) render_settings: Option<String>,
    /// Environment map replacing the scene's (lat-long .exr/.hdr/.png/.jpg, or a square
    /// equal-area map).
    #[arg(long)]
    pub(crate) env: Option<PathBuf>,
    /// Radiance scale of the environment (with --env; otherwise the scene's).
    #[arg(long)]
    pub(crate) env_scale: Option<f32>,
    /// Rotation of the environment about +Y in degrees (d_world = R_y·d_local).
    #[arg(long, allow_hyphen_values = true)]
    pub(crate) env_rotate_y: Option<f32>,
    /// USD: the time code to render the stage at — a number (time samples interpolated
    /// linearly, held outside their range), `earliest` (each attribute's first sample, the
    /// default, as Pixar's usdrecord) or `default` (default values only, UsdTimeCode::Default).
    /// A JSON or built-in scene is static: the same at every frame.
    #[arg(long, value_name = "F", value_parser = parse_frame, allow_hyphen_values = true)]
    pub(crate) frame: Option<String>,
}

/// `--frame`: a finite number (written back as Rust writes an f64, so `10` and `10.0` are the
/// same frame), `earliest` or `default`.
fn parse_frame(text: &str) -> Result<String, String> {
    match text {
        "earliest" | "default" => Ok(text.to_string()),
        _ => match text.parse::<f64>() {
            Ok(t) if t.is_finite() => Ok(t.to_string()),
            _ => Err(format!("{text:?} is not a time code (a finite number, `earliest` or `default`)")),
        },
    }
}

/// How a render samples, shared by `render` and `report`.
#[derive(Args)]
pub(crate) struct SamplingArgs {
    /// Primary rays (shading points) per pixel, each spending spp/P visibility samples
    /// [default: spp over the method's light samples per shading point — two pairs for the
    /// MIS methods (eight under an environment and other lights), one for env, brdf and ris,
    /// more for the samplers built per shading point].
    /// `render`: a P given must divide --spp; `report`: reduced to a divisor of each spp.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub(crate) shading_points: Option<u32>,
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// Worker threads, for the BVH and environment builds and the render (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub(crate) threads: Option<u32>,
    /// Image width, overriding the scene's camera.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub(crate) width: Option<u32>,
    /// Image height, overriding the scene's camera.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub(crate) height: Option<u32>,
    /// No shadow rays: every light direction counts as visible (for analysis: the error of
    /// sampling light × BRDF without the error visibility adds).
    #[arg(long)]
    pub(crate) unshadowed: bool,
    /// How lights besides the environment are picked per shading point: `tree` (a light tree:
    /// power, distance and orientation) or `power` (in proportion to power alone).
    #[arg(long, value_name = "tree|power", default_value = "tree", value_parser = parse_light_selection)]
    pub(crate) light_selection: LightSelection,
    /// With an environment and other lights, the share of each shading point's visibility
    /// samples spent on the other lights, in (0, 1).
    #[arg(long, value_name = "SHARE", default_value_t = 0.5, value_parser = parse_share)]
    pub(crate) light_share: f64,
    /// Where the scene has an environment, how a distant light with an angular size (the sun)
    /// is sampled: `cone` (by its cone, MIS with BRDF samples), `map` (rasterised into the
    /// environment map, so that the map's samplers, the product among them, sample it) or
    /// `auto` (whichever a pilot render of the scene measures better).
    #[arg(long, value_enum, value_name = "cone|map|auto", default_value = "auto")]
    pub(crate) distant_carrier: Carrier,
    /// Short for `--distant-carrier map`.
    #[arg(long, conflicts_with = "distant_carrier")]
    pub(crate) distant_in_env: bool,
    /// `--method sis`: the strata (directional lights) the environment is stratified into
    /// (the paper's 300 by default), each shaded at every shading point.
    #[arg(long, value_name = "N", default_value_t = sampler_core::sis::DEFAULT_LIGHTS, value_parser = parse_sis_lights)]
    pub(crate) sis_lights: usize,
    /// `--method lightcuts`: the relative error bound each cluster of a cut stays under (the
    /// paper's 0.02), in (0, 1).
    #[arg(long, value_name = "E", default_value_t = sampler_core::lightcuts::DEFAULT_ERROR, value_parser = parse_lightcut_error)]
    pub(crate) lightcut_error: f32,
}

/// `--sis-lights`'s value: at least one stratum, at most 65 536 (a stratum per cell of the
/// stratification's finest level).
fn parse_sis_lights(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(n) if (1..=65_536).contains(&n) => Ok(n),
        _ => Err(format!("{s:?} is not a number of strata in 1..=65536")),
    }
}

/// `--lightcut-error`'s value.
fn parse_lightcut_error(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("{s:?} is not a relative error in (0, 1)")),
    }
}

/// `--light-share`'s value.
fn parse_share(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("{s:?} is not a share in (0, 1)")),
    }
}

/// `--light-selection`'s value.
fn parse_light_selection(s: &str) -> Result<LightSelection, String> {
    match s {
        "tree" => Ok(LightSelection::Tree),
        "power" => Ok(LightSelection::Power),
        _ => Err(format!("unknown light selection {s:?} (tree or power)")),
    }
}

impl SamplingArgs {
    /// How the lights besides the environment are sampled, and the baselines' lights.
    pub(crate) fn lights(&self) -> LightOptions {
        LightOptions {
            selection: self.light_selection,
            share: self.light_share,
            sis_lights: self.sis_lights,
            lightcut_error: self.lightcut_error,
        }
    }

    /// `--distant-carrier`, `--distant-in-env` read as `map`.
    pub(crate) fn carrier(&self) -> Carrier {
        if self.distant_in_env { Carrier::Map } else { self.distant_carrier }
    }

    /// --width and --height, as given.
    pub(crate) fn size(&self) -> (Option<u32>, Option<u32>) {
        (self.width, self.height)
    }

    /// Applies --width/--height to the scene's camera.
    pub(crate) fn resize(&self, scene: &mut Scene) {
        if let Some(w) = self.width {
            scene.camera.width = w;
        }
        if let Some(h) = self.height {
            scene.camera.height = h;
        }
    }

    /// Worker threads: --threads, or every core.
    pub(crate) fn threads(&self) -> usize {
        self.threads.map_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()), |t| t as usize)
    }
}

/// `--brdf-samples` within what the renderer's product arenas hold: the one-line error naming
/// both otherwise.
pub(crate) fn check_brdf_samples(brdf_samples: u32) -> anyhow::Result<()> {
    host_std::render::product_arena::check_brdf_samples(brdf_samples as usize)
        .map_err(|e| anyhow::anyhow!("--brdf-samples {brdf_samples}: {e}"))
}

/// The render's K: `--brdf-samples` for every material, checked, or without it each
/// material's from its lobes.
pub(crate) fn brdf_samples(given: Option<u32>) -> anyhow::Result<BrdfSamples> {
    match given {
        Some(k) => check_brdf_samples(k).map(|()| BrdfSamples::Fixed(k as usize)),
        None => Ok(BrdfSamples::PerLobe),
    }
}

pub(crate) fn parse_method(s: &str) -> Result<Method, String> {
    s.parse()
}
