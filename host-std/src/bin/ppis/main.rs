//! `ppis`: render scenes with product importance sampling of environment light.
//! Every failure prints one line naming the file or option and exits with status 2.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use host_std::light::environment::{EnvSource, Environment, Placement};
use host_std::plan::Method;
use host_std::plan::pilot;
use host_std::plan::{self, Settings};
use host_std::scene::Scene;
use host_std::scene::{builtin, json};
use host_std::trace::bvh::Bvh;
use host_std::{output, report};
use std::path::{Path, PathBuf};
use std::time::Instant;

mod report_cmd;
use report_cmd::{ReportArgs, report_command};

/// Largest visibility-sample count per pixel accepted (2^26: converging single techniques on
/// sharp highlights takes millions; pixel counters are u64, per-point indices u32).
const MAX_SPP: i64 = 1 << 26;

#[derive(Parser)]
#[command(
    name = "ppis",
    version,
    about = "Product importance sampling of environment light × BRDF (Clarberg & Akenine-Möller 2008)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (the embedded default scene when none is given) to linear EXR + sRGB PNG.
    Render(RenderArgs),
    /// Print what a scene holds and what a render of it would build.
    Info(InfoArgs),
    /// Error against run time: render each method at each spp, compare with a reference, write
    /// DIR/error_vs_time.csv, DIR/error_vs_time.{svg,png} and DIR/report.md.
    Report(ReportArgs),
}

#[derive(Args)]
struct SceneArgs {
    /// Scene file: .json (docs/scene-format.md) or USD (.usda, .usdc, .usdz, .usd). Without
    /// it: the embedded default scene.
    scene: Option<PathBuf>,
    /// USD: the camera prim to render through (default: the render settings' camera, else
    /// the stage's first camera).
    #[arg(long)]
    camera: Option<String>,
    /// USD: the RenderSettings prim whose resolution and camera apply (default: the layer's
    /// renderSettingsPrimPath, else the stage's only RenderSettings prim).
    #[arg(long, value_name = "PRIM")]
    render_settings: Option<String>,
    /// Environment map replacing the scene's (lat-long .exr/.hdr/.png/.jpg, or a square
    /// equal-area map).
    #[arg(long)]
    env: Option<PathBuf>,
    /// Radiance scale of the environment (with --env; otherwise the scene's).
    #[arg(long)]
    env_scale: Option<f32>,
    /// Rotation of the environment about +Y in degrees (d_world = R_y·d_local).
    #[arg(long, allow_hyphen_values = true)]
    env_rotate_y: Option<f32>,
}

#[derive(Args)]
struct RenderArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// product, wavelet, env, brdf, mis, product-mis, ris, two-stage or auto. The default,
    /// product-MIS, is product sampling beside BRDF sampling: on the default scene 5× faster
    /// than `product` alone and far less noisy (docs/perf.md).
    #[arg(long, default_value = "product-mis", value_parser = parse_method)]
    method: Method,
    /// Visibility samples (shadow rays) per pixel.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP))]
    spp: u32,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Output EXR; a PNG is written beside it. Default: render.exr in the current folder.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Write timings and counts as JSON.
    #[arg(long)]
    stats_json: Option<PathBuf>,
}

/// Primary rays per pixel when `--shading-points` is not given (reduced to a divisor of spp).
const DEFAULT_SHADING_POINTS: u32 = 4;

/// How a render samples, shared by `render` and `report`.
#[derive(Args)]
struct SamplingArgs {
    /// Primary rays (shading points) per pixel, each spending spp/P visibility samples
    /// [default: 4, or the largest divisor of --spp below it]. `render`: a P given must divide
    /// --spp; `report`: reduced to a divisor of each spp.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    shading_points: Option<u32>,
    /// BRDF samples per product sampler (the paper's K).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=256))]
    brdf_samples: u32,
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads, for the BVH and environment builds and the render (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=256))]
    threads: Option<u32>,
    /// Image width, overriding the scene's camera.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Image height, overriding the scene's camera.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// No shadow rays: every light direction counts as visible (for analysis: the error of
    /// sampling light × BRDF without the error visibility adds).
    #[arg(long)]
    unshadowed: bool,
}

impl SamplingArgs {
    /// --width and --height, as given.
    fn size(&self) -> (Option<u32>, Option<u32>) {
        (self.width, self.height)
    }

    /// Applies --width/--height to the scene's camera.
    fn resize(&self, scene: &mut Scene) {
        if let Some(w) = self.width {
            scene.camera.width = w;
        }
        if let Some(h) = self.height {
            scene.camera.height = h;
        }
    }

    /// Worker threads: --threads, or every core.
    fn threads(&self) -> usize {
        self.threads.map_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()), |t| t as usize)
    }
}

#[derive(Args)]
struct InfoArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// USD conformance: check every USD file under DIR that has a `<name>.expected.json`
    /// (Pixar's answers: world matrices, bound materials, metadata) and import it.
    #[arg(long, value_name = "DIR")]
    expected: Option<PathBuf>,
}

fn parse_method(s: &str) -> Result<Method, String> {
    s.parse()
}

/// The command line, or the one-line error (exit 2) a failure to parse it is; help and the
/// version print as clap prints them.
fn parse_command_line() -> Cli {
    use clap::error::ErrorKind;
    match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) => e.exit(),
        Err(e) => {
            let line = match e.kind() {
                ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    "no command given: render, info or report (see ppis --help)".to_string()
                }
                _ => {
                    let text = e.render().to_string();
                    let first = text.lines().next().unwrap_or_default().trim_start_matches("error: ").to_string();
                    format!("{first} (see --help)")
                }
            };
            eprintln!("ppis: error: {line}");
            std::process::exit(2);
        }
    }
}

fn main() {
    let cli = parse_command_line();
    let result = match cli.command {
        Command::Render(args) => render_command(args),
        Command::Info(args) => info_command(args),
        Command::Report(args) => report_command(args),
    };
    if let Err(e) = result {
        eprintln!("ppis: error: {e:#}");
        std::process::exit(2);
    }
}

/// A loaded scene with what the importer left out or reduced (USD), for the user.
struct Loaded {
    scene: Scene,
    notes: Vec<String>,
    #[cfg(feature = "usd")]
    usd: Option<host_usd::UsdScene>,
}

/// Loads the scene the arguments name (or the default scene) and applies `--env`.
fn load_scene(args: &SceneArgs, size: (Option<u32>, Option<u32>)) -> Result<Loaded> {
    #[cfg(feature = "usd")]
    let mut usd = None;
    #[cfg_attr(not(feature = "usd"), allow(unused_mut))]
    let mut notes = Vec::new();
    let mut scene = match &args.scene {
        None => builtin::scene(),
        Some(path) => {
            let ext = path.extension().and_then(|e| e.to_str()).unwrap_or_default().to_ascii_lowercase();
            match ext.as_str() {
                "json" => json::load(path)?,
                #[cfg(feature = "usd")]
                "usd" | "usda" | "usdc" | "usdz" => {
                    let options = host_std::scene::usd::Options {
                        camera: args.camera.clone(),
                        render_settings: args.render_settings.clone(),
                        width: size.0,
                        height: size.1,
                    };
                    let c = host_std::scene::usd::load(path, &options)?;
                    notes = c.notes;
                    usd = Some(c.usd);
                    c.scene
                }
                #[cfg(not(feature = "usd"))]
                "usd" | "usda" | "usdc" | "usdz" => {
                    bail!("{}: this ppis was built without USD support (cargo feature `usd`)", path.display())
                }
                _ => bail!("{}: unknown scene format (expected .json, .usda, .usdc, .usdz or .usd)", path.display()),
            }
        }
    };
    let is_usd =
        args.scene.as_ref().and_then(|p| p.extension()).is_some_and(|e| {
            matches!(e.to_string_lossy().to_ascii_lowercase().as_str(), "usd" | "usda" | "usdc" | "usdz")
        });
    if args.camera.is_some() && !is_usd {
        bail!("--camera applies to USD scenes only");
    }
    if args.render_settings.is_some() && !is_usd {
        bail!("--render-settings applies to USD scenes only");
    }
    if let Some(env) = &args.env {
        if !env.exists() {
            bail!("{}: environment map not found", env.display());
        }
        scene.env = Some((EnvSource::File(env.clone()), Placement::default()));
    }
    if let Some((_, placement)) = scene.env.as_mut() {
        if let Some(s) = args.env_scale {
            if !(s >= 0.0 && s.is_finite()) {
                bail!("--env-scale must be a finite number ≥ 0, got {s}");
            }
            placement.scale = s;
        }
        if let Some(r) = args.env_rotate_y {
            if !r.is_finite() {
                bail!("--env-rotate-y must be finite, got {r}");
            }
            placement.rotate_y_deg = r;
        }
    }
    Ok(Loaded {
        scene,
        notes,
        #[cfg(feature = "usd")]
        usd,
    })
}

/// One warning summary of what an import left out (all of it is in `ppis info`).
fn warn_notes(scene: &Scene, notes: &[String]) {
    const SHOWN: usize = 12;
    if notes.is_empty() {
        return;
    }
    // Group alike notes: the same message about different prims or files.
    let mut groups: Vec<(String, usize, &str)> = Vec::new();
    for n in notes {
        let (path, what) = n.split_once(": ").unwrap_or(("", n));
        let key: String = what
            .split(' ')
            .map(|w| if w.contains('/') || w.contains('.') && w.len() > 4 { "…" } else { w })
            .collect::<Vec<_>>()
            .join(" ");
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1 += 1,
            None => groups.push((key, 1, path)),
        }
    }
    eprintln!(
        "ppis: warning: {}: {} things were not rendered as authored (`ppis info` lists them all):",
        scene.name,
        notes.len()
    );
    for (key, count, first) in groups.iter().take(SHOWN) {
        eprintln!("  {count}× {key} (e.g. {first})");
    }
    if groups.len() > SHOWN {
        eprintln!("  … and {} more kinds", groups.len() - SHOWN);
    }
}

fn render_command(args: RenderArgs) -> Result<()> {
    let shading_points = match args.sampling.shading_points {
        Some(p) if !args.spp.is_multiple_of(p) => bail!("--shading-points {p} must divide --spp {}", args.spp),
        Some(p) => p,
        None => report::shading_points_for(args.spp as usize, DEFAULT_SHADING_POINTS as usize) as u32,
    };
    let exr_path = args.output.clone().unwrap_or_else(|| PathBuf::from("render.exr"));
    let is_exr = exr_path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !is_exr {
        // `-o out.png` would otherwise write the EXR there and then the PNG over it.
        bail!(
            "{}: the output is an OpenEXR file and must end in .exr (the PNG is written beside it)",
            exr_path.display()
        );
    }
    let png_path = exr_path.with_extension("png");
    check_writable(&exr_path)?;
    if let Some(stats) = &args.stats_json {
        check_writable(stats)?;
    }

    let t_load = Instant::now();
    let loaded = load_scene(&args.scene, args.sampling.size())?;
    warn_notes(&loaded.scene, &loaded.notes);
    let mut scene = loaded.scene;
    args.sampling.resize(&mut scene);
    let load_seconds_scene = t_load.elapsed().as_secs_f64();

    // Preprocess (only what this render uses) and render on --threads threads.
    let threads = args.sampling.threads();
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("cannot start the worker threads")?;
    let environment = match &scene.env {
        Some((source, placement)) => Some(pool.install(|| Environment::build(source, *placement))?),
        None => None,
    };
    let t_bvh = Instant::now();
    let bvh = pool.install(|| Bvh::build(&scene));
    let bvh_seconds = t_bvh.elapsed().as_secs_f64();
    if let Some(env) = &environment
        && env.stats.sanitized > 0
    {
        eprintln!(
            "ppis: warning: {}: {} texels were NaN, infinite or negative and were set to 0",
            env.stats.source, env.stats.sanitized
        );
    }

    let settings = Settings {
        method: args.method,
        spp: args.spp as usize,
        shading_points: shading_points as usize,
        brdf_samples: args.sampling.brdf_samples as usize,
        seed: args.sampling.seed,
        progress: true,
        shadows: !args.sampling.unshadowed,
    };
    let hierarchy = environment.as_ref().map(Environment::hierarchy);
    let image = pool.install(|| plan::render(&scene, &bvh, hierarchy.as_ref(), &settings));

    output::write_exr(&exr_path, image.width, image.height, &image.pixels)?;
    output::write_png(&png_path, image.width, image.height, &image.pixels)?;

    let env_load = environment.as_ref().map_or(0.0, |e| e.stats.load_seconds);
    let env_build = environment.as_ref().map_or(0.0, |e| e.stats.build_seconds);
    let samples = image.shadow_rays as f64;
    if let Some(path) = &args.stats_json {
        let stats = serde_json::json!({
            "scene": scene.name,
            "method": args.method.name(),
            "spp": args.spp,
            "shading_points_per_pixel": shading_points,
            "brdf_samples": args.sampling.brdf_samples,
            "threads": threads,
            "seed": args.sampling.seed,
            "unshadowed": args.sampling.unshadowed,
            "width": image.width,
            "height": image.height,
            "load_seconds": load_seconds_scene + env_load,
            "preprocess_seconds": env_build + bvh_seconds,
            "env_build_seconds": env_build,
            "bvh_seconds": bvh_seconds,
            "render_seconds": image.render_seconds,
            "shading_points": image.shading_points,
            "shadow_rays": image.shadow_rays,
            "camera_rays": image.camera_rays,
            "non_finite_pixels": image.non_finite,
            "env_level": environment.as_ref().map(|e| e.level),
            "env_bytes": environment.as_ref().map(|e| e.stats.bytes),
            "env_sanitized_texels": environment.as_ref().map(|e| e.stats.sanitized),
            "env_source_mean_rgb": environment.as_ref().map(|e| e.stats.source_mean),
            "env_map_mean_rgb": environment.as_ref().map(|e| e.stats.map_mean),
            "env_mean_relative_error": environment.as_ref().map(|e| {
                (0..3).map(|c| (e.stats.map_mean[c] / e.stats.source_mean[c].max(1e-300) - 1.0).abs()).fold(0.0, f64::max)
            }),
            "primitives": bvh.primitive_count(),
            "env_peak": hierarchy.as_ref().map(|h| h.peak(5)),
            "pilot_seconds": image.pilot_seconds,
            "auto_plans": image.pilot.iter().map(|r| serde_json::json!({
                "material": scene.materials[r.material].bsdf.label(),
                "plan": pilot::plan_name(r.chosen),
                "rule_plan": r.rule.map(pilot::plan_name),
                "pilot_pixels": r.pixels,
                "scores": (0..pilot::PLANS.len()).map(|c| (pilot::plan_name(c), serde_json::json!(r.scores[c]))).collect::<serde_json::Map<_, _>>(),
            })).collect::<Vec<_>>(),
        });
        output::write_text(path, &serde_json::to_string_pretty(&stats)?)?;
    }
    let t = image.render_seconds.max(1e-9);
    eprintln!(
        "ppis: {}×{} {} spp ({} shading points/pixel), method {}, {} threads: {:.2} s, {:.2} M samples/s, {:.0} k shading points/s; wrote {} and {}",
        image.width,
        image.height,
        args.spp,
        shading_points,
        args.method,
        threads,
        image.render_seconds,
        samples / t * 1e-6,
        image.shading_points as f64 / t * 1e-3,
        exr_path.display(),
        png_path.display()
    );
    for r in &image.pilot {
        eprintln!(
            "ppis: auto: {} → {}{} (pilot: {} pixels, {:.2} s in all)",
            scene.materials[r.material].bsdf.label(),
            pilot::plan_name(r.chosen),
            if Some(r.chosen) == r.rule { "" } else { ", measured ahead of the rule's plan" },
            r.pixels,
            image.pilot_seconds
        );
    }
    if image.non_finite > 0 {
        eprintln!("ppis: warning: {} pixels were not finite and were written as 0", image.non_finite);
    }
    Ok(())
}

/// Fails early (before any work) when the output folder does not exist.
fn check_writable(path: &Path) -> Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        bail!("{}: the output folder does not exist", path.display());
    }
    Ok(())
}

fn info_command(args: InfoArgs) -> Result<()> {
    if let Some(dir) = &args.expected {
        return conformance(dir);
    }
    let loaded = load_scene(&args.scene, (None, None))?;
    #[cfg(feature = "usd")]
    if let Some(usd) = &loaded.usd {
        host_std::scene::usd_info::print_import(usd);
    }
    if !loaded.notes.is_empty() {
        println!("not rendered as authored ({}):", loaded.notes.len());
        for n in &loaded.notes {
            println!("  {n}");
        }
    }
    let scene = loaded.scene;
    let c = &scene.camera;
    println!("scene {}", scene.name);
    println!(
        "camera: {}×{}, fov {}°, from {:?} to {:?}",
        c.width,
        c.height,
        c.fov_y_deg,
        c.origin.to_array(),
        c.target.to_array()
    );
    println!("objects: {} ({} triangles)", scene.objects.len(), scene.triangle_count());
    for (i, m) in scene.materials.iter().enumerate() {
        println!("  material {i}: {}{}", m.bsdf.kind(), if m.twosided { ", two-sided" } else { "" });
    }
    match &scene.env {
        None => println!("environment: none — a render builds no env hierarchy and is black except for hits"),
        Some((EnvSource::Sky { level }, _)) => {
            println!("environment: built-in sky, equal-area {}² (pyramid {} MB)", 1u32 << level, pyramid_mb(*level))
        }
        Some((EnvSource::Bytes { name, .. }, p)) => println!(
            "environment: {} (tint {:?}), resampled to a power-of-two equal-area square",
            name.display(),
            p.tint
        ),
        Some((EnvSource::Constant { .. }, p)) => println!("environment: constant radiance {:?}", p.tint),
        Some((EnvSource::File(path), p)) => println!(
            "environment: {} (scale {}, rotate_y {}°), resampled to a power-of-two equal-area square",
            path.display(),
            p.scale,
            p.rotate_y_deg
        ),
    }
    println!(
        "a render builds: {} BVH primitives{}; product samplers for methods product and wavelet (per shading point), product-mis (per pixel and material, reused by nearby pixels; {} of its samples from the product on GGX conductors with α ≥ {} when the map's peak is under {}, half elsewhere); auto = product-mis on GGX conductors with α in {:?} ({:?} when the map's peak is under {}: no sun), mis on the other materials ({} of it env samples on diffuse surfaces when the peak is under {}), or BRDF sampling when the lighting is smooth (peak < {}) — then checked per material by a pilot render of 32–64 of its pixels with the candidate plans env, BRDF, MIS and product-MIS (those whose sample weights are bounded there, the two MIS methods at the rules' splits; of {} plans in all), which replaces the rule's plan where another measures {}× better at equal cost (about 2% of the render; images of at least ~96×96 per material)",
        Bvh::build(&scene).primitive_count(),
        if scene.env.is_some() { ", the env hierarchy" } else { "" },
        host_std::plan::rules::WIDE_LOBE_PRODUCT_SHARE,
        host_std::plan::rules::WIDE_LOBE,
        host_std::plan::rules::SUN_PEAK,
        host_std::plan::rules::PRODUCT_ALPHA,
        host_std::plan::rules::PRODUCT_ALPHA_EXTENDED,
        host_std::plan::rules::SUN_PEAK,
        host_std::plan::rules::AUTO_DIFFUSE_ENV_SHARE,
        host_std::plan::rules::SUN_PEAK,
        host_std::plan::rules::SMOOTH_LIGHTING_PEAK,
        pilot::PLANS.len(),
        pilot::OVERRIDE_MARGIN
    );
    Ok(())
}

fn pyramid_mb(level: u32) -> f64 {
    (sampler_core::env::pyramid_len(level) * 4 + (1usize << (2 * level)) * 12) as f64 / 1e6
}

#[cfg(feature = "usd")]
fn conformance(dir: &Path) -> Result<()> {
    host_std::scene::usd_info::conformance(dir)
}

#[cfg(not(feature = "usd"))]
fn conformance(_dir: &Path) -> Result<()> {
    bail!("--expected: this ppis was built without USD support (cargo feature `usd`)")
}
