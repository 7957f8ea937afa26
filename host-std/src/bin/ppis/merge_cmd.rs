//! `ppis merge`: a frame from the tiles `ppis render --crop` wrote, checked to be of one render
//! and to hold every pixel once; the same bytes as the frame rendered in one process.

use anyhow::{Result, bail};
use clap::Args;
use host_std::merge::{Part, merge, read_part};
use host_std::output;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct MergeArgs {
    /// The tiles (EXR files written by `ppis render --crop`), in any order.
    #[arg(required = true, value_name = "TILE.exr")]
    tiles: Vec<PathBuf>,
    /// The frame's EXR; its PNG is written beside it.
    #[arg(short = 'o', long = "output", value_name = "FRAME.exr")]
    output: PathBuf,
}

pub(crate) fn merge_command(args: MergeArgs) -> Result<()> {
    let out = &args.output;
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!("{}: the output is an OpenEXR file and must end in .exr (the PNG is written beside it)", out.display());
    }
    let dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        bail!("{}: the output folder does not exist", out.display());
    }
    let parts: Vec<(PathBuf, Part)> =
        args.tiles.iter().map(|path| Ok((path.clone(), read_part(path)?))).collect::<Result<_>>()?;
    let frame = merge(&parts)?;
    let (w, h) = frame.frame;
    output::write_exr_part(out, frame.frame, frame.crop, &frame.pixels, Some(&frame.settings))?;
    output::write_png(&out.with_extension("png"), w, h, &frame.pixels)?;
    eprintln!("ppis: merged {} tiles into the {w}×{h} frame {}", parts.len(), out.display());
    Ok(())
}
