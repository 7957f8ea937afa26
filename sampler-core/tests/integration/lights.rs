//! The light samplers (`sampler_core::light`): each draws directions as its pdf says (χ² on a
//! polar chart about the light), the pdf integrates to 1 over the directions that reach the
//! light, and the pdf returned with a sample is the one `pdf(p, ω)` gives.

use crate::common::*;
use glam::Vec3;
use sampler_core::light::Light;

const SAMPLES: usize = 60_000;

#[test]
fn light_samplers_match_their_pdf() {
    let cases = light_cases();
    let alpha = sidak(cases.len());
    let mut failures = Vec::new();
    for (k, c) in cases.iter().enumerate() {
        let chart = Chart::Polar { axis: c.axis, scale: c.scale };
        let r = chi_square(
            chart,
            32,
            12,
            SAMPLES,
            40 + k as u64,
            |u| c.light.sample(c.p, u.as_vec2()).map(|s| (s.dir, s.pdf)),
            |d| c.light.pdf(c.p, d),
        );
        // "Impossible" samples land in bins whose sub-points all miss the light's outline.
        if r.p_value < alpha || r.impossible > SAMPLES / 1000 || r.pdf_mismatch > 1e-3 || r.failed > 0.0 {
            failures.push(format!("{}: {r:?}", c.name));
        }
    }
    assert!(failures.is_empty(), "α = {alpha:.2e}\n{}", failures.join("\n"));
}

/// The pdfs are indicator-like: integrated by jittered quadrature (its error ~1e-4 here).
#[test]
fn light_pdfs_integrate_to_one() {
    for (k, c) in light_cases().iter().enumerate() {
        let total = integrate_cone_jittered(c.axis, c.cone, 600, k as u64, |d| c.light.pdf(c.p, d) as f64);
        assert!((total - 1.0).abs() < 1e-3, "{}: {total}", c.name);
    }
}

/// Every sample's direction reaches the light (`eval` sees it, at the sample's distance, with
/// the sample's radiance), and directions that miss the light have density 0.
#[test]
fn samples_and_rays_agree() {
    let mut rng = sampler_core::rng::Pcg32::new(3, 9);
    for c in light_cases() {
        for _ in 0..2000 {
            let u = glam::Vec2::new(rng.next_f32(), rng.next_f32());
            let s = c.light.sample(c.p, u).unwrap();
            assert!((s.dir.length() - 1.0).abs() < 1e-5 && s.pdf > 0.0, "{}: {s:?}", c.name);
            let hit = c.light.eval(c.p, s.dir).unwrap_or_else(|| panic!("{}: {s:?} misses", c.name));
            assert_eq!(hit.radiance, s.radiance, "{}", c.name);
            let close = hit.distance == s.distance || (hit.distance - s.distance).abs() <= 1e-3 * s.distance;
            assert!(close, "{}: {hit:?} vs {s:?}", c.name);
        }
        // Directions away from the light.
        for d in [-c.axis, Vec3::new(c.axis.y, -c.axis.x, 0.0).normalize_or(Vec3::X)] {
            if c.cone < 1.5 {
                assert_eq!(c.light.pdf(c.p, d), 0.0, "{}", c.name);
                assert!(c.light.eval(c.p, d).is_none(), "{}", c.name);
            }
        }
    }
}

/// Random and degenerate shading points (on a light's plane, at a sphere's centre, on its
/// surface, NaN, far away) and uniform points including 0 and the largest below 1: nothing panics, every sample
/// is finite with a positive density, and `pdf` agrees with the sample's density but for the
/// rare direction drawn on a light's outline.
#[test]
fn odd_shading_points_give_finite_consistent_samples() {
    use sampler_core::light::*;
    let l = Vec3::new(1.0, 0.5, 0.25);
    let lights: Vec<SceneLight> = vec![
        PointLight::new(Vec3::new(0.0, 0.0, 1.0), l).unwrap().into(),
        SphereLight::new(Vec3::new(0.5, 0.0, 0.0), 0.5, l).unwrap().into(),
        SphereLight::new(Vec3::new(0.5, 0.0, 0.0), 0.5, l).unwrap().with_two_sided(true).into(),
        RectLight::new(Vec3::ZERO, Vec3::X, Vec3::Y, l).unwrap().into(),
        RectLight::new(Vec3::ZERO, Vec3::X, Vec3::Y, l).unwrap().with_two_sided(true).into(),
        DiskLight::new(Vec3::ZERO, Vec3::Z, 0.5, l).unwrap().into(),
        TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], l).unwrap().into(),
        TriangleLight::new([Vec3::ZERO, Vec3::X, Vec3::Y], l).unwrap().with_sampling(TriangleSampling::Area).into(),
        DistantLight::new(Vec3::Z, l, 0.3).unwrap().into(),
        DistantLight::new(Vec3::Z, l, 0.0).unwrap().into(),
    ];
    let fixed = [
        Vec3::ZERO,
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.3, 0.3, 0.0),
        Vec3::new(2.0, 0.5, 0.0),
        Vec3::new(0.3, 0.3, 1e-7),
        Vec3::new(0.3, 0.3, -1e-7),
        Vec3::splat(f32::NAN),
        Vec3::new(1e30, 0.0, 1e30),
        Vec3::new(0.2, 0.1, 1e9),
    ];
    let mut rng = sampler_core::rng::Pcg32::new(8, 8);
    let (mut drawn, mut mismatched) = (0usize, 0usize);
    for k in 0..40_000 {
        let p = if k % 4 == 0 {
            fixed[(k / 4) % fixed.len()]
        } else {
            Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 3.0 - Vec3::splat(1.5)
        };
        let u = match k % 7 {
            0 => glam::Vec2::ZERO,
            1 => glam::Vec2::splat(1.0 - f32::EPSILON / 2.0),
            _ => glam::Vec2::new(rng.next_f32(), rng.next_f32()),
        };
        for light in &lights {
            let Some(s) = light.sample(p, u) else { continue };
            drawn += 1;
            let ok = s.dir.is_finite()
                && (s.dir.length() - 1.0).abs() < 1e-4
                && s.pdf.is_finite()
                && s.pdf > 0.0
                && s.distance > 0.0
                && s.radiance.is_finite();
            assert!(ok, "{light:?} from {p} with {u}: {s:?}");
            if !s.delta {
                let q = light.pdf(p, s.dir);
                mismatched += usize::from((q - s.pdf).abs() > 1e-3 * s.pdf);
            }
        }
    }
    assert!(drawn > 100_000 && mismatched * 10_000 <= drawn, "{mismatched} of {drawn} densities disagree");
}
