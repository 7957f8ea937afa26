//! Each light sampler is unbiased: the irradiance it estimates at a point (∫ L cos dω by
//! L·cos/pdf) equals the closed form — a distant light's E·cos for any angular size, a point
//! light's I cos/d², a sphere's π L sin²θmax cos, a polygon's by Lambert's formula, a coaxial
//! disk's π L r²/(r² + h²), the inside of a two-sided sphere's π L — or, where the light dips
//! below the horizon, jittered quadrature of what rays see (`eval`), within 4 standard errors
//! plus the quadrature's error. Near and far, face-on and grazing.

use crate::common::integrate_cone_jittered;
use glam::{DVec3, Vec2, Vec3};
use sampler_core::light::{
    DiskLight, DistantLight, Light, PointLight, RectLight, SceneLight, SphereLight, TriangleLight, TriangleSampling,
};
use sampler_core::rng::Pcg32;
use std::f64::consts::PI;

const SAMPLES: usize = 40_000;

/// The irradiance at `p` on the plane of unit normal `n` estimated from the light's samples:
/// (mean, standard error), red channel.
fn estimate(light: &SceneLight, p: Vec3, n: Vec3, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 77);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..SAMPLES {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let v = light.sample(p, u).map_or(0.0, |s| s.radiance.x as f64 * n.dot(s.dir).max(0.0) as f64 / s.pdf as f64);
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / SAMPLES as f64;
    let var = (sum2 / SAMPLES as f64 - mean * mean).max(0.0);
    (mean, (var / SAMPLES as f64).sqrt())
}

/// Lambert's formula: the irradiance from a polygon of radiance `l` entirely above the plane
/// (p, n): l/2 · Σ Θᵢ n·Γᵢ, Θᵢ the angle between successive vertices and Γᵢ the unit normal of
/// the plane through them and p.
fn lambert_polygon(l: f64, p: Vec3, n: Vec3, vertices: &[Vec3]) -> f64 {
    let (p, n) = (p.as_dvec3(), n.as_dvec3());
    let dirs: Vec<DVec3> = vertices.iter().map(|v| (v.as_dvec3() - p).normalize()).collect();
    let mut sum = 0.0;
    for i in 0..dirs.len() {
        let (a, b) = (dirs[i], dirs[(i + 1) % dirs.len()]);
        let theta = a.cross(b).length().atan2(a.dot(b));
        sum += theta * n.dot(a.cross(b).normalize());
    }
    0.5 * l * sum.abs()
}

struct Check {
    name: String,
    light: SceneLight,
    p: Vec3,
    n: Vec3,
    expected: f64,
    /// Relative error of `expected` itself (quadrature), 0 for a closed form.
    tolerance: f64,
}

/// The irradiance by jittered quadrature of what rays see, with its tolerance.
fn quadrature(light: &SceneLight, p: Vec3, n: Vec3, axis: Vec3, cone: f64) -> f64 {
    integrate_cone_jittered(axis, cone, 500, 5, |d| {
        light.eval(p, d).map_or(0.0, |h| h.radiance.x as f64 * n.dot(d).max(0.0) as f64)
    })
}

fn checks() -> Vec<Check> {
    let mut out = Vec::new();
    let mut push = |name: String, light: SceneLight, p: Vec3, n: Vec3, expected: f64, tolerance: f64| {
        out.push(Check { name, light, p, n, expected, tolerance });
    };
    let tilt = |deg: f32| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
    // Distant lights: E·cos of the plane's tilt, whatever the angular size.
    for angle in [0.0f32, 0.53, 10.0, 40.0] {
        for t in [0.0f32, 30.0, 60.0] {
            let light = DistantLight::new(Vec3::Z, Vec3::splat(3.0), angle.to_radians()).unwrap();
            let e = 3.0 * (t as f64).to_radians().cos();
            push(format!("distant {angle}°, plane tilted {t}°"), light.into(), Vec3::ZERO, tilt(t), e, 0.0);
        }
    }
    // Point lights: I cos/d², near and far.
    for (d, t) in [(0.01f32, 0.0f32), (1.0, 45.0), (1e3, 80.0)] {
        let light = PointLight::new(Vec3::new(0.0, 0.0, d), Vec3::splat(2.0)).unwrap();
        let e = 2.0 * (t as f64).to_radians().cos() / (d as f64 * d as f64);
        push(format!("point at {d}, plane tilted {t}°"), light.into(), Vec3::ZERO, tilt(t), e, 0.0);
    }
    // Spheres straight above: π L sin²θmax cos (the cone above the horizon).
    for (d, t) in [(1.05f32, 0.0f32), (3.0, 40.0), (100.0, 0.0), (1e4, 60.0)] {
        let light = SphereLight::new(Vec3::new(0.0, 0.0, d), 1.0, Vec3::splat(1.5)).unwrap();
        let e = PI * 1.5 / (d as f64 * d as f64) * (t as f64).to_radians().cos();
        push(format!("sphere at {d}, plane tilted {t}°"), light.into(), Vec3::ZERO, tilt(t), e, 0.0);
    }
    let sphere = SphereLight::new(Vec3::new(0.0, 0.0, 1.5), 1.0, Vec3::splat(1.5)).unwrap();
    let e = quadrature(&sphere.into(), Vec3::ZERO, tilt(80.0), Vec3::Z, (1.0f64 / 1.5).asin() * 1.02);
    push("sphere across the horizon".into(), sphere.into(), Vec3::ZERO, tilt(80.0), e, 3e-3);
    let inside = SphereLight::new(Vec3::ZERO, 2.0, Vec3::splat(1.5)).unwrap().with_two_sided(true);
    push("inside a two-sided sphere".into(), inside.into(), Vec3::new(0.5, 1.0, -0.3), tilt(70.0), PI * 1.5, 0.0);
    // Rectangles: Lambert's formula above the horizon (the last one sampled by area), quadrature
    // across it.
    let rect = |d: f32| {
        let c = [Vec3::new(-0.5, -1.0, d), Vec3::new(0.5, -1.0, d), Vec3::new(0.5, 1.0, d), Vec3::new(-0.5, 1.0, d)];
        (RectLight::new(c[0], c[1] - c[0], c[3] - c[0], Vec3::splat(2.0)).unwrap().with_two_sided(true), c)
    };
    for (d, t, p) in [(0.05f32, 0.0f32, Vec3::ZERO), (1.0, 30.0, Vec3::new(0.6, 0.3, 0.0)), (3e4, 20.0, Vec3::ZERO)] {
        let (light, c) = rect(d);
        let e = lambert_polygon(2.0, p, tilt(t), &c);
        push(format!("rectangle at {d}, plane tilted {t}°"), light.into(), p, tilt(t), e, 0.0);
    }
    let (light, _) = rect(0.3);
    let p = Vec3::new(2.0, 0.0, 0.0);
    let axis = (Vec3::new(0.0, 0.0, 0.3) - p).normalize();
    let e = quadrature(&light.into(), p, Vec3::Z, axis, 1.0);
    push("rectangle at grazing angles".into(), light.into(), p, Vec3::Z, e, 3e-3);
    // Disks: coaxial closed form; off axis and grazing by quadrature.
    for h in [0.2f32, 1.0, 50.0] {
        let light = DiskLight::new(Vec3::new(0.0, 0.0, h), Vec3::NEG_Z, 0.8, Vec3::splat(2.0)).unwrap();
        let e = PI * 2.0 * 0.64 / (0.64 + h as f64 * h as f64);
        push(format!("coaxial disk at {h}"), light.into(), Vec3::ZERO, Vec3::Z, e, 0.0);
    }
    let disk = DiskLight::new(Vec3::new(0.0, 0.0, 0.4), Vec3::new(0.3, 0.0, -1.0), 0.8, Vec3::splat(2.0)).unwrap();
    let p = Vec3::new(1.2, 0.2, 0.0);
    let axis = (Vec3::new(0.0, 0.0, 0.4) - p).normalize();
    let e = quadrature(&disk.into(), p, tilt(-30.0), axis, 1.2);
    push("disk off axis, across the horizon".into(), disk.into(), p, tilt(-30.0), e, 3e-3);
    // Triangles, both samplers: Lambert's formula.
    let tri = [Vec3::new(-1.0, 0.0, 0.5), Vec3::new(1.0, 1.5, 0.5), Vec3::new(0.0, -0.5, 0.5)];
    for sampling in [TriangleSampling::Area, TriangleSampling::default()] {
        let light = TriangleLight::new(tri, Vec3::splat(2.0)).unwrap().with_sampling(sampling).with_two_sided(true);
        for (p, t) in
            [(Vec3::new(0.1, 0.2, 0.45), 0.0f32), (Vec3::new(3.0, 0.0, 0.0), -40.0), (Vec3::splat(-200.0), 0.0)]
        {
            let e = lambert_polygon(2.0, p, tilt(t), &tri);
            push(format!("triangle {sampling:?} from {p}, tilted {t}°"), light.into(), p, tilt(t), e, 0.0);
        }
    }
    out
}

#[test]
fn light_samplers_estimate_the_irradiance_without_bias() {
    let mut failures = Vec::new();
    for (k, c) in checks().iter().enumerate() {
        let (mean, se) = estimate(&c.light, c.p, c.n, 100 + k as u64);
        let bound = 4.0 * se + c.tolerance * c.expected + 1e-6 * c.expected;
        let agrees = (mean - c.expected).abs() <= bound && c.expected > 0.0;
        if !agrees {
            failures.push(format!("{}: {mean} ± {se} against {}", c.name, c.expected));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// One light picked by power, then sampled: L cos / (pmf · pdf) estimates the sum of every
/// light's irradiance (here each one's closed form), delta lights included.
#[test]
fn picking_lights_by_power_keeps_the_estimate_unbiased() {
    use sampler_core::light::PowerSelector;
    let (p, n) = (Vec3::ZERO, Vec3::Z);
    let corners =
        [Vec3::new(-0.5, 1.0, 2.0), Vec3::new(0.5, 1.0, 2.0), Vec3::new(0.5, 2.0, 2.0), Vec3::new(-0.5, 2.0, 2.0)];
    let rect = RectLight::new(corners[0], corners[3] - corners[0], corners[1] - corners[0], Vec3::splat(2.0)).unwrap();
    let lights: Vec<(SceneLight, f64)> = vec![
        (PointLight::new(Vec3::new(0.0, 0.0, 2.0), Vec3::splat(3.0)).unwrap().into(), 0.75),
        (SphereLight::new(Vec3::new(0.0, 0.0, 5.0), 1.0, Vec3::splat(4.0)).unwrap().into(), PI * 4.0 / 25.0),
        (rect.into(), lambert_polygon(2.0, p, n, &corners)),
        (DiskLight::new(Vec3::new(0.0, 0.0, 1.0), Vec3::NEG_Z, 0.5, Vec3::ONE).unwrap().into(), PI * 0.25 / 1.25),
        (DistantLight::new(Vec3::new(0.0, 0.6, 0.8), Vec3::splat(0.5), 0.1).unwrap().into(), 0.4),
        (DistantLight::new(Vec3::new(0.6, 0.0, 0.8), Vec3::splat(0.2), 0.0).unwrap().into(), 0.16),
    ];
    assert!(rect.normal().z < 0.0, "the rectangle faces the receiver");
    let expected: f64 = lights.iter().map(|(_, e)| e).sum();
    let weights: Vec<f32> = lights.iter().map(|(l, _)| l.power(10.0).x).collect();
    let mut cdf = vec![0.0; weights.len() + 1];
    let selector = PowerSelector::build(&weights, &mut cdf).unwrap();
    let mut rng = Pcg32::new(31, 5);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..SAMPLES {
        let picked = selector.pick(rng.next_f64());
        let light = &lights[picked.index].0;
        let u = Vec2::new(picked.u_remapped as f32, rng.next_f32());
        let v = light
            .sample(p, u)
            .map_or(0.0, |s| s.radiance.x as f64 * n.dot(s.dir).max(0.0) as f64 / (s.pdf as f64 * picked.pmf));
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / SAMPLES as f64;
    let se = ((sum2 / SAMPLES as f64 - mean * mean).max(0.0) / SAMPLES as f64).sqrt();
    assert!((mean - expected).abs() <= 4.0 * se, "{mean} ± {se} against {expected}");
}
