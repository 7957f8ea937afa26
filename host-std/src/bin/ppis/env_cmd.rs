//! `ppis env`: the equal-area map `ppis render --env` builds from a lat-long map, written once
//! as a float32 OpenEXR square, so that a farm's tile processes read it instead of each
//! resampling the lat-long map again. `--env SQUARE.exr` then renders the same pixels as
//! `--env LATLONG`: the square holds the resampled texels exactly (float32, lossless), loading a
//! square power-of-two map takes its texels as they are, and `--env-scale` and `--env-rotate-y`
//! are applied after resampling and at lookup, so none of them is baked into the file.

use anyhow::{Context, Result, bail};
use clap::Args;
use host_std::light::environment::{EnvSource, Environment, Placement};
use host_std::output;
use std::path::PathBuf;

#[derive(Args)]
pub(crate) struct EnvArgs {
    /// The environment map: lat-long (.exr/.hdr/.png/.jpg), as `ppis render --env` takes it.
    #[arg(value_name = "SRC")]
    source: PathBuf,
    /// The equal-area square, float32 OpenEXR (for `ppis render --env`).
    #[arg(short = 'o', long = "output", value_name = "SQUARE.exr")]
    output: PathBuf,
    /// Worker threads for the resampling (default: all cores).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=256))]
    threads: Option<u32>,
}

pub(crate) fn env_command(args: EnvArgs) -> Result<()> {
    let out = &args.output;
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!("{}: the equal-area map is written as OpenEXR and must end in .exr", out.display());
    }
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    if !dir.is_dir() {
        bail!("{}: the output folder does not exist", out.display());
    }
    if !args.source.exists() {
        bail!("{}: environment map not found", args.source.display());
    }
    let threads =
        args.threads.map_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()), |t| t as usize);
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().context("cannot start the worker threads")?;
    // The default placement: scale, tint and rotation stay the render's to apply.
    let env = pool.install(|| Environment::build(&EnvSource::File(args.source.clone()), Placement::default()))?;
    if env.stats.sanitized > 0 {
        eprintln!(
            "ppis: warning: {}: {} texels were NaN, infinite or negative and were set to 0",
            env.stats.source, env.stats.sanitized
        );
    }
    let n = 1usize << env.level;
    output::write_exr(out, n, n, &env.rgb)?;
    eprintln!(
        "ppis: wrote the {n}×{n} equal-area map of {} ({}×{}) to {} ({:.2} s to build)",
        env.stats.source,
        env.stats.source_size.0,
        env.stats.source_size.1,
        out.display(),
        env.stats.build_seconds
    );
    Ok(())
}
