//! `ppis`: render scenes with product importance sampling of environment light.
//! Every failure prints one line naming the file or option and exits with status 2.

use clap::{Parser, Subcommand};

mod args;
mod env_cmd;
mod info_cmd;
mod load;
mod merge_cmd;
mod provenance;
mod render_cmd;
mod report_cmd;
mod stats;
mod tiles_cmd;

use env_cmd::{EnvArgs, env_command};
use info_cmd::{InfoArgs, info_command};
use merge_cmd::{MergeArgs, merge_command};
use render_cmd::{RenderArgs, render_command};
use report_cmd::{ReportArgs, report_command};
use tiles_cmd::{TilesArgs, tiles_command};

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
    /// Print the crops (x0,y0,x1,y1, one per line) that split a frame into tiles, for
    /// `ppis render --crop` on a render farm.
    Tiles(TilesArgs),
    /// Assemble the tiles `ppis render --crop` wrote into the frame (EXR + PNG): the same bytes
    /// as the frame rendered in one process.
    Merge(MergeArgs),
    /// Write the equal-area map `render --env` builds from a lat-long map, as a float32 EXR
    /// square that `render --env` reads without resampling (the same pixels): built once for
    /// all of a farm's tiles.
    Env(EnvArgs),
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
                    "no command given: render, info, report, tiles, merge or env (see ppis --help)".to_string()
                }
                _ => {
                    let text = e.render().to_string();
                    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
                    let mut first = lines.next().unwrap_or_default().trim_start_matches("error: ").to_string();
                    // "the following required arguments were not provided:" lists them below.
                    if first.ends_with(':') {
                        let named: Vec<&str> = lines.take_while(|l| !l.starts_with("Usage:")).collect();
                        first = format!("{} {}", first, named.join(", "));
                    }
                    format!("{first} (see --help)")
                }
            };
            eprintln!("ppis: error: {line}");
            std::process::exit(2);
        }
    }
}

fn main() {
    refuse_a_cpu_the_build_cannot_run_on();
    end_quietly_on_a_closed_pipe();
    one_malloc_arena();
    let cli = parse_command_line();
    let result = match cli.command {
        Command::Render(args) => render_command(args),
        Command::Info(args) => info_command(args),
        Command::Report(args) => report_command(args),
        Command::Tiles(args) => tiles_command(args),
        Command::Merge(args) => merge_command(args),
        Command::Env(args) => env_command(args),
    };
    if let Err(e) = result {
        eprintln!("ppis: error: {e:#}");
        std::process::exit(2);
    }
}

/// A build that assumes instruction-set extensions throughout (x86-64 builds assume
/// x86-64-v3: `.cargo/config.toml`) would stop at its first such instruction on a CPU without
/// them; it says so in one line instead, first thing.
fn refuse_a_cpu_the_build_cannot_run_on() {
    if let Some(feature) = sampler_core::cpu::missing_build_feature() {
        let feature = feature.to_string_lossy();
        eprintln!(
            "ppis: error: this ppis is built for CPUs with {feature} (`-C target-cpu` in .cargo/config.toml) and this \
             CPU lacks it; build it for any x86-64 with RUSTFLAGS=\"-C target-cpu=x86-64\""
        );
        std::process::exit(2);
    }
}

/// glibc's malloc gives each thread that allocates an arena of its own, and memory freed
/// in one arena serves only later requests made in it. The usda parser runs on a thread of
/// its own (for its stack), so the small blocks it frees while it builds a layer stayed
/// unused holes beside the layer while the import, on the main thread, took fresh pages: a
/// tenth to a sixth of a large usda import's peak (docs/usd.md, "Import speed"). One arena
/// lets the import fill them; each thread's malloc cache still serves most small requests
/// without the arena's lock.
fn one_malloc_arena() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: a malloc parameter set before any other thread exists.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
    }
}

/// A reader that stops early (`ppis info | head`) ends the process as it ends C tools, by the
/// default SIGPIPE, instead of making the next print panic (Rust ignores SIGPIPE and turns the
/// write's error into a panic in `println!`).
fn end_quietly_on_a_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: restoring a signal's default disposition, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
