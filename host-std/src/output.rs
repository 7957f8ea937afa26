//! Writing results: linear float OpenEXR and a tone-mapped sRGB PNG beside it. Every file is
//! written to a temporary name in the same folder and renamed into place, so an error never
//! leaves a partial file behind.

use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error("{path}: cannot write: {message}")]
    Write { path: PathBuf, message: String },
}

fn temp_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(".partial");
    path.with_file_name(name)
}

/// Writes with `write` to a temporary file, then renames it over `path`.
fn atomically(path: &Path, write: impl FnOnce(&Path) -> Result<(), String>) -> Result<(), WriteError> {
    let tmp = temp_path(path);
    let result = write(&tmp).and_then(|()| std::fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if let Err(message) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(WriteError::Write { path: path.to_owned(), message });
    }
    Ok(())
}

/// Linear RGB as 32-bit float OpenEXR.
pub fn write_exr(path: &Path, width: usize, height: usize, pixels: &[[f32; 3]]) -> Result<(), WriteError> {
    atomically(path, |tmp| {
        exr::prelude::write_rgb_file(tmp, width, height, |x, y| {
            let p = pixels[y * width + x];
            (p[0], p[1], p[2])
        })
        .map_err(|e| e.to_string())
    })
}

/// Tone-mapped (extended Reinhard per channel, white point 4) sRGB PNG.
pub fn write_png(path: &Path, width: usize, height: usize, pixels: &[[f32; 3]]) -> Result<(), WriteError> {
    let bytes: Vec<u8> =
        pixels.iter().flat_map(|p| p.map(|c| (linear_to_srgb(tone_map(c)) * 255.0 + 0.5) as u8)).collect();
    atomically(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            &bytes,
            width as u32,
            height as u32,
            image::ColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())
    })
}

/// Extended Reinhard: c·(1 + c/W²)/(1 + c), W = 4; NaN and negatives go to 0.
pub fn tone_map(c: f32) -> f32 {
    let c = if c.is_nan() { 0.0 } else { c.max(0.0) };
    const W2: f32 = 16.0;
    (c * (1.0 + c / W2) / (1.0 + c)).min(1.0)
}

/// The sRGB transfer function.
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Writes `text` atomically (stats files, reports).
pub fn write_text(path: &Path, text: &str) -> Result<(), WriteError> {
    atomically(path, |tmp| std::fs::write(tmp, text).map_err(|e| e.to_string()))
}
