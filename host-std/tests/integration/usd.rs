//! USD scenes end to end: the DomeLight's orientation (a one-bright-texel dome seen in a
//! mirror-like sphere, for Y-up and Z-up stages and both DomeLight types), and paying only
//! for what a scene uses.
#![cfg(feature = "usd")]

use host_std::light::environment::Environment;
use host_std::plan::Method;
use host_std::plan::{Settings, render};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::usd;
use host_std::trace::bvh::Bvh;
use host_std::trace::camera::Camera;
use sampler_core::glam::{Mat3, Vec3};
use std::f32::consts::PI;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures").join(name)
}

/// The bright texel's direction in the renderer's frame, straight from the convention
/// (USD's): the texel at column 8, row 4 of the 32×16 lat-long has u = 8.5/32, v = 4.5/16;
/// u = ½ − atan2(x, z)/2π, v = ½ − asin(y)/π in the light's frame; then the dome's
/// rotateY(20°); DomeLight_1 with poleAxis "scene" on a Z-up stage first turns +Y to +Z
/// (rotateX(+90°)); a Z-up stage then maps (x, y, z) → (x, z, −y).
fn texel_direction(z_up: bool, pole_to_z: bool) -> Vec3 {
    let (u, v) = (8.5f32 / 32.0, 4.5f32 / 16.0);
    let phi = 2.0 * PI * (0.5 - u);
    let y = (PI * (0.5 - v)).sin();
    let r = (1.0 - y * y).sqrt();
    let local = Vec3::new(r * phi.sin(), y, r * phi.cos());
    let pole = if pole_to_z { Mat3::from_rotation_x(PI / 2.0) } else { Mat3::IDENTITY };
    let stage = Mat3::from_rotation_y(20f32.to_radians()) * pole * local;
    if z_up { Vec3::new(stage.x, stage.z, -stage.y) } else { stage }
}

/// The pixel whose camera ray, mirrored on the unit sphere at the origin, leaves closest to `l`.
fn predicted_pixel(camera: &Camera, l: Vec3) -> (f32, f32) {
    let mut best = (f32::MIN, (0.0, 0.0));
    for j in 0..camera.height {
        for i in 0..camera.width {
            let (x, y) = (i as f32 + 0.5, j as f32 + 0.5);
            let d = camera.direction(x, y);
            let o = camera.origin;
            let b = o.dot(d);
            let disc = b * b - (o.length_squared() - 1.0);
            if disc < 0.0 {
                continue;
            }
            let n = (o + (-b - disc.sqrt()) * d).normalize();
            let r = d - 2.0 * d.dot(n) * n;
            if r.dot(l) > best.0 {
                best = (r.dot(l), (x, y));
            }
        }
    }
    best.1
}

/// The luminance-weighted centre of the pixels above half the image's maximum.
fn highlight(pixels: &[[f32; 3]], width: u32) -> (f32, f32) {
    let lum: Vec<f32> = pixels.iter().map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]).collect();
    let max = lum.iter().copied().fold(0.0, f32::max);
    let (mut sx, mut sy, mut sw) = (0.0, 0.0, 0.0);
    for (k, &l) in lum.iter().enumerate() {
        if l > 0.5 * max {
            let (x, y) = ((k as u32 % width) as f32 + 0.5, (k as u32 / width) as f32 + 0.5);
            (sx, sy, sw) = (sx + l * x, sy + l * y, sw + l);
        }
    }
    (sx / sw, sy / sw)
}

#[test]
fn dome_light_orientation_matches_the_convention() {
    let cases = [
        ("dome_y.usda", false, false),
        ("dome1_y.usda", false, false),
        ("dome_z.usda", true, false),
        ("dome1_z.usda", true, true),
        ("dome1_z_poley.usda", true, false),
    ];
    let mut predicted = Vec::new();
    for (file, z_up, pole_to_z) in cases {
        let mut c = usd::load(&fixture(file), &Default::default()).unwrap();
        assert!(c.notes.is_empty(), "{file}: {:?}", c.notes);
        c.scene.camera.width = 96;
        c.scene.camera.height = 72;
        let (source, placement) = c.scene.env.clone().expect("a dome");
        let env = Environment::build(&source, placement).unwrap();
        let bvh = Bvh::build(&c.scene);
        let settings = Settings {
            method: Method::Mis,
            spp: 16,
            shading_points: 4,
            brdf_samples: BrdfSamples::Fixed(64),
            seed: 3,
            progress: false,
            shadows: true,
            lights: Default::default(),
        };
        let image = render(&c.scene, &bvh, Some(&env.hierarchy()), &settings);
        let got = highlight(&image.pixels, image.width as u32);
        let want = predicted_pixel(&Camera::new(&c.scene.camera), texel_direction(z_up, pole_to_z));
        let dist = ((got.0 - want.0).powi(2) + (got.1 - want.1).powi(2)).sqrt();
        assert!(dist < 2.5, "{file}: highlight at {got:?}, the convention puts it at {want:?}");
        predicted.push(want);
    }
    // The cases are told apart: Z-up moves the highlight, and so does DomeLight_1's pole.
    let apart = |a: (f32, f32), b: (f32, f32)| ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt() > 8.0;
    assert!(apart(predicted[0], predicted[2]), "{predicted:?}");
    assert!(apart(predicted[2], predicted[3]), "{predicted:?}");
    assert!(!apart(predicted[2], predicted[4]), "{predicted:?}");
}

#[test]
fn a_scene_without_a_dome_builds_no_environment() {
    let c = usd::load(&fixture("materials.usda"), &Default::default()).unwrap();
    assert!(c.usd.dome.is_none());
    assert!(c.scene.env.is_none(), "no DomeLight, so no env hierarchy is built");
    // Its camera frames the scene's bounds.
    assert_eq!(c.usd.camera.as_ref().unwrap().path, "<default view>");
}

#[test]
fn usd_errors_name_the_file_and_do_not_panic() {
    let tmp = tempfile::Builder::new().prefix("ppis-usd-").tempdir().unwrap();
    let dir = tmp.path();
    let missing = dir.join("missing.usda");
    let e = usd::load(&missing, &Default::default()).err().unwrap().to_string();
    assert!(e.contains("missing.usda") && e.contains("not found"), "{e}");
    for (name, bytes) in [
        ("garbage.usda", b"#usda 1.0\ndef Xform \"A\" {\n  double3 xformOp:translate = (1, 2\n".to_vec()),
        ("garbage.usdc", b"PXR-USDC\x00\x00\x00\x00garbage".to_vec()),
        ("garbage.usdz", b"PK\x03\x04 not a zip".to_vec()),
        ("empty.usda", Vec::new()),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = usd::load(&p, &Default::default()).err().map(|e| e.to_string());
        let e = e.unwrap_or_else(|| panic!("{name} was accepted"));
        assert!(e.contains(name), "{name}: {e}");
    }
    let options = usd::Options { camera: Some("/Root/NoSuchCam".into()), ..Default::default() };
    let e = usd::load(&fixture("dome_y.usda"), &options).err().unwrap().to_string();
    assert!(e.contains("/Root/NoSuchCam"), "{e}");
}

#[test]
fn textures_are_looked_up_at_each_hit() {
    // A quad with a 2×2 texture (red, green above blue, white; clamped), texture coordinates
    // from the primvar the material names (`uv`), under a constant white dome.
    let mut c = usd::load(&fixture("uv_quad.usda"), &Default::default()).unwrap();
    assert!(c.notes.is_empty(), "{:?}", c.notes);
    c.scene.camera.width = 40;
    c.scene.camera.height = 30;
    let (source, placement) = c.scene.env.clone().unwrap();
    let env = Environment::build(&source, placement).unwrap();
    let bvh = Bvh::build(&c.scene);
    let settings = Settings {
        method: Method::Auto,
        spp: 16,
        shading_points: 4,
        brdf_samples: BrdfSamples::Fixed(64),
        seed: 5,
        progress: false,
        shadows: true,
        lights: Default::default(),
    };
    let image = render(&c.scene, &bvh, Some(&env.hierarchy()), &settings);
    let at = |x: usize, y: usize| image.pixels[y * image.width + x];
    let dominant = |p: [f32; 3], k: usize| (0..3).all(|j| j == k || p[k] > 3.0 * p[j]);
    assert!(dominant(at(4, 4), 0), "top left is red: {:?}", at(4, 4));
    assert!(dominant(at(35, 4), 1), "top right is green: {:?}", at(35, 4));
    assert!(dominant(at(4, 25), 2), "bottom left is blue: {:?}", at(4, 25));
    let white = at(35, 25);
    assert!(white.iter().all(|&v| v > 0.6) && white[0] / white[2] < 1.2, "bottom right is white: {white:?}");
}
