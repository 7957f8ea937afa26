//! The image in 16×16 tiles over rayon's threads, each tile with its own scratch (and so its
//! own kept samplers), put together in a fixed order whatever the thread count. A crop renders
//! every tile it meets from the tile's first pixel, as the whole frame does, and keeps the pixels
//! inside it: a pixel's value depends on the tile's earlier pixels (the samplers they leave
//! behind), so the crop's pixels are the frame's bit for bit.

use crate::render::crop::Crop;
use crate::render::pixel::{Scratch, pixel};
use crate::render::{Context, Counters};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Tile edge, in pixels.
pub const TILE: usize = 16;

/// A rendered image (the crop's pixels) and what rendering it did.
pub struct Image {
    /// Width in pixels (the crop's).
    pub width: usize,
    /// Height in pixels (the crop's).
    pub height: usize,
    /// Where the pixels are in the frame.
    pub crop: Crop,
    /// Linear RGB, rows top to bottom.
    pub pixels: Vec<[f32; 3]>,
    /// What the render did.
    pub counters: Counters,
}

/// Renders the pixels of `crop`, inside the frame (every tile that meets it, whole). `start` is
/// when the caller's clock started: the progress bar shows once a second has passed since (and
/// `ctx.options.progress` asks for it).
pub fn render_tiles(ctx: &Context<'_, '_>, crop: Crop, start: Instant) -> Image {
    let (w, h) = (ctx.camera.width as usize, ctx.camera.height as usize);
    let tiles: Vec<(usize, usize)> = (crop.y0 / TILE..crop.y1.div_ceil(TILE))
        .flat_map(|ty| (crop.x0 / TILE..crop.x1.div_ceil(TILE)).map(move |tx| (tx, ty)))
        .collect();
    let bar = ProgressBar::with_draw_target(Some(tiles.len() as u64), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{wide_bar}] {percent}% ETA {eta}").expect("valid template"),
    );
    let shown = AtomicBool::new(false);
    let results: Vec<(Vec<[f32; 3]>, Counters)> = tiles
        .par_iter()
        .map(|&(tx, ty)| {
            let mut scratch = Scratch::new(ctx.scene.materials.len(), ctx.options.shading_points);
            let mut out = Vec::with_capacity(TILE * TILE);
            for y in ty * TILE..((ty + 1) * TILE).min(h) {
                for x in tx * TILE..((tx + 1) * TILE).min(w) {
                    out.push(pixel(ctx, x, y, &mut scratch));
                }
            }
            if ctx.options.progress && start.elapsed().as_secs_f64() > 1.0 && !shown.swap(true, Ordering::Relaxed) {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
            bar.inc(1);
            (out, scratch.counters)
        })
        .collect();
    bar.finish_and_clear();
    let (cw, ch) = (crop.width(), crop.height());
    let mut pixels = vec![[0.0f32; 3]; cw * ch];
    let mut counters = Counters::default();
    for (&(tx, ty), (tile, c)) in tiles.iter().zip(&results) {
        counters += *c;
        let mut k = 0;
        for y in ty * TILE..((ty + 1) * TILE).min(h) {
            for x in tx * TILE..((tx + 1) * TILE).min(w) {
                if crop.contains(x, y) {
                    pixels[(y - crop.y0) * cw + x - crop.x0] = tile[k];
                }
                k += 1;
            }
        }
    }
    Image { width: cw, height: ch, crop, pixels, counters }
}
