//! `ppis tiles`: the crops a farm splits a frame into, one `x0,y0,x1,y1` per line, for job
//! scripts to pass to `ppis render --crop` (and then `ppis merge`).

use crate::args::SceneArgs;
use crate::load::load_scene;
use anyhow::{Result, bail};
use clap::Args;
use host_std::render::crop::Crop;
use host_std::render::tiles::TILE;

#[derive(Args)]
#[command(group = clap::ArgGroup::new("split").required(true).args(["count", "size"]))]
pub(crate) struct TilesArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Image width, overriding the scene's camera (as `ppis render --width`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Image height, overriding the scene's camera (as `ppis render --height`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// Split into N tiles: the grid of N whose tiles are the most nearly square.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=65536))]
    count: Option<u32>,
    /// Split into tiles of S×S pixels (smaller at the right and bottom edges).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    size: Option<u32>,
    /// Print only tile I (counting from 0), as a job's task index names it.
    #[arg(long, value_name = "I")]
    index: Option<usize>,
}

pub(crate) fn tiles_command(args: TilesArgs) -> Result<()> {
    let loaded = load_scene(&args.scene, (args.width, args.height), true)?;
    let camera = &loaded.scene.camera;
    let w = args.width.unwrap_or(camera.width) as usize;
    let h = args.height.unwrap_or(camera.height) as usize;
    // Edges on the renderer's tile edges, so that no 16×16 render tile is rendered twice.
    let crops = match (args.count, args.size) {
        (Some(n), _) => match Crop::split(w, h, n as usize, TILE) {
            Some(crops) => crops,
            None => bail!("--count {n}: more tiles than the {w}×{h} frame has rows or columns for"),
        },
        (None, Some(s)) => Crop::squares(w, h, s as usize),
        (None, None) => unreachable!("clap requires --count or --size"),
    };
    match args.index {
        Some(i) if i >= crops.len() => {
            bail!("--index {i}: the frame has {} tiles (0 to {})", crops.len(), crops.len() - 1)
        }
        Some(i) => println!("{}", crops[i]),
        None => crops.iter().for_each(|c| println!("{c}")),
    }
    Ok(())
}
