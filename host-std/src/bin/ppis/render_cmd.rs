//! `ppis render`: one scene, one method, to a linear EXR, an sRGB PNG and optionally the
//! stats JSON; with `--crop`, a part of the frame (a tile for `ppis merge`).

use crate::args::{MAX_SPP, SamplingArgs, SceneArgs, brdf_samples, parse_method};
use crate::load::{load_scene, warn_notes};
use crate::provenance;
use crate::stats::Stats;
use anyhow::{Context, Result, bail};
use clap::Args;
use host_std::light::environment::Environment;
use host_std::output;
use host_std::plan::carrier::{self, Carrier, CarrierChoice};
use host_std::plan::prepass::Prepass;
use host_std::plan::{self, Method, Rendered, Settings, ShadingPoints};
use host_std::render::crop::Crop;
use host_std::scene::Scene;
use host_std::trace::bvh::Bvh;
use sampler_core::env::MisHeuristic;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args)]
pub(crate) struct RenderArgs {
    #[command(flatten)]
    pub(crate) scene: SceneArgs,
    /// product, wavelet, env, brdf, mis, product-mis, ris, two-stage, two-level, two-level-mis,
    /// sis, lightcuts, plane-product or auto. plane-product samples diffuse planes by the map ×
    /// the plane's cosine, a pyramid per plane, and everything else as mis. sis (structured
    /// importance sampling) and lightcuts are the seed's deterministic, biased baselines: each
    /// shading point shades every stratum or a whole cut: P = spp/64 shading points per pixel
    /// (docs/renderer.md). The default, auto, picks per material the plan with the least error
    /// at equal time, from rules checked by a pilot render (docs/perf.md#auto-and-its-pilot).
    #[arg(long, default_value = "auto", value_parser = parse_method)]
    pub(crate) method: Method,
    /// Visibility samples (shadow rays) per pixel.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP))]
    pub(crate) spp: u32,
    /// BRDF samples per product sampler (the paper's K; at most 1024), for every material.
    /// Default: each material's from its lobes — 16 diffuse, 64 one glossy lobe, 128 layered
    /// (docs/tuning.md, "BRDF samples per sampler at equal time").
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub(crate) brdf_samples: Option<u32>,
    #[command(flatten)]
    pub(crate) sampling: SamplingArgs,
    /// How MIS weighs a sample against the other technique's density: `balance`, `power`
    /// (Veach's heuristics) or `pilot` (whichever the split pilot measures better, where it
    /// runs: the MIS methods other than `auto` from 128 spp; the balance heuristic elsewhere).
    #[arg(long, value_enum, value_name = "balance|power|pilot", default_value = "pilot")]
    pub(crate) mis_heuristic: HeuristicArg,
    /// Output EXR; a PNG is written beside it. Default: render.exr in the current folder.
    #[arg(short = 'o', long = "output")]
    output: Option<PathBuf>,
    /// Write timings and counts as JSON.
    #[arg(long)]
    stats_json: Option<PathBuf>,
    /// Render only the pixels x0 ≤ x < x1, y0 ≤ y < y1 (half-open, as pbrt's --pixelbounds),
    /// bit for bit those of the whole frame's render: the EXR's data window is the crop, its
    /// display window the frame (a tile for `ppis merge`); the PNG holds the crop.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop, allow_hyphen_values = true)]
    crop: Option<Crop>,
}

fn parse_crop(text: &str) -> Result<Crop, String> {
    Crop::parse(text).map_err(|e| e.to_string().trim_start_matches(&format!("--crop {text}: ")).to_string())
}

/// A scene ready to render: loaded, its environment and BVH built, and how long that took.
pub(crate) struct Prepared {
    pub(crate) scene: Scene,
    pub(crate) environment: Option<Environment>,
    pub(crate) bvh: Bvh,
    /// Seconds loading the scene (the environment's own load time is in its stats).
    pub(crate) load_seconds: f64,
    pub(crate) bvh_seconds: f64,
    /// The pixels to render: `--crop`, checked against the frame, or the whole frame.
    pub(crate) crop: Crop,
    /// The files the scene refers to (`Loaded::files`).
    pub(crate) files: Vec<PathBuf>,
    /// The process's CPU seconds (every thread) loading the scene, reading and building the
    /// environment, and building the BVH (`None` where the platform does not say).
    pub(crate) cpu_seconds: Option<[f64; 3]>,
}

pub(crate) fn render_command(args: RenderArgs) -> Result<()> {
    let brdf_samples = brdf_samples(args.brdf_samples)?;
    if let Some(p) = args.sampling.shading_points
        && !args.spp.is_multiple_of(p)
    {
        bail!("--shading-points {p} must divide --spp {}", args.spp);
    }
    let (exr_path, png_path) = output_paths(&args)?;
    let threads = args.sampling.threads();
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("cannot start the worker threads")?;
    let mut prepared = prepare(&args, &pool)?;
    let mut settings = Settings {
        method: args.method,
        spp: args.spp as usize,
        shading_points: 1,
        brdf_samples,
        seed: args.sampling.seed,
        progress: true,
        shadows: !args.sampling.unshadowed,
        lights: args.sampling.lights(),
    };
    let points = args.sampling.shading_points.map_or(ShadingPoints::Rule, |p| ShadingPoints::Given(p as usize));
    let carries = prepared.environment.is_some() && carrier::has_wide_distant_light(&prepared.scene);
    let carrier = pool.install(|| carry_distant_lights(args.sampling.carrier(), &mut prepared, &settings, points));
    let hierarchy = prepared.environment.as_ref().map(Environment::hierarchy);
    let heuristic = args.mis_heuristic.given();
    let prepass =
        pool.install(|| Prepass::run(&prepared.scene, &prepared.bvh, hierarchy.as_ref(), &settings, points, heuristic));
    let shading_points = prepass.shading_points as u32;
    settings.shading_points = prepass.shading_points;
    let camera = &prepared.scene.camera;
    let frame = (camera.width as usize, camera.height as usize);
    let crop = prepared.crop;
    let used = carries.then(|| carrier.as_ref().map_or(args.sampling.carrier(), |c| c.carrier));
    let record = provenance::settings_text(&args, &settings, frame, &prepared.files, (used, prepass.mis_heuristic))?;
    let view = hierarchy.as_ref().map(|h| prepass.view(h));
    let mut image = pool.install(|| plan::render_crop(&prepared.scene, &prepared.bvh, view.as_ref(), &settings, crop));
    // The pilots and the prepass are part of the render's cost.
    prepass.charge(&mut image);
    if let Some(c) = &carrier {
        image.add_pilot(c.seconds, c.cpu_seconds);
    }

    output::write_exr_part(&exr_path, frame, crop, &image.pixels, Some(&record))?;
    output::write_png(&png_path, image.width, image.height, &image.pixels)?;
    if let Some(path) = &args.stats_json {
        let stats =
            Stats::new(&args, &prepared, hierarchy.as_ref(), &image, shading_points, prepass.split.as_ref(), threads);
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
        image.shadow_rays as f64 / t * 1e-6,
        image.shading_points as f64 / t * 1e-3,
        exr_path.display(),
        png_path.display()
    );
    if let Some(c) = &carrier {
        eprintln!(
            "ppis: distant light: {} (pilot of {} pixels: variance × cost {:.3e} by its cone, {:.3e} in the map; {:.2} s)",
            if c.carrier == Carrier::Map { "carried by the environment map" } else { "sampled by its cone" },
            c.pixels,
            c.scores[0],
            c.scores[1],
            c.seconds
        );
    }
    if let Some(c) = &prepass.split {
        let score = |k: usize| c.scores[k].map_or(String::from("—"), |s| format!("{s:.3e}"));
        let cpu = c.cpu_seconds.map_or(String::from("CPU time unknown"), |s| format!("{s:.2} CPU s"));
        let power = c.power_score.map_or(String::new(), |p| {
            format!(
                ", {p:.3e} at {} by the power heuristic against {}",
                c.samples_per_point,
                score(usize::from(c.samples_per_point == c.candidates[1]))
            )
        });
        if c.scores[0].is_some() {
            eprintln!(
                "ppis: light samples per shading point: {} (pilot of {} pixels at {} spp: variance × cost {} at {}, {} at {}{power}; {:.2} s, {cpu})",
                c.samples_per_point,
                c.pixels,
                c.pilot_spp,
                score(0),
                c.candidates[0],
                score(1),
                c.candidates[1],
                c.seconds,
            );
        } else if c.pixels > 0 {
            eprintln!(
                "ppis: light samples per shading point: {} (extended light; pilot of {} pixels at {} spp{power}; {:.2} s, {cpu})",
                c.samples_per_point, c.pixels, c.pilot_spp, c.seconds,
            );
        } else {
            eprintln!("ppis: light samples per shading point: {} (extended light)", c.samples_per_point);
        }
        if c.power_score.is_some() {
            eprintln!("ppis: MIS heuristic: {}", heuristic_name(c.heuristic));
        }
    }
    report_pilot(&prepared.scene, &image);
    if image.non_finite > 0 {
        eprintln!("ppis: warning: {} pixels were not finite and were written as 0", image.non_finite);
    }
    Ok(())
}

/// The EXR and PNG to write, checked before any work.
fn output_paths(args: &RenderArgs) -> Result<(PathBuf, PathBuf)> {
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
    Ok((exr_path, png_path))
}

/// Loads the scene and builds (only what this render uses) on the pool's threads.
fn prepare(args: &RenderArgs, pool: &rayon::ThreadPool) -> Result<Prepared> {
    let cpu = || host_std::cpu_time::process_cpu_time().map(|d| d.as_secs_f64());
    let cpu_start = cpu();
    let t_load = Instant::now();
    let loaded = load_scene(&args.scene, args.sampling.size(), false)?;
    warn_notes(&loaded.scene, &loaded.notes);
    let (mut scene, files) = (loaded.scene, loaded.files);
    args.sampling.resize(&mut scene);
    let (width, height) = (scene.camera.width as usize, scene.camera.height as usize);
    let crop = match args.crop {
        Some(crop) => crop.check(width, height)?,
        None => Crop::full(width, height),
    };
    let load_seconds = t_load.elapsed().as_secs_f64();
    let cpu_loaded = cpu();
    let environment = match &scene.env {
        Some((source, placement)) => Some(pool.install(|| Environment::build(source, *placement))?),
        None => None,
    };
    let cpu_env = cpu();
    let t_bvh = Instant::now();
    let bvh = pool.install(|| Bvh::build(&scene));
    let bvh_seconds = t_bvh.elapsed().as_secs_f64();
    let cpu_seconds = match (cpu_start, cpu_loaded, cpu_env, cpu()) {
        (Some(a), Some(b), Some(c), Some(d)) => Some([b - a, c - b, d - c]),
        _ => None,
    };
    if let Some(env) = &environment
        && env.stats.sanitized > 0
    {
        eprintln!(
            "ppis: warning: {}: {} texels were NaN, infinite or negative and were set to 0",
            env.stats.source, env.stats.sanitized
        );
    }
    Ok(Prepared { scene, environment, bvh, load_seconds, bvh_seconds, crop, files, cpu_seconds })
}

/// Applies `--distant-carrier` to the prepared scene (a chosen or measured `map` moves its wide
/// distant lights into the environment); returns what `auto`'s pilot measured, where it ran.
fn carry_distant_lights(
    carrier: Carrier,
    prepared: &mut Prepared,
    settings: &Settings,
    points: ShadingPoints,
) -> Option<CarrierChoice> {
    let env = prepared.environment.as_mut()?;
    let choice = match carrier {
        Carrier::Auto => carrier::choose(&prepared.scene, &prepared.bvh, env, settings, points),
        _ => None,
    };
    carrier::apply(choice.map_or(carrier, |c| c.carrier), &mut prepared.scene.lights, env);
    choice
}

/// One line per material `auto`'s pilot measured, with its light samples per shading point.
fn report_pilot(scene: &Scene, image: &Rendered) {
    // Materials the rules planned alone, by plan and samples, in the order they first appear.
    let mut by_rules: Vec<((&str, usize), Vec<String>)> = Vec::new();
    for (m, plan, samples, pilot) in image.auto_choices() {
        let label = scene.materials[m].bsdf.label();
        let Some(r) = pilot else {
            match by_rules.iter_mut().find(|(key, _)| *key == (plan, samples)) {
                Some((_, labels)) => labels.push(label),
                None => by_rules.push(((plan, samples), vec![label])),
            }
            continue;
        };
        eprintln!(
            "ppis: auto: {label} → {plan}, {samples} samples per shading point{} (pilot: {} pixels, {:.2} s in all)",
            if Some(r.chosen) == r.rule { "" } else { ", measured ahead of the rule's plan" },
            r.pixels,
            image.pilot_seconds
        );
    }
    for ((plan, samples), labels) in by_rules {
        eprintln!("ppis: auto: {} → {plan}, {samples} samples per shading point (by the rules)", counted(&labels));
    }
}

/// `labels` with repeats counted, in first-seen order: `diffuse ×2, carpaint`; past
/// `MAX_LISTED` distinct labels, how many more.
fn counted(labels: &[String]) -> String {
    const MAX_LISTED: usize = 6;
    let mut distinct: Vec<(&str, usize)> = Vec::new();
    for l in labels {
        match distinct.iter_mut().find(|(d, _)| *d == l.as_str()) {
            Some((_, n)) => *n += 1,
            None => distinct.push((l, 1)),
        }
    }
    let mut parts: Vec<String> = distinct
        .iter()
        .take(MAX_LISTED)
        .map(|&(l, n)| if n > 1 { format!("{l} ×{n}") } else { l.to_string() })
        .collect();
    if distinct.len() > MAX_LISTED {
        parts.push(format!("{} more", distinct.len() - MAX_LISTED));
    }
    parts.join(", ")
}

/// Fails early (before any work) when the output folder does not exist.
fn check_writable(path: &Path) -> Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        bail!("{}: the output folder does not exist", path.display());
    }
    Ok(())
}

/// `--mis-heuristic`: one of Veach's heuristics, or the split pilot's choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum HeuristicArg {
    /// The balance heuristic.
    Balance,
    /// The power heuristic (β = 2).
    Power,
    /// Whichever the split pilot measures better where it runs, else the balance heuristic.
    Pilot,
}

impl HeuristicArg {
    /// The heuristic given, `None` for the pilot's.
    pub(crate) fn given(self) -> Option<MisHeuristic> {
        match self {
            Self::Balance => Some(MisHeuristic::Balance),
            Self::Power => Some(MisHeuristic::Power),
            Self::Pilot => None,
        }
    }
}

/// The heuristic's name, as `--mis-heuristic` spells it.
pub(crate) fn heuristic_name(h: MisHeuristic) -> &'static str {
    match h {
        MisHeuristic::Balance => "balance",
        MisHeuristic::Power => "power",
    }
}
