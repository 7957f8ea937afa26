//! `ppis report`: every method at every sample count against a reference — error against
//! render time as CSV, plot and equal-time tables.

use crate::args::{MAX_SPP, SamplingArgs, SceneArgs, check_brdf_samples, parse_method};
use crate::load::{load_scene, warn_notes};
use anyhow::{Context, Result, bail};
use clap::Args;
use host_std::light::environment::Environment;
use host_std::plan::Method;
use host_std::plan::carrier::Carrier;
use host_std::plan::method::Lighting;
use host_std::plan::{self, Settings, ShadingPoints};
use host_std::render::brdf_samples::BrdfSamples;
use host_std::report::{Clock, KSweep, Series, Timing};
use host_std::scene::Scene;
use host_std::trace::bvh::Bvh;
use host_std::{output, report};
use sampler_core::env::EnvHierarchy;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct ReportArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Comma-separated methods.
    #[arg(long, default_value = "product,env,brdf,mis,product-mis,ris,two-stage,auto", value_delimiter = ',', value_parser = parse_method)]
    methods: Vec<Method>,
    /// Comma-separated visibility samples per pixel.
    #[arg(long, default_value = "4,16,64", value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=MAX_SPP))]
    spp: Vec<u32>,
    /// Comma-separated BRDF samples per product sampler (the paper's K; each at most 1024),
    /// for every material. More than one: the methods that build product samplers are
    /// rendered at each, and the report adds relMSE at equal time against K (error_vs_k.csv,
    /// .md, .svg, .png). Default: each material's K from its lobes, as `render`'s.
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..))]
    brdf_samples: Vec<u32>,
    /// Reference image (linear EXR of the same size); otherwise one is rendered.
    #[arg(long, conflicts_with = "reference_spp")]
    reference: Option<PathBuf>,
    /// Visibility samples per pixel of the rendered reference.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=MAX_SPP))]
    reference_spp: u32,
    /// Visibility samples per shading point for every method and the reference: primary rays
    /// per pixel P = spp / V (instead of each method's own V).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    samples_per_point: Option<u32>,
    /// Method of the rendered reference (an independent code path from the product by default).
    #[arg(long, default_value = "mis", value_parser = parse_method)]
    reference_method: Method,
    /// The method the equal-time tables compare every other one against (one of --methods).
    /// Default: product, or the first of --methods when product is not among them.
    #[arg(long, value_parser = parse_method)]
    base: Option<Method>,
    /// Render every method faster than the base on at doubling spp (at most 8× its largest)
    /// until its time reaches the base's at its largest spp, so that its error at the base's
    /// times is interpolated, not extrapolated.
    #[arg(long)]
    bracket: bool,
    /// Time every render this many times in all (in rounds over all renders) and keep the
    /// fastest: single timings vary with what else the machine is doing.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// What renders are timed by: `wall` (seconds of the render, for an idle machine) or `cpu`
    /// (CPU seconds of its threads, for a machine shared with other work).
    #[arg(long, value_enum, default_value_t = Clock::Wall)]
    clock: Clock,
    #[command(flatten)]
    sampling: SamplingArgs,
    /// Output folder (created if missing).
    #[arg(long)]
    out: PathBuf,
}

pub(crate) fn report_command(args: ReportArgs) -> Result<()> {
    for &k in &args.brdf_samples {
        check_brdf_samples(k)?;
    }
    let mut ks: Vec<usize> = args.brdf_samples.iter().map(|&k| k as usize).collect();
    ks.sort_unstable();
    ks.dedup();
    let reference_k = report::reference_k(&ks);
    // One K or none: every series at the render's K (the one given, or each material's).
    let render_k = match ks.as_slice() {
        [] => BrdfSamples::PerLobe,
        [k] => BrdfSamples::Fixed(*k),
        _ => BrdfSamples::Fixed(reference_k),
    };
    if ks.is_empty() {
        ks.push(reference_k);
    }
    let base_method = match args.base {
        Some(b) if !args.methods.contains(&b) => bail!("--base {b} is not among --methods"),
        Some(b) => b,
        None if args.methods.contains(&Method::Product) => Method::Product,
        None => args.methods[0],
    };
    let loaded = load_scene(&args.scene, args.sampling.size(), false)?;
    warn_notes(&loaded.scene, &loaded.notes);
    let mut scene = loaded.scene;
    args.sampling.resize(&mut scene);
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    // Everything that reads input comes first: bad input leaves no output folder behind.
    let given = match &args.reference {
        Some(path) => {
            let image = host_std::light::image_file::load(path)?;
            if (image.width, image.height) != (w, h) {
                bail!("{}: the reference is {}×{}, the render {}×{}", path.display(), image.width, image.height, w, h);
            }
            Some((image.texels, format!("{}", path.display())))
        }
        None => None,
    };
    let mut environment = match &scene.env {
        Some((source, placement)) => Some(Environment::build(source, *placement)?),
        None => None,
    };
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("{}: cannot create the output folder", args.out.display()))?;
    let bvh = Bvh::build(&scene);
    let threads = args.sampling.threads();
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("cannot start the worker threads")?;
    if let Some(env) = environment.as_mut() {
        carry_distant_lights(&args, &mut scene, &bvh, env, render_k, &pool);
    }
    let hierarchy = environment.as_ref().map(Environment::hierarchy);
    let base = Settings {
        method: Method::Product,
        spp: 1,
        shading_points: 1,
        brdf_samples: render_k,
        seed: args.sampling.seed,
        progress: false,
        shadows: !args.sampling.unshadowed,
        lights: args.sampling.lights(),
    };
    let (reference, note) = match given {
        Some(given) => given,
        None => render_reference(&args, &pool, &scene, &bvh, hierarchy.as_ref(), &base)?,
    };
    let spps: Vec<usize> = args.spp.iter().map(|&s| s as usize).collect();
    let base_series = Series::of(base_method, &ks, reference_k);
    let bracket = args.bracket.then_some(base_series);
    let measurements = pool.install(|| {
        let points = shading_points(&args);
        let methods = &args.methods;
        let timing = Timing { clock: args.clock, repeat: args.repeat as usize };
        report::sweep(
            &scene,
            &bvh,
            hierarchy.as_ref(),
            methods,
            &spps,
            &ks,
            &base,
            points,
            &reference,
            bracket,
            timing,
            |m| {
                eprintln!(
                    "ppis: {:>20} {:>6} spp  {:>8.3} s  RMSE {:.4e}  relMSE {:.4e}  bias {:+.2}%",
                    m.series().to_string(),
                    m.spp,
                    m.seconds,
                    m.rmse,
                    m.relmse,
                    100.0 * m.bias
                );
            },
        )
    });
    write_outputs(&args, &scene.name, &measurements, base_series, threads, &note)?;
    if ks.len() > 1 {
        write_k_sweep(&args, &scene.name, &measurements, reference_k, threads, &note)?;
    }
    Ok(())
}

/// Applies `--distant-carrier` once for the whole report: `auto` measures it for the first
/// method at the largest spp (its pilot's time is not in the series' times).
fn carry_distant_lights(
    args: &ReportArgs,
    scene: &mut Scene,
    bvh: &Bvh,
    env: &mut Environment,
    brdf_samples: BrdfSamples,
    pool: &rayon::ThreadPool,
) {
    let mut carrier = args.sampling.carrier();
    if carrier == Carrier::Auto {
        let settings = Settings {
            method: args.methods[0],
            spp: args.spp.iter().copied().max().unwrap_or(1) as usize,
            shading_points: 1,
            brdf_samples,
            seed: args.sampling.seed,
            progress: false,
            shadows: !args.sampling.unshadowed,
            lights: args.sampling.lights(),
        };
        let choice = pool.install(|| plan::carrier::choose(scene, bvh, env, &settings, shading_points(args)));
        if let Some(c) = choice {
            eprintln!(
                "ppis: distant light: {} for every series ({} at {} spp: variance × cost {:.3e} by its cone, {:.3e} in the map)",
                if c.carrier == Carrier::Map { "carried by the environment map" } else { "sampled by its cone" },
                settings.method,
                settings.spp,
                c.scores[0],
                c.scores[1]
            );
            carrier = c.carrier;
        }
    }
    plan::carrier::apply(carrier, &mut scene.lights, env);
}

/// Renders the reference (`--reference-method` at `--reference-spp`, an independent seed),
/// writes it as reference.exr, and returns it with the report's note about it.
fn render_reference(
    args: &ReportArgs,
    pool: &rayon::ThreadPool,
    scene: &Scene,
    bvh: &Bvh,
    hierarchy: Option<&EnvHierarchy<'_>>,
    base: &Settings,
) -> Result<(Vec<[f32; 3]>, String)> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let spp = args.reference_spp as usize;
    let settings = Settings {
        method: args.reference_method,
        spp,
        shading_points: shading_points(args).resolve(
            args.reference_method,
            spp,
            Lighting::of(hierarchy.is_some(), scene.lights.len()),
        ),
        seed: args.sampling.seed ^ 0x0005_eed0_f4ef,
        progress: true,
        ..*base
    };
    eprintln!("ppis: rendering the reference ({}, {spp} spp)", args.reference_method);
    let image = pool.install(|| plan::render(scene, bvh, hierarchy, &settings));
    output::write_exr(&args.out.join("reference.exr"), w, h, &image.pixels)?;
    Ok((
        image.pixels,
        format!(
            "{} at {spp} spp (reference.exr, {:.1} s), independent seed",
            args.reference_method, image.render_seconds
        ),
    ))
}

/// Writes the CSV, report.md and the plot into `--out`.
fn write_outputs(
    args: &ReportArgs,
    scene: &str,
    measurements: &[report::Measurement],
    base: Series,
    threads: usize,
    note: &str,
) -> Result<()> {
    output::write_text(&args.out.join("error_vs_time.csv"), &report::csv(measurements))?;
    output::write_text(
        &args.out.join("report.md"),
        &report::markdown(scene, measurements, base, threads, &timing_note(note, args.repeat, args.clock)),
    )?;
    report::plot(
        &args.out.join("error_vs_time.svg"),
        &args.out.join("error_vs_time.png"),
        &format!("{scene}: relMSE against render time ({threads} threads)"),
        measurements,
    )
    .map_err(|e| anyhow::anyhow!("{}: cannot draw the plot: {e}", args.out.display()))?;
    eprintln!(
        "ppis: wrote error_vs_time.csv, error_vs_time.svg, error_vs_time.png and report.md in {}",
        args.out.display()
    );
    Ok(())
}

/// Writes the K sweep — relMSE at equal time against K — as error_vs_k.csv, .md, .svg and
/// .png into `--out`.
fn write_k_sweep(
    args: &ReportArgs,
    scene: &str,
    measurements: &[report::Measurement],
    reference_k: usize,
    threads: usize,
    note: &str,
) -> Result<()> {
    let Some(sweep) = KSweep::new(measurements, reference_k) else { return Ok(()) };
    output::write_text(&args.out.join("error_vs_k.csv"), &sweep.csv())?;
    let note = timing_note(note, args.repeat, args.clock);
    output::write_text(&args.out.join("error_vs_k.md"), &sweep.markdown(scene, threads, &note))?;
    report::plot_k(
        &args.out.join("error_vs_k.svg"),
        &args.out.join("error_vs_k.png"),
        &format!("{scene}: relMSE at equal time against K (each method's time at K = {reference_k})"),
        &sweep,
    )
    .map_err(|e| anyhow::anyhow!("{}: cannot draw the plot: {e}", args.out.display()))?;
    eprintln!("ppis: wrote error_vs_k.csv, error_vs_k.md, error_vs_k.svg and error_vs_k.png in {}", args.out.display());
    Ok(())
}

/// The report's reference note, and how renders were timed when more than once.
fn timing_note(reference: &str, repeat: u32, clock: Clock) -> String {
    let clock = match clock {
        Clock::Wall => "",
        Clock::Cpu => "; times: CPU seconds of the render threads",
    };
    let repeat = if repeat > 1 { format!("; times: the fastest of {repeat} runs") } else { String::new() };
    format!("{reference}{clock}{repeat}")
}

/// The report's shading points per pixel: `--samples-per-point`, else `--shading-points`, else
/// each method's rule.
fn shading_points(args: &ReportArgs) -> ShadingPoints {
    match (args.samples_per_point, args.sampling.shading_points) {
        (Some(v), _) => ShadingPoints::PerPoint(v as usize),
        (None, Some(p)) => ShadingPoints::Given(p as usize),
        (None, None) => ShadingPoints::Rule,
    }
}
