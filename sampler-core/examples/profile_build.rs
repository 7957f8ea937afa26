//! Runs many shading-point builds in a loop, for profilers (`perf record`, callgrind).
//! `cargo run --release -p sampler-core --example profile_build -- [brdf] [iterations] [mode] [K] [level]`
//! (brdf: lambert, phong, carpaint, ggx — α 0.1 — or ggxA for GGX α = A)
//! (mode `mis`: the product-MIS preset `ProductParams::for_mis`, probed and refined leaves;
//! `points`: only the shading points, build + 16 warps each, without the stages after them, for
//! a CPU-time measure of the whole process such as `perf stat -e task-clock`; `many`: as
//! `points`, the 16 warps drawn together by `sample_many` as the renderer draws them;
//! `mis-many`: as `many` with the product-MIS preset; level: the map is 2^level square, 10 by
//! default).

use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map_or("ggx", String::as_str);
    let iters: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(50_000);
    let k: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(256);
    let mode = args.get(3).map_or("", String::as_str);
    let params = if mode.starts_with("mis") {
        ProductParams::for_mis(k)
    } else {
        ProductParams { brdf_samples: k, ..ProductParams::default() }
    };
    let brdf = brdf_named(which);
    let level: u32 = args.get(5).and_then(|s| s.parse().ok()).unwrap_or(10);
    let n = 1usize << level;
    let mut rgb = vec![[0.5f32; 3]; n * n];
    rgb[n * 300 + 200] = [1e5; 3];
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let mut rng = Pcg32::new(1, 1);
    let mut acc = 0.0f64;
    let mut nodes = 0usize;
    let t = std::time::Instant::now();
    for i in 0..iters {
        let normal = square_to_sphere(Vec2::new(rng.next_f32(), 0.5 * rng.next_f32() + 0.25));
        let frame = Frame::from_normal(normal);
        let wo = frame.to_world(Vec3::new(0.2, 0.1, 1.0).normalize());
        let s = arena.build(&env, brdf.as_ref(), &frame, wo, &params, i).unwrap();
        nodes += s.node_count();
        let mut pts = [DVec2::ZERO; 16];
        sobol02(i, 0, &mut pts);
        if mode.ends_with("many") {
            let mut drawn = [None; 16];
            s.sample_many(&pts, &mut drawn);
            acc += drawn.iter().map(|d| d.map_or(0.0, |d| d.pdf as f64)).sum::<f64>();
        } else {
            for u in pts {
                acc += s.sample(u).map_or(0.0, |d| d.pdf as f64);
            }
        }
    }
    let dt = t.elapsed().as_secs_f64();
    if mode == "points" || mode.ends_with("many") {
        println!("{which}: {:.2} µs per shading point ({acc:.3e})", dt / iters as f64 * 1e6);
        return;
    }
    // Stages, each over the same shading points.
    let mut frames = Vec::new();
    let mut rng = Pcg32::new(1, 1);
    for _ in 0..1000 {
        let normal = square_to_sphere(Vec2::new(rng.next_f32(), 0.5 * rng.next_f32() + 0.25));
        let frame = Frame::from_normal(normal);
        frames.push((frame, frame.to_world(Vec3::new(0.2, 0.1, 1.0).normalize())));
    }
    let reps = (iters / 1000).max(1);
    let per = |t: std::time::Instant| t.elapsed().as_secs_f64() / (reps * 1000) as f64 * 1e6;
    let mut pts = vec![Vec2::ZERO; 256];
    let mut out = vec![sampler_core::brdf::BrdfDraw::default(); 256];
    let t0 = std::time::Instant::now();
    for r in 0..reps {
        for (i, (frame, wo)) in frames.iter().enumerate() {
            sampler_core::points::sobol02_shifted(r * 1000 + i as u64, 0, &mut pts);
            let n = brdf.sample_batch(frame.to_local(*wo), &pts, &mut out);
            acc += out[n / 2].value as f64;
        }
    }
    let a = per(t0);
    let t0 = std::time::Instant::now();
    for r in 0..reps {
        for (i, (frame, wo)) in frames.iter().enumerate() {
            let s = arena.build(&env, brdf.as_ref(), frame, *wo, &params, r * 1000 + i as u64).unwrap();
            nodes += s.node_count();
        }
    }
    let b = per(t0);
    let t0 = std::time::Instant::now();
    let s = arena.build(&env, brdf.as_ref(), &frames[0].0, frames[0].1, &params, 1).unwrap();
    let mut p16 = [DVec2::ZERO; 16];
    for r in 0..reps * 1000 {
        sobol02(r, 0, &mut p16);
        for u in p16 {
            acc += s.sample(u).map_or(0.0, |d| d.pdf as f64);
        }
    }
    let c = per(t0);
    println!("stages: 256 BRDF samples {a:.2} µs, full build {b:.2} µs, 16 warps {c:.2} µs");
    println!(
        "{which}: {:.2} µs per shading point, {:.0} nodes on average ({acc:.3e})",
        dt / iters as f64 * 1e6,
        nodes as f64 / iters as f64
    );
}

/// The BRDF the first argument names (GGX α = 0.1 by default; `ggx0.3`: GGX α = 0.3).
fn brdf_named(which: &str) -> Box<dyn Brdf> {
    if let Some(alpha) = which.strip_prefix("ggx").and_then(|a| a.parse().ok()) {
        return Box::new(RoughConductor::new(alpha, Vec3::ONE));
    }
    match which {
        "lambert" => Box::new(Lambert::new(Vec3::splat(0.5))),
        "phong" => Box::new(Phong::new(Vec3::splat(0.1), Vec3::splat(0.8), 1e3)),
        "carpaint" => Box::new(CarPaint::default()),
        _ => Box::new(RoughConductor::new(0.1, Vec3::ONE)),
    }
}
