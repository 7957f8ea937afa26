//! Writing results: linear float OpenEXR and a tone-mapped sRGB PNG beside it. Every file is
//! written to a temporary name in the same folder and renamed into place, so an error never
//! leaves a partial file behind.

use crate::render::crop::Crop;
use std::path::{Path, PathBuf};

/// Why an output file cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The file cannot be written.
    #[error("{path}: cannot write: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
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

/// Linear RGB as 32-bit float OpenEXR, byte for byte the same for the same pixels: the tiles
/// are compressed in parallel but written in increasing order (the exr crate's default order,
/// "unspecified", writes them as they finish, so the file's bytes varied from run to run).
pub fn write_exr(path: &Path, width: usize, height: usize, pixels: &[[f32; 3]]) -> Result<(), WriteError> {
    write_exr_part(path, (width, height), Crop::full(width, height), pixels, None)
}

/// The header attribute that holds the render's settings (one text attribute: the exr crate
/// keeps custom attributes in a hash map and writes them in its order, so several would make
/// the file's bytes vary from run to run).
pub const SETTINGS_ATTRIBUTE: &str = "ppisRenderSettings";

/// Linear RGB of `crop` of a `frame` (width, height) as 32-bit float OpenEXR: the data window
/// is the crop, the display window the frame; `settings` goes into the header as
/// [`SETTINGS_ATTRIBUTE`] (Latin-1 text: escape anything else). Byte for byte the same for the same arguments, as [`write_exr`].
pub fn write_exr_part(
    path: &Path,
    frame: (usize, usize),
    crop: Crop,
    pixels: &[[f32; 3]],
    settings: Option<&str>,
) -> Result<(), WriteError> {
    use exr::prelude::*;
    let width = crop.width();
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p: [f32; 3] = pixels[y * width + x];
        (p[0], p[1], p[2])
    });
    let encoding = Encoding { line_order: LineOrder::Increasing, ..Encoding::FAST_LOSSLESS };
    let mut attributes = LayerAttributes { layer_position: Vec2(crop.x0 as i32, crop.y0 as i32), ..Default::default() };
    if let Some(text) = settings {
        let Some(text) = Text::new_or_none(text) else {
            return Err(WriteError::Write { path: path.to_owned(), message: "settings beyond Latin-1".into() });
        };
        attributes.other.insert(Text::from(SETTINGS_ATTRIBUTE), AttributeValue::Text(text));
    }
    let layer = Layer::new((width, crop.height()), attributes, encoding, channels);
    let display = IntegerBounds::new((0, 0), frame);
    atomically(path, |tmp| {
        Image::new(ImageAttributes::new(display), layer).write().to_file(tmp).map_err(|e| e.to_string())
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_exr_is_written_byte_for_byte_the_same_and_reads_back_exactly() {
        let (w, h) = (300, 200); // 5 × 4 tiles of 64², compressed in parallel
        let pixels: Vec<[f32; 3]> = (0..w * h)
            .map(|i| [(i % 977) as f32 * 0.37, (i / w) as f32 / 7.0, if i % 13 == 0 { 1e5 } else { 0.0 }])
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let files: Vec<Vec<u8>> = (0..4)
            .map(|k| {
                let path = dir.path().join(format!("{k}.exr"));
                write_exr(&path, w, h, &pixels).unwrap();
                std::fs::read(path).unwrap()
            })
            .collect();
        assert!(files.iter().all(|f| f == &files[0]), "the same pixels made different files");
        let image = exr::prelude::read_first_rgba_layer_from_file(
            dir.path().join("0.exr"),
            |size, _| vec![[0.0f32; 3]; size.0 * size.1],
            move |px: &mut Vec<[f32; 3]>, pos, (r, g, b, _a): (f32, f32, f32, f32)| px[pos.1 * w + pos.0] = [r, g, b],
        )
        .unwrap();
        assert!(image.layer_data.channel_data.pixels == pixels);
    }
}
