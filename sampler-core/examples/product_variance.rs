//! Per-sample and per-net variance of the product estimators against BRDF sampling and MIS on
//! GGX lobes of several widths under a smooth sky (no sun): how far B̃'s piecewise-constant
//! leaves are from B, and what the (0,2)-nets gain on each estimator. Knobs: EPS (defensive
//! fraction), REFINE (refine_share), BILINEAR (set: bilinear B̃).
//! `cargo run --release -p sampler-core --example product_variance`
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::RoughConductor;
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::estimator::{self, ShadingPoint};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::quadtree::{Leaves, ProductKind};
use sampler_core::sampler::{ProductArena, ProductParams};

fn main() {
    let level = 9;
    let rgb = sky(level);
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let mut arena: Box<ProductArena<256, 2048, 2048>> = Box::new(ProductArena::new());
    let eps: f32 = std::env::var("EPS").ok().and_then(|v| v.parse().ok()).unwrap_or(0.02);
    let refine: f32 = std::env::var("REFINE").ok().and_then(|v| v.parse().ok()).unwrap_or(0.0);
    let bilinear = std::env::var("BILINEAR").is_ok();
    for alpha in [0.01f32, 0.02, 0.05, 0.1, 0.3] {
        let brdf = RoughConductor::new(alpha, Vec3::ONE);
        let frame = Frame::from_normal(Vec3::new(0.1, 0.2, 1.0).normalize());
        let wo = frame.to_world(Vec3::new(-0.3, -0.4, 0.87).normalize());
        let sp = ShadingPoint { frame, wo, brdf: &brdf };
        for probe in [false, true] {
            let leaves = match (bilinear, probe) {
                (true, _) => Leaves::Bilinear,
                (false, true) => Leaves::Probed,
                (false, false) => Leaves::Sampled,
            };
            let kind = ProductKind::Quadtree { leaves, refine_share: refine };
            let params = ProductParams { defensive: eps, kind, ..ProductParams::default() };
            // Relative variance per sample (over builds) and of 64-point net means (×64: 1 = no gain).
            let mut stats = [[0.0f64; 3]; 4];
            let mut net = [[0.0f64; 3]; 4];
            for seed in 0..400u64 {
                let sampler = arena.build(&env, &brdf, &frame, wo, &params, seed).unwrap();
                let mut pts = [DVec2::ZERO; 64];
                let mut oth = [DVec2::ZERO; 64];
                sobol02(seed + 77, 0, &mut pts);
                sobol02(seed + 991, 0, &mut oth);
                let mut sums = [0.0f64; 4];
                for (u, o) in pts.iter().zip(&oth) {
                    let v = [
                        estimator::luminance64(estimator::sampled(&sampler, &sp, *u, &mut |_| true).value),
                        {
                            let [a, b] = estimator::sampled_mis(&sampler, &sp, *u, o.as_vec2(), &mut |_| true);
                            estimator::luminance64(a.value + b.value)
                        },
                        estimator::luminance64(estimator::brdf(&env, &sp, *u, &mut |_| true).value),
                        {
                            let [a, b] = estimator::sampled_mis(&env, &sp, *u, o.as_vec2(), &mut |_| true);
                            estimator::luminance64(a.value + b.value)
                        },
                    ];
                    for k in 0..4 {
                        stats[k][0] += v[k];
                        stats[k][1] += v[k] * v[k];
                        stats[k][2] += 1.0;
                        sums[k] += v[k];
                    }
                }
                for k in 0..4 {
                    let e = sums[k] / 64.0;
                    net[k][0] += e;
                    net[k][1] += e * e;
                    net[k][2] += 1.0;
                }
            }
            let rv = |s: [f64; 3]| {
                let mean = s[0] / s[2];
                (s[1] / s[2] - mean * mean) / (mean * mean)
            };
            println!(
                "α={alpha:<5} probe={probe:<5} per-sample relVar: product {:.3e} pmis {:.3e} brdf {:.3e} mis {:.3e} | 64-net relVar×64: {:.3e} {:.3e} {:.3e} {:.3e}",
                rv(stats[0]),
                rv(stats[1]),
                rv(stats[2]),
                rv(stats[3]),
                rv(net[0]) * 64.0,
                rv(net[1]) * 64.0,
                rv(net[2]) * 64.0,
                rv(net[3]) * 64.0
            );
        }
    }
}

/// A smooth grey sky on a `2^level` equal-area map: brighter towards +z, banded along x.
fn sky(level: u32) -> Vec<[f32; 3]> {
    let m = 1usize << level;
    let mut rgb = vec![[0.0f32; 3]; m * m];
    for y in 0..m {
        for x in 0..m {
            let d = square_to_sphere(Vec2::new((x as f32 + 0.5) / m as f32, (y as f32 + 0.5) / m as f32));
            let sky = 0.2 + d.z.max(0.0) + 0.3 * (5.0 * d.x).sin().abs();
            rgb[y * m + x] = [sky, sky, sky];
        }
    }
    rgb
}
