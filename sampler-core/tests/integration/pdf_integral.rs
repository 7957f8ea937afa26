//! Every sampler's pdf integrates to 1 over the sphere within 1e-3.

use crate::common::*;
use glam::{Vec2, Vec3};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::frame::Frame;
use sampler_core::quadtree::ProductKind;
use sampler_core::sampler::{ProductArena, ProductParams};

fn brdfs() -> Vec<(&'static str, Box<dyn Brdf>, f64)> {
    vec![
        ("lambert", Box::new(Lambert::new(Vec3::splat(0.8))), 1.0),
        ("phong n=1", Box::new(Phong::new(Vec3::splat(0.2), Vec3::splat(0.6), 1.0)), 1.0),
        ("phong n=1e4", Box::new(Phong::new(Vec3::ZERO, Vec3::splat(0.9), 1e4)), 0.02),
        ("phong n=1e6", Box::new(Phong::new(Vec3::splat(0.1), Vec3::splat(0.9), 1e6)), 2e-3),
        ("ggx a=1", Box::new(RoughConductor::new(1.0, Vec3::ONE)), 1.0),
        ("ggx a=0.05", Box::new(RoughConductor::new(0.05, Vec3::ONE)), 0.1),
        ("ggx a=1e-3", Box::new(RoughConductor::new(1e-3, Vec3::ONE)), 2e-3),
        ("ggx a=1e-4", Box::new(RoughConductor::new(1e-4, Vec3::ONE)), 2e-4),
        ("carpaint", Box::new(CarPaint::default()), 0.01),
    ]
}

#[test]
fn brdf_pdfs_integrate_to_one() {
    for (name, brdf, width) in brdfs() {
        for cos in [0.95f32, 0.5, 0.05] {
            let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
            let axis = Vec3::new(-wo.x, -wo.y, wo.z);
            // The GGX pdf includes reflected directions below the surface: it is a density over
            // the whole sphere.
            let total = integrate_lobe(axis, width, 1500, |wi| brdf.pdf(wo, wi) as f64);
            assert!((total - 1.0).abs() < 1e-3, "{name} at cos {cos}: {total}");
        }
    }
}

/// Exact integral of a density that is constant on dyadic cells (see `chi_square_dyadic`).
fn dyadic_integral(depth_at: &dyn Fn(Vec2) -> u32, pdf: &dyn Fn(Vec2) -> f32, d: u32, x: u64, y: u64) -> f64 {
    let s = 1.0 / (1u64 << d) as f64;
    let c = Vec2::new(((x as f64 + 0.5) * s) as f32, ((y as f64 + 0.5) * s) as f32);
    if depth_at(c) <= d || d >= 24 {
        return pdf(c) as f64 * s * s;
    }
    (0..4).map(|k| dyadic_integral(depth_at, pdf, d + 1, 2 * x + (k & 1), 2 * y + (k >> 1))).sum()
}

#[test]
fn env_and_product_pdfs_integrate_to_one() {
    let envs = [TestEnv::random_smooth(6, 8), TestEnv::sun(8, (200, 3), 1e7), TestEnv::constant(0, 1.0)];
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    for env in &envs {
        let e = env.view();
        let total = dyadic_integral(&|_| e.finest_level(), &|uv| e.pdf_square(uv), 0, 0, 0);
        assert!((total - 1.0).abs() < 1e-5, "env: {total}");
        // Independent check on directions: a plain grid over the sphere.
        let grid = integrate(Chart::EqualArea, 1024, |d| e.pdf(d) as f64);
        assert!((grid - 1.0).abs() < 1e-3, "env on a grid: {grid}");
        for kind in [ProductKind::QUADTREE, ProductKind::WAVELET] {
            let params = ProductParams { kind, ..ProductParams::default() };
            for (name, brdf, _) in brdfs() {
                for (k, normal) in
                    [Vec3::Z, Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.5, 0.5, -0.7).normalize()].iter().enumerate()
                {
                    let frame = Frame::from_normal(*normal);
                    let wo = frame.to_world(Vec3::new(0.6, 0.0, 0.8));
                    let s = arena.build(&e, brdf.as_ref(), &frame, wo, &params, k as u64).unwrap();
                    let total = dyadic_integral(&|uv| s.constant_depth_at(uv), &|uv| s.pdf_square(uv), 0, 0, 0);
                    assert!((total - 1.0).abs() < 1e-4, "{name} {kind:?}: {total}");
                }
            }
        }
    }
}
