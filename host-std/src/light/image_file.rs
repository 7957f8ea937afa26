//! Loading environment images: OpenEXR (the `exr` crate), Radiance HDR, PNG and JPEG (the
//! `image` crate). Every failure names the file and the problem; NaN, ±Inf and negative texels
//! are replaced by 0 and counted, never propagated.

use std::path::{Path, PathBuf};

/// A loaded image: linear RGB, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// Linear RGB, row by row.
    pub texels: Vec<[f32; 3]>,
    /// Texels that held NaN, ±Inf or negative values and were set to 0.
    pub sanitized: usize,
}

/// Why an image cannot be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file cannot be read.
    #[error("{path}: cannot read the file: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The file is not valid in its format.
    #[error("{path}: not a readable {format} image: {message}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// The format it was read as.
        format: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The image has no pixels.
    #[error("{path}: the image is empty (zero width or height)")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// The file's extension names no format this build reads.
    #[error("{path}: unsupported image format (expected .exr, .hdr, .png, .jpg, .jpeg or .tga)")]
    Unsupported {
        /// The file.
        path: PathBuf,
    },
    /// The format's cargo feature was left out of this build.
    #[error("{path}: support for {format} images was left out of this build (cargo feature `{feature}`)")]
    FeatureDisabled {
        /// The file.
        path: PathBuf,
        /// The format it was read as.
        format: &'static str,
        /// The cargo feature.
        feature: &'static str,
    },
    /// The image is larger than the renderer accepts.
    #[error("{path}: the image is {width}×{height}, larger than the 32768×16384 this renderer accepts")]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// The header's size cannot fit in the file.
    #[error("{path}: the header claims {width}×{height} pixels, more than a file of {bytes} bytes can hold")]
    Implausible {
        /// The file.
        path: PathBuf,
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
        /// The file's size in bytes.
        bytes: usize,
    },
}

const MAX_WIDTH: usize = 32_768;
const MAX_HEIGHT: usize = 16_384;

/// Loads an image by its extension.
pub fn load(path: &Path) -> Result<RgbImage, LoadError> {
    let bytes = std::fs::read(path).map_err(|error| LoadError::Io { path: path.to_owned(), error })?;
    load_bytes(path, &bytes)
}

/// Decodes the bytes of an image file; `path` gives the format (by extension) and names the
/// file in errors.
pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<RgbImage, LoadError> {
    load_bytes_as(path, bytes, None)
}

/// [`load_bytes`] with the encoding of 8- and 16-bit images forced: `Some(true)` sRGB,
/// `Some(false)` linear data (a roughness map); `None` sRGB for 8/16-bit, linear for float.
pub fn load_bytes_as(path: &Path, bytes: &[u8], srgb: Option<bool>) -> Result<RgbImage, LoadError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    match ext.as_str() {
        "exr" => load_exr(path, bytes),
        "hdr" => load_with_image(path, bytes, "Radiance HDR", image_format("hdr", path)?, srgb),
        "png" => load_with_image(path, bytes, "PNG", image::ImageFormat::Png, srgb),
        "jpg" | "jpeg" => load_with_image(path, bytes, "JPEG", image_format("jpeg", path)?, srgb),
        "tga" => load_with_image(path, bytes, "TGA", image_format("tga", path)?, srgb),
        _ => Err(LoadError::Unsupported { path: path.to_owned() }),
    }
}

fn image_format(which: &'static str, path: &Path) -> Result<image::ImageFormat, LoadError> {
    match which {
        #[cfg(feature = "hdr")]
        "hdr" => Ok(image::ImageFormat::Hdr),
        #[cfg(feature = "jpeg")]
        "jpeg" => Ok(image::ImageFormat::Jpeg),
        #[cfg(feature = "tga")]
        "tga" => Ok(image::ImageFormat::Tga),
        _ => Err(LoadError::FeatureDisabled {
            path: path.to_owned(),
            format: match which {
                "hdr" => "Radiance HDR",
                "tga" => "TGA",
                _ => "JPEG",
            },
            feature: which,
        }),
    }
}

fn finish(path: &Path, width: usize, height: usize, mut texels: Vec<[f32; 3]>) -> Result<RgbImage, LoadError> {
    if width == 0 || height == 0 {
        return Err(LoadError::Empty { path: path.to_owned() });
    }
    let sanitized = sampler_core::env::sanitize_rgb(&mut texels);
    Ok(RgbImage { width, height, texels, sanitized })
}

/// Checks a header's size before any pixel storage is allocated from it: non-empty, within the
/// largest map we accept, and no larger than the file could hold — decoded RGB of at most 1000×
/// the file's bytes (beyond any compression real maps reach), or 64 MB, whichever is more.
fn check_size(path: &Path, width: usize, height: usize, file_bytes: usize) -> Result<(), LoadError> {
    if width == 0 || height == 0 {
        return Err(LoadError::Empty { path: path.to_owned() });
    }
    if width > MAX_WIDTH || height > MAX_HEIGHT {
        return Err(LoadError::TooLarge { path: path.to_owned(), width, height });
    }
    let decoded = width.saturating_mul(height).saturating_mul(12);
    if decoded > (1000 * file_bytes).max(64 << 20) {
        return Err(LoadError::Implausible { path: path.to_owned(), width, height, bytes: file_bytes });
    }
    Ok(())
}

fn load_exr(path: &Path, bytes: &[u8]) -> Result<RgbImage, LoadError> {
    use exr::prelude::*;
    let decode = |message: String| LoadError::Decode { path: path.to_owned(), format: "OpenEXR", message };
    // Check the header's size before any pixel storage is allocated from it.
    let meta = MetaData::read_from_buffered(std::io::Cursor::new(bytes), false).map_err(|e| decode(e.to_string()))?;
    let header = meta.headers.first().ok_or_else(|| decode("no image layer".into()))?;
    let size = header.layer_size;
    check_size(path, size.width(), size.height(), bytes.len())?;
    let image = read_first_rgba_layer_from_file_bytes(bytes, size).map_err(|e| decode(e.to_string()))?;
    let (width, height) = (size.width(), size.height());
    finish(path, width, height, image)
}

/// Reads the first RGB(A) layer into a texel vector (alpha ignored; missing channels are 0,
/// a single luminance channel becomes grey).
fn read_first_rgba_layer_from_file_bytes(
    bytes: &[u8],
    size: exr::prelude::Vec2<usize>,
) -> exr::error::Result<Vec<[f32; 3]>> {
    use exr::prelude::*;
    let width = size.width();
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            move |resolution, _| vec![[0.0f32; 3]; resolution.width() * resolution.height()],
            move |texels: &mut Vec<[f32; 3]>, position, (r, g, b, _a): (f32, f32, f32, f32)| {
                texels[position.y() * width + position.x()] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))?;
    Ok(image.layer_data.channel_data.pixels)
}

fn load_with_image(
    path: &Path,
    bytes: &[u8],
    name: &'static str,
    format: image::ImageFormat,
    srgb_override: Option<bool>,
) -> Result<RgbImage, LoadError> {
    let decode = |message: String| LoadError::Decode { path: path.to_owned(), format: name, message };
    // The decoders refuse sizes beyond the largest map we accept; `check_size` then bounds the
    // header by what the file can hold, before any pixel storage is allocated.
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_WIDTH as u32);
    limits.max_image_height = Some(MAX_HEIGHT as u32);
    let reader = |limits: image::Limits| {
        let mut r = image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
        r.limits(limits);
        r
    };
    let (w, h) = reader(limits.clone()).into_dimensions().map_err(|e| decode(e.to_string()))?;
    check_size(path, w as usize, h as usize, bytes.len())?;
    let decoded = reader(limits).decode().map_err(|e| decode(e.to_string()))?;
    let float = matches!(format, image::ImageFormat::Hdr)
        || matches!(decoded, image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_));
    let srgb = srgb_override.unwrap_or(!float);
    let rgb = decoded.into_rgb32f();
    let (width, height) = (rgb.width() as usize, rgb.height() as usize);
    // 8- and 16-bit images are sRGB-encoded: decode to linear radiance.
    let texels =
        rgb.pixels()
            .map(|p| {
                if srgb {
                    [srgb_to_linear(p[0]), srgb_to_linear(p[1]), srgb_to_linear(p[2])]
                } else {
                    [p[0], p[1], p[2]]
                }
            })
            .collect();
    finish(path, width, height, texels)
}

/// The sRGB transfer function, inverted.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}
