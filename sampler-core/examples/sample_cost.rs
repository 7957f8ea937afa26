//! Per-sample cost of product-MIS against MIS at one shared sampler, as the renderer uses them
//! (one sampler per pixel, hundreds of pairs through it, 16 pairs per batched call), without rays.
//! `cargo run --release -p sampler-core --example sample_cost -- [alpha] [level]`; `PARAMS=default`
//! (the paper's build), `noprobe` or `norefine` change the product-MIS preset's build.

use glam::{DVec2, DVec3, Vec2, Vec3};
use sampler_core::brdf::RoughConductor;
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::estimator::{Contribution, ShadingPoint, sampled_mis, sampled_mis_drawn, sampled_mis_many};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::quadtree::{Leaves, ProductKind};
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let alpha: f32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(0.05);
    let level: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(10);
    let rgb = sky_with_sun(level);
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let brdf = RoughConductor::new(alpha, Vec3::ONE);
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let points = shading_points(64);
    let pairs = 512;
    let params = params_from_env();
    let mut us = vec![DVec2::ZERO; pairs];
    let mut vs = vec![DVec2::ZERO; pairs];
    let mut brdf_points = vec![Vec2::ZERO; pairs];
    let mut out = [[Contribution::default(); 2]; 64];
    let mut drawn = vec![None; pairs];
    let mut pdrawn = vec![None; pairs];
    let mut vis = |_: Vec3| true;
    for round in 0..3 {
        let (mut t_build, mut t_sample, mut t_pm, mut t_mis, mut t_pmb, mut t_sb) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let mut t_misb = 0.0;
        let mut acc = DVec3::ZERO;
        for (i, (frame, wo)) in points.iter().enumerate() {
            let sp = ShadingPoint { frame: *frame, wo: *wo, brdf: &brdf };
            sobol02(i as u64, 0, &mut us);
            sobol02(i as u64 + 99, 0, &mut vs);
            for (b, v) in brdf_points.iter_mut().zip(&vs) {
                *b = v.as_vec2();
            }
            let t = Instant::now();
            let s = arena.build(&env, &brdf, frame, *wo, &params, i as u64).unwrap();
            t_build += t.elapsed().as_secs_f64();
            let t = Instant::now();
            for u in &us {
                acc.x += s.sample(*u).map_or(0.0, |d| d.pdf as f64);
            }
            t_sample += t.elapsed().as_secs_f64();
            let t = Instant::now();
            for (u, v) in us.iter().zip(&vs) {
                let [a, b] = sampled_mis(&s, &sp, *u, v.as_vec2(), &mut vis);
                acc += a.value + b.value;
            }
            t_pm += t.elapsed().as_secs_f64();
            // The renderer's paths: a batch at a time.
            let t = Instant::now();
            for (u, b) in us.chunks(64).zip(brdf_points.chunks(64)) {
                sampled_mis_many(&s, &sp, u, b, &mut vis, &mut out);
                acc += out.iter().map(|[a, b]| a.value + b.value).sum::<DVec3>();
            }
            t_pmb += t.elapsed().as_secs_f64();
            let t = Instant::now();
            for (u, b) in us.chunks(64).zip(brdf_points.chunks(64)) {
                sampled_mis_many(&env, &sp, u, b, &mut vis, &mut out);
                acc += out.iter().map(|[a, b]| a.value + b.value).sum::<DVec3>();
            }
            t_misb += t.elapsed().as_secs_f64();
            let t = Instant::now();
            s.sample_many(&us, &mut pdrawn);
            for d in &pdrawn {
                acc.x += d.map_or(0.0, |d| d.pdf as f64);
            }
            t_sb += t.elapsed().as_secs_f64();
            let t = Instant::now();
            env.sample_many(&us, &mut drawn);
            for (d, v) in drawn.iter().zip(&vs) {
                let [a, b] = sampled_mis_drawn(&env, &sp, *d, v.as_vec2(), &mut vis);
                acc += a.value + b.value;
            }
            t_mis += t.elapsed().as_secs_f64();
        }
        let times = [t_build, t_sample, t_sb, t_pm, t_pmb, t_mis, t_misb];
        print_round(round, times, points.len(), pairs, acc.x);
    }
}

/// One round's line: the build per shading point, then each sampling path per sample or pair.
fn print_round(round: usize, times: [f64; 7], points: usize, pairs: usize, checksum: f64) {
    let [t_build, t_sample, t_sb, t_pm, t_pmb, t_mis, t_misb] = times;
    let per = |t: f64| t / (points * pairs) as f64 * 1e9;
    println!(
        "round {round}: build {:.1} µs | product sample {:.0} ns, batched {:.0} | product-MIS pair {:.0} ns, batched {:.0} | MIS pair {:.0} ns, batched {:.0} | batched ratio {:.2} ({:.1e})",
        t_build / points as f64 * 1e6,
        per(t_sample),
        per(t_sb),
        per(t_pm),
        per(t_pmb),
        per(t_mis),
        per(t_misb),
        t_pmb / t_misb,
        checksum
    );
}

/// A blue sky with structure and a small sun of radiance 1e4, on a `2^level` equal-area map.
fn sky_with_sun(level: u32) -> Vec<[f32; 3]> {
    let n = 1usize << level;
    let sun = Vec3::new(0.4, 0.5, 0.75).normalize();
    let mut rgb = vec![[0.0f32; 3]; n * n];
    for y in 0..n {
        for x in 0..n {
            let d = square_to_sphere(Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32));
            let sky = 0.3 + 0.7 * d.z.max(0.0) + 0.2 * (13.0 * d.x).sin() * (7.0 * d.y).cos();
            let s = if d.dot(sun) > 0.9998 { 1e4 } else { 0.0 };
            rgb[y * n + x] = [0.4 * sky + s, 0.6 * sky + s, sky + s];
        }
    }
    rgb
}

/// The settings `PARAMS` names: `default`, `noprobe`, `norefine`, or `ProductParams::for_mis`.
fn params_from_env() -> ProductParams {
    let mut params = ProductParams::for_mis(256);
    match std::env::var("PARAMS").as_deref() {
        Ok("default") => params = ProductParams::default(),
        Ok("noprobe") => params.kind = ProductKind::Quadtree { leaves: Leaves::Sampled, refine_share: 1.0 / 256.0 },
        Ok("norefine") => params.kind = ProductKind::Quadtree { leaves: Leaves::Probed, refine_share: 0.0 },
        _ => {}
    }
    params
}

/// `n` shading points: normals from the middle band of the square, views within ~35° of them.
fn shading_points(n: usize) -> Vec<(Frame, Vec3)> {
    let mut rng = Pcg32::new(3, 3);
    (0..n)
        .map(|_| {
            let nrm = square_to_sphere(Vec2::new(rng.next_f32(), 0.5 * rng.next_f32() + 0.25));
            let f = Frame::from_normal(nrm);
            (f, f.to_world(Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 1.0).normalize()))
        })
        .collect()
}
