//! UsdLux lights render as authored: the USD twins of the light scenes
//! `docs/scenes/light_{point,sphere,rectangle,disk,distant,mesh}.json` (authored with Pixar's
//! library by `host-usd/tests/fixtures/make_lights.py`: a SphereLight with `treatAsPoint`, a
//! SphereLight with exposure, a normalised RectLight, a scaled DiskLight, an angular
//! DistantLight and a mesh with MeshLightAPI) hold lights of the JSON lights' power, and
//! render, at 32 × 32, to the JSON original's mean within noise; so does the twin of
//! `docs/scenes/lights_env.json`, every one of those lights together under a DomeLight of the
//! courtyard map.
#![cfg(feature = "usd")]

use host_std::light::environment::{EnvSource, Environment, Placement};
use host_std::plan::{Method, Settings, render};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::scene::{Scene, json, usd};
use host_std::trace::bvh::Bvh;
use sampler_core::glam::Mat3;
use sampler_core::light::{Light, SceneLight};
use std::path::PathBuf;

const KINDS: [&str; 6] = ["point", "sphere", "rectangle", "disk", "distant", "mesh"];
const SIZE: u32 = 32;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn render_mean(scene: &Scene, seed: u64) -> Vec<f64> {
    let bvh = Bvh::build(scene);
    let settings = Settings {
        method: Method::Mis,
        spp: 512,
        shading_points: 128,
        brdf_samples: BrdfSamples::Fixed(64),
        seed,
        progress: false,
        shadows: true,
        lights: Default::default(),
    };
    let env = scene.env.clone().map(|(source, placement)| Environment::build(&source, placement).unwrap());
    let image = render(scene, &bvh, env.as_ref().map(Environment::hierarchy).as_ref(), &settings);
    image.pixels.iter().map(|p| f64::from(p[0] + p[1] + p[2])).collect()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Loads `docs/scenes/{name}.json` and its twin `host-usd/tests/fixtures/{name}.usda` at 32 × 32
/// and checks that they hold the same camera, lights and environment and render alike.
fn twin_renders_like_its_original(name: &str) {
    let mut original = json::load(&root().join(format!("docs/scenes/{name}.json"))).unwrap();
    (original.camera.width, original.camera.height) = (SIZE, SIZE);
    let file = root().join(format!("host-usd/tests/fixtures/{name}.usda"));
    let options = usd::Options { width: Some(SIZE), height: Some(SIZE), ..Default::default() };
    let twin = usd::load(&file, &options).unwrap();
    assert!(twin.notes.is_empty(), "{name}: {:?}", twin.notes);
    let twin = twin.scene;
    assert!((twin.camera.fov_y_deg - original.camera.fov_y_deg).abs() < 1e-3, "{name}");
    assert!((twin.camera.origin - original.camera.origin).length() < 1e-5, "{name}");
    assert_eq!(twin.env.is_some(), original.env.is_some(), "{name}: an environment in one only");
    if let (Some((source, at)), Some((source_json, at_json))) = (&twin.env, &original.env) {
        // The same map, as bright and in the same frame (the dome is not rotated). A dome's
        // texture is read into memory, named by its path.
        let file = |s: &EnvSource| match s {
            EnvSource::File(path) | EnvSource::Bytes { name: path, .. } => path.canonicalize().unwrap(),
            _ => panic!("{name}: the environment is not a map"),
        };
        assert_eq!(file(source), file(source_json), "{name}");
        let radiance = |p: &Placement| p.tint.map(|t| t * p.scale);
        assert_eq!(radiance(at), radiance(at_json), "{name}");
        let frame = |p: &Placement| Mat3::from_rotation_y(p.rotate_y_deg.to_radians()) * p.rotation;
        assert!(frame(at).abs_diff_eq(frame(at_json), 1e-6), "{name}: the map's frame");
    }
    // The same emitters: as many lights, of the same power.
    assert_eq!(twin.lights.len(), original.lights.len(), "{name}");
    let power = |s: &Scene| s.lights.iter().map(|l| l.power(10.0)).sum::<sampler_core::glam::Vec3>();
    let (p, q) = (power(&twin), power(&original));
    assert!((p - q).abs().max_element() <= 1e-4 * q.max_element(), "{name}: power {p} against {q}");
    // The image's mean within 4 standard errors (from two renders of the original) plus 0.5%.
    // Pixels are clamped to a few times the mean first, the same way in every image: the
    // near-mirror sphere's highlights of small lights are rare bright samples that would
    // swamp the estimate of the error, and equal images stay equal under any clamp.
    let (a, b) = (render_mean(&original, 1), render_mean(&original, 3));
    let clamp = 4.0 * mean(&a);
    let clamped = |v: Vec<f64>| v.into_iter().map(|x| x.min(clamp)).collect::<Vec<f64>>();
    let (a, b) = (clamped(a), clamped(b));
    let n = a.len() as f64;
    let se = (a.iter().zip(&b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / (2.0 * n * n)).sqrt();
    let reference = mean(&a);
    let bound = 4.0 * std::f64::consts::SQRT_2 * se + 0.005 * reference;
    assert!(bound < 0.03 * reference, "{name}: the test resolves a 3% error ({bound:.3e} of {reference:.3e})");
    let got = mean(&clamped(render_mean(&twin, 2)));
    eprintln!("{name}: USD {got:.5}, JSON {reference:.5}, bound {bound:.2e}");
    assert!((got - reference).abs() < bound, "{name}: USD {got:.5}, JSON {reference:.5}, bound {bound:.2e}");
}

#[test]
fn usd_light_twins_render_like_their_json_originals() {
    for kind in KINDS {
        twin_renders_like_its_original(&format!("light_{kind}"));
    }
}

#[test]
fn usd_twin_of_every_light_under_an_environment_renders_like_its_json_original() {
    twin_renders_like_its_original("lights_env");
}

/// The scene format's `shaping` (cone, focus, IES profiles on a point, a rectangle and a mesh
/// light) and ShapingAPI in USD give the same lights: same power, same image within noise.
#[test]
fn usd_twin_of_shaped_lights_renders_like_its_json_original() {
    let original = json::load(&root().join("docs/scenes/lights_shaped.json")).unwrap();
    // Shaped: each kind emits less than it would unshaped.
    let point = original.lights.iter().find_map(|l| if let SceneLight::Point(p) = l { Some(*p) } else { None });
    let point = point.unwrap();
    assert!(point.shaping().profile().is_some() && point.power(1.0).x < 0.9 * 4.0 * std::f32::consts::PI * 12.0);
    twin_renders_like_its_original("lights_shaped");
    // Light by light, the same radiance towards floor points: the profiles sit the same way.
    let twin = usd::load(&root().join("host-usd/tests/fixtures/lights_shaped.usda"), &usd::Options::default());
    let twin = twin.unwrap().scene;
    let mut compared = 0;
    for q in [[0.3, 0.0, 1.2], [-1.0, 0.0, 0.4], [1.4, 0.0, -0.5], [0.2, 0.0, 2.6]] {
        let q = sampler_core::glam::Vec3::from_array(q);
        for (a, b) in original.lights.iter().zip(&twin.lights) {
            let u = sampler_core::glam::Vec2::new(0.4, 0.7);
            let (Some(a), Some(b)) = (a.sample(q, u), b.sample(q, u)) else { continue };
            let tolerance = 1e-3 * a.radiance.max_element() + 1e-6;
            assert!(
                (a.radiance - b.radiance).abs().max_element() <= tolerance,
                "{q}: {} against {}",
                b.radiance,
                a.radiance
            );
            compared += usize::from(a.radiance.max_element() > 0.0);
        }
    }
    assert!(compared > 50, "{compared} lit samples compared");
}

/// ShapingAPI reaches the renderer's lights (`lights_shaping.usda`): the RectLight facing down
/// with a 30° cone lights the floor straight below it and not a point 45° off its axis, the
/// point light aimed along +X lights along +X and not along −X, and the shaped lights' power
/// is the unshaped one's times the integral of their falloff (less).
#[test]
fn shaped_usd_lights_render_their_cone() {
    use sampler_core::glam::{Vec2, Vec3};
    use sampler_core::light::SceneLight;
    let file = root().join("host-usd/tests/fixtures/lights_shaping.usda");
    let converted = usd::load(&file, &usd::Options::default()).unwrap();
    let lights = &converted.scene.lights;
    let rect = lights.iter().find_map(|l| if let SceneLight::Rect(r) = l { Some(*r) } else { None }).unwrap();
    let point = lights.iter().find_map(|l| if let SceneLight::Point(p) = l { Some(*p) } else { None }).unwrap();
    let lit = |l: &dyn Light, p: Vec3| l.sample(p, Vec2::splat(0.5)).is_some_and(|s| s.radiance.max_element() > 0.0);
    assert!(lit(&rect, Vec3::ZERO) && !lit(&rect, Vec3::new(3.0, 0.0, 0.0)));
    assert!(lit(&point, Vec3::new(5.0, 3.0, 0.0)) && !lit(&point, Vec3::new(-1.0, 3.0, 0.0)));
    assert!(lit(&point, Vec3::new(5.0, 4.5, 0.0)) && !lit(&point, Vec3::new(3.0, 4.5, 0.0)), "40° cone");
    let unshaped = sampler_core::light::RectLight::new(Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::splat(10.0)).unwrap();
    assert!(rect.power(1.0).x < 0.5 * unshaped.power(1.0).x, "{} against {}", rect.power(1.0), unshaped.power(1.0));
}

/// A RectLight's `texture:file` (`lights_textured.usda`, a 4 × 2 image on a 2 × 1 rectangle
/// facing down, its first texel at the local (+X, +Y) corner): one emitting cell per texel but
/// the black one, each where the schema puts it with the light's radiance times its texel; and
/// the irradiance the cells deliver, picked by power and sampled by solid angle, matches
/// quadrature over the rectangle of the texture looked up at each point (every channel).
#[test]
fn a_textured_rect_light_emits_its_image() {
    use host_std::light::image_file;
    use sampler_core::glam::{Vec2, Vec3};
    use sampler_core::light::{PowerSelector, SceneLight};
    use sampler_core::rng::Pcg32;
    let fixtures = root().join("host-usd/tests/fixtures");
    let converted = usd::load(&fixtures.join("lights_textured.usda"), &usd::Options::default()).unwrap();
    assert!(converted.notes.is_empty(), "{:?}", converted.notes);
    assert!(converted.files.iter().any(|f| f.ends_with("light_texture.png")), "{:?}", converted.files);
    let lights = &converted.scene.lights;
    assert_eq!(lights.len(), 7, "one cell per texel, the black one left out");
    let image = image_file::load(&fixtures.join("light_texture.png")).unwrap();
    // The image at a point of the rectangle: columns run from x = +1 to −1, rows from z = −½ to +½.
    let texel = |q: Vec3| {
        let col = (((1.0 - q.x) / 2.0 * 4.0) as usize).min(3);
        let row = (((q.z + 0.5) * 2.0) as usize).min(1);
        Vec3::from_array(image.texels[row * 4 + col]) * 3.0
    };
    // The red texel's cell: x in [0.5, 1], z in [−0.5, 0], facing down.
    let red = lights
        .iter()
        .find_map(|l| match l {
            SceneLight::Rect(r) if r.power(1.0).y == 0.0 && r.power(1.0).x > 0.0 => Some(*r),
            _ => None,
        })
        .unwrap();
    let Some(sampler_core::light::LightSurface::Rect { p0, e1, e2 }) = SceneLight::Rect(red).surface() else {
        panic!()
    };
    let centre = p0 + 0.5 * (e1 + e2);
    assert!((centre - Vec3::new(0.75, 2.0, -0.25)).length() < 1e-5 && red.normal().y < -0.999, "{centre}");
    // Irradiance at a point below, by light sampling against quadrature.
    let (p, n) = (Vec3::new(0.3, 0.0, 0.1), Vec3::Y);
    let weights: Vec<f32> = lights.iter().map(|l| l.power(1.0).element_sum()).collect();
    let mut cdf = vec![0.0; weights.len() + 1];
    let selector = PowerSelector::build(&weights, &mut cdf).unwrap();
    let mut rng = Pcg32::new(7, 1);
    let count = 200_000;
    let (mut sum, mut sum2) = (Vec3::ZERO.as_dvec3(), Vec3::ZERO.as_dvec3());
    for _ in 0..count {
        let picked = selector.pick(rng.next_f64());
        let u = Vec2::new(picked.u_remapped as f32, rng.next_f32());
        let v = lights[picked.index].sample(p, u).map_or(Vec3::ZERO.as_dvec3(), |s| {
            (s.radiance * n.dot(s.dir).max(0.0)).as_dvec3() / (s.pdf as f64 * picked.pmf)
        });
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / count as f64;
    let se = ((sum2 / count as f64 - mean * mean).max(Vec3::ZERO.as_dvec3()) / count as f64).powf(0.5);
    let steps = (400, 200);
    let mut quad = Vec3::ZERO.as_dvec3();
    for j in 0..steps.1 {
        for i in 0..steps.0 {
            let q = Vec3::new(
                -1.0 + 2.0 * (i as f32 + 0.5) / steps.0 as f32,
                2.0,
                -0.5 + (j as f32 + 0.5) / steps.1 as f32,
            );
            let d = q - p;
            let g = (n.dot(d) * d.y) as f64 / (d.length_squared() as f64).powi(2);
            quad += texel(q).as_dvec3() * g * (2.0 / (steps.0 * steps.1) as f64);
        }
    }
    for c in 0..3 {
        assert!((mean[c] - quad[c]).abs() <= 4.0 * se[c] + 1e-3 * quad[c], "channel {c}: {mean} ± {se} against {quad}");
    }
}

/// `ppis info` lists every light feature the render leaves out (`lights_unrendered.usda`), and
/// `ppis render` says so in its one warning summary.
#[test]
fn unrendered_light_features_are_listed_and_warned() {
    let file = root().join("host-usd/tests/fixtures/lights_unrendered.usda");
    let ppis = || std::process::Command::new(env!("CARGO_BIN_EXE_ppis"));
    let info = ppis().arg("info").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    let needles = ["IES profile", "light filters", "light linking", "shadow linking", "PortalLight", "portals ignored"];
    for needle in needles {
        assert!(text.contains(needle), "ppis info does not list {needle:?}: {text}");
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.exr");
    let args = ["--width", "8", "--height", "8", "--spp", "1", "--method", "mis", "-o"];
    let render = ppis().arg("render").arg(&file).args(args).arg(&out).output().unwrap();
    let stderr = String::from_utf8_lossy(&render.stderr);
    assert!(render.status.success(), "{stderr}");
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.starts_with("ppis: warning:")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    assert!(warnings[0].contains("not rendered as authored"), "{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "ppis render does not warn of {needle:?}: {stderr}");
    }
}

/// ShapingAPI on a CylinderLight and a mesh light (`lights_shaped_meshes.usda`): each face is
/// shaped about the light's axis (its −Z, turned down here), not the face's normal. The tube's
/// 45° cone lights the floor below it and not a point 53° off its axis; the upright two-sided
/// panel (faces perpendicular to its axis) lights a point 9.5° off its axis and not one 65°
/// off; both have less power than unshaped (their IES-profiled twins: `tests/usd_ies.rs`).
#[test]
fn shaped_cylinder_and_mesh_lights_render_their_cone() {
    use sampler_core::glam::{Vec2, Vec3};
    use sampler_core::light::SceneLight;
    let file = root().join("host-usd/tests/fixtures/lights_shaped_meshes.usda");
    let converted = usd::load(&file, &usd::Options::default()).unwrap();
    assert!(converted.notes.is_empty(), "{:?}", converted.notes);
    let faces = |x_range: std::ops::Range<f32>| -> Vec<SceneLight> {
        let in_range = |l: &SceneLight| match l.surface() {
            Some(sampler_core::light::LightSurface::Triangle(v)) => x_range.contains(&v[0].x) && v[0].y > 2.0,
            _ => false,
        };
        converted.scene.lights.iter().filter(|l| in_range(l)).copied().collect()
    };
    let (tube, panel) = (faces(-2.0..2.0), faces(4.0..6.0));
    assert_eq!((tube.len(), panel.len()), (128, 2));
    for l in tube.iter().chain(&panel) {
        let SceneLight::Triangle(t) = l else { panic!() };
        assert!((t.shaping().axis() - Vec3::NEG_Y).length() < 1e-5, "{:?}", t.shaping().axis());
    }
    // Light arriving at q from a set of faces, a few samples each.
    let arriving = |lights: &[SceneLight], q: Vec3| -> f32 {
        let mut sum = 0.0;
        for l in lights {
            for k in 0..16 {
                let u = Vec2::new((k % 4) as f32 / 4.0 + 0.125, (k / 4) as f32 / 4.0 + 0.125);
                sum += l.sample(q, u).map_or(0.0, |s| s.radiance.x);
            }
        }
        sum
    };
    assert!(arriving(&tube, Vec3::new(0.7, 0.0, 0.0)) > 0.0);
    assert_eq!(arriving(&tube, Vec3::new(0.0, 0.0, 4.0)), 0.0, "53° off the axis, outside the 45° cone");
    assert!(arriving(&panel, Vec3::new(5.5, 0.0, 0.0)) > 0.0);
    assert_eq!(arriving(&panel, Vec3::new(5.0 + 3.0 * 65f32.to_radians().tan(), 0.0, 0.0)), 0.0);
    let power = |lights: &[SceneLight]| lights.iter().map(|l| l.power(1.0).x).sum::<f32>();
    let unshaped = |lights: &[SceneLight]| {
        lights
            .iter()
            .map(|l| {
                if let SceneLight::Triangle(t) = l {
                    t.with_shaping(sampler_core::light::Shaping::NONE).power(1.0).x
                } else {
                    0.0
                }
            })
            .sum::<f32>()
    };
    for (name, lights) in [("tube", &tube), ("panel", &panel)] {
        let (p, u) = (power(lights), unshaped(lights));
        assert!(p > 0.05 * u && p < 0.8 * u, "{name}: {p} against {u} unshaped");
    }
}
