//! `ppis render scene.usda --frame F`: a stage whose parent Xform moves, whose sphere grows
//! and whose camera rises, all by time samples, renders at each frame the pixels of the same
//! stage with those values authored as plain (default) values — interpolated between keys,
//! held outside them, the earliest sample without `--frame`.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The stage with the parent's translate, the sphere's radius and the camera's translate
/// authored as the given usda text: time samples (`.timeSamples = { 1: a, 10: b }`) or a
/// plain value (` = a`).
fn stage(translate: &str, radius: &str, camera: &str) -> String {
    format!(
        r#"#usda 1.0
(
    startTimeCode = 1
    endTimeCode = 10
)
def Xform "World"
{{
    double3 xformOp:translate{translate}
    uniform token[] xformOpOrder = ["xformOp:translate"]
    def Sphere "Ball"
    {{
        double radius{radius}
    }}
}}
def Camera "Cam"
{{
    double3 xformOp:translate{camera}
    uniform token[] xformOpOrder = ["xformOp:translate"]
    float focalLength = 35
}}
"#
    )
}

/// The animated stage: keys at 1 and 10, chosen so that the value at 5.5 is exact in binary.
fn animated() -> String {
    stage(
        ".timeSamples = { 1: (-1.5, 0, 0), 10: (1.5, 0, 0) }",
        " = 3\n        double radius.timeSamples = { 1: 0.5, 10: 1 }",
        ".timeSamples = { 1: (0, 0, 8), 10: (0, 1, 8) }",
    )
}

fn env_map() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures/twins_env.exr")
}

/// Renders `scene` (a file in `dir`) with `extra` arguments; returns its pixels.
fn render(dir: &Path, scene: &str, extra: &[&str]) -> Vec<[f32; 3]> {
    let out = dir.join(format!("{scene}{}.exr", extra.join("_")));
    let env = env_map();
    let mut args = vec!["render", scene, "--width", "40", "--height", "30", "--spp", "2", "--method", "env"];
    args.extend(["--threads", "1", "--env", env.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    args.extend(extra);
    let o = Command::new(env!("CARGO_BIN_EXE_ppis")).current_dir(dir).args(&args).output().unwrap();
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    host_std::merge::read_part(&out).unwrap().pixels
}

#[test]
fn a_frame_renders_the_stage_at_that_time_code() {
    let tmp = tempfile::Builder::new().prefix("ppis-usd-time-").tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("anim.usda"), animated()).unwrap();
    let at = |name: &str, t: &str, r: &str, c: &str| {
        let file = format!("{name}.usda");
        std::fs::write(dir.join(&file), stage(&format!(" = {t}"), &format!(" = {r}"), &format!(" = {c}"))).unwrap();
        render(dir, &file, &[])
    };
    let first = at("first", "(-1.5, 0, 0)", "0.5", "(0, 0, 8)");
    let middle = at("middle", "(0, 0, 0)", "0.75", "(0, 0.5, 8)");
    let last = at("last", "(1.5, 0, 0)", "1", "(0, 1, 8)");
    assert!(first != last && first != middle, "the animation changes the image");
    let frame = |f: &str| render(dir, "anim.usda", &["--frame", f]);
    assert!(frame("1") == first, "frame 1 is the first key");
    assert!(frame("5.5") == middle, "frame 5.5 is halfway between the keys");
    assert!(frame("10") == last, "frame 10 is the last key");
    assert!(frame("-4") == first && frame("12") == last, "held outside the keys");
    // No --frame: each attribute's earliest sample (the first key), as Pixar's usdrecord.
    assert!(render(dir, "anim.usda", &[]) == first);
    // `default`: the default values only — the sphere's radius 3, the samples-only translates
    // the identity (as Pixar's UsdGeomXformable computes them).
    let default = at("default", "(0, 0, 0)", "3", "(0, 0, 0)");
    assert!(frame("default") == default, "--frame default reads default values only");
}

#[test]
fn a_json_scene_is_the_same_at_every_frame_and_bad_frames_are_refused() {
    let tmp = tempfile::Builder::new().prefix("ppis-usd-time-").tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("anim.usda"), animated()).unwrap();
    let ppis = |args: &[&str]| Command::new(env!("CARGO_BIN_EXE_ppis")).current_dir(dir).args(args).output().unwrap();
    let small = ["--width", "16", "--height", "12", "--spp", "1", "--method", "env", "--threads", "1"];
    let run = |frame: &[&str], out: &str| {
        let o = ppis(&[&["render"][..], &small, frame, &["-o", out]].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        host_std::merge::read_part(&dir.join(out)).unwrap()
    };
    let still = run(&[], "still.exr");
    let moved = run(&["--frame", "7"], "seven.exr");
    assert!(still.pixels == moved.pixels, "the built-in scene is static");
    assert!(moved.settings.contains("\nframe=7\n") && !still.settings.contains("frame="), "{}", moved.settings);
    for bad in ["nan", "inf", "seven", ""] {
        let o = ppis(&["render", "anim.usda", "--frame", bad, "-o", "bad.exr"]);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {stderr}");
        assert!(stderr.starts_with("ppis: error: ") && stderr.contains("time code"), "{bad}: {stderr}");
        assert!(!dir.join("bad.exr").exists());
    }
}
