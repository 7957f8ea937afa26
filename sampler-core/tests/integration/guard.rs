//! The bias trap of product sampling and its guard, and trees at their limits.
//!
//! B̃ is built from BRDF samples. Where B̃ = 0 but L·B > 0 a pure product sampler never looks,
//! and the energy there is silently lost. Here a BRDF's sampler covers only half of its support
//! and spends its other samples below the horizon (B = 0): every leaf over the unsampled half
//! then inherits B̃ = 0. Without the defensive mixture the estimate is visibly biased; with it,
//! it matches quadrature.

use crate::common::*;
use glam::{DVec2, Vec2, Vec3};
use sampler_core::brdf::{Brdf, BrdfSample};
use sampler_core::env::luminance;
use sampler_core::estimator::{self, ShadingPoint, luminance64};
use sampler_core::frame::Frame;
use sampler_core::points::sobol02;
use sampler_core::sampler::{ProductArena, ProductParams};
use sampler_core::sampling::{square_to_cosine_hemisphere, square_to_cosine_hemisphere_pdf};
use std::f32::consts::PI;

/// Lambert (albedo 0.5) whose sampler only draws the x < 0 half of the hemisphere, and half of
/// the time a useless direction below the surface.
struct HalfBlind;

impl Brdf for HalfBlind {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z > 0.0 && wi.z > 0.0 { Vec3::splat(0.5 / PI * wi.z) } else { Vec3::ZERO }
    }
    fn sample(&self, wo: Vec3, u: Vec2) -> Option<BrdfSample> {
        let wi = if u.x < 0.5 {
            let mut w = square_to_cosine_hemisphere(Vec2::new(2.0 * u.x, u.y));
            w.x = -w.x.abs();
            w
        } else {
            let z = -(2.0 * u.x - 1.0);
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * (2.0 * PI * u.y).cos(), r * (2.0 * PI * u.y).sin(), z)
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BrdfSample { wi, value: self.eval(wo, wi), pdf })
    }
    fn pdf(&self, _wo: Vec3, wi: Vec3) -> f32 {
        if wi.z > 0.0 && wi.x < 0.0 {
            square_to_cosine_hemisphere_pdf(wi)
        } else if wi.z < 0.0 {
            0.5 / (2.0 * PI)
        } else {
            0.0
        }
    }
}

fn estimate(params: &ProductParams, env: &TestEnv, frame: &Frame, wo: Vec3) -> (f64, f64) {
    let e = env.view();
    let brdf = HalfBlind;
    let sp = ShadingPoint { frame: *frame, wo, brdf: &brdf };
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let mut vis = |_: Vec3| true;
    let (mut sum, mut sum2, n) = (0.0f64, 0.0f64, 400);
    for seed in 0..n {
        let s = arena.build(&e, &brdf, frame, wo, params, seed).unwrap();
        let mut pts = [DVec2::ZERO; 32];
        sobol02(seed + 1000, 0, &mut pts);
        let v = pts.iter().map(|p| luminance64(estimator::sampled(&s, &sp, *p, &mut vis).value)).sum::<f64>() / 32.0;
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean) * n as f64 / (n as f64 - 1.0);
    (mean, (var / n as f64).sqrt())
}

#[test]
fn zero_btilde_where_b_is_positive_is_guarded() {
    let env = TestEnv::random_smooth(6, 5);
    let frame = Frame::from_normal(Vec3::new(0.1, 0.2, 1.0).normalize());
    let wo = frame.to_world(Vec3::new(0.0, 0.3, 0.95).normalize());
    let e = env.view();
    let sp_brdf = HalfBlind;
    let reference = integrate(Chart::EqualArea, 1024, |d| {
        luminance(e.radiance(d) * sp_brdf.eval(frame.to_local(wo), frame.to_local(d))) as f64
    });

    // The trap is real: a pure product sampler (ε = 0) loses the unsampled half.
    let unguarded = ProductParams { defensive: 0.0, ..ProductParams::default() };
    let (mean, se) = estimate(&unguarded, &env, &frame, wo);
    assert!(
        reference - mean > 10.0 * se && mean < 0.9 * reference,
        "no bias without the guard? {mean} vs {reference} (SE {se})"
    );

    // The guard (default ε) makes it unbiased.
    let (mean, se) = estimate(&ProductParams::default(), &env, &frame, wo);
    assert!((mean - reference).abs() < 3.0 * se + 1e-4 * reference, "guarded: {mean} vs {reference} (SE {se})");
}

/// A BRDF whose sampler returns the same direction every time (value `value`).
struct Coincident {
    value: f32,
}

impl Brdf for Coincident {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z > 0.0 && wi.z > 0.0 { Vec3::splat(self.value * wi.z) } else { Vec3::ZERO }
    }
    fn sample(&self, wo: Vec3, _u: Vec2) -> Option<BrdfSample> {
        let wi = Vec3::new(0.3, 0.1, 0.9).normalize();
        Some(BrdfSample { wi, value: self.eval(wo, wi), pdf: 1.0 })
    }
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }
}

fn check_distribution<const K: usize, const N: usize>(
    arena: &mut ProductArena<K, N>,
    brdf: &dyn Brdf,
    params: &ProductParams,
    env: &TestEnv,
) -> usize {
    let e = env.view();
    let frame = Frame::from_normal(Vec3::Z);
    let s = arena.build(&e, brdf, &frame, Vec3::new(0.0, 0.6, 0.8), params, 3).unwrap();
    assert!(s.node_count() <= N);
    let r = chi_square_dyadic(
        50_000,
        4,
        40.0,
        |u| s.sample(u).map(|d| d.uv),
        |uv| s.constant_depth_at(uv),
        |uv| s.pdf_square(uv),
    );
    assert!(r.p_value > 1e-3 && r.impossible == 0, "{r:?}");
    s.node_count()
}

#[test]
fn coincident_samples_stop_at_the_depth_cap() {
    let env = TestEnv::sun(6, (10, 50), 1e5);
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let params = ProductParams { max_depth: 12, ..ProductParams::default() };
    let nodes = check_distribution(&mut arena, &Coincident { value: 1.0 }, &params, &env);
    // One chain of 12 splits, 4 nodes each, plus the root.
    assert_eq!(nodes, 1 + 4 * 12);
}

#[test]
fn all_zero_samples_fall_back_to_the_environment() {
    let env = TestEnv::random_smooth(5, 9);
    let mut arena: Box<ProductArena> = Box::new(ProductArena::new());
    let e = env.view();
    let frame = Frame::from_normal(Vec3::Z);
    let s = arena.build(&e, &Coincident { value: 0.0 }, &frame, Vec3::Z, &ProductParams::default(), 1).unwrap();
    assert_eq!(s.defensive(), 1.0);
    check_distribution(&mut arena, &Coincident { value: 0.0 }, &ProductParams::default(), &env);
}

#[test]
fn one_brdf_sample_and_a_full_arena_still_sample_correctly() {
    let env = TestEnv::sun(7, (100, 20), 1e6);
    let brdf = sampler_core::brdf::RoughConductor::new(0.05, Vec3::ONE);
    // K = 1: a single leaf, i.e. B̃ constant.
    let mut tiny: Box<ProductArena<1, 16>> = Box::new(ProductArena::new());
    let one = ProductParams { brdf_samples: 1, ..ProductParams::default() };
    let n = check_distribution(&mut tiny, &brdf, &one, &env);
    assert_eq!(n, 1);
    // 256 samples but room for only 64 nodes: splitting stops early, leaves keep the mean of
    // their samples, the distribution stays exact.
    let mut small: Box<ProductArena<256, 64>> = Box::new(ProductArena::new());
    let n = check_distribution(&mut small, &brdf, &ProductParams::default(), &env);
    assert!(n <= 64 && n > 16);
}

#[test]
fn more_brdf_samples_than_the_arena_holds_is_an_error_naming_both() {
    use sampler_core::sampler::ProductError;
    let env = TestEnv::random_smooth(4, 1);
    let e = env.view();
    let mut arena: Box<ProductArena<64, 512>> = Box::default();
    let frame = Frame::from_normal(Vec3::Z);
    let params = ProductParams { brdf_samples: 65, ..ProductParams::default() };
    let brdf = sampler_core::brdf::Lambert::new(Vec3::ONE);
    let err = arena.build(&e, &brdf, &frame, Vec3::Z, &params, 1).unwrap_err();
    assert_eq!(err, ProductError::AboveCapacity { asked: 65, capacity: 64 });
    assert_eq!(err.to_string(), "65 BRDF samples asked of a product arena that holds 64");
    let params = ProductParams { brdf_samples: 64, ..params };
    assert!(arena.build(&e, &brdf, &frame, Vec3::Z, &params, 1).is_ok());
}
