//! Variance per shading point of the two-level product (8×8, 16×16, 32×32 cells) beside the
//! quadtree product and plain MIS, each in its MIS form with BRDF sampling and alone, under a
//! smooth sky and under a sky with a sun 1e5× brighter than the sky: how much of the quadtree's
//! gain the cheap product keeps. Each estimate is `PAIRS` sample pairs from one build (one
//! shading point); the relative variance is over 400 builds (different BRDF samples for the
//! quadtree), times `PAIRS`, so 1 means "as good as one sample pair of a perfect-ratio
//! estimator of unit relative variance".
//! `cargo run --release -p sampler-core --example two_level_variance`
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, RoughConductor};
use sampler_core::cone::{Cone, build_cell_cones, cell_count};
use sampler_core::direction::DirectionSampler;
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::estimator::{self, ShadingPoint, luminance64};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::sampler::{ProductArena, ProductParams};
use sampler_core::two_level::TwoLevelArena;
use std::time::Instant;

const PAIRS: usize = 16;
const BUILDS: u64 = 400;

fn sky(level: u32, sun: Option<Vec3>) -> (Vec<[f32; 3]>, Vec<f32>) {
    let m = 1usize << level;
    let mut rgb = vec![[0.0f32; 3]; m * m];
    for y in 0..m {
        for x in 0..m {
            let d = square_to_sphere(Vec2::new((x as f32 + 0.5) / m as f32, (y as f32 + 0.5) / m as f32));
            let mut v = 0.2 + d.z.max(0.0) + 0.3 * (5.0 * d.x).sin().abs();
            if let Some(s) = sun
                && d.dot(s) > 0.99996
            {
                v = 1e5;
            }
            rgb[y * m + x] = [v * 0.8, v, v * 1.2];
        }
    }
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    (rgb, pyramid)
}

/// Relative variance × PAIRS and microseconds per shading point (build + PAIRS pairs) of an
/// estimator given as a closure from the build index to one shading point's mean.
fn measure(mut f: impl FnMut(u64) -> f64) -> (f64, f64) {
    let t = Instant::now();
    let v: Vec<f64> = (0..BUILDS).map(&mut f).collect();
    let us = t.elapsed().as_secs_f64() * 1e6 / BUILDS as f64;
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
    (var / (mean * mean) * PAIRS as f64, us)
}

fn main() {
    let level = 10;
    let sun = Vec3::new(0.5, 0.3, 0.81).normalize();
    let cones: Vec<Vec<Cone>> = [3u32, 4, 5]
        .iter()
        .map(|&l| {
            let mut c = vec![Cone::default(); cell_count(l)];
            build_cell_cones(&mut c);
            c
        })
        .collect();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let mut two: Box<TwoLevelArena> = Box::default();
    let brdfs: Vec<(&str, Box<dyn Brdf>)> = vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.7)))),
        ("ggx 0.01", Box::new(RoughConductor::new(0.01, Vec3::ONE))),
        ("ggx 0.05", Box::new(RoughConductor::new(0.05, Vec3::ONE))),
        ("ggx 0.1", Box::new(RoughConductor::new(0.1, Vec3::ONE))),
        ("ggx 0.3", Box::new(RoughConductor::new(0.3, Vec3::ONE))),
        ("carpaint", Box::new(CarPaint::default())),
    ];
    println!("relative variance x {PAIRS} (µs per shading point: build + {PAIRS} pairs, no rays)");
    for (map, with_sun) in [("smooth sky", None), ("sky + sun 1e5", Some(sun))] {
        let (rgb, pyramid) = sky(level, with_sun);
        let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
        println!(
            "\n{map}: {:<10} {:>18} {:>18} {:>18} {:>18} {:>18}",
            "", "mis", "product-mis", "2L-mis 8", "2L-mis 16", "2L-mis 32"
        );
        for (name, brdf) in &brdfs {
            // A view whose mirror direction passes 10° from the sun.
            let normal = (sun + Vec3::new(-0.2, 0.1, 1.0).normalize()).normalize();
            let frame = Frame::from_normal((normal + Vec3::new(0.08, 0.0, 0.0)).normalize());
            let wo = Vec3::new(-0.2, 0.1, 1.0).normalize();
            let sp = ShadingPoint { frame, wo, brdf: brdf.as_ref() };
            // One shading point's MIS estimate from `PAIRS` pairs, whatever the sampler.
            let pairs = |s: &dyn DirectionSampler, seed: u64| {
                let (mut p, mut q) = ([DVec2::ZERO; PAIRS], [DVec2::ZERO; PAIRS]);
                sobol02(seed + 77, 0, &mut p);
                sobol02(seed + 991, 0, &mut q);
                let sum: f64 = p
                    .iter()
                    .zip(&q)
                    .map(|(p, q)| {
                        let [a, b] = estimator::sampled_mis(s, &sp, *p, q.as_vec2(), &mut |_| true);
                        luminance64(a.value + b.value)
                    })
                    .sum();
                sum / PAIRS as f64
            };
            let mut row = vec![measure(|seed| pairs(&env, seed))];
            let params = ProductParams::for_mis(256);
            row.push(measure(|seed| {
                pairs(&arena.build(&env, brdf.as_ref(), &frame, wo, &params, seed).unwrap(), seed)
            }));
            for c in &cones {
                row.push(measure(|seed| pairs(&two.build(&env, c, brdf.as_ref(), &frame, wo).unwrap(), seed)));
            }
            let cells: Vec<String> = row.iter().map(|(v, us)| format!("{v:>9.3e} ({us:>5.1})")).collect();
            println!("{:<22} {}", name, cells.join(" "));
        }
    }
}
