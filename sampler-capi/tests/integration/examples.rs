//! The C and C++ examples (`examples/c/embed.c`, `examples/cpp/embed.cpp`) compile with the
//! system's compilers against the static library, run, pass their own check against
//! quadrature, and draw through the C ABI the same directions and pdfs as the Rust API, bit for
//! bit. The equal-time comparison (`examples/c/glossy.c`) compiles and runs its quick version.

use sampler_core::brdf::{Brdf, BrdfSample, RoughConductor};
use sampler_core::cone::{Cone, build_cell_cones, cell_count};
use sampler_core::env::{EnvHierarchy, build_pyramid, pyramid_len, sanitize_rgb};
use sampler_core::frame::Frame;
use sampler_core::glam::{DVec2, Vec2, Vec3};
use sampler_core::latlong::{equal_area_level, latlong_to_equal_area};
use sampler_core::points::sobol02;
use sampler_core::sampler::{ProductArena, ProductParams};
use sampler_core::two_level::TwoLevelArena;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The examples' engine material, as the C code writes it.
struct Clay(Vec3);

impl Brdf for Clay {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Vec3::ZERO;
        }
        let k = std::f32::consts::FRAC_1_PI * wi.z;
        Vec3::new(self.0.x * k, self.0.y * k, self.0.z * k)
    }
    fn sample(&self, _: Vec3, _: Vec2) -> Option<BrdfSample> {
        unreachable!("the two-level build only evaluates")
    }
    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        unreachable!("the two-level build only evaluates")
    }
    fn is_diffuse(&self) -> bool {
        true
    }
}

/// The lines the examples print, computed with the Rust API.
fn expected() -> Vec<String> {
    let (w, h) = (128usize, 64usize);
    let mut latlong = vec![[0.0f32; 3]; w * h];
    for j in 0..h {
        for i in 0..w {
            let sky = 0.2f32 + 0.6f32 * (h - j) as f32 / h as f32;
            let sun = (40..42).contains(&i) && (20..22).contains(&j);
            latlong[j * w + i] = if sun { [2000.0, 2000.0, 1900.0] } else { [0.8 * sky, sky, 1.2 * sky] };
        }
    }
    let level = equal_area_level(w, h);
    let mut rgb = vec![[0.0f32; 3]; 1 << (2 * level)];
    latlong_to_equal_area(&latlong, w, h, level, 2, &mut rgb).unwrap();
    sanitize_rgb(&mut rgb);
    let mut pyramid = vec![0.0f32; pyramid_len(level)];
    build_pyramid(level, &rgb, &mut pyramid).unwrap();
    let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
    let metal = RoughConductor::new(0.1, Vec3::new(1.0, 0.78, 0.34));
    let clay = Clay(Vec3::new(0.7, 0.5, 0.4));
    let frame = Frame::from_normal(Vec3::new(0.6, 0.0, 0.8));
    let wo = Vec3::new(0.0, 0.6, 0.8);
    let mut u = [DVec2::ZERO; 8];
    sobol02(7, 0, &mut u);
    let line = |name: &str, k: usize, d: Vec3, pdf: f32, again: f32| {
        let b = |v: f32| v.to_bits();
        format!("{name} {k} {:08x} {:08x} {:08x} {:08x} {:08x}", b(d.x), b(d.y), b(d.z), b(pdf), b(again))
    };
    let mut lines = Vec::new();
    let mut arena: Box<ProductArena> = Box::default();
    let product = arena.build(&env, &metal, &frame, wo, &ProductParams::for_mis(256), 42).unwrap();
    for (k, p) in u.iter().enumerate() {
        let s = product.sample(*p).unwrap();
        lines.push(line("product", k, s.dir, s.pdf, product.pdf(s.dir)));
    }
    let mut cones = vec![Cone::default(); cell_count(4)];
    build_cell_cones(&mut cones);
    let mut two: Box<TwoLevelArena> = Box::default();
    let two = two.build(&env, &cones, &clay, &frame, wo).unwrap();
    for (k, p) in u.iter().enumerate() {
        let s = two.sample(*p).unwrap();
        lines.push(line("two-level", k, s.dir, s.pdf, two.pdf(s.dir)));
    }
    for (k, p) in u.iter().enumerate() {
        let s = env.sample(*p).unwrap();
        lines.push(line("env", k, s.dir, s.pdf, env.pdf(s.dir)));
    }
    lines
}

/// A C99 hex float (`%a`) as the bits of the f32 it prints.
fn hex_float_bits(s: &str) -> u32 {
    let (negative, s) = s.strip_prefix('-').map_or((false, s), |r| (true, r));
    let s = s.strip_prefix("0x").expect("a hex float");
    let (mantissa, exponent) = s.split_once('p').expect("an exponent");
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let mut value = u64::from_str_radix(int, 16).unwrap() as f64;
    for (k, c) in frac.chars().enumerate() {
        value += c.to_digit(16).unwrap() as f64 / 16f64.powi(k as i32 + 1);
    }
    let value = value * 2f64.powi(exponent.parse().unwrap());
    (if negative { -value } else { value } as f32).to_bits()
}

/// The examples' sample lines with their hex floats as bits.
fn sample_lines(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .filter(|l| !l.starts_with("estimate"))
        .map(|l| {
            let mut f = l.split_whitespace();
            let (name, k) = (f.next().unwrap(), f.next().unwrap());
            let bits: Vec<String> = f.map(|v| format!("{:08x}", hex_float_bits(v))).collect();
            format!("{name} {k} {}", bits.join(" "))
        })
        .collect()
}

/// The static library cargo built for this test run, and the repository root.
fn paths() -> (PathBuf, PathBuf) {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    let lib = deps.join("libsampler_capi.a");
    assert!(lib.exists(), "{} is missing (cargo builds it with the tests)", lib.display());
    (lib, Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf())
}

/// Compiles one example with `compiler` and runs it with `args`: its standard output.
fn build_and_run(compiler: &str, standard: &str, source: &str, libs: &[&str], args: &[&str]) -> String {
    let (lib, root) = paths();
    let name = Path::new(source).file_stem().unwrap().to_string_lossy();
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{compiler}"));
    let status = Command::new(compiler)
        .args([standard, "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror"])
        .arg(root.join(source))
        .arg("-I")
        .arg(root.join("sampler-capi/include"))
        .arg(&lib)
        .args(libs)
        .arg("-o")
        .arg(&out)
        .status()
        .unwrap_or_else(|e| panic!("cannot run {compiler} (a C/C++ compiler is needed): {e}"));
    assert!(status.success(), "{compiler} failed on {source}");
    let run = Command::new(&out).args(args).output().unwrap();
    let stdout = String::from_utf8(run.stdout).unwrap();
    assert!(run.status.success(), "{source} failed:\n{stdout}{}", String::from_utf8_lossy(&run.stderr));
    stdout
}

/// The embedding examples end with their estimate's check against quadrature.
fn passed(stdout: &str) -> bool {
    stdout.lines().any(|l| l.starts_with("estimate") && l.ends_with("PASS"))
}

#[test]
fn the_c_example_draws_what_the_rust_api_draws() {
    let stdout = build_and_run("cc", "-std=c99", "examples/c/embed.c", &["-lm", "-lpthread", "-ldl"], &[]);
    assert!(passed(&stdout), "{stdout}");
    assert_eq!(sample_lines(&stdout), expected());
}

#[test]
fn the_cpp_example_draws_what_the_rust_api_draws() {
    let stdout = build_and_run("c++", "-std=c++17", "examples/cpp/embed.cpp", &["-lpthread", "-ldl"], &[]);
    assert!(passed(&stdout), "{stdout}");
    let two_level: Vec<String> = expected().into_iter().filter(|l| l.starts_with("two-level")).collect();
    assert_eq!(sample_lines(&stdout), two_level);
}

#[test]
fn the_c_equal_time_comparison_runs_and_its_methods_agree_with_the_reference() {
    let stdout = build_and_run("cc", "-std=c99", "examples/c/glossy.c", &["-lm", "-lpthread", "-ldl"], &["--quick"]);
    // One table row per material and sample count, every method measured.
    let rows = stdout.lines().filter(|l| l.starts_with("| ") && l.contains(" µs, ")).count();
    assert_eq!(rows, 3 * 2, "{stdout}");
    assert_eq!(stdout.lines().last(), Some("PASS"), "{stdout}");
}
