//! Tree sizes over many shading points: mean and max node count per BRDF, for the paper's
//! build and product-MIS's preset (refined leaves), from K BRDF samples (default 256).
//! `cargo run --release -p sampler-core --example node_stats -- [K ≤ 1024]`
use glam::{Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};

fn main() {
    let level = 10;
    let n = 1usize << level;
    let rgb = vec![[0.5f32; 3]; n * n];
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let k: usize = std::env::args().nth(1).map_or(256, |a| a.parse().expect("K: a number of BRDF samples"));
    // Room for any tree of up to 1024 samples, so that the counts are never capped.
    let mut arena: Box<ProductArena<1024, 65536>> = Box::new(ProductArena::new());
    let brdfs: Vec<(&str, Box<dyn Brdf>)> = vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.5)))),
        ("ggx 0.1", Box::new(RoughConductor::new(0.1, Vec3::ONE))),
        ("ggx 1e-3", Box::new(RoughConductor::new(1e-3, Vec3::ONE))),
        ("ggx 1e-4", Box::new(RoughConductor::new(1e-4, Vec3::ONE))),
        ("phong 1e5", Box::new(Phong::new(Vec3::ZERO, Vec3::ONE, 1e5))),
        ("carpaint", Box::new(CarPaint::default())),
    ];
    let mut rng = Pcg32::new(5, 5);
    let presets = [
        ("paper", ProductParams { brdf_samples: k, ..ProductParams::default() }),
        ("for_mis", ProductParams::for_mis(k)),
    ];
    for (preset, params) in presets {
        println!("K = {k}, {preset}:");
        for (name, brdf) in &brdfs {
            let (mut sum, mut max) = (0usize, 0usize);
            for i in 0..5000u64 {
                let normal = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
                let frame = Frame::from_normal(normal);
                let c = rng.next_f32();
                let wo = frame.to_world(Vec3::new((1.0 - c * c).sqrt(), 0.0, c));
                let s = arena.build(&env, brdf.as_ref(), &frame, wo, &params, i).unwrap();
                sum += s.node_count();
                max = max.max(s.node_count());
            }
            println!("  {name:10} mean {:6.0} max {max}", sum as f64 / 5000.0);
        }
    }
}
