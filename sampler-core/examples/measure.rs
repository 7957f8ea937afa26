//! Figures for the docs: mapping round-trip error, and the variance cost of the defensive
//! mixture. `cargo run --release -p sampler-core --example measure`
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, RoughConductor};
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::estimator::{self, ShadingPoint};
use sampler_core::frame::Frame;
use sampler_core::mapping::{angle_between, sphere_to_square, square_to_sphere};
use sampler_core::points::sobol02;
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};

fn main() {
    // Round trip over 10M random directions (uniform on the sphere) plus special ones.
    let mut rng = Pcg32::new(1, 9);
    let mut worst = 0.0f32;
    let mut sum = 0.0f64;
    let n = 10_000_000;
    for _ in 0..n {
        let z = 2.0 * rng.next_f64() - 1.0;
        let phi = 2.0 * std::f64::consts::PI * rng.next_f64();
        let r = (1.0 - z * z).sqrt();
        let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32).normalize();
        let e = angle_between(square_to_sphere(sphere_to_square(d)), d);
        worst = worst.max(e);
        sum += e as f64;
    }
    println!("mapping round trip over {n} directions: max {worst:.2e} rad, mean {:.2e} rad", sum / n as f64);

    // Defensive mixture cost: per-sample variance with ε = 0.05 relative to ε = 0, on cases
    // where ε = 0 is unbiased (B̃ > 0 wherever B > 0).
    let level = 9;
    let m = 1usize << level;
    let mut rgb = vec![[0.0f32; 3]; m * m];
    let sun = Vec3::new(0.3, 0.4, 0.87).normalize();
    for y in 0..m {
        for x in 0..m {
            let d = square_to_sphere(Vec2::new((x as f32 + 0.5) / m as f32, (y as f32 + 0.5) / m as f32));
            let s = if d.dot(sun) > 0.9995 { 5e3 } else { 0.0 };
            let sky = 0.2 + d.z.max(0.0);
            rgb[y * m + x] = [0.5 * sky + s, 0.7 * sky + s, sky + s];
        }
    }
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let brdfs: Vec<(&str, Box<dyn Brdf>)> = vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.5)))),
        ("ggx 0.1", Box::new(RoughConductor::new(0.1, Vec3::ONE))),
        ("carpaint", Box::new(CarPaint::default())),
    ];
    for (name, brdf) in &brdfs {
        let frame = Frame::from_normal(Vec3::new(0.1, 0.2, 1.0).normalize());
        let wo = frame.to_world(Vec3::new(-0.3, -0.4, 0.87).normalize());
        let sp = ShadingPoint { frame, wo, brdf: brdf.as_ref() };
        let mut var = [0.0f64; 3];
        for (k, eps) in [0.0f32, 0.02, 0.05].iter().enumerate() {
            let params = ProductParams { defensive: *eps, ..ProductParams::default() };
            let (mut s1, mut s2, mut cnt) = (0.0f64, 0.0f64, 0.0f64);
            for seed in 0..2000u64 {
                let sampler = arena.build(&env, brdf.as_ref(), &frame, wo, &params, seed).unwrap();
                let mut pts = [DVec2::ZERO; 64];
                sobol02(seed + 77, 0, &mut pts);
                for u in pts {
                    let v = estimator::luminance64(estimator::sampled(&sampler, &sp, u, &mut |_| true).value);
                    s1 += v;
                    s2 += v * v;
                    cnt += 1.0;
                }
            }
            let mean = s1 / cnt;
            var[k] = s2 / cnt - mean * mean;
            println!("{name:9} ε = {eps:<4}: mean {mean:.5}, per-sample variance {:.4e}", var[k]);
        }
        println!("{name:9} variance ratio vs ε=0: ε=0.02 {:.3}, ε=0.05 {:.3}", var[1] / var[0], var[2] / var[0]);
    }
}
