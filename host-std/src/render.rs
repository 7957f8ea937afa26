//! The tracer: rayon over 16×16 tiles, every pixel seeded from (seed, pixel index) — so the
//! image depends only on the scene, the settings and the seed, never on the thread count or on
//! which thread rendered which tile. Each pixel gets P shading points (primary rays jittered
//! uniformly inside the pixel: a box filter) and each shading point spp/P visibility samples.

use crate::integrator::{self, CountingVisibility, Method, Technique};
use crate::pilot::PilotResult;
use crate::scene::{Bsdf, Scene};
use crate::trace::bvh::Bvh;
use crate::trace::camera::Camera;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use sampler_core::brdf::Brdf;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::ShadingPoint;
use sampler_core::frame::Frame;
use sampler_core::glam::{DVec2, DVec3, Vec3};
use sampler_core::points::{permutation_element, sobol02};
use sampler_core::rng::hash_combine;
use sampler_core::sampler::ProductArena;
use sampler_core::two_stage::TwoStageSampler;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// What to render and how.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    pub method: Method,
    /// Visibility samples per pixel.
    pub spp: usize,
    /// Primary rays (shading points) per pixel; divides `spp`.
    pub shading_points: usize,
    /// BRDF samples that build each product sampler.
    pub brdf_samples: usize,
    pub seed: u64,
    /// Show a progress bar on stderr (after the first second).
    pub progress: bool,
    /// Trace shadow rays (false: every direction counts as visible — unshadowed direct light,
    /// to tell the error that visibility adds from the error of sampling light × BRDF).
    pub shadows: bool,
}

/// A rendered image and what it took.
pub struct Rendered {
    pub width: usize,
    pub height: usize,
    /// Linear RGB, rows top to bottom.
    pub pixels: Vec<[f32; 3]>,
    pub render_seconds: f64,
    pub shading_points: u64,
    pub shadow_rays: u64,
    pub camera_rays: u64,
    /// Pixel values that came out NaN or infinite and were set to 0 (should stay 0).
    pub non_finite: u64,
    /// `auto`: what its pilot measured per material (empty for the other methods).
    pub pilot: Vec<PilotResult>,
    /// `auto`: seconds of the pilot, included in `render_seconds`.
    pub pilot_seconds: f64,
}

const TILE: usize = 16;

/// Renders the scene. `env` is `None` when the scene has no environment light.
pub fn render(scene: &Scene, bvh: &Bvh, env: Option<&EnvHierarchy<'_>>, settings: &Settings) -> Rendered {
    // The summed-area table exists only for the method that reads it.
    let sat = match (env, settings.method) {
        (Some(e), Method::TwoStage) => {
            let mut sat = vec![0.0f64; sampler_core::two_stage::sat_len(e.finest_level())];
            sampler_core::two_stage::build_sat(e, &mut sat);
            Some(sat)
        }
        _ => None,
    };
    let sat = sat.as_deref();
    // `auto` resolves per material once, knowing how peaked the lighting is.
    let env_peak = match (env, settings.method) {
        (Some(e), Method::Auto | Method::ProductMis) => e.peak(5),
        _ => f32::MAX,
    };
    let plans: Vec<MaterialPlan> = scene
        .materials
        .iter()
        .map(|m| {
            let method = settings.method.for_material(&m.bsdf, env_peak);
            let split = match (settings.method, method) {
                (_, Method::ProductMis) => integrator::product_share(&m.bsdf, env_peak),
                (Method::Auto, Method::Mis) => integrator::auto_env_share(&m.bsdf, env_peak),
                _ => 0.5,
            };
            MaterialPlan { method, reuse_cosine: integrator::reuse_cosine(&m.bsdf), split }
        })
        .collect();
    let camera = Camera::new(&scene.camera);
    let (w, h) = (camera.width as usize, camera.height as usize);
    // Timed from here: `auto`'s pilot is part of its cost.
    let start = Instant::now();
    let (plans, pilot) = match (settings.method, env) {
        (Method::Auto, Some(e)) => crate::pilot::choose(scene, bvh, e, &camera, settings, &plans, env_peak),
        _ => (plans, Vec::new()),
    };
    let pilot_seconds = start.elapsed().as_secs_f64();
    let tiles: Vec<(usize, usize)> =
        (0..h.div_ceil(TILE)).flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx, ty))).collect();
    let counters = [AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0)];
    let bar = ProgressBar::with_draw_target(Some(tiles.len() as u64), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{wide_bar}] {percent}% ETA {eta}").expect("valid template"),
    );
    let shown = std::sync::atomic::AtomicBool::new(false);
    let results: Vec<Vec<[f32; 3]>> = tiles
        .par_iter()
        .map(|&(tx, ty)| {
            let mut scratch = Scratch::new(scene.materials.len(), settings.shading_points);
            let mut out = Vec::with_capacity(TILE * TILE);
            for y in ty * TILE..((ty + 1) * TILE).min(h) {
                for x in tx * TILE..((tx + 1) * TILE).min(w) {
                    out.push(pixel(scene, bvh, env, sat, &camera, settings, &plans, x, y, &mut scratch));
                }
            }
            for (c, l) in counters.iter().zip(scratch.stats) {
                c.fetch_add(l, Ordering::Relaxed);
            }
            if settings.progress && start.elapsed().as_secs_f64() > 1.0 && !shown.swap(true, Ordering::Relaxed) {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
            bar.inc(1);
            out
        })
        .collect();
    bar.finish_and_clear();
    let render_seconds = start.elapsed().as_secs_f64();
    let mut pixels = vec![[0.0f32; 3]; w * h];
    for (&(tx, ty), tile) in tiles.iter().zip(&results) {
        let mut k = 0;
        for y in ty * TILE..((ty + 1) * TILE).min(h) {
            for x in tx * TILE..((tx + 1) * TILE).min(w) {
                pixels[y * w + x] = tile[k];
                k += 1;
            }
        }
    }
    let [shading_points, shadow_rays, camera_rays, non_finite] = counters.map(|c| c.into_inner());
    Rendered {
        width: w,
        height: h,
        pixels,
        render_seconds,
        shading_points,
        shadow_rays,
        camera_rays,
        non_finite,
        pilot,
        pilot_seconds,
    }
}

/// A primary ray's hit, ready to shade.
struct Hit {
    frame: Frame,
    wo: Vec3,
    /// The BRDF at this hit when its material is textured; otherwise the material's.
    bsdf: Option<Bsdf>,
    origin: Vec3,
    material: usize,
    method: Method,
    index: usize,
}

/// How a material is shaded, resolved once per render.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MaterialPlan {
    /// The method (`auto` resolved for the material and lighting).
    pub method: Method,
    /// Cosine of the angle within which a product-MIS sampler is reused.
    pub reuse_cosine: f32,
    /// Share of an MIS budget spent on the first technique (product or env samples).
    pub split: f64,
}

/// A tile's scratch memory, reused from pixel to pixel.
pub(crate) struct Scratch {
    /// For the product samplers built per shading point.
    arena: Option<Box<ProductArena>>,
    /// The pixel's primary hits.
    hits: Vec<Hit>,
    /// Per material, the product-MIS sampler built last and where (see `SharedSampler`).
    shared: Vec<Option<SharedSampler>>,
    /// Shading points, shadow rays, camera rays and non-finite pixel values.
    stats: [u64; 4],
}

impl Scratch {
    pub fn new(materials: usize, shading_points: usize) -> Self {
        Self {
            arena: None,
            hits: Vec::with_capacity(shading_points.clamp(1, 64)),
            shared: (0..materials).map(|_| None).collect(),
            stats: [0; 4],
        }
    }
}

/// A product-MIS sampler kept for the next pixels of the tile, with the normal and mirror
/// direction of the shading point it was built at.
struct SharedSampler {
    arena: Box<ProductArena>,
    normal: Vec3,
    mirror: Vec3,
}

/// One pixel: the mean over its shading points (product-MIS samplers shared per pixel and
/// material, and reused by the tile's next pixels while their shading points stay within
/// the material's reuse angle; every other sampler built per shading point).
#[allow(clippy::too_many_arguments)]
pub(crate) fn pixel(
    scene: &Scene,
    bvh: &Bvh,
    env: Option<&EnvHierarchy<'_>>,
    sat: Option<&[f64]>,
    camera: &Camera,
    s: &Settings,
    plans: &[MaterialPlan],
    x: usize,
    y: usize,
    scratch: &mut Scratch,
) -> [f32; 3] {
    let Scratch { arena, hits, shared: kept, stats } = scratch;
    let seed = hash_combine(s.seed, (y * camera.width as usize + x) as u64);
    // The seed of the pixel's light-sample sequences, shared by its shading points (each takes
    // its own run of them, see `integrator::shade`).
    let light_seed = hash_combine(seed, 0x11647);
    let p = s.shading_points.max(1);
    let budget = (s.spp / p).max(1);
    let mut film = [DVec2::ZERO; 64];
    // Accumulated in f64: single samples of a 1e30 map can exceed the f32 range.
    let mut sum = DVec3::ZERO;
    let mut done = 0;
    while done < p {
        let m = (p - done).min(64);
        sobol02(seed, done as u32, &mut film[..m]);
        hits.clear();
        for (k, f) in film[..m].iter().enumerate() {
            let dir = camera.direction(x as f32 + f.x as f32, y as f32 + f.y as f32);
            stats[2] += 1;
            let Some(hit) = bvh.intersect(camera.origin, dir, camera.near_clip, f32::INFINITY) else {
                if let (Some(e), false) = (env, scene.hide_emitters) {
                    sum += e.radiance(dir).as_dvec3();
                }
                continue;
            };
            let material = &scene.materials[hit.material as usize];
            let wo = -dir;
            let (mut n, mut ns) = (hit.normal, hit.shading_normal);
            if n.dot(wo) < 0.0 {
                // Seen from the back, a one-sided surface reflects nothing.
                if !material.twosided {
                    continue;
                }
                (n, ns) = (-n, -ns);
            }
            // The shading frame follows the interpolated normal, kept on the viewer's side
            // of the surface.
            if ns.dot(n) <= 0.0 {
                ns = n;
            }
            if env.is_none() {
                continue;
            }
            let eps = 1e-4 * (1.0 + hit.point.abs().max_element());
            hits.push(Hit {
                frame: Frame::from_normal(ns),
                wo,
                bsdf: match (&material.texture, hit.uv) {
                    (Some(t), Some(uv)) => Some(t.0.bsdf_at(uv)),
                    _ => None,
                },
                origin: hit.point + n * eps,
                material: hit.material as usize,
                method: plans[hit.material as usize].method,
                index: done + k,
            });
        }
        if let Some(env) = env {
            // Product-MIS shares one sampler per pixel and material, built from the group's first
            // shading point: MIS with BRDF sampling covers where another point's lobe leaves the
            // shared B̃ (measured 2.4× faster at equal error on s1). Plain product, wavelet and
            // two-stage build per shading point: shared, they grow fireflies near silhouettes and
            // on sharp lobes, where only the defensive mixture covers the mismatch.
            let mut first = 0;
            while first < hits.len() {
                let group = hits[first].material;
                let shared = hits[first].method == Method::ProductMis;
                if shared && hits[..first].iter().any(|h| h.material == group && h.method == Method::ProductMis) {
                    first += 1;
                    continue;
                }
                let lead = &hits[first];
                let lead_sp = shading_point(scene, lead);
                let build_seed = hash_combine(seed, 0xb5df ^ (group as u64) << 20);
                let product;
                let two_stage;
                let technique = match lead.method {
                    Method::ProductMis => {
                        let (normal, mirror) = (lead.frame.n, reflect(lead.wo, lead.frame.n));
                        let cos = plans[group].reuse_cosine;
                        let near = |c: &SharedSampler| c.normal.dot(normal) >= cos && c.mirror.dot(mirror) >= cos;
                        let slot = &mut kept[group];
                        if lead.bsdf.is_some() || !slot.as_ref().is_some_and(near) {
                            let c = slot.get_or_insert_with(|| SharedSampler {
                                arena: Box::new(ProductArena::new()),
                                normal,
                                mirror,
                            });
                            let params = integrator::product_params(lead.method, s.brdf_samples);
                            c.arena.build(env, lead_sp.brdf, &lead_sp.frame, lead_sp.wo, &params, build_seed);
                            (c.normal, c.mirror) = (normal, mirror);
                        }
                        product = slot.as_ref().and_then(|c| c.arena.last_built(env)).expect("built above");
                        Technique::Product(&product)
                    }
                    Method::Product | Method::Wavelet => {
                        let a = arena.get_or_insert_with(|| Box::new(ProductArena::new()));
                        let params = integrator::product_params(lead.method, s.brdf_samples);
                        product = a.build(env, lead_sp.brdf, &lead_sp.frame, lead_sp.wo, &params, build_seed);
                        Technique::Product(&product)
                    }
                    Method::TwoStage => match sat {
                        Some(sat) => {
                            two_stage = TwoStageSampler::new(env, sat, lead_sp.brdf, &lead_sp.frame, lead_sp.wo);
                            Technique::TwoStage(&two_stage)
                        }
                        None => Technique::None,
                    },
                    _ => Technique::None,
                };
                let members = hits[first..]
                    .iter()
                    .enumerate()
                    .filter(|(k, h)| if shared { h.material == group } else { *k == 0 });
                for (_, h) in members {
                    stats[0] += 1;
                    let origin = h.origin;
                    let shadows = s.shadows;
                    let mut vis = CountingVisibility {
                        test: |d: Vec3| !shadows || !bvh.occluded(origin, d, 0.0, f32::INFINITY),
                        rays: 0,
                    };
                    sum += integrator::shade(
                        h.method,
                        env,
                        &shading_point(scene, h),
                        budget,
                        plans[h.material].split,
                        light_seed,
                        permutation_element(h.index as u32, p as u32, light_seed as u32) as usize,
                        &technique,
                        &mut vis,
                    );
                    // Only rays traced count.
                    stats[1] += if shadows { vis.rays } else { 0 };
                }
                first += 1;
            }
        }
        done += m;
    }
    let mean = (sum / p as f64).as_vec3();
    if mean.is_finite() {
        mean.to_array()
    } else {
        // The mean itself exceeds the f32 range of the output (or is NaN): counted, written as 0.
        stats[3] += 1;
        [0.0; 3]
    }
}

/// The mirror direction of `wo` about `n`.
fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

/// The hit's shading point: its own BRDF if its material is textured, the material's otherwise.
fn shading_point<'a>(scene: &'a Scene, h: &'a Hit) -> ShadingPoint<'a, dyn Brdf + 'a> {
    let brdf = match &h.bsdf {
        Some(b) => b.as_brdf(),
        None => scene.materials[h.material].bsdf.as_brdf(),
    };
    ShadingPoint { frame: h.frame, wo: h.wo, brdf }
}
