//! The plane product (`env/plane.rs`): a view sampled ∝ radiance × a plane's cosine matches
//! its pdf, keeps a density wherever a surface near the plane's normal receives light, and
//! estimates a diffuse plane's irradiance without bias and with nothing left to vary but the
//! texels' own cosine spread.

use crate::common::{Chart, TestEnv, chi_square_dyadic, integrate, sidak};
use glam::{DVec2, Mat3, Vec2, Vec3};
use sampler_core::cone::cell_radius_bound;
use sampler_core::env::{COSINE_LEVEL, EnvHierarchy, build_pyramid_from_importance, pyramid_len};
use sampler_core::mapping::square_to_sphere;
use sampler_core::rng::Pcg32;

/// Normals within this many radians of the plane's share its pyramid (the renderer's
/// `NORMAL_TOLERANCE`).
const TOLERANCE: f32 = 1e-3;

/// The plane pyramid of `env`'s view for `normal`.
fn plane_pyramid(view: &EnvHierarchy<'_>, normal: Vec3) -> Vec<f32> {
    let level = view.finest_level();
    let mut importance = vec![0.0; 1 << (2 * level)];
    view.plane_importance_rows(normal, TOLERANCE, 0, &mut importance).unwrap();
    let mut pyramid = vec![0.0; pyramid_len(level)];
    build_pyramid_from_importance(level, &importance, &mut pyramid).unwrap();
    pyramid
}

/// Maps under test, each with a world rotation (none, or a turn about y as a scene's
/// `rotate_y_deg` gives), and plane normals: up, tilted, and one grazing the sun.
fn cases() -> Vec<(String, TestEnv, Mat3, Vec3)> {
    let tilted = Vec3::new(0.3, 0.8, -0.5).normalize();
    let mut out = Vec::new();
    for (name, rotation) in [("", Mat3::IDENTITY), (", rotated", Mat3::from_rotation_y(1.1))] {
        out.push((format!("smooth, up{name}"), TestEnv::random_smooth(6, 3), rotation, Vec3::Y));
        out.push((format!("smooth, tilted{name}"), TestEnv::random_smooth(6, 4), rotation, tilted));
        let sun = TestEnv::sun(7, (37, 101), 1e6);
        // A normal 89.9° from the sun's direction: the sun sits on the plane's horizon.
        let n = sun.view().with_rotation(rotation).dir_of(Vec2::new(37.5 / 128.0, 101.5 / 128.0));
        let grazing = (Vec3::Y - n * n.dot(Vec3::Y)).normalize() * 0.99999 + n * 0.0017;
        out.push((format!("sun 1e6, grazing{name}"), sun, rotation, grazing.normalize()));
    }
    // A map finer than the cosine's grid: its texels share their cell's weight.
    out.push(("smooth, level 11, tilted".into(), TestEnv::random_smooth(11, 5), Mat3::IDENTITY, tilted));
    out
}

#[test]
fn the_plane_view_matches_its_pdf() {
    let cases = cases();
    let alpha = sidak(cases.len());
    for (name, env, rotation, normal) in &cases {
        let view = env.view().with_rotation(*rotation);
        let pyramid = plane_pyramid(&view, *normal);
        let plane = view.with_importance(&pyramid).unwrap();
        // The cells the cosine is weighed over, whose texels may all be drawn.
        let reach = cell_radius_bound(plane.finest_level().min(COSINE_LEVEL)) + TOLERANCE;
        let r = chi_square_dyadic(
            200_000,
            3,
            40.0,
            |u| plane.sample(u).map(|s| s.uv),
            |_| plane.finest_level(),
            |uv| plane.pdf_square(uv),
        );
        assert!(r.p_value >= alpha && r.impossible == 0, "{name}: {r:?}");
        // The direction-level pdf agrees with the one returned, but where the direction's round
        // trip through the mapping lands in the next texel: never in maps of 128² or coarser,
        // rarely in the 2048² one, whose texels are a sixteenth of the size.
        let allowed = if env.level <= 7 { 0 } else { 10 };
        let (mut rng, mut mismatch) = (Pcg32::new(1, 1), 0);
        for _ in 0..10_000 {
            let s = plane.sample(DVec2::new(rng.next_f64(), rng.next_f64())).unwrap();
            mismatch += usize::from((plane.pdf(s.dir) - s.pdf).abs() > 1e-4 * s.pdf);
            assert!(s.dir.dot(*normal) > -(2.0 * reach).sin(), "{name}: drawn {:?} beyond the texels' reach", s.dir);
        }
        assert!(mismatch <= allowed, "{name}: {mismatch} of 10000 pdfs differ");
    }
}

#[test]
fn every_lit_direction_above_a_normal_within_the_tolerance_has_a_density() {
    let mut rng = Pcg32::new(7, 7);
    for (name, env, rotation, normal) in cases() {
        let view = env.view().with_rotation(rotation);
        let pyramid = plane_pyramid(&view, normal);
        let plane = view.with_importance(&pyramid).unwrap();
        let frame = sampler_core::frame::Frame::from_normal(normal);
        for _ in 0..200_000 {
            // A shading normal tilted by up to the tolerance, and a direction just above its
            // horizon or anywhere above it.
            let phi = rng.next_f32() * core::f32::consts::TAU;
            let tilt = rng.next_f32() * 0.99 * TOLERANCE;
            let shading = frame.to_world(Vec3::new(tilt * phi.cos(), tilt * phi.sin(), 1.0)).normalize();
            let d = square_to_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            let d = if rng.next_f32() < 0.5 { (d - shading * shading.dot(d) * 0.999).normalize() } else { d };
            if shading.dot(d) > 0.0 && view.radiance(d).max_element() > 0.0 {
                assert!(plane.pdf(d) > 0.0, "{name}: lit direction {d:?} above {shading:?} has no density");
            }
        }
    }
}

#[test]
fn a_diffuse_plane_s_irradiance_is_unbiased_and_nearly_noiseless() {
    // Quadrature at 8× the map's resolution: the maps up to 128².
    for (name, env, rotation, normal) in cases().into_iter().filter(|c| c.1.level <= 7) {
        let view = env.view().with_rotation(rotation);
        let pyramid = plane_pyramid(&view, normal);
        let plane = view.with_importance(&pyramid).unwrap();
        let f = |d: Vec3| (view.radiance(d).y * d.dot(normal).max(0.0)) as f64;
        let truth = integrate(Chart::EqualArea, 8 << view.finest_level(), f);
        let n = 1 << 16;
        let (mut plane_stats, mut env_stats) = ([0.0f64; 2], [0.0f64; 2]);
        let mut rng = Pcg32::new(11, 3);
        for _ in 0..n {
            let u = DVec2::new(rng.next_f64(), rng.next_f64());
            for (sampler, stats) in [(&plane, &mut plane_stats), (&view, &mut env_stats)] {
                let v = sampler.sample(u).map_or(0.0, |s| f(s.dir) / s.pdf as f64);
                stats[0] += v;
                stats[1] += v * v;
            }
        }
        let (mean, var) = (plane_stats[0] / n as f64, plane_stats[1] / n as f64 - (plane_stats[0] / n as f64).powi(2));
        let env_var = env_stats[1] / n as f64 - (env_stats[0] / n as f64).powi(2);
        let se = (var / n as f64).sqrt();
        assert!((mean - truth).abs() <= 4.0 * se + 1e-4 * truth, "{name}: {mean} against {truth} (se {se})");
        // What is left is the cosine's spread within each texel: largest for a sun on the
        // horizon, whose texel's cosine runs from 0 to its reach.
        let limit = if name.starts_with("sun") { 0.15 } else { 0.05 };
        assert!(var <= limit * env_var, "{name}: variance {var} against env sampling's {env_var}");
    }
}
