//! A frame rendered as a farm renders it: `ppis tiles` splits it, four `ppis render --crop`
//! processes render the tiles, `ppis merge` assembles them — byte for byte the EXR and PNG of
//! the frame rendered in one process. And the merge's and the crop's refusals: one error line,
//! exit 2, nothing written.

use std::path::Path;
use std::process::{Command, Output};

const FRAME: [&str; 9] = ["render", "--width", "64", "--height", "48", "--spp", "4", "--method", "product-mis"];

fn ppis(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ppis")).current_dir(dir).args(args).output().unwrap()
}

fn ok(dir: &Path, args: &[&str]) -> String {
    let out = ppis(dir, args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// Exit 2, one line `ppis: error: …` mentioning `needle`, and no `frame.*` or `tile*.partial` left.
fn fails(dir: &Path, args: &[&str], needle: &str) {
    let out = ppis(dir, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: one line: {stderr}");
    assert!(stderr.starts_with("ppis: error: ") && stderr.contains(needle), "{args:?}: wants {needle:?}: {stderr}");
    let files: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(files.iter().all(|f| !f.starts_with("frame") && !f.ends_with(".partial")), "{args:?} left {files:?}");
}

fn with(args: &[&str], more: &[&str]) -> Vec<String> {
    args.iter().chain(more).map(|s| s.to_string()).collect()
}

fn run(dir: &Path, args: &[String]) -> String {
    ok(dir, &args.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn four_tile_processes_merge_into_the_bytes_of_the_one_process_frame() {
    let tmp = tempfile::Builder::new().prefix("ppis-farm-").tempdir().unwrap();
    let dir = tmp.path();
    run(dir, &with(&FRAME, &["--threads", "2", "-o", "whole.exr"]));
    let tiles = ok(dir, &["tiles", "--width", "64", "--height", "48", "--count", "4"]);
    let crops: Vec<&str> = tiles.lines().collect();
    assert_eq!(crops, ["0,0,32,32", "32,0,64,32", "0,32,32,48", "32,32,64,48"]);
    // The four processes at once, as a farm's machines run them; a tile at 1 thread, one at 2.
    let children: Vec<_> = crops
        .iter()
        .enumerate()
        .map(|(i, crop)| {
            let t = (1 + i % 2).to_string();
            let out = format!("tile{i}.exr");
            let args = with(&FRAME, &["--crop", crop, "--threads", &t, "-o", &out]);
            Command::new(env!("CARGO_BIN_EXE_ppis")).current_dir(dir).args(&args).output()
        })
        .collect();
    for child in children {
        let out = child.unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    // Merged in another order than rendered.
    ok(dir, &["merge", "tile3.exr", "tile1.exr", "tile0.exr", "tile2.exr", "-o", "frame.exr"]);
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert!(read("frame.exr") == read("whole.exr"), "the merged EXR differs from the one-process frame");
    assert!(read("frame.png") == read("whole.png"), "the merged PNG differs from the one-process frame");
    // A tile's data window is its crop, its display window the frame.
    let tile = host_std::merge::read_part(&dir.join("tile1.exr")).unwrap();
    assert_eq!((tile.frame, tile.crop.to_string(), tile.pixels.len()), ((64, 48), "32,0,64,32".into(), 32 * 32));
    assert!(tile.settings.contains("\nmethod=product-mis\nspp=4\n"), "{}", tile.settings);
}

/// The split pilot (`plan/split.rs`) decides from the whole frame, so every crop takes the
/// frame's split: two tile processes still merge into the one-process frame's bytes.
#[test]
fn tiles_take_the_frames_split_of_light_samples_per_shading_point() {
    let tmp = tempfile::Builder::new().prefix("ppis-farm-split-").tempdir().unwrap();
    let dir = tmp.path();
    let frame = ["render", "--width", "224", "--height", "192", "--spp", "128", "--method", "mis"];
    let out = ppis(dir, &with(&frame, &["-o", "whole.exr"]).iter().map(String::as_str).collect::<Vec<_>>());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && stderr.contains("light samples per shading point:"), "{stderr}");
    for (i, crop) in ["0,0,224,96", "0,96,224,192"].iter().enumerate() {
        run(dir, &with(&frame, &["--crop", crop, "--threads", "1", "-o", &format!("tile{i}.exr")]));
    }
    ok(dir, &["merge", "tile1.exr", "tile0.exr", "-o", "frame.exr"]);
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert!(read("frame.exr") == read("whole.exr"), "the merged EXR differs from the one-process frame");
}

#[test]
fn a_merge_refuses_overlapping_missing_foreign_and_truncated_tiles() {
    let tmp = tempfile::Builder::new().prefix("ppis-merge-").tempdir().unwrap();
    let dir = tmp.path();
    for (crop, out) in [("0,0,40,48", "left.exr"), ("32,0,64,48", "right.exr"), ("40,0,64,48", "rest.exr")] {
        run(dir, &with(&FRAME, &["--crop", crop, "-o", out]));
    }
    run(dir, &with(&FRAME, &["--crop", "40,0,64,48", "--seed", "9", "-o", "seed9.exr"]));
    run(dir, &with(&FRAME, &["--crop", "40,0,64,48", "--light-share", "0.25", "-o", "share.exr"]));
    run(
        dir,
        &["render", "--width", "64", "--height", "40", "--spp", "4", "--crop", "40,0,64,40", "-o", "short.exr"]
            .map(String::from),
    );
    let m = |tiles: &[&str]| -> Vec<String> {
        let mut a = vec!["merge".to_string()];
        a.extend(tiles.iter().map(|t| t.to_string()));
        a.extend(["-o".into(), "frame.exr".into()]);
        a
    };
    let fails_m =
        |tiles: &[&str], needle: &str| fails(dir, &m(tiles).iter().map(String::as_str).collect::<Vec<_>>(), needle);
    fails_m(&["left.exr", "right.exr"], "overlap (pixels 32,0,40,48)");
    fails_m(&["left.exr"], "1152 of the frame's 3072 pixels are in no tile (the first at x 40, y 0)");
    fails_m(&["left.exr", "seed9.exr"], "seed9.exr: a tile of another render than left.exr (seed=9 against seed=0)");
    fails_m(
        &["left.exr", "share.exr"],
        "share.exr: a tile of another render than left.exr (light_share=0.25 against light_share=0.5)",
    );
    fails_m(&["left.exr", "short.exr"], "short.exr: a tile of another render than left.exr (a 64×40 frame");
    let bytes = std::fs::read(dir.join("rest.exr")).unwrap();
    std::fs::write(dir.join("cut.exr"), &bytes[..bytes.len() * 2 / 3]).unwrap();
    fails_m(&["left.exr", "cut.exr"], "cut.exr: cannot read as an OpenEXR tile");
    std::fs::write(dir.join("empty.exr"), b"").unwrap();
    fails_m(&["left.exr", "empty.exr"], "empty.exr: cannot read as an OpenEXR tile");
    exr::prelude::write_rgb_file(dir.join("plain.exr"), 24, 48, |_, _| (0.0f32, 0.0f32, 0.0f32)).unwrap();
    fails_m(&["left.exr", "plain.exr"], "plain.exr: not a tile of a ppis render");
    fails_m(&["left.exr", "missing.exr"], "missing.exr");
    fails(dir, &["merge", "left.exr", "rest.exr", "-o", "frame.png"], "must end in .exr");
    fails(dir, &["merge", "-o", "frame.exr"], "TILE.exr");
    ok(dir, &["merge", "left.exr", "rest.exr", "-o", "frame.exr"]);
}

#[test]
fn a_crop_outside_the_frame_empty_or_reversed_is_refused() {
    let tmp = tempfile::Builder::new().prefix("ppis-crop-").tempdir().unwrap();
    let dir = tmp.path();
    let render = |crop: &str| with(&FRAME, &["--crop", crop, "-o", "frame.exr"]);
    let fails_r =
        |crop: &str, needle: &str| fails(dir, &render(crop).iter().map(String::as_str).collect::<Vec<_>>(), needle);
    fails_r("0,0,65,48", "--crop 0,0,65,48: outside the 64×48 frame");
    fails_r("0,40,64,49", "outside the 64×48 frame");
    fails_r("8,8,8,16", "--crop 8,8,8,16: empty or reversed");
    fails_r("9,8,4,16", "empty or reversed");
    fails_r("1,2,3", "expected x0,y0,x1,y1");
    fails_r("a,b,c,d", "expected x0,y0,x1,y1");
    fails_r("-1,0,4,4", "--crop");
    fails(dir, &["tiles", "--width", "64", "--height", "48"], "--count");
    fails(dir, &["tiles", "--width", "4", "--height", "4", "--count", "32"], "--count 32");
    fails(dir, &["tiles", "--width", "64", "--height", "48", "--count", "4", "--index", "4"], "--index 4");
}

/// A 32×16 frame of `scene` (in `dir`) lit by its map, as tile `crop`.
fn small_tile(dir: &Path, scene: &str, extra: &[&str], crop: &str, out: &str) {
    let mut args = vec!["render", scene, "--width", "32", "--height", "16", "--spp", "1", "--method", "env"];
    args.extend(["--threads", "1", "--crop", crop, "-o", out]);
    args.extend(extra);
    ok(dir, &args);
}

#[test]
fn a_merge_refuses_tiles_of_other_frames_and_of_changed_referenced_files() {
    let tmp = tempfile::Builder::new().prefix("ppis-inputs-").tempdir().unwrap();
    let dir = tmp.path();
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../host-usd/tests/fixtures");
    let map = std::fs::read(fixtures.join("twins_env.exr")).unwrap();
    std::fs::write(dir.join("sky.exr"), &map).unwrap();
    std::fs::write(
        dir.join("scene.json"),
        r#"{"envmap": {"file": "sky.exr"},
            "camera": {"origin": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 40, "width": 32, "height": 16},
            "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                        "material": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}}]}"#,
    )
    .unwrap();
    let (left, right) = ("0,0,16,16", "16,0,32,16");
    small_tile(dir, "scene.json", &["--frame", "1", "--stats-json", "left.json"], left, "left.exr");
    // Another frame of the same scene.
    small_tile(dir, "scene.json", &["--frame", "2"], right, "second.exr");
    fn merge(tiles: [&str; 2]) -> [&str; 5] {
        ["merge", tiles[0], tiles[1], "-o", "frame.exr"]
    }
    fails(
        dir,
        &merge(["left.exr", "second.exr"]),
        "second.exr: a tile of another render than left.exr (frame=2 against frame=1)",
    );
    // The map the scene file names, changed between the tiles (a texel brighter).
    let mut brighter = map.clone();
    let last = brighter.len() - 8;
    brighter[last] ^= 0x40;
    std::fs::write(dir.join("sky.exr"), &brighter).unwrap();
    small_tile(dir, "scene.json", &["--frame", "1"], right, "changed.exr");
    fails(
        dir,
        &merge(["left.exr", "changed.exr"]),
        "changed.exr: a tile of another render than left.exr (reads=sky.exr ",
    );
    std::fs::write(dir.join("sky.exr"), &map).unwrap();
    small_tile(dir, "scene.json", &["--frame", "1"], right, "right.exr");
    ok(dir, &merge(["left.exr", "right.exr"]));
    std::fs::remove_file(dir.join("frame.exr")).unwrap();
    std::fs::remove_file(dir.join("frame.png")).unwrap();
    // A crop's stats: its own size, and the frame's.
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("left.json")).unwrap()).unwrap();
    assert_eq!((stats["width"].as_u64(), stats["height"].as_u64()), (Some(16), Some(16)));
    assert_eq!((stats["frame_width"].as_u64(), stats["frame_height"].as_u64()), (Some(32), Some(16)));
    assert_eq!((stats["crop"].to_string(), stats["time_code"].as_str()), ("[0,0,16,16]".into(), Some("1")));

    // A USD stage's sublayer, changed between the tiles.
    let layer = |x: f64| {
        format!(
            "#usda 1.0\ndef Sphere \"Ball\" {{\n    double3 xformOp:translate = ({x}, 0, -6)\n    uniform token[] xformOpOrder = [\"xformOp:translate\"]\n}}\n"
        )
    };
    std::fs::write(dir.join("root.usda"), "#usda 1.0\n(\n    subLayers = [@ball.usda@]\n)\n").unwrap();
    std::fs::write(dir.join("ball.usda"), layer(0.0)).unwrap();
    let env = ["--env", "sky.exr"];
    small_tile(dir, "root.usda", &env, left, "usd_left.exr");
    std::fs::write(dir.join("ball.usda"), layer(0.5)).unwrap();
    small_tile(dir, "root.usda", &env, right, "usd_changed.exr");
    fails(dir, &merge(["usd_left.exr", "usd_changed.exr"]), "(reads=ball.usda ");
    std::fs::write(dir.join("ball.usda"), layer(0.0)).unwrap();
    small_tile(dir, "root.usda", &env, right, "usd_right.exr");
    ok(dir, &merge(["usd_left.exr", "usd_right.exr"]));
}
