//! `ppis info`: what a scene holds and what a render of it would build, or USD conformance
//! against Pixar's answers.

use crate::args::SceneArgs;
use crate::load::load_scene;
use anyhow::Result;
#[cfg(not(feature = "usd"))]
use anyhow::bail;
use clap::Args;
use host_std::light::environment::EnvSource;
use host_std::plan::Method;
use host_std::plan::pace::MAX_SLOWDOWN;
use host_std::plan::pilot::{self, MAX_PILOT_SHARE, MAX_PIXELS, MIN_PIXELS, OVERRIDE_MARGIN, PILOT_SHARE, PLANS};
use host_std::plan::pilot::{COSTLIER_OVERRIDE_MARGIN, SEPARATION};
use host_std::plan::rules::{
    AUTO_DIFFUSE_ENV_SHARE, PRODUCT_ALPHA, PRODUCT_ALPHA_EXTENDED, SMOOTH_LIGHTING_PEAK, SUN_PEAK, WIDE_LOBE,
    WIDE_LOBE_PRODUCT_SHARE,
};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::Scene;
use host_std::trace::bvh::Bvh;
use sampler_core::light::{Light, SceneLight};
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct InfoArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// USD conformance: check every USD file under DIR that has a `<name>.expected.json`
    /// (Pixar's answers: world matrices, bound materials, metadata) and import it.
    #[arg(long, value_name = "DIR")]
    expected: Option<PathBuf>,
}

pub(crate) fn info_command(args: InfoArgs) -> Result<()> {
    if let Some(dir) = &args.expected {
        return conformance(dir);
    }
    let loaded = load_scene(&args.scene, (None, None), true)?;
    #[cfg(feature = "usd")]
    if let Some(usd) = &loaded.usd {
        host_std::scene::usd_info::print_import(usd);
    }
    if !loaded.notes.is_empty() {
        println!("not rendered as authored ({}):", loaded.notes.len());
        for n in &loaded.notes {
            println!("  {n}");
        }
    }
    let scene = loaded.scene;
    print_scene(&scene);
    println!(
        "a render builds: {} BVH primitives{}; {}",
        Bvh::count_primitives(&scene),
        if scene.env.is_some() { ", the env hierarchy" } else { "" },
        sampling_summary()
    );
    Ok(())
}

/// The scene's camera, objects, materials and environment.
fn print_scene(scene: &Scene) {
    let c = &scene.camera;
    println!("scene {}", scene.name);
    println!(
        "camera: {}×{}, fov {}°, from {:?} to {:?}",
        c.width,
        c.height,
        c.fov_y_deg,
        c.origin.to_array(),
        c.target.to_array()
    );
    println!("objects: {} ({} triangles)", scene.objects.len(), scene.triangle_count());
    for (i, m) in scene.materials.iter().enumerate() {
        let twosided = if m.twosided { ", two-sided" } else { "" };
        // The K a render without --brdf-samples builds its product samplers from.
        let k = BrdfSamples::PerLobe.for_bsdf(&m.bsdf);
        println!("  material {i}: {}{twosided} (product samplers from {k} BRDF samples)", m.bsdf.kind());
    }
    print_lights(scene);
    match &scene.env {
        None if !scene.lights.is_empty() => println!("environment: none"),
        None => println!("environment: none, no lights — a render builds no env hierarchy and is black"),
        Some((EnvSource::Sky { level }, _)) => {
            println!("environment: built-in sky, equal-area {}² (pyramid {} MB)", 1u32 << level, pyramid_mb(*level))
        }
        Some((EnvSource::Bytes { name, .. }, p)) => println!(
            "environment: {} (tint {:?}), resampled to a power-of-two equal-area square",
            name.display(),
            p.tint
        ),
        Some((EnvSource::Constant { .. }, p)) => println!("environment: constant radiance {:?}", p.tint),
        Some((EnvSource::File(path), p)) => println!(
            "environment: {} (scale {}, rotate_y {}°), resampled to a power-of-two equal-area square",
            path.display(),
            p.scale,
            p.rotate_y_deg
        ),
    }
}

/// The scene's lights besides the environment, counted by kind (a mesh light's triangles each).
fn print_lights(scene: &Scene) {
    if scene.lights.is_empty() {
        return;
    }
    let mut kinds: Vec<(&str, usize)> = Vec::new();
    for l in &scene.lights {
        let kind = match l {
            SceneLight::Point(_) => "point",
            SceneLight::Sphere(_) => "sphere",
            SceneLight::Rect(_) => "rectangle",
            SceneLight::Disk(_) => "disk",
            SceneLight::Triangle(_) => "mesh triangle",
            SceneLight::Distant(d) if d.is_delta() => "distant (delta)",
            SceneLight::Distant(_) => "distant (with an angle)",
        };
        match kinds.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, n)) => *n += 1,
            None => kinds.push((kind, 1)),
        }
    }
    let list: Vec<String> = kinds.iter().map(|(k, n)| format!("{n} {k}")).collect();
    let shapings = || scene.lights.iter().filter_map(SceneLight::shaping).filter(|s| !s.is_none());
    let (shaped, profiled) = (shapings().count(), shapings().filter(|s| s.profile().is_some()).count());
    let shaped = match (shaped, profiled) {
        (0, _) => String::new(),
        (n, 0) => format!("; {n} shaped (cone or focus)"),
        (n, p) => format!("; {n} shaped, {p} of them by an IES profile"),
    };
    println!(
        "lights: {} ({}{shaped}); a render picks one per sample by a light tree (--light-selection), samples it by solid angle, MIS with BRDF samples",
        scene.lights.len(),
        list.join(", ")
    );
}

/// What the methods build and how `auto` decides, from the constants that decide it.
fn sampling_summary() -> String {
    let mut candidates: Vec<&str> = Vec::new();
    for c in &PLANS {
        let name = Method::of(c.strategy).name();
        if !candidates.contains(&name) {
            candidates.push(name);
        }
    }
    let last = candidates.pop().unwrap_or_default();
    format!(
        "product samplers for methods product and wavelet (per shading point), product-mis (per pixel and material, reused by nearby pixels; {WIDE_LOBE_PRODUCT_SHARE} of its samples from the product on GGX conductors with α ≥ {WIDE_LOBE} when the map's peak is under {SUN_PEAK}, half elsewhere), two-level-mis (per pixel and material, reused likewise), plane-product (per normal of a diffuse material's flat objects, on first use); auto = plane-product on diffuse materials whose objects are all flat when the map's peak is under {SUN_PEAK}, product-mis on GGX conductors with α in {PRODUCT_ALPHA:?} ({PRODUCT_ALPHA_EXTENDED:?} when the map's peak is under {SUN_PEAK}: no sun), mis on the other materials ({AUTO_DIFFUSE_ENV_SHARE} of it env samples on diffuse surfaces when the peak is under {SUN_PEAK}), or BRDF sampling when the lighting is smooth (peak < {SMOOTH_LIGHTING_PEAK}) — then checked per material by a pilot render of {MIN_PIXELS}–{MAX_PIXELS} of its pixels with the candidate plans {} and {last} (those whose sample weights are bounded there, the two MIS methods at the rules' splits; of {} plans in all: {}), each at about MIS's cost per shading point (fewer samples for a costlier plan), which replaces the rule's plan where another measures {OVERRIDE_MARGIN}× better ({COSTLIER_OVERRIDE_MARGIN}× where it costs more per sample) and by {SEPARATION} standard errors (about {}% of the render, at most {}%: with fewer than {MIN_PIXELS} pixels per material within that, the rules decide alone); the materials left at plain MIS's cost or below then take more samples where the others' plans make the image costlier, as long as that slows it by at most {}%",
        candidates.join(", "),
        PLANS.len(),
        (0..PLANS.len()).map(pilot::plan_name).collect::<Vec<_>>().join(", "),
        PILOT_SHARE * 100.0,
        MAX_PILOT_SHARE * 100.0,
        ((MAX_SLOWDOWN - 1.0) * 100.0).round(),
    )
}

/// Megabytes of the built-in sky's map and importance pyramid at `level`.
fn pyramid_mb(level: u32) -> f64 {
    (sampler_core::env::pyramid_len(level) * 4 + (1usize << (2 * level)) * 12) as f64 / 1e6
}

#[cfg(feature = "usd")]
fn conformance(dir: &Path) -> Result<()> {
    host_std::scene::usd_info::conformance(dir)
}

#[cfg(not(feature = "usd"))]
fn conformance(_dir: &Path) -> Result<()> {
    bail!("--expected: this ppis was built without USD support (cargo feature `usd`)")
}
