//! A hash of 8 400 product builds' samples and densities (300 shading points × seven BRDFs × four
//! presets, a noisy map with a sun): a change to the build that must keep every tree prints the
//! same hash before and after. Also prints the default arena's size.
//! `cargo run --release -p sampler-core --example tree_hash`
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::frame::Frame;
use sampler_core::mapping::square_to_sphere;
use sampler_core::points::sobol02;
use sampler_core::quadtree::ProductKind;
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};

fn main() {
    let level = 9;
    let n = 1usize << level;
    let mut rgb = vec![[0.5f32; 3]; n * n];
    for (i, t) in rgb.iter_mut().enumerate() {
        let v = 0.2 + ((i * 7919) % 1000) as f32 * 1e-3;
        *t = [v, v * 0.5, v];
    }
    rgb[n * 300 + 200] = [1e5; 3];
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let brdfs: Vec<Box<dyn Brdf>> = vec![
        Box::new(Lambert::new(Vec3::splat(0.5))),
        Box::new(Phong::new(Vec3::splat(0.1), Vec3::splat(0.8), 1e3)),
        Box::new(Phong::new(Vec3::splat(0.0), Vec3::splat(0.8), 1e5)),
        Box::new(RoughConductor::new(0.1, Vec3::ONE)),
        Box::new(RoughConductor::new(1e-4, Vec3::ONE)),
        Box::new(RoughConductor::new(0.01, Vec3::ONE)),
        Box::new(CarPaint::default()),
    ];
    let params = [
        ProductParams::default(),
        ProductParams::for_mis(256),
        ProductParams { kind: ProductKind::WAVELET, ..ProductParams::default() },
        ProductParams { brdf_samples: 64, max_depth: 6, ..ProductParams::default() },
    ];
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let mut h: u64 = 0xcbf29ce484222325;
    let mut mix = |x: u64| {
        h ^= x;
        h = h.wrapping_mul(0x100000001b3);
    };
    let mut rng = Pcg32::new(1, 1);
    let mut nodes = 0usize;
    for i in 0..300u64 {
        let normal = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
        let frame = Frame::from_normal(normal);
        let wo = frame
            .to_world(Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() * 0.9 + 0.02).normalize());
        for b in &brdfs {
            for p in &params {
                let s = arena.build(&env, b.as_ref(), &frame, wo, p, i).unwrap();
                nodes += s.node_count();
                mix(s.node_count() as u64);
                mix(s.product_mean().to_bits() as u64);
                let mut pts = [DVec2::ZERO; 32];
                sobol02(i, 0, &mut pts);
                for u in pts {
                    if let Some(d) = s.sample(u) {
                        mix(d.pdf.to_bits() as u64);
                        mix(d.uv.x.to_bits() as u64);
                        mix(s.pdf(d.dir).to_bits() as u64);
                    }
                }
            }
        }
    }
    println!("hash {h:016x}, {nodes} nodes in all");
    println!(
        "size_of ProductArena: {} bytes, with corners: {} bytes",
        std::mem::size_of::<ProductArena>(),
        std::mem::size_of::<ProductArena<256, 2048, 2048>>()
    );
}
