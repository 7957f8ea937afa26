//! USD scenes render as authored: the USD twins of a JSON scene (authored with Pixar's
//! library by `host-usd/tests/fixtures/make_twins.py`: Lambert, metallic conductor, specular
//! workflow, clear coat) render like the JSON original, sphere by sphere, within noise — and a
//! material given the wrong GGX α (roughness instead of roughness²) would not. The twins'
//! UsdRenderSettings pick the image size and the camera.
#![cfg(feature = "usd")]

use host_std::light::environment::Environment;
use host_std::plan::Method;
use host_std::plan::{Settings, render};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::{Bsdf, Scene, Shape};
use host_std::scene::{json, usd};
use host_std::trace::bvh::Bvh;
use host_std::trace::camera::Camera;
use sampler_core::brdf::RoughConductor;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures").join(name)
}

fn render_scene(scene: &Scene, seed: u64) -> Vec<[f32; 3]> {
    let (source, placement) = scene.env.clone().expect("an environment");
    let env = Environment::build(&source, placement).unwrap();
    let bvh = Bvh::build(scene);
    let settings = Settings {
        method: Method::ProductMis,
        spp: 1024,
        shading_points: 64,
        brdf_samples: BrdfSamples::Fixed(64),
        seed,
        progress: false,
        shadows: true,
        lights: Default::default(),
    };
    render(scene, &bvh, Some(&env.hierarchy()), &settings).pixels
}

/// The pixels whose centre ray passes well inside each sphere (edges excluded: they mix the
/// sphere with the background).
fn sphere_pixels(scene: &Scene) -> Vec<Vec<usize>> {
    let camera = Camera::new(&scene.camera);
    let mut pixels = vec![Vec::new(); scene.objects.len()];
    for j in 0..camera.height {
        for i in 0..camera.width {
            let d = camera.direction(i as f32 + 0.5, j as f32 + 0.5);
            for (k, o) in scene.objects.iter().enumerate() {
                let Shape::Sphere { center, radius } = o.shape else { panic!("the twins hold spheres") };
                let to = center - camera.origin;
                if (to - to.dot(d) * d).length() < 0.85 * radius {
                    pixels[k].push((j * camera.width + i) as usize);
                }
            }
        }
    }
    assert!(pixels.iter().all(|p| p.len() > 50), "each sphere covers enough pixels");
    pixels
}

/// Each sphere's mean colour.
fn sphere_means(scene: &Scene, image: &[[f32; 3]]) -> Vec<[f64; 3]> {
    let mean = |ps: &Vec<usize>| {
        let mut s = [0.0f64; 3];
        ps.iter().for_each(|&p| (0..3).for_each(|c| s[c] += f64::from(image[p][c])));
        s.map(|v| v / ps.len() as f64)
    };
    sphere_pixels(scene).iter().map(mean).collect()
}

/// The standard error of each sphere's mean, per channel, from two independent renders `a`
/// and `b` of one scene: pixels are independent, so Var(mean) = Σ (a − b)² / (2 n²).
fn sphere_errors(scene: &Scene, a: &[[f32; 3]], b: &[[f32; 3]]) -> Vec<[f64; 3]> {
    let se = |ps: &Vec<usize>| {
        let n = ps.len() as f64;
        let mut s = [0.0f64; 3];
        ps.iter().for_each(|&p| (0..3).for_each(|c| s[c] += f64::from(a[p][c] - b[p][c]).powi(2)));
        s.map(|v| (v / (2.0 * n * n)).sqrt())
    };
    sphere_pixels(scene).iter().map(se).collect()
}

/// How far two independent estimates of one sphere's mean may be apart: 4 standard errors
/// of their difference (√2 · se), plus 0.5% for the lat-long → equal-area resampling.
fn tolerance(se: f64, value: f64) -> f64 {
    4.0 * std::f64::consts::SQRT_2 * se + 0.005 * value
}

#[test]
fn usd_twins_render_like_their_json_original() {
    let json = json::load(&fixture("twins.json")).unwrap();
    let (a, b) = (render_scene(&json, 1), render_scene(&json, 3));
    let reference = sphere_means(&json, &a);
    let errors = sphere_errors(&json, &a, &b);
    for file in ["twins.usda", "twins.usdc"] {
        let c = usd::load(&fixture(file), &Default::default()).unwrap();
        assert!(c.notes.is_empty(), "{file}: {:?}", c.notes);
        // The render settings' resolution and camera (not the first camera in namespace order).
        assert_eq!((c.scene.camera.width, c.scene.camera.height), (96, 64), "{file}");
        assert_eq!(c.usd.camera.as_ref().unwrap().path, "/World/Camera", "{file}");
        assert!((c.scene.camera.fov_y_deg - json.camera.fov_y_deg).abs() < 1e-3, "{file}");
        assert!((c.scene.camera.origin - json.camera.origin).length() < 1e-6, "{file}");
        for (o, p) in c.scene.objects.iter().zip(&json.objects) {
            assert_eq!(o.shape, p.shape, "{file}");
        }
        let got = sphere_means(&c.scene, &render_scene(&c.scene, 2));
        for (k, (g, r)) in got.iter().zip(&reference).enumerate() {
            for c in 0..3 {
                let bound = tolerance(errors[k][c], r[c]);
                let d = (g[c] - r[c]).abs();
                assert!(d < bound, "{file}: sphere {k} channel {c}: USD {g:?}, JSON {r:?}: {d:.2e} > {bound:.2e}");
            }
        }
    }
}

#[test]
fn a_conductor_of_roughness_as_alpha_would_fail_the_twin_test() {
    // The control: the metal sphere's α set to its USD roughness (0.3) instead of 0.3² moves
    // its mean far beyond the twin test's tolerance.
    let json = json::load(&fixture("twins.json")).unwrap();
    let mut wrong = json.clone();
    let metal = wrong.objects[1].material;
    let Bsdf::Conductor(c) = wrong.materials[metal].bsdf else { panic!("sphere 1 is the conductor") };
    wrong.materials[metal].bsdf = Bsdf::Conductor(RoughConductor::new(c.ggx.alpha().sqrt(), c.specular));
    let (a, b) = (render_scene(&json, 1), render_scene(&json, 3));
    let (good, errors) = (sphere_means(&json, &a), sphere_errors(&json, &a, &b));
    let bad = sphere_means(&wrong, &render_scene(&wrong, 2));
    for c in 0..3 {
        let (d, bound) = ((bad[1][c] - good[1][c]).abs(), tolerance(errors[1][c], good[1][c]));
        assert!(d > 2.0 * bound, "channel {c}: {:?} vs {:?}: {d:.2e} within {bound:.2e}", bad[1], good[1]);
    }
}

#[test]
fn width_and_height_override_the_render_settings() {
    let options = usd::Options { width: Some(48), ..Default::default() };
    let c = usd::load(&fixture("twins.usda"), &options).unwrap();
    assert_eq!((c.scene.camera.width, c.scene.camera.height), (48, 64));
    // expandAperture: the 3:2 aperture grows vertically to fill the 3:4 image, so the
    // horizontal field of view stays the authored one.
    let horizontal = |fov_y: f32, aspect: f32| (fov_y.to_radians() * 0.5).tan() * aspect;
    let authored = horizontal(40.0, 1.5);
    assert!((horizontal(c.scene.camera.fov_y_deg, 0.75) - authored).abs() < 1e-5);
}
