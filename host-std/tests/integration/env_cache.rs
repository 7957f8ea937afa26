//! The cached environment a farm's tiles read: `ppis env` writes the equal-area square of a
//! lat-long map, and rendering with `--env SQUARE.exr` gives the pixels of rendering with the
//! lat-long map bit for bit, with the env's scale and rotation applied at render time.

use std::path::Path;
use std::process::{Command, Output};

fn ppis(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ppis")).current_dir(dir).args(args).output().unwrap()
}

fn ok(dir: &Path, args: &[&str]) {
    let out = ppis(dir, args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// A 64×32 lat-long map with a gradient, a hot pixel (the resampler's splat) and a NaN (the
/// loader's sanitizing).
fn write_latlong(path: &Path) {
    let (w, h) = (64usize, 32usize);
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        if (x, y) == (40, 10) {
            (5000.0f32, 4000.0, 3000.0)
        } else if (x, y) == (3, 20) {
            (f32::NAN, 1.0, 1.0)
        } else {
            (x as f32 / w as f32, y as f32 / h as f32, 0.25)
        }
    })
    .unwrap();
}

fn pixels(path: &Path) -> Vec<[u32; 3]> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.0, vec![[0u32; 3]; size.0 * size.1]),
        |(w, px): &mut (usize, Vec<[u32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            px[pos.1 * *w + pos.0] = [r.to_bits(), g.to_bits(), b.to_bits()]
        },
    )
    .unwrap();
    image.layer_data.channel_data.pixels.1
}

#[test]
fn rendering_from_the_cached_square_gives_the_lat_long_renders_pixels() {
    let tmp = tempfile::Builder::new().prefix("ppis-envcache-").tempdir().unwrap();
    let dir = tmp.path();
    write_latlong(&dir.join("latlong.exr"));
    ok(dir, &["env", "latlong.exr", "-o", "square.exr", "--threads", "2"]);
    let square = pixels(&dir.join("square.exr"));
    assert_eq!(square.len(), 64 * 64, "64×32 resamples to 64²");
    let frame = ["render", "--width", "32", "--height", "24", "--spp", "4", "--threads", "2"];
    for placement in [&[][..], &["--env-scale", "2.5", "--env-rotate-y", "30"][..]] {
        let mut images = Vec::new();
        for env in ["latlong.exr", "square.exr"] {
            let out = format!("from_{env}");
            let args: Vec<&str> =
                frame.iter().copied().chain(["--env", env, "-o", &out]).chain(placement.iter().copied()).collect();
            ok(dir, &args);
            images.push(pixels(&dir.join(&out)));
        }
        assert!(images[0] == images[1], "{placement:?}: the cached square renders different pixels");
        assert!(images[0].iter().any(|p| p[0] != 0), "{placement:?}: a black image proves nothing");
    }
}

#[test]
fn a_bad_output_is_one_error_line_and_no_file() {
    let tmp = tempfile::Builder::new().prefix("ppis-envcache-").tempdir().unwrap();
    let dir = tmp.path();
    write_latlong(&dir.join("latlong.exr"));
    for (args, needle) in [
        (&["env", "latlong.exr", "-o", "square.png"][..], "must end in .exr"),
        (&["env", "missing.exr", "-o", "square.exr"][..], "not found"),
        (&["env", "latlong.exr", "-o", "nodir/square.exr"][..], "output folder does not exist"),
    ] {
        let out = ppis(dir, args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.starts_with("ppis: error: ") && stderr.lines().count() == 1 && stderr.contains(needle));
        assert!(!dir.join("square.exr").exists() && !dir.join("square.png").exists());
    }
}
