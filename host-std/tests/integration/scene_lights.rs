//! The scene format's `lights` (docs/scene-format.md): every kind is read into the light it
//! names, a mesh light into one triangle light per face with an area, the environment becomes
//! optional; and a light that cannot exist (negative or NaN radiance, a zero radius or area, a
//! degenerate direction, a missing mesh) is refused by `ppis` in one line naming the file, the
//! light and the problem, with exit code 2 and nothing written.

use host_std::scene::json;
use sampler_core::glam::Vec3;
use sampler_core::light::{Light, SceneLight};
use std::path::Path;
use std::process::Command;

const CAMERA: &str = r#""camera": {"origin": [0, 1, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40, "width": 8, "height": 8}"#;
const FLOOR: &str = r#""shapes": [{"type": "rectangle", "p0": [-2, 0, -2], "e1": [0, 0, 4], "e2": [4, 0, 0],
    "material": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}}]"#;

fn scene_with(lights: &str) -> String {
    format!("{{ {CAMERA}, \"lights\": [{lights}], {FLOOR} }}")
}

#[test]
fn every_kind_of_light_is_read_and_the_environment_is_optional() {
    let dir = tempfile::tempdir().unwrap();
    // Two triangles and one without an area.
    std::fs::write(dir.path().join("lamp.obj"), "v 0 2 0\nv 1 2 0\nv 0 2 1\nv 1 2 1\nf 1 3 2\nf 2 3 4\nf 1 1 2\n")
        .unwrap();
    let text = scene_with(
        r#"{"type": "point", "position": [0, 2, 0], "intensity": [1, 2, 3]},
        {"type": "sphere", "center": [1, 2, 0], "radius": 0.25, "radiance": [4, 4, 4]},
        {"type": "rectangle", "p0": [0, 3, 0], "e1": [1, 0, 0], "e2": [0, 0, 1], "radiance": [1, 1, 1]},
        {"type": "disk", "center": [0, 3, 1], "normal": [0, -1, 0], "radius": 0.5, "radiance": [2, 2, 2]},
        {"type": "mesh", "file": "lamp.obj", "radiance": [3, 3, 3]},
        {"type": "distant", "direction": [0, 1, 1], "irradiance": [1, 1, 1], "angle_deg": 0.53},
        {"type": "distant", "direction": [1, 1, 0], "irradiance": [2, 2, 2]}"#,
    );
    let path = dir.path().join("s.json");
    std::fs::write(&path, &text).unwrap();
    let scene = json::load(&path).unwrap();
    assert!(scene.env.is_none());
    let kinds: Vec<&str> = scene
        .lights
        .iter()
        .map(|l| match l {
            SceneLight::Point(_) => "point",
            SceneLight::Sphere(_) => "sphere",
            SceneLight::Rect(_) => "rect",
            SceneLight::Disk(_) => "disk",
            SceneLight::Triangle(_) => "triangle",
            SceneLight::Distant(_) => "distant",
        })
        .collect();
    assert_eq!(kinds, ["point", "sphere", "rect", "disk", "triangle", "triangle", "distant", "distant"]);
    // The point light's intensity, as irradiance at 2 units facing it.
    let s = scene.lights[0].sample(Vec3::ZERO, sampler_core::glam::Vec2::splat(0.5)).unwrap();
    assert_eq!(s.radiance, Vec3::new(1.0, 2.0, 3.0) / 4.0);
    // Only the distant light with an angle is found by rays that leave the scene.
    assert!(scene.lights[6].is_infinite_area() && !scene.lights[7].is_infinite_area());
    assert_eq!(json::files_read(&path).unwrap(), [dir.path().join("lamp.obj")]);
}

fn ppis_fails(dir: &Path, file: &str, needles: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_ppis")).current_dir(dir).args(["render", file]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{file}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{file}: one line: {stderr}");
    assert!(stderr.starts_with("ppis: error: ") && !stderr.contains("panicked"), "{file}: {stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "{file}: stderr does not mention {needle:?}: {stderr}");
    }
    let left: Vec<_> = std::fs::read_dir(dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    assert!(left.iter().all(|f| !f.to_string_lossy().starts_with("render")), "{file} left {left:?}");
}

#[test]
fn lights_that_cannot_exist_are_refused_in_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let cases = [
        ("negative.json", r#"{"type": "point", "position": [0, 2, 0], "intensity": [1, -1, 1]}"#, "negative"),
        ("nan.json", r#"{"type": "sphere", "center": [0, 2, 0], "radius": 1, "radiance": [1, 1e40, 1]}"#, "radiance"),
        (
            "radius.json",
            r#"{"type": "disk", "center": [0, 2, 0], "normal": [0, -1, 0], "radius": 0, "radiance": [1, 1, 1]}"#,
            "radius",
        ),
        (
            "area.json",
            r#"{"type": "rectangle", "p0": [0, 2, 0], "e1": [1, 0, 0], "e2": [2, 0, 0], "radiance": [1, 1, 1]}"#,
            "area",
        ),
        ("direction.json", r#"{"type": "distant", "direction": [0, 0, 0], "irradiance": [1, 1, 1]}"#, "direction"),
        (
            "angle.json",
            r#"{"type": "distant", "direction": [0, 1, 0], "irradiance": [1, 1, 1], "angle_deg": 200}"#,
            "angular",
        ),
        ("mesh.json", r#"{"type": "mesh", "file": "nowhere.obj", "radiance": [1, 1, 1]}"#, "nowhere.obj"),
        ("kind.json", r#"{"type": "spot", "position": [0, 2, 0]}"#, "spot"),
    ];
    for (file, light, needle) in cases {
        std::fs::write(
            dir.join(file),
            scene_with(&format!("{{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [1, 1, 1]}}, {light}")),
        )
        .unwrap();
        // An unknown kind is the JSON reader's error, which names the kind.
        let light_name = if file == "kind.json" { needle } else { "lights[1]" };
        ppis_fails(dir, file, &[file, light_name, needle]);
    }
}

/// A shaping that cannot exist, or an IES file that cannot be read or is not a profile, stops
/// the render with one line naming the scene file, the light and the field (or the IES file);
/// shaping on a distant light is the JSON reader's unknown field.
#[test]
fn shapings_that_cannot_exist_are_refused_in_one_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("not.ies"), "this is no photometric file\n").unwrap();
    let ies = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/scenes/ies/bilateral_1995.ies");
    std::fs::copy(ies, dir.join("ok.ies")).unwrap();
    let point = |shaping: &str| {
        format!(r#"{{"type": "point", "position": [0, 2, 0], "intensity": [1, 1, 1], "shaping": {shaping}}}"#)
    };
    let cases = [
        ("no_axis.json", point(r#"{"cone_angle_deg": 30}"#), "shaping.axis is required"),
        ("zero_axis.json", point(r#"{"axis": [0, 0, 0]}"#), "shaping.axis has no direction"),
        ("cone.json", point(r#"{"axis": [0, -1, 0], "cone_angle_deg": -5}"#), "shaping.cone_angle_deg"),
        ("softness.json", point(r#"{"axis": [0, -1, 0], "cone_softness": 1.5}"#), "shaping.cone_softness"),
        ("focus.json", point(r#"{"axis": [0, -1, 0], "focus": -1}"#), "shaping.focus must"),
        ("tint.json", point(r#"{"axis": [0, -1, 0], "focus_tint": [1, -1, 0]}"#), "shaping.focus_tint"),
        ("missing.json", point(r#"{"axis": [0, -1, 0], "ies": {"file": "nowhere.ies"}}"#), "nowhere.ies"),
        ("bad.json", point(r#"{"axis": [0, -1, 0], "ies": {"file": "not.ies"}}"#), "not.ies: no TILT= line"),
        (
            "parallel.json",
            point(r#"{"axis": [0, -1, 0], "ies": {"file": "ok.ies", "x": [0, 2, 0]}}"#),
            "shaping.ies.x is parallel to the axis",
        ),
        (
            "distant.json",
            r#"{"type": "distant", "direction": [0, 1, 0], "irradiance": [1, 1, 1], "shaping": {}}"#.to_string(),
            "unknown field `shaping`",
        ),
    ];
    for (file, light, needle) in &cases {
        let scene =
            scene_with(&format!("{{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": [1, 1, 1]}}, {light}"));
        std::fs::write(dir.join(file), scene).unwrap();
        let light_name = if *file == "distant.json" { "shaping" } else { "lights[1]" };
        ppis_fails(dir, file, &[file, light_name, needle]);
    }
}

/// `ppis info` counts a JSON scene's shaped lights and those with an IES profile.
#[test]
fn info_counts_shaped_lights() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/scenes/lights_shaped.json");
    let out = Command::new(env!("CARGO_BIN_EXE_ppis")).arg("info").arg(&scene).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        text.contains("(1 point, 1 rectangle, 384 mesh triangle; 386 shaped, 386 of them by an IES profile)"),
        "{text}"
    );
}
