//! Shaped lights (UsdLux ShapingAPI: cone, softness, focus, focus tint). A spot light over a
//! Lambert plane delivers I·factor(θ)·cos/d² with the factor written out here from the schema's
//! formulas, inside the cone, in its soft band and outside it; shaped area lights sampled as
//! unshaped ones (same densities) estimate the irradiance that jittered quadrature of `eval`
//! gives, in every channel (the tint makes them differ); and the light tree's bounds of a
//! shaped light never cull a point the light reaches.

use crate::common::integrate_cone_jittered;
use glam::{Vec2, Vec3};
use sampler_core::light::{DiskLight, Light, LightBounds, PointLight, RectLight, SceneLight, Shaping, SphereLight};
use sampler_core::rng::Pcg32;
use std::f64::consts::PI;

/// The schema's factor, in f64: 1 − smoothstep(θ; cutoff·(1 − softness), cutoff), times
/// lerp(|cos θ|^focus, tint, 1).
fn schema_factor(theta: f64, cone: f64, softness: f64, focus: f64, tint: f64) -> f64 {
    if theta > cone {
        return 0.0;
    }
    let start = cone * (1.0 - softness);
    let t = if theta > start { ((theta - start) / (cone - start)).clamp(0.0, 1.0) } else { 0.0 };
    let f = theta.cos().abs().powf(focus);
    (1.0 - t * t * (3.0 - 2.0 * t)) * (tint + f * (1.0 - tint))
}

#[test]
fn a_spot_light_over_a_lambert_plane_matches_the_formula() {
    // A spot 2 units above the plane z = 0 pointing straight down, cone 30°, softness 0.4 (the
    // band 18°–30°), focus 2 towards a tint of 0.25.
    let (h, cone, softness, focus, tint) = (2.0f64, 30f64.to_radians(), 0.4, 2.0, 0.25);
    let shaping = Shaping::new(Vec3::NEG_Z, cone as f32, softness as f32, focus as f32, Vec3::splat(tint as f32));
    let light =
        PointLight::new(Vec3::new(0.0, 0.0, h as f32), Vec3::splat(5.0)).unwrap().with_shaping(shaping.unwrap());
    let mut inside = 0;
    let mut band = 0;
    let mut outside = 0;
    for deg in [0.0f64, 10.0, 17.0, 20.0, 24.0, 29.0, 31.0, 60.0] {
        let theta = deg.to_radians();
        let x = h * theta.tan();
        let p = Vec3::new(x as f32, 0.0, 0.0);
        let d2 = h * h + x * x;
        // cos at the receiver = cos θ for a plane under a light pointing straight down.
        let expected = 5.0 * schema_factor(theta, cone, softness, focus, tint) * theta.cos() / d2;
        let s = light.sample(p, Vec2::splat(0.5)).unwrap();
        let e = s.radiance.x as f64 * s.dir.dot(Vec3::Z) as f64;
        assert!((e - expected).abs() <= 1e-5 * expected.max(1e-3), "{deg}°: {e} against {expected}");
        match deg {
            d if d < 18.0 => inside += 1,
            d if d <= 30.0 => band += usize::from(expected > 0.0 && expected < 5.0 / d2 * theta.cos()),
            _ => outside += usize::from(e == 0.0),
        }
    }
    assert_eq!((inside, band, outside), (3, 3, 2));
    // Its power is I·∫ factor dω, by quadrature of the schema's factor.
    let n = 20_000;
    let quad: f64 = (0..n)
        .map(|i| {
            let theta = PI * (i as f64 + 0.5) / n as f64;
            schema_factor(theta, cone, softness, focus, tint) * theta.sin() * 2.0 * PI * PI / n as f64
        })
        .sum();
    let power = light.power(1.0).x as f64;
    assert!((power - 5.0 * quad).abs() < 1e-3 * power, "{power} against {}", 5.0 * quad);
}

/// Mean and standard error of L·cos/pdf per channel over `samples` light samples.
fn estimate(light: &SceneLight, p: Vec3, n: Vec3, samples: usize, seed: u64) -> [(f64, f64); 3] {
    let mut rng = Pcg32::new(seed, 12);
    let mut sum = [0.0f64; 3];
    let mut sum2 = [0.0f64; 3];
    for _ in 0..samples {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let v = light.sample(p, u).map_or(Vec3::ZERO, |s| s.radiance * n.dot(s.dir).max(0.0) / s.pdf);
        for c in 0..3 {
            sum[c] += v[c] as f64;
            sum2[c] += (v[c] as f64).powi(2);
        }
    }
    core::array::from_fn(|c| {
        let mean = sum[c] / samples as f64;
        (mean, ((sum2[c] / samples as f64 - mean * mean).max(0.0) / samples as f64).sqrt())
    })
}

#[test]
fn shaped_area_lights_estimate_what_quadrature_sees() {
    let tint = Vec3::new(0.0, 0.3, 1.0);
    let shaping = |axis: Vec3, cone: f32, softness: f32, focus: f32| {
        Shaping::new(axis, cone.to_radians(), softness, focus, tint).unwrap()
    };
    let rect =
        RectLight::new(Vec3::new(-1.0, -0.5, 1.5), Vec3::new(0.0, 1.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::ONE)
            .unwrap();
    assert!(rect.normal().z < 0.0);
    let cases: Vec<(&str, SceneLight, Vec3, Vec3, Vec3, f64)> = vec![
        (
            "sphere, cone 50° soft, focus 3",
            SphereLight::new(Vec3::new(0.0, 0.0, 2.0), 0.5, Vec3::splat(2.0))
                .unwrap()
                .with_shaping(shaping(Vec3::new(0.4, 0.0, -1.0), 50.0, 0.5, 3.0))
                .into(),
            Vec3::new(0.3, 0.2, 0.0),
            Vec3::Z,
            Vec3::new(0.0, 0.0, 2.0),
            0.5,
        ),
        (
            "rectangle, cone 35°, soft band across it",
            rect.with_shaping(shaping(rect.normal(), 35.0, 0.6, 1.0)).into(),
            Vec3::new(0.8, 0.0, 0.0),
            Vec3::Z,
            Vec3::new(0.0, 0.0, 1.5),
            1.2,
        ),
        (
            "disk, focus 8 only",
            DiskLight::new(Vec3::new(0.0, 0.0, 1.0), Vec3::NEG_Z, 0.8, Vec3::splat(3.0))
                .unwrap()
                .with_shaping(shaping(Vec3::NEG_Z, 180.0, 0.0, 8.0))
                .into(),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.2, 0.0, 1.0).normalize(),
            Vec3::new(0.0, 0.0, 1.0),
            0.8,
        ),
    ];
    let mut failures = Vec::new();
    for (k, (name, light, p, n, centre, reach)) in cases.iter().enumerate() {
        let to = *centre - *p;
        let cone = ((*reach as f32 / to.length()).min(1.0) as f64).asin() * 1.1;
        let est = estimate(light, *p, *n, 60_000, 50 + k as u64);
        for (c, &(mean, se)) in est.iter().enumerate() {
            let quad = integrate_cone_jittered(to.normalize(), cone, 500, 9 + k as u64, |d| {
                light.eval(*p, d).map_or(0.0, |h| h.radiance[c] as f64 * n.dot(d).max(0.0) as f64)
            });
            if (mean - quad).abs() > 4.0 * se + 3e-3 * quad {
                failures.push(format!("{name}, channel {c}: {mean} ± {se} against {quad}"));
            }
        }
        // The shaping changes the value, never the density.
        let s = light.sample(*p, Vec2::new(0.3, 0.6)).unwrap();
        assert!((light.pdf(*p, s.dir) - s.pdf).abs() <= 1e-4 * s.pdf, "{name}");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn bounds_of_a_spot_light_cull_only_where_it_is_dark() {
    let shaping = Shaping::new(Vec3::NEG_Z, 25f32.to_radians(), 0.0, 0.0, Vec3::ZERO).unwrap();
    let spot: SceneLight = PointLight::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ONE).unwrap().with_shaping(shaping).into();
    let b = LightBounds::of(&spot).unwrap();
    let mut rng = Pcg32::new(4, 4);
    let (mut lit, mut culled_dark) = (0, 0);
    for _ in 0..20_000 {
        let p = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 2.0);
        let reaches = spot.sample(p, Vec2::ZERO).is_some_and(|s| s.radiance.x > 0.0);
        let importance = b.importance(p, Vec3::Z);
        if reaches {
            lit += 1;
            assert!(importance > 0.0, "{p} is lit but culled");
        } else {
            culled_dark += usize::from(importance == 0.0);
        }
    }
    // Most points outside the cone are culled (the bounds are not a whole sphere).
    assert!(lit > 500 && culled_dark > 10_000, "{lit} lit, {culled_dark} dark points culled");
}

/// A face of a shaped mesh light, tilted from the shaping axis (the light's −Z): its power is
/// radiance × area × ∫ factor · max(0, ω·n) dω (|ω·n| two-sided) by brute-force quadrature over
/// the sphere, at tilts from 0° to 150°; sampled as an unshaped triangle, it estimates what
/// quadrature of `eval` gives.
#[test]
fn a_tilted_shaped_triangle_has_the_power_and_radiance_of_its_falloff() {
    use sampler_core::light::TriangleLight;
    let axis = Vec3::new(0.0, 0.0, -1.0);
    let shaping = Shaping::new(axis, 50f32.to_radians(), 0.4, 2.0, Vec3::new(0.2, 0.6, 1.0)).unwrap();
    let n = 500;
    let quad = |normal: Vec3, two_sided: bool, c: usize| {
        let mut total = 0.0;
        for i in 0..n {
            let theta = PI * (i as f64 + 0.5) / n as f64;
            for j in 0..2 * n {
                let phi = PI * (j as f64 + 0.5) / n as f64;
                let w =
                    Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
                let cos = w.dot(normal) as f64;
                let cos = if two_sided { cos.abs() } else { cos.max(0.0) };
                total += shaping.factor(w)[c] as f64 * cos * theta.sin();
            }
        }
        total * (PI / n as f64).powi(2)
    };
    for tilt_deg in [0.0f32, 30.0, 80.0, 150.0] {
        let t = tilt_deg.to_radians();
        let normal = Vec3::new(t.sin(), 0.0, -t.cos());
        // A triangle of area ½ whose front faces `normal`.
        let (u, v) = (Vec3::Y, normal.cross(Vec3::Y));
        let tri = TriangleLight::new([Vec3::ZERO, u, v], Vec3::splat(2.0)).unwrap().with_shaping(shaping);
        for two_sided in [false, true] {
            let tri = tri.with_two_sided(two_sided);
            for c in 0..3 {
                let expected = 2.0 * 0.5 * quad(normal, two_sided, c);
                let power = tri.power(1.0)[c] as f64;
                assert!(
                    (power - expected).abs() <= 2e-3 * expected + 1e-6,
                    "tilt {tilt_deg}°, two-sided {two_sided}, channel {c}: {power} against {expected}"
                );
            }
        }
    }
    // Radiance: a triangle 1 above a receiver, tilted 40° from the axis, against quadrature.
    let t = 40f32.to_radians();
    let normal = Vec3::new(t.sin(), 0.0, -t.cos());
    let (u, v) = (Vec3::Y, normal.cross(Vec3::Y));
    let c0 = Vec3::new(0.0, 0.0, 1.0);
    let tri: SceneLight =
        TriangleLight::new([c0 - 0.5 * u, c0 + 0.5 * u, c0 + v], Vec3::ONE).unwrap().with_shaping(shaping).into();
    let p = Vec3::new(0.4, 0.1, 0.0);
    let est = estimate(&tri, p, Vec3::Z, 60_000, 90);
    let to = c0 - p;
    for (c, &(mean, se)) in est.iter().enumerate() {
        let quad = integrate_cone_jittered(to.normalize(), 1.2, 500, 91, |d| {
            tri.eval(p, d).map_or(0.0, |h| h.radiance[c] as f64 * Vec3::Z.dot(d).max(0.0) as f64)
        });
        assert!((mean - quad).abs() <= 4.0 * se + 3e-3 * quad, "channel {c}: {mean} ± {se} against {quad}");
    }
}
