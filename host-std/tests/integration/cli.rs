//! The `ppis` binary on bad input: one clear error line naming the file or option, exit code 2,
//! no panic, and no output file written.

use std::path::Path;
use std::process::Command;

fn ppis() -> Command {
    Command::new(env!("CARGO_BIN_EXE_ppis"))
}

/// A folder removed when the test ends, pass or fail.
fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new().prefix(&format!("ppis-cli-{name}-")).tempdir().unwrap()
}

/// Runs ppis in `dir` and checks the failure: exit code 2, one stderr line mentioning `needle`,
/// and no render.* left behind.
fn fails(dir: &Path, args: &[&str], needle: &str) {
    let out = ppis().current_dir(dir).args(args).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(needle), "{args:?}: stderr does not mention {needle:?}: {stderr}");
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: one line: {stderr}");
    assert!(stderr.starts_with("ppis: error: "), "{args:?}: {stderr}");
    // Each cause said once (an error's source printed again after its own message read
    // "…: No such file or directory (os error 2): No such file or directory (os error 2)").
    for line in stderr.lines() {
        let parts: Vec<_> = line.split(": ").collect();
        assert!(parts.windows(2).all(|w| w[0] != w[1]), "{args:?}: repeated cause: {line}");
    }
    let leftovers: Vec<_> = std::fs::read_dir(dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    assert!(leftovers.iter().all(|f| !f.to_string_lossy().starts_with("render")), "{args:?} left {leftovers:?}");
}

#[test]
fn bad_input_fails_cleanly() {
    let tmp = scratch("bad");
    let dir = tmp.path();
    fails(dir, &["render", "missing.json"], "missing.json");
    fails(dir, &["render", "--method", "magic"], "magic");
    fails(dir, &["render", "--spp", "0"], "--spp");
    fails(dir, &["render", "--spp", "6", "--shading-points", "4"], "--shading-points");
    fails(dir, &["render", "--env", "nothere.exr"], "nothere.exr");
    fails(dir, &["render", "scene.txt"], "scene.txt");
    // Usage errors too.
    fails(dir, &["render", "--no-such-flag"], "--no-such-flag");
    fails(dir, &["render", "--spp"], "--spp");
    fails(dir, &["info", "--no-such-flag"], "--no-such-flag");
    fails(dir, &["report", "--methods", "mis,nope"], "nope");
    fails(dir, &["report", "--spp", "0"], "--spp");
    // The baselines' parameters.
    fails(dir, &["render", "--method", "sis", "--sis-lights", "0"], "--sis-lights");
    fails(dir, &["render", "--method", "lightcuts", "--lightcut-error", "0"], "--lightcut-error");
    fails(dir, &["render", "--method", "lightcuts", "--lightcut-error=-0.1"], "--lightcut-error");
    fails(dir, &["report", "--methods", "sis", "--sis-lights=-3"], "--sis-lights");
    // The sun's carrier.
    fails(dir, &["render", "--distant-carrier", "sky"], "sky");
    fails(dir, &["render", "--distant-carrier", "cone", "--distant-in-env"], "--distant-in-env");
    // A K above the largest arena names both; no silent clamp.
    fails(
        dir,
        &["render", "--brdf-samples", "1025"],
        "--brdf-samples 1025: 1025 BRDF samples asked of a product arena that holds 1024",
    );
    fails(
        dir,
        &["report", "--out", "k", "--brdf-samples", "64,4096"],
        "4096 BRDF samples asked of a product arena that holds 1024",
    );
    fails(dir, &["render", "--brdf-samples", "0"], "--brdf-samples");
    fails(dir, &["bogus"], "bogus");
    fails(dir, &[], "render");
    fails(dir, &["render", "--render-settings", "/Render/S"], "USD");

    // Broken files.
    std::fs::write(dir.join("bad.json"), "{ \"camera\": 3 }").unwrap();
    fails(dir, &["render", "bad.json"], "bad.json");
    std::fs::write(
        dir.join("typo.json"),
        r#"{"camera":{"origin":[0,0,5],"target":[0,0,0],"up":[0,1,0],"fov_y_deg":40,"width":8,"height":8},
        "shapes":[{"type":"sphere","center":[0,0,0],"radius":1,"material":{"type":"diffuse","albdo":[1,1,1]}}]}"#,
    )
    .unwrap();
    fails(dir, &["render", "typo.json"], "albdo");
    std::fs::write(dir.join("truncated.exr"), b"v/1\x01\x02\x00\x00\x00channels").unwrap();
    fails(dir, &["render", "--env", "truncated.exr"], "truncated.exr");
    std::fs::write(dir.join("garbage.hdr"), b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 0\n").unwrap();
    fails(dir, &["render", "--env", "garbage.hdr"], "garbage.hdr");
    std::fs::write(dir.join("noise.png"), b"\x89PNG\r\n\x1a\nnot really").unwrap();
    fails(dir, &["render", "--env", "noise.png"], "noise.png");
    // A valid image of the wrong shape.
    exr::prelude::write_rgb_file(dir.join("odd.exr"), 30, 20, |_, _| (1.0f32, 1.0f32, 1.0f32)).unwrap();
    fails(dir, &["render", "--env", "odd.exr"], "odd.exr");
    // An output folder that does not exist.
    fails(dir, &["render", "-o", "no/such/folder/out.exr"], "no/such/folder");
    fails(dir, &["render", "--stats-json", "no/such/folder/s.json"], "no/such/folder");
    // The EXR and the PNG beside it would be one file.
    fails(dir, &["render", "-o", "out.png"], "out.png");
    fails(dir, &["render", "-o", "out"], ".exr");
}

#[test]
fn a_small_render_writes_exr_png_and_stats() {
    let tmp = scratch("ok");
    let dir = tmp.path();
    let out = ppis()
        .current_dir(dir)
        .args([
            "render",
            "--width",
            "32",
            "--height",
            "18",
            "--spp",
            "4",
            "--shading-points",
            "2",
            "--stats-json",
            "stats.json",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("wrote render.exr and render.png"), "{stderr}");
    for f in ["render.exr", "render.png", "stats.json"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap();
    for key in [
        "method",
        "spp",
        "brdf_samples",
        "threads",
        "seed",
        "load_seconds",
        "preprocess_seconds",
        "render_seconds",
        "render_cpu_seconds",
        "shading_points",
        "shadow_rays",
    ] {
        assert!(stats.get(key).is_some(), "stats.json lacks {key}");
    }
    assert_eq!(stats["non_finite_pixels"], 0);
}

/// Without --shading-points a pixel gets spp / 4 primary rays with the default method (two
/// pairs of light samples each), reduced to a divisor of --spp, and spp / 16 with `product` (a P the
/// user gives that does not divide it is an error: `bad_input_fails_cleanly`).
#[test]
fn the_default_shading_points_grow_with_spp_and_divide_it() {
    let tmp = scratch("divide");
    let dir = tmp.path();
    for (method, spp, p) in [
        ("product-mis", "12", 3),
        ("product-mis", "10", 2),
        ("product-mis", "7", 1),
        ("mis", "256", 64),
        ("product", "64", 4),
    ] {
        let out = ppis()
            .current_dir(dir)
            .args([
                "render",
                "--width",
                "8",
                "--height",
                "6",
                "--method",
                method,
                "--spp",
                spp,
                "--stats-json",
                "s.json",
            ])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let stats: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("s.json")).unwrap()).unwrap();
        assert_eq!(stats["shading_points_per_pixel"], p, "{method} --spp {spp}");
    }
}

#[test]
fn the_same_seed_writes_the_same_files_at_any_thread_count() {
    let tmp = scratch("same");
    let dir = tmp.path();
    for threads in ["1", "2", "3"] {
        let out = ppis()
            .current_dir(dir)
            .args(["render", "--width", "200", "--height", "130", "--spp", "4", "--threads", threads, "-o"])
            .arg(format!("t{threads}.exr"))
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    for ext in ["exr", "png"] {
        let one = std::fs::read(dir.join(format!("t1.{ext}"))).unwrap();
        for threads in [2, 3] {
            let other = std::fs::read(dir.join(format!("t{threads}.{ext}"))).unwrap();
            assert!(one == other, "{ext}: 1 and {threads} threads wrote different files");
        }
    }
}

#[test]
fn a_suns_carrier_is_measured_once_and_the_same_at_any_thread_count() {
    let tmp = scratch("carrier");
    let dir = tmp.path();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/scenes/sun_env.json");
    let render = |threads: &str, carrier: &str| {
        let out = ppis()
            .current_dir(dir)
            .arg("render")
            .arg(&scene)
            .args(["--width", "40", "--height", "24", "--spp", "8", "--shading-points", "2", "--threads", threads])
            .args(["--distant-carrier", carrier, "-o"])
            .arg(format!("{carrier}{threads}.exr"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{stderr}");
        (std::fs::read(dir.join(format!("{carrier}{threads}.exr"))).unwrap(), stderr)
    };
    let (one, said) = render("1", "auto");
    assert_eq!(said.matches("ppis: distant light: ").count(), 1, "{said}");
    assert!(one == render("2", "auto").0, "the pilot's choice and the image do not depend on threads");
    let (cone, map) = (render("1", "cone"), render("1", "map"));
    assert!(!cone.1.contains("distant light:") && cone.0 != map.0, "a given carrier runs no pilot");
    let chosen = if said.contains("carried by the environment map") { &map.0 } else { &cone.0 };
    assert!(one == *chosen, "auto renders the image of the carrier it names, and records it");
    // Tiles of the carrier `auto` chose merge with tiles given it, not with the other's.
    let other = if said.contains("carried by the environment map") { "cone" } else { "map" };
    let merged = ppis().current_dir(dir).args(["merge", "auto1.exr", &format!("{other}1.exr"), "-o", "m.exr"]).output();
    let stderr = String::from_utf8_lossy(&merged.unwrap().stderr).into_owned();
    assert!(stderr.contains(&format!("(distant_carrier={other} against distant_carrier=")), "{stderr}");
}

/// Runs `ppis report` on a tiny image (24×14, 2 samples per shading point, a 16-spp rendered
/// reference) into `dir/rep` with `args` added; asserts success and returns stderr.
fn tiny_report(dir: &Path, args: &[&str]) -> String {
    let common = ["report", "--samples-per-point", "2", "--width", "24", "--height", "14", "--reference-spp", "16"];
    let out = ppis().current_dir(dir).args(common).args(args).args(["--out", "rep"]).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    stderr
}

#[test]
fn report_writes_csv_plots_and_table() {
    let tmp = scratch("report");
    let dir = tmp.path();
    let stderr = tiny_report(dir, &["--spp", "2,4", "--methods", "product,env,mis"]);
    for f in ["error_vs_time.csv", "error_vs_time.svg", "error_vs_time.png", "report.md", "reference.exr"] {
        assert!(dir.join("rep").join(f).is_file(), "{f} missing: {stderr}");
    }
    let csv = std::fs::read_to_string(dir.join("rep/error_vs_time.csv")).unwrap();
    assert_eq!(csv.lines().filter(|l| l.contains(",all,")).count(), 3 * 2, "{csv}");
    assert!(csv.lines().any(|l| l.contains(",carpaint,")), "{csv}");
    let md = std::fs::read_to_string(dir.join("rep/report.md")).unwrap();
    assert!(md.contains("## Equal time") && md.contains("env relMSE"), "{md}");
    fails(dir, &["report", "--out", "rep2", "--methods", "product,nope"], "nope");
    fails(dir, &["report", "--out", "rep3", "--methods", "product,mis", "--base", "env"], "--base env");
    // Bad input fails before the output folder is made.
    fails(dir, &["report", "--out", "rep4", "--reference", "missing.exr"], "missing.exr");
    assert!(!dir.join("rep4").exists(), "a failed report left its folder");
}

/// `--brdf-samples 16,300`: product-MIS at each K (300 in the large arena), MIS once, and the
/// K sweep's files beside the report's.
#[test]
fn report_sweeps_brdf_samples() {
    let tmp = scratch("ksweep");
    let dir = tmp.path();
    let args = ["--spp", "2,4", "--methods", "product-mis,mis", "--brdf-samples", "300,16", "--base", "product-mis"];
    tiny_report(dir, &args);
    for f in ["error_vs_k.csv", "error_vs_k.md", "error_vs_k.svg", "error_vs_k.png"] {
        assert!(dir.join("rep").join(f).is_file(), "{f} missing");
    }
    let csv = std::fs::read_to_string(dir.join("rep/error_vs_time.csv")).unwrap();
    let all: Vec<&str> = csv.lines().filter(|l| l.contains(",all,")).collect();
    assert_eq!(all.len(), 2 * 2 + 2, "product-MIS at two K, MIS once, two spp each: {csv}");
    assert!(all.iter().any(|l| l.starts_with("product-mis,4,") && l.ends_with(",300")), "{csv}");
    assert!(all.iter().any(|l| l.starts_with("mis,4,") && l.ends_with(',')), "{csv}");
    let k = std::fs::read_to_string(dir.join("rep/error_vs_k.csv")).unwrap();
    assert!(k.lines().any(|l| l.starts_with("all,product-mis,16,")), "{k}");
    assert!(!k.contains(",mis,"), "MIS reads no K: {k}");
    let md = std::fs::read_to_string(dir.join("rep/error_vs_k.md")).unwrap();
    assert!(md.contains("## Optimum") && md.contains("| 300 |"), "{md}");
    let report = std::fs::read_to_string(dir.join("rep/report.md")).unwrap();
    assert!(report.contains("| product-mis K=16 | 2 |"), "{report}");
}

/// The report names each material's `auto` plan with its light samples per shading point.
#[test]
fn report_lists_auto_s_plans_with_their_samples_per_point() {
    let tmp = scratch("report_auto");
    let dir = tmp.path();
    tiny_report(dir, &["--spp", "4", "--methods", "mis,auto", "--base", "mis"]);
    let md = std::fs::read_to_string(dir.join("rep/report.md")).unwrap();
    let line = md.lines().find(|l| l.starts_with("auto at 4 spp: ")).unwrap_or_else(|| panic!("{md}"));
    // The tiny image has too few pixels per material for a pilot: the rules give car paint
    // under the default scene's sun MIS, at the render's two samples per shading point.
    assert!(line.contains("carpaint → mis, 2 samples per shading point"), "{line}");
}

#[test]
fn report_compares_against_the_first_method_when_product_is_not_among_them() {
    let tmp = scratch("base");
    let dir = tmp.path();
    tiny_report(dir, &["--spp", "2", "--methods", "mis,env"]);
    let md = std::fs::read_to_string(dir.join("rep/report.md")).unwrap();
    assert!(md.contains("For the time mis takes at each spp"), "{md}");
}

/// `--repeat N` renders the same images (the same errors) and the report says it kept the
/// fastest of N runs (the keep-the-fastest rule itself: `report::tests`).
#[test]
fn report_repeats_timings() {
    let tmp = scratch("repeat");
    let dir = tmp.path();
    let rows = |name: &str| {
        let csv = std::fs::read_to_string(dir.join(name).join("error_vs_time.csv")).unwrap();
        csv.lines().skip(1).map(|l| l.split(',').map(str::to_string).collect::<Vec<_>>()).collect::<Vec<_>>()
    };
    tiny_report(dir, &["--spp", "2,4", "--methods", "env,mis", "--base", "mis"]);
    std::fs::rename(dir.join("rep"), dir.join("one")).unwrap();
    tiny_report(dir, &["--spp", "2,4", "--methods", "env,mis", "--base", "mis", "--repeat", "3"]);
    std::fs::rename(dir.join("rep"), dir.join("three")).unwrap();
    let (one, three) = (rows("one"), rows("three"));
    assert_eq!(one.len(), three.len());
    for (a, b) in one.iter().zip(&three) {
        // method, spp, region and both errors agree; only the time may differ.
        assert_eq!((&a[0], &a[1], &a[3], &a[4], &a[5]), (&b[0], &b[1], &b[3], &b[4], &b[5]));
        assert!(b[2].parse::<f64>().unwrap() > 0.0, "a time is measured");
    }
    let md = std::fs::read_to_string(dir.join("three/report.md")).unwrap();
    assert!(md.contains("fastest of 3 runs"), "{md}");
    fails(dir, &["report", "--out", "rep4", "--repeat", "0"], "--repeat");
}

/// `--base` keys the equal-time tables; `--bracket` renders the faster methods on until they
/// reach the base's time or have doubled their spp three times.
#[test]
fn report_brackets_the_base_time() {
    let tmp = scratch("bracket");
    let dir = tmp.path();
    tiny_report(dir, &["--spp", "4", "--methods", "mis,product-mis", "--base", "product-mis", "--bracket"]);
    let csv = std::fs::read_to_string(dir.join("rep/error_vs_time.csv")).unwrap();
    let rows: Vec<(String, usize, f64)> = csv
        .lines()
        .skip(1)
        .filter(|l| l.contains(",all,"))
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].to_string(), f[1].parse().unwrap(), f[2].parse().unwrap())
        })
        .collect();
    let base_time = rows.iter().filter(|r| r.0 == "product-mis").map(|r| r.2).fold(0.0, f64::max);
    let mis: Vec<&(String, usize, f64)> = rows.iter().filter(|r| r.0 == "mis").collect();
    assert_eq!(rows.iter().filter(|r| r.0 == "product-mis").count(), 1, "{csv}");
    // MIS starts at 4 spp and doubles until it reaches the base's time (at most three times,
    // to 32 spp), then halves while its fastest render is still slower than the base (down to
    // 1 spp); renders this small can time either way, so either side may do the work.
    assert_eq!(mis[0].1, 4, "{csv}");
    assert!(mis.iter().all(|r| r.1.is_power_of_two() && (1..=32).contains(&r.1)), "{csv}");
    let largest = mis.iter().max_by_key(|r| r.1).unwrap();
    let smallest = mis.iter().min_by_key(|r| r.1).unwrap();
    assert!(largest.2 >= base_time || largest.1 == 32, "{csv}");
    assert!(smallest.2 <= base_time || smallest.1 == 1, "{csv}");
    let mut spps: Vec<usize> = mis.iter().map(|r| r.1).collect();
    spps.sort_unstable();
    spps.dedup();
    assert_eq!(spps.len(), mis.len(), "every bracketing render is at a new spp: {csv}");
    assert!(spps.windows(2).all(|w| w[1] == 2 * w[0]), "{csv}");
    let md = std::fs::read_to_string(dir.join("rep/report.md")).unwrap();
    assert!(md.contains("For the time product-mis takes") && md.contains("| product-mis spp |"), "{md}");
}

/// `ppis info | head`: a reader gone before the output is written ends the process as the
/// default SIGPIPE ends C tools, without a panic's message. The pipe's read end is closed
/// before the process starts, so its first write meets it closed.
#[cfg(unix)]
#[test]
fn a_closed_output_pipe_ends_the_process_without_a_panic() {
    use std::os::fd::{FromRawFd, OwnedFd};
    use std::os::unix::process::ExitStatusExt;
    let mut fds = [0; 2];
    // SAFETY: `fds` has room for the two descriptors `pipe` writes.
    assert_eq!(unsafe { libc::pipe(fds.as_mut_ptr()) }, 0);
    // SAFETY: both descriptors were just opened and are owned here alone.
    let (read, write) = unsafe { (OwnedFd::from_raw_fd(fds[0]), OwnedFd::from_raw_fd(fds[1])) };
    drop(read);
    let out = ppis().args(["info"]).stdout(write).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{:?}: {stderr}", out.status);
}
