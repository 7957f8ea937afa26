//! Embedding `sampler-core` in an engine, the code to copy: the engine's own BRDF (a trait
//! impl), its own visibility query (a closure), a map and pyramid shared read-only by every
//! thread, one product arena per thread, and product-MIS per shading point.
//! `cargo run --release -p sampler-core --example embed`
//!
//! docs/design.md §9 shows the part between the `[embed]` markers; a test keeps the two equal.

use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, BrdfSample};
use sampler_core::env::{EnvHierarchy, build_pyramid, luminance, pyramid_len, sanitize_rgb};
use sampler_core::estimator::{self, ShadingPoint};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::rng::hash_combine;
use sampler_core::sampler::{ProductArena, ProductParams};
use sampler_core::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};

/// The engine's material: a two-tone diffuse surface (any `Brdf` works, built in or not).
struct Plaster {
    albedo: Vec3,
}

impl Brdf for Plaster {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        self.albedo * (core::f32::consts::FRAC_1_PI * wi.z)
    }
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        (wo.z > 0.0).then(|| {
            let wi = square_to_cosine_hemisphere(u);
            BrdfSample { wi, value: self.eval(wo, wi), pdf: square_to_cosine_hemisphere_pdf(wi) }
        })
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 { square_to_cosine_hemisphere_pdf(wi) } else { 0.0 }
    }
    fn is_diffuse(&self) -> bool {
        true
    }
}

/// The engine's scene, for the visibility query: a sphere hovering over the shading points.
fn occluded(p: Vec3, dir: Vec3) -> bool {
    let (centre, radius) = (Vec3::new(0.0, 0.0, 2.0), 0.8f32);
    let oc = p - centre;
    let b = oc.dot(dir);
    let c = oc.length_squared() - radius * radius;
    b * b - c > 0.0 && -b - (b * b - c).sqrt() > 0.0
}

/// A 256 × 256 equal-area sky with a small sun, as an engine would load it (row-major RGB).
fn load_equal_area_map(level: u32) -> Vec<[f32; 3]> {
    let n = 1usize << level;
    let sun = Vec3::new(0.4, 0.2, 0.9).normalize();
    (0..n * n)
        .map(|i| {
            let uv = Vec2::new(((i % n) as f32 + 0.5) / n as f32, ((i / n) as f32 + 0.5) / n as f32);
            let d = square_to_sphere(uv);
            let sky = 0.3 + 0.7 * d.z.max(0.0);
            let s = if d.dot(sun) > 0.9995 { 3e3 } else { 0.0 };
            [0.5 * sky + s, 0.7 * sky + s, sky + s]
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // [embed]
    // Once: the host owns the map (row-major RGB, sanitized) and its pyramid; threads share
    // both read-only through the `EnvHierarchy` view.
    let level = 8;
    let mut rgb = load_equal_area_map(level);
    sanitize_rgb(&mut rgb);
    let mut pyramid = vec![0.0f32; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid)?;
    let env = EnvHierarchy::new(level, &pyramid, &rgb)?;
    let brdf = Plaster { albedo: Vec3::new(0.8, 0.7, 0.6) };
    let params = ProductParams::for_mis(256);
    let seed = 7u64;

    // A row of shading points on the ground plane (normal +z), one per "pixel", split over
    // threads: each thread owns one arena (~45 KB) and reuses it for every point.
    let pixels: Vec<usize> = (0..64).collect();
    let radiance: Vec<Vec3> = std::thread::scope(|scope| {
        let workers: Vec<_> = pixels
            .chunks(16)
            .map(|chunk| {
                let (env, brdf, params) = (&env, &brdf, &params);
                scope.spawn(move || {
                    let mut arena: Box<ProductArena> = Box::default();
                    let mut out = Vec::with_capacity(chunk.len());
                    for &pixel in chunk {
                        let p = Vec3::new(pixel as f32 / 16.0 - 2.0, 0.0, 0.0);
                        let frame = Frame::from_normal(Vec3::Z);
                        let wo = Vec3::new(0.3, -0.4, 0.866).normalize();
                        // Per shading point: seeded by the pixel, not the thread, so the image
                        // is the same whatever the thread count.
                        let point_seed = hash_combine(seed, pixel as u64);
                        let sampler = arena.build(env, brdf, &frame, wo, params, point_seed).expect("256 samples fit");
                        let sp = ShadingPoint { frame, wo, brdf };
                        let (mut u, mut v) = ([DVec2::ZERO; 16], [DVec2::ZERO; 16]);
                        sobol02(point_seed ^ 1, 0, &mut u);
                        sobol02(point_seed ^ 2, 0, &mut v);
                        let mut sum = Vec3::ZERO;
                        for (u, v) in u.iter().zip(&v) {
                            let mut visible = |dir: Vec3| !occluded(p, dir);
                            let [a, b] = estimator::sampled_mis(&sampler, &sp, *u, v.as_vec2(), &mut visible);
                            sum += (a.value + b.value).as_vec3();
                        }
                        out.push(sum / 16.0);
                    }
                    out
                })
            })
            .collect();
        workers.into_iter().flat_map(|w| w.join().expect("a worker")).collect()
    });
    // [embed]

    let shadowed = radiance.iter().map(|c| luminance(*c)).fold(f32::INFINITY, f32::min);
    let lit = radiance.iter().map(|c| luminance(*c)).fold(0.0f32, f32::max);
    println!("{} shading points: luminance {shadowed:.4} under the sphere, {lit:.4} in the open", radiance.len());
    Ok(())
}
