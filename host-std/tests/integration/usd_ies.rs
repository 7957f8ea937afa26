//! IES profiles authored in USD (`host-usd/tests/fixtures/lights_ies.usda`, from Pixar's
//! library): the lights the renderer builds deliver, at points on the floor, the irradiance the
//! schema gives from the file's own table (looked up here from the parsed file at the angles
//! worked out by hand from the light's transform); a normalised, rescaled profile keeps the
//! unshaped light's power within its cone; `ppis info` describes each profile and no longer
//! lists IES as unrendered; a type B or missing file stops `ppis render` with one error line
//! naming the file, exit code 2.
#![cfg(feature = "usd")]

use host_std::scene::{ies, usd};
use sampler_core::glam::{Vec2, Vec3};
use sampler_core::light::{Light, SceneLight};
use std::path::PathBuf;

fn fixtures() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures")
}

fn ppis() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_ppis"))
}

#[test]
fn a_profiled_point_light_lights_the_floor_as_its_table_says() {
    let converted = usd::load(&fixtures().join("lights_ies.usda"), &usd::Options::default()).unwrap();
    assert!(converted.notes.is_empty(), "{:?}", converted.notes);
    assert!(converted.files.iter().any(|f| f.ends_with("bilateral_1995.ies")), "{:?}", converted.files);
    let lights = &converted.scene.lights;
    assert_eq!(lights.len(), 3);
    let SceneLight::Point(spot) = lights[0] else { panic!("{:?}", lights[0]) };
    let file = ies::parse(&std::fs::read(fixtures().join("ies/bilateral_1995.ies")).unwrap()).unwrap();
    let table = file.profile();
    // The light is 3 above the origin, its −Z down, +X along world +X, +Y along world −Z. For a
    // floor point q, the direction back to the light in its frame is w = (−q.x, q.z, 3)/d:
    // θ = acos(3/d), φ = atan2(q.z, −q.x).
    for q in [Vec3::new(0.5, 0.0, 0.0), Vec3::new(-2.0, 0.0, 0.3), Vec3::new(0.4, 0.0, 1.5), Vec3::new(1.0, 0.0, -2.5)]
    {
        let d = (Vec3::new(0.0, 3.0, 0.0) - q).length();
        let (theta, phi) = ((3.0 / d).acos(), q.z.atan2(-q.x));
        // treatAsPoint: intensity π r² L, radius 0.5 (the fallback), L = 2.
        let expected = std::f32::consts::PI * 0.25 * 2.0 * table.eval(theta, phi) * (3.0 / d) / (d * d);
        let s = spot.sample(q, Vec2::splat(0.5)).unwrap();
        let e = s.radiance.x * s.dir.dot(Vec3::Y);
        assert!((e - expected).abs() <= 1e-4 * expected.max(1e-3), "{q}: {e} against {expected}");
    }
    // The bilateral table differs across its plane of symmetry's normal: +X and −X differ.
    let at = |x: f32| spot.sample(Vec3::new(x, 0.0, 0.0), Vec2::ZERO).unwrap().radiance.x;
    assert!((at(2.0) - at(-2.0)).abs() > 0.05 * at(2.0), "{} {}", at(2.0), at(-2.0));
    // The rectangle's normalised profile, squeezed by angleScale 0.5 into 45°, inside the
    // schema's 90° cone: its power is the unshaped panel's times the profile's share of the
    // cosine-weighted hemisphere, less than the unshaped panel's but not zero.
    let SceneLight::Rect(panel) = lights[1] else { panic!() };
    let unshaped = sampler_core::light::RectLight::new(Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::splat(5.0)).unwrap();
    let ratio = panel.power(1.0).x / unshaped.power(1.0).x;
    assert!(ratio > 0.1 && ratio < 1.0, "{ratio}");
    let lit = |l: &dyn Light, p: Vec3| l.sample(p, Vec2::splat(0.5)).is_some_and(|s| s.radiance.x > 0.0);
    // 45° off the panel's axis is the edge of the squeezed profile (the downlight is dark at 90°).
    assert!(lit(&panel, Vec3::new(4.0, 0.0, 0.0)) && !lit(&panel, Vec3::new(8.0, 0.0, 0.0)));
    // The disk authors the file without ShapingAPI: no cone, the quadrant profile lights ahead of its −Z.
    assert!(matches!(lights[2], SceneLight::Disk(_)) && lit(&lights[2], Vec3::new(-4.0, 3.0, -3.0)));
}

#[test]
fn info_describes_each_profile_and_ies_is_no_longer_unrendered() {
    let info = ppis().arg("info").arg(fixtures().join("lights_ies.usda")).output().unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success(), "{}", String::from_utf8_lossy(&info.stderr));
    for needle in [
        "IES profile",
        "bilateral_1995.ies (LM-63-1995, type C, 5 vertical angles 0°–180° × 5 horizontal 0°–180°",
        "angleScale 0.5, normalized",
        "quadrant_1986.ies (LM-63-1986",
    ] {
        assert!(text.contains(needle), "{needle:?} not in {text}");
    }
    assert!(!text.contains("not rendered"), "{text}");
}

#[test]
fn a_bad_or_missing_profile_is_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    for (fixture, needle) in [
        (
            "lights_ies_bad.usda",
            "type_b.ies: type B photometry is not supported (type C only) (the IES profile of /Lamp)",
        ),
        ("lights_ies_missing.usda", "inputs:shaping:ies:file ies/nowhere.ies not found"),
    ] {
        let out = dir.path().join("r.exr");
        let args = ["--width", "8", "--height", "8", "--spp", "1", "-o"];
        let run = ppis().arg("render").arg(fixtures().join(fixture)).args(args).arg(&out).output().unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{fixture}: {stderr}");
        let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("ppis: error:")).collect();
        assert_eq!(errors.len(), 1, "{stderr}");
        assert!(errors[0].contains(needle), "{fixture}: {stderr}");
        assert!(!out.exists(), "{fixture}: an image was written");
    }
}

/// The IES profiles of `lights_shaped_meshes.usda` on a CylinderLight (the round downlight) and
/// on a mesh light whose quad is tilted 30° from its axis (the bilateral wall washer): every
/// face sends, along a sampled direction, the light's intensity times the file's table at the
/// angles worked out by hand from the light's transform (about the light's axis, not the
/// face's normal); each face's power (from the grid its mesh shares) matches brute-force
/// quadrature of what it emits over the sphere; `ppis info` lists nothing as unrendered.
#[test]
fn profiles_on_cylinder_and_mesh_lights_follow_their_tables() {
    let file = fixtures().join("lights_shaped_meshes.usda");
    let converted = usd::load(&file, &usd::Options::default()).unwrap();
    assert!(converted.notes.is_empty(), "{:?}", converted.notes);
    let faces = |x: std::ops::Range<f32>| -> Vec<sampler_core::light::TriangleLight> {
        let lights = converted.scene.lights.iter();
        lights
            .filter_map(|l| if let SceneLight::Triangle(t) = l { Some(*t) } else { None })
            .filter(|t| {
                let sampler_core::light::LightSurface::Triangle(v) = t.surface() else { return false };
                x.contains(&v[0].x)
            })
            .collect()
    };
    let (tube, panel) = (faces(-6.0..-4.0), faces(9.0..11.0));
    assert_eq!((tube.len(), panel.len()), (128, 2));
    let table = |name: &str| {
        let file = ies::parse(&std::fs::read(fixtures().join("ies").join(name)).unwrap()).unwrap();
        file.profile()
    };
    let (round, wall) = (table("downlight_2002.ies"), table("bilateral_1995.ies"));
    // Both lights: −Z turned down (world −Y), +X along world +X, +Y along world −Z. For the
    // direction w back to the light, θ = acos(w.y) and φ = atan2(−w.z, w.x).
    let angles = |w: Vec3| (w.y.clamp(-1.0, 1.0).acos(), (-w.z).atan2(w.x));
    let mut checked = 0;
    for (lights, centre, intensity, profile) in
        [(&tube, Vec3::new(-5.0, 3.0, 0.0), 0.05, round), (&panel, Vec3::new(10.0, 3.0, 0.0), 0.02, wall)]
    {
        for q in [Vec3::new(0.4, 0.0, 0.3), Vec3::new(-1.5, 0.0, 0.8), Vec3::new(0.9, 0.0, -2.0)] {
            let q = q + Vec3::new(centre.x, 0.0, centre.z);
            for t in lights.iter() {
                let Some(s) = t.sample(q, Vec2::new(0.3, 0.6)) else { continue };
                let (theta, phi) = angles(s.dir);
                let expected = intensity * profile.eval(theta, phi);
                assert!(
                    (s.radiance.x - expected).abs() <= 1e-4 * expected.max(1e-3),
                    "{q}: {} against {expected}",
                    s.radiance.x
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 20, "{checked} samples checked");
    // Power: radiance × area × ∫ factor · max(0, ω·n) dω by a fine midpoint rule over the sphere.
    let n = 400;
    for t in panel.iter().chain(tube.iter().step_by(16)) {
        let sampler_core::light::LightSurface::Triangle(v) = t.surface() else { panic!() };
        let cross = (v[1] - v[0]).cross(v[2] - v[0]);
        let (normal, area) = (cross.normalize(), 0.5 * cross.length());
        let mut total = 0.0f64;
        for i in 0..n {
            let theta = std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
            for j in 0..2 * n {
                let phi = std::f64::consts::PI * (j as f64 + 0.5) / n as f64;
                let w =
                    Vec3::new((theta.sin() * phi.cos()) as f32, theta.cos() as f32, (theta.sin() * phi.sin()) as f32);
                let cos = f64::from(w.dot(normal).max(0.0));
                total += f64::from(t.shaping().factor(w).x) * cos * theta.sin();
            }
        }
        let radiance = if t.surface() == panel[0].surface() || t.surface() == panel[1].surface() { 0.02 } else { 0.05 };
        let expected = radiance * f64::from(area) * total * (std::f64::consts::PI / n as f64).powi(2);
        let power = f64::from(t.power(1.0).x);
        assert!((power - expected).abs() <= 5e-3 * expected + 1e-7, "{power} against {expected}");
    }
    let info = ppis().arg("info").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(info.status.success(), "{}", String::from_utf8_lossy(&info.stderr));
    for needle in
        ["/World/ProfiledTube", "downlight_2002.ies (LM-63-2002", "/World/ProfiledPanel", "bilateral_1995.ies (LM-63"]
    {
        assert!(text.contains(needle), "{needle:?} not in {text}");
    }
    assert!(!text.contains("not rendered"), "{text}");
}
