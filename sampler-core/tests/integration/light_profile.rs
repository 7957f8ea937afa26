//! Lights shaped by an IES profile (UsdLux `shaping:ies:file`, `…:angleScale`, `…:normalize`).
//! A profiled spot over a Lambert plane delivers I·profile(θ_ies, φ)·cos/d², with the profile
//! interpolated here independently of the core and oriented as HdEmbree orients it (θ from the
//! light's −Z, φ of the direction back to the light from its +X towards +Y); a light's power is
//! its intensity times a brute-force quadrature of the factor over the sphere, cone and focus
//! included; profiled area lights keep their unshaped densities and estimate what quadrature of
//! `eval` gives; the tree's bounds never cull a point the light reaches.

use crate::common::integrate_cone_jittered;
use glam::{Vec2, Vec3};
use sampler_core::light::{
    DiskLight, IntensityProfile, Light, LightBounds, PointLight, RectLight, SceneLight, Shaping, SphereLight,
};
use sampler_core::rng::Pcg32;
use std::f64::consts::PI;

/// A table that depends on both angles: vertical 0°, 20°, 45°, 90°, 135°; horizontal 0°–180°
/// (bilateral) in steps of 45°; one value at the nadir, where every horizontal angle meets.
const VERTICAL_DEG: [f32; 5] = [0.0, 20.0, 45.0, 90.0, 135.0];
const HORIZONTAL_DEG: [f32; 5] = [0.0, 45.0, 90.0, 135.0, 180.0];

fn candela(h: usize, v: usize) -> f32 {
    let base = [900.0, 800.0, 400.0, 60.0, 0.0][v];
    if v == 0 { base } else { base * (1.0 + 0.5 * h as f32 / 4.0) }
}

fn profile() -> &'static IntensityProfile<'static> {
    let rad = |d: &[f32]| -> &'static [f32] { Box::leak(d.iter().map(|x| x.to_radians()).collect::<Box<[f32]>>()) };
    let table: Vec<f32> = (0..5).flat_map(|h| (0..5).map(move |v| candela(h, v))).collect();
    let table: &'static [f32] = Box::leak(table.into_boxed_slice());
    Box::leak(Box::new(IntensityProfile::new(rad(&VERTICAL_DEG), rad(&HORIZONTAL_DEG), table).unwrap()))
}

/// The table interpolated in f64: bilinear, φ folded about the 0°–180° plane, 0 past 135°.
fn reference(theta_deg: f64, phi_deg: f64) -> f64 {
    let mut phi = phi_deg.rem_euclid(360.0);
    if phi > 180.0 {
        phi = 360.0 - phi;
    }
    if theta_deg > 135.0 {
        return 0.0;
    }
    let v = VERTICAL_DEG.iter().rposition(|&a| f64::from(a) <= theta_deg).unwrap().min(3);
    let h = ((phi / 45.0).floor() as usize).min(3);
    let (t0, t1) = (f64::from(VERTICAL_DEG[v]), f64::from(VERTICAL_DEG[v + 1]));
    let t = (theta_deg - t0) / (t1 - t0);
    let s = (phi - 45.0 * h as f64) / 45.0;
    let at = |h: usize, v: usize| f64::from(candela(h, v));
    let row = |h: usize| at(h, v) + t * (at(h, v + 1) - at(h, v));
    row(h) + s * (row(h + 1) - row(h))
}

#[test]
fn a_profiled_spot_over_a_lambert_plane_matches_the_table() {
    // A point light 2 above the plane z = 0, its axis straight down, its +X along world +X.
    let h = 2.0f64;
    let shaping = Shaping::new(Vec3::NEG_Z, std::f32::consts::PI, 0.0, 0.0, Vec3::ZERO).unwrap();
    for angle_scale in [0.0f64, 0.5, -1.5] {
        let shaped = shaping.with_profile(profile(), Vec3::X, Vec3::Y, angle_scale as f32, false).unwrap();
        let light = PointLight::new(Vec3::new(0.0, 0.0, h as f32), Vec3::splat(2.0)).unwrap().with_shaping(shaped);
        for (theta_deg, azimuth_deg) in [(5.0f64, 0.0f64), (10.0, 30.0), (33.0, 100.0), (50.0, 200.0), (70.0, 300.0)] {
            let (theta, az) = (theta_deg.to_radians(), azimuth_deg.to_radians());
            let x = h * theta.tan();
            let p = Vec3::new((x * az.cos()) as f32, (x * az.sin()) as f32, 0.0);
            // The light emits towards azimuth `az`; the direction back to it has azimuth az + π.
            let theta_ies = match angle_scale {
                s if s > 0.0 => theta_deg / s,
                s if s < 0.0 => (theta_deg - 180.0) / -s + 180.0,
                _ => theta_deg,
            }
            .clamp(0.0, 180.0);
            let d2 = h * h + x * x;
            let expected = 2.0 * reference(theta_ies, azimuth_deg + 180.0) * theta.cos() / d2;
            let s = light.sample(p, Vec2::splat(0.5)).unwrap();
            let e = f64::from(s.radiance.x) * f64::from(s.dir.dot(Vec3::Z));
            assert!(
                (e - expected).abs() <= 2e-4 * expected.max(1.0),
                "scale {angle_scale}, {theta_deg}° at {azimuth_deg}°: {e} against {expected}"
            );
        }
    }
}

#[test]
fn normalize_divides_by_the_mean_intensity_of_the_profile() {
    let p = profile();
    let shaping = Shaping::new(Vec3::NEG_Z, std::f32::consts::PI, 0.0, 0.0, Vec3::ZERO).unwrap();
    let raw = shaping.with_profile(p, Vec3::X, Vec3::Y, 0.0, false).unwrap();
    let normalized = shaping.with_profile(p, Vec3::X, Vec3::Y, 0.0, true).unwrap();
    let d = Vec3::new(0.3, -0.2, -1.0).normalize();
    let ratio = raw.factor(d).x / normalized.factor(d).x;
    // The table spans 135°, more than a hemisphere: its flux over 4π.
    let flux = quadrature(|d| f64::from(raw.factor(d).x), 800);
    assert!(
        (f64::from(ratio) - flux / (4.0 * PI)).abs() < 2e-3 * ratio as f64,
        "{ratio} against {}",
        flux / (4.0 * PI)
    );
    // Normalised, the profile's flux is the unshaped light's: 4π.
    assert!((quadrature(|d| f64::from(normalized.factor(d).x), 800) - 4.0 * PI).abs() < 5e-3);
}

/// ∫ f dω over the sphere by the midpoint rule on an n × 2n grid in (θ, φ).
fn quadrature(f: impl Fn(Vec3) -> f64, n: usize) -> f64 {
    let mut total = 0.0;
    for i in 0..n {
        let theta = PI * (i as f64 + 0.5) / n as f64;
        for j in 0..2 * n {
            let phi = PI * (j as f64 + 0.5) / n as f64;
            let d = Vec3::new((theta.sin() * phi.cos()) as f32, (theta.sin() * phi.sin()) as f32, theta.cos() as f32);
            total += f(d) * theta.sin();
        }
    }
    total * (PI / n as f64) * (PI / n as f64)
}

#[test]
fn power_includes_the_profile_cone_and_focus() {
    let axis = Vec3::new(0.2, -0.3, -1.0).normalize();
    let cases = [(PI, 0.0, 0.0, 0.0), (60f64.to_radians(), 0.4, 2.0, 0.7), (100f64.to_radians(), 0.2, 0.0, -0.8)];
    for (cone, softness, focus, angle_scale) in cases {
        let shaping = Shaping::new(axis, cone as f32, softness, focus, Vec3::new(0.2, 0.5, 1.0))
            .unwrap()
            .with_profile(profile(), Vec3::new(1.0, 0.5, 0.0), Vec3::Y, angle_scale, true)
            .unwrap();
        let point = PointLight::new(Vec3::ZERO, Vec3::splat(3.0)).unwrap().with_shaping(shaping);
        let quad = quadrature(|d| f64::from(shaping.factor(d).y), 600);
        let power = f64::from(point.power(1.0).y);
        assert!((power - 3.0 * quad).abs() < 2e-3 * power, "point, cone {cone}: {power} against {}", 3.0 * quad);
        // A disk facing along the axis: L·A·∫ factor·cos over its front, both sides when two-sided.
        let disk = DiskLight::new(Vec3::ZERO, axis, 0.5, Vec3::splat(2.0)).unwrap().with_shaping(shaping);
        let quad_cos = quadrature(|d| f64::from(shaping.factor(d).y) * f64::from(d.dot(axis).max(0.0)), 600);
        let area = PI * 0.25;
        let expected = 2.0 * area * quad_cos;
        let power = f64::from(disk.power(1.0).y);
        assert!((power - expected).abs() < 2e-3 * expected, "disk, cone {cone}: {power} against {expected}");
        let two = disk.with_two_sided(true);
        let quad_both = quadrature(|d| f64::from(shaping.factor(d).y) * f64::from(d.dot(axis).abs()), 600);
        let power = f64::from(two.power(1.0).y);
        assert!((power - 2.0 * area * quad_both).abs() < 2e-3 * power, "two-sided disk: {power}");
    }
}

/// Mean and standard error of L·cos/pdf per channel over `samples` light samples.
fn estimate(light: &SceneLight, p: Vec3, n: Vec3, samples: usize, seed: u64) -> [(f64, f64); 3] {
    let mut rng = Pcg32::new(seed, 12);
    let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..samples {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let v = light.sample(p, u).map_or(Vec3::ZERO, |s| s.radiance * n.dot(s.dir).max(0.0) / s.pdf);
        for c in 0..3 {
            sum[c] += f64::from(v[c]);
            sum2[c] += f64::from(v[c]).powi(2);
        }
    }
    core::array::from_fn(|c| {
        let mean = sum[c] / samples as f64;
        (mean, ((sum2[c] / samples as f64 - mean * mean).max(0.0) / samples as f64).sqrt())
    })
}

#[test]
fn profiled_area_lights_estimate_what_quadrature_sees() {
    let shaping = |axis: Vec3, focus: f32| {
        Shaping::new(axis, std::f32::consts::PI, 0.0, focus, Vec3::new(0.0, 0.4, 1.0))
            .unwrap()
            .with_profile(profile(), Vec3::X, Vec3::Y, 0.8, true)
            .unwrap()
    };
    let rect =
        RectLight::new(Vec3::new(-1.0, -0.5, 1.5), Vec3::new(0.0, 1.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::ONE)
            .unwrap();
    let cases: Vec<(&str, SceneLight, Vec3, Vec3, f64)> = vec![
        (
            "sphere",
            SphereLight::new(Vec3::new(0.0, 0.0, 2.0), 0.5, Vec3::splat(2.0))
                .unwrap()
                .with_shaping(shaping(Vec3::new(0.3, 0.0, -1.0).normalize(), 2.0))
                .into(),
            Vec3::new(0.6, 0.2, 0.0),
            Vec3::new(0.0, 0.0, 2.0),
            0.5,
        ),
        (
            "rectangle",
            rect.with_shaping(shaping(rect.normal(), 0.0)).into(),
            Vec3::new(0.8, 0.3, 0.0),
            Vec3::new(0.0, 0.0, 1.5),
            1.2,
        ),
        (
            "disk",
            DiskLight::new(Vec3::new(0.0, 0.0, 1.0), Vec3::NEG_Z, 0.8, Vec3::splat(3.0))
                .unwrap()
                .with_shaping(shaping(Vec3::NEG_Z, 1.0))
                .into(),
            Vec3::new(-0.5, 0.4, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            0.8,
        ),
    ];
    let mut failures = Vec::new();
    for (k, (name, light, p, centre, reach)) in cases.iter().enumerate() {
        let n = Vec3::Z;
        let to = *centre - *p;
        let cone = ((*reach as f32 / to.length()).min(1.0) as f64).asin() * 1.1;
        let est = estimate(light, *p, n, 60_000, 70 + k as u64);
        for (c, &(mean, se)) in est.iter().enumerate() {
            let quad = integrate_cone_jittered(to.normalize(), cone, 500, 19 + k as u64, |d| {
                light.eval(*p, d).map_or(0.0, |h| f64::from(h.radiance[c]) * f64::from(n.dot(d).max(0.0)))
            });
            if (mean - quad).abs() > 4.0 * se + 3e-3 * quad {
                failures.push(format!("{name}, channel {c}: {mean} ± {se} against {quad}"));
            }
        }
        let s = light.sample(*p, Vec2::new(0.3, 0.6)).unwrap();
        assert!((light.pdf(*p, s.dir) - s.pdf).abs() <= 1e-4 * s.pdf, "{name}: the density is the unshaped one");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn bounds_of_a_profiled_spot_cull_only_where_it_is_dark() {
    // A downlight: 0°–90°, dark from 90°, squeezed by angleScale 0.5 to 45°.
    let v: &'static [f32] = Box::leak(Box::new([0.0f32, 0.5, 1.0, std::f32::consts::FRAC_PI_2]));
    let table: &'static [f32] = Box::leak(Box::new([50.0f32, 40.0, 5.0, 0.0]));
    let p = Box::leak(Box::new(IntensityProfile::new(v, &[0.0], table).unwrap()));
    let shaping = Shaping::new(Vec3::NEG_Z, std::f32::consts::PI, 0.0, 0.0, Vec3::ZERO)
        .unwrap()
        .with_profile(p, Vec3::X, Vec3::Y, 0.5, false)
        .unwrap();
    assert!((shaping.emission_extent() - std::f32::consts::FRAC_PI_4).abs() < 1e-6, "{}", shaping.emission_extent());
    let spot: SceneLight = PointLight::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ONE).unwrap().with_shaping(shaping).into();
    let b = LightBounds::of(&spot).unwrap();
    let mut rng = Pcg32::new(5, 4);
    let (mut lit, mut culled_dark) = (0, 0);
    for _ in 0..20_000 {
        let q = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 2.0);
        let reaches = spot.sample(q, Vec2::ZERO).is_some_and(|s| s.radiance.x > 0.0);
        let importance = b.importance(q, Vec3::Z);
        if reaches {
            lit += 1;
            assert!(importance > 0.0, "{q} is lit but culled");
        } else {
            culled_dark += usize::from(importance == 0.0);
        }
    }
    assert!(lit > 500 && culled_dark > 10_000, "{lit} lit, {culled_dark} dark points culled");
}

/// A face of a profiled mesh light, tilted from the light's axis: its power, computed alone
/// (`with_shaping`) or from the grid its mesh shares (`with_shaping_on_grid`), is radiance ×
/// area × brute-force quadrature of factor · max(0, ω·n) (|ω·n| two-sided) over the sphere,
/// at tilts 0°–150°, for a profile alone, and squeezed inside a narrow cone with a focus.
#[test]
fn a_tilted_profiled_triangle_has_the_power_of_its_profile() {
    use sampler_core::light::{TILTED_GRID_CELLS, TiltedGrid, TriangleLight};
    let axis = Vec3::new(0.0, 0.0, -1.0);
    let shapings = [
        Shaping::new(axis, std::f32::consts::PI, 0.0, 0.0, Vec3::ONE).unwrap(),
        Shaping::new(axis, 25f32.to_radians(), 0.3, 2.0, Vec3::new(0.2, 0.6, 1.0)).unwrap(),
    ]
    .map(|s| s.with_profile(profile(), Vec3::X, Vec3::Y, 0.0, true).unwrap());
    for (k, shaping) in shapings.iter().enumerate() {
        let mut cells = vec![(Vec3::ZERO, Vec3::ZERO); TILTED_GRID_CELLS];
        let grid = TiltedGrid::build(shaping, &mut cells);
        for tilt_deg in [0.0f32, 20.0, 80.0, 150.0] {
            let t = tilt_deg.to_radians();
            let normal = Vec3::new(t.sin(), 0.0, -t.cos());
            let (u, v) = (Vec3::Y, normal.cross(Vec3::Y));
            let tri = TriangleLight::new([Vec3::ZERO, u, v], Vec3::splat(2.0)).unwrap();
            for two_sided in [false, true] {
                let tri = tri.with_two_sided(two_sided);
                let cos = |d: Vec3| if two_sided { d.dot(normal).abs() } else { d.dot(normal).max(0.0) };
                let quad = quadrature(|d| f64::from(shaping.factor(d).y) * f64::from(cos(d)), 700);
                let expected = 2.0 * 0.5 * quad;
                for (how, light) in
                    [("alone", tri.with_shaping(*shaping)), ("on the grid", tri.with_shaping_on_grid(*shaping, &grid))]
                {
                    let power = f64::from(light.power(1.0).y);
                    assert!(
                        (power - expected).abs() <= 3e-3 * expected + 1e-6,
                        "shaping {k}, tilt {tilt_deg}°, two-sided {two_sided}, {how}: {power} against {expected}"
                    );
                }
            }
        }
    }
}

/// A face of a mesh light shaped by a 30° cone about an axis tilted 50° from its normal: the
/// tree's bounds narrow to the cone (most points outside it are culled; the face's two-sided
/// hemisphere bounds cull about half as many) and never cull a point the face lights.
#[test]
fn bounds_of_a_shaped_tilted_face_cull_only_where_it_is_dark() {
    use sampler_core::light::TriangleLight;
    let axis = Vec3::new(50f32.to_radians().sin(), 0.0, -50f32.to_radians().cos());
    let shaping = Shaping::new(axis, 30f32.to_radians(), 0.5, 0.0, Vec3::ONE).unwrap();
    let c = Vec3::new(0.0, 0.0, 3.0);
    let face = TriangleLight::new([c, c + Vec3::new(0.0, 0.5, 0.0), c + Vec3::new(0.5, 0.0, 0.0)], Vec3::ONE)
        .unwrap()
        .with_two_sided(true)
        .with_shaping(shaping);
    let face: SceneLight = face.into();
    let b = LightBounds::of(&face).unwrap();
    let mut rng = Pcg32::new(9, 4);
    let (mut lit, mut culled_dark) = (0, 0);
    for _ in 0..20_000 {
        let q = Vec3::new(rng.next_f32() * 12.0 - 6.0, rng.next_f32() * 12.0 - 6.0, rng.next_f32() * 2.0);
        let n = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE).normalize();
        let reaches = (0..16).any(|k| {
            let u = Vec2::new((k % 4) as f32 / 4.0 + 0.1, (k / 4) as f32 / 4.0 + 0.1);
            face.sample(q, u).is_some_and(|s| s.radiance.x > 0.0 && s.dir.dot(n) > 0.0)
        });
        let importance = b.importance(q, n);
        if reaches {
            lit += 1;
            assert!(importance > 0.0, "{q} (normal {n}) is lit but culled");
        } else {
            culled_dark += usize::from(importance == 0.0);
        }
    }
    assert!(lit > 500 && culled_dark > 15_000, "{lit} lit, {culled_dark} dark points culled");
}
