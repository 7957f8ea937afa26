//! The paper's point is full-resolution lighting: a 4096² map (16.7 M texels) with a one-texel
//! sun of 1e6× the sky is sampled exactly — env-only and product — down to the texel.

use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::RoughConductor;
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len};
use sampler_core::frame::Frame;
use sampler_core::mapping::texel_of;
use sampler_core::rng::Pcg32;
use sampler_core::sampler::{ProductArena, ProductParams};

#[test]
fn a_one_texel_sun_in_a_4096_map_is_found_with_the_right_probability() {
    let level = 12;
    let n = 1usize << level;
    let sun = (3001usize, 1234usize);
    let mut rgb = vec![[0.2f32, 0.3, 0.5]; n * n];
    rgb[sun.1 * n + sun.0] = [3e5; 3];
    let mut pyramid = vec![0.0f32; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();

    // Probability of the sun texel under env-only sampling: its share of the total importance.
    let lum_sky = 0.212_671 * 0.2 + 0.715_160 * 0.3 + 0.072_169 * 0.5;
    let p_sun = 3e5 / (3e5 + lum_sky * (n * n - 1) as f64);
    let mut rng = Pcg32::new(4, 4);
    let draws = 200_000;
    let mut hits = 0usize;
    for _ in 0..draws {
        let s = env.sample(DVec2::new(rng.next_f64(), rng.next_f64())).unwrap();
        if texel_of(s.uv, n as u32) == (sun.0 as u32, sun.1 as u32) {
            hits += 1;
        }
    }
    let expected = p_sun * draws as f64;
    let sd = (expected * (1.0 - p_sun)).sqrt();
    assert!((hits as f64 - expected).abs() < 4.0 * sd, "{hits} sun hits, expected {expected:.0} ± {sd:.0}");

    // A mirror-like lobe pointing at the sun: the product finds it, its pdf integrates to 1.
    let sun_dir = env.dir_of(Vec2::new((sun.0 as f32 + 0.5) / n as f32, (sun.1 as f32 + 0.5) / n as f32));
    let normal = (sun_dir + Vec3::Z).normalize();
    let frame = Frame::from_normal(normal);
    let wo = Vec3::Z;
    let brdf = RoughConductor::new(0.02, Vec3::ONE);
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let s = arena.build(&env, &brdf, &frame, wo, &ProductParams::default(), 9).unwrap();
    let mut sun_hits = 0;
    for _ in 0..10_000 {
        let d = s.sample(DVec2::new(rng.next_f64(), rng.next_f64())).unwrap();
        assert!(
            (s.pdf(d.dir) - d.pdf).abs() <= 1e-4 * d.pdf
                || texel_of(env.square_of(d.dir), n as u32) != texel_of(d.uv, n as u32)
        );
        sun_hits += usize::from(texel_of(d.uv, n as u32) == (sun.0 as u32, sun.1 as u32));
    }
    assert!(sun_hits > 9_000, "the product should go for the sun in the lobe: {sun_hits}/10000");
    fn integral(s: &sampler_core::sampler::ProductSampler<'_, '_>, d: u32, x: u64, y: u64) -> f64 {
        let h = 1.0 / (1u64 << d) as f64;
        let c = Vec2::new(((x as f64 + 0.5) * h) as f32, ((y as f64 + 0.5) * h) as f32);
        if s.constant_depth_at(c) <= d {
            return s.pdf_square(c) as f64 * h * h;
        }
        (0..4).map(|k| integral(s, d + 1, 2 * x + (k & 1), 2 * y + (k >> 1))).sum()
    }
    // Exact integration over the pieces: every one of the 16.7 M texels (and deeper leaves).
    let total = integral(&s, 0, 0, 0);
    assert!((total - 1.0).abs() < 1e-4, "{total}");
}
