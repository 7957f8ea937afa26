//! Assembling a frame from parts rendered apart (`ppis merge`): each part is an OpenEXR file
//! whose data window is its crop, whose display window is the frame, and whose header holds the
//! render's settings ([`crate::output::SETTINGS_ATTRIBUTE`]). The parts must be of one frame,
//! rendered with the same settings, and hold every pixel of it exactly once; the frame then
//! holds the same pixels, and written with the same settings the same bytes, as a render of the
//! whole frame in one process.

use crate::output::SETTINGS_ATTRIBUTE;
use crate::render::crop::Crop;
use std::path::{Path, PathBuf};

/// A part of a frame, read back.
#[derive(Clone, Debug)]
pub struct Part {
    /// The frame's (display window's) width and height.
    pub frame: (usize, usize),
    /// Where the pixels are in the frame (the data window).
    pub crop: Crop,
    /// The render's settings, as the header holds them.
    pub settings: String,
    /// Linear RGB of the crop, rows top to bottom.
    pub pixels: Vec<[f32; 3]>,
}

/// Why parts do not make a frame. Each names the file(s) concerned.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// Not a readable RGB OpenEXR file (missing, truncated, other channels).
    #[error("{path}: cannot read as an OpenEXR tile: {message}")]
    Read {
        /// The file.
        path: PathBuf,
        /// What the reader said.
        message: String,
    },
    /// No settings attribute: not written by `ppis render`.
    #[error("{path}: not a tile of a ppis render (its header has no {SETTINGS_ATTRIBUTE} attribute)")]
    NotPpis {
        /// The file.
        path: PathBuf,
    },
    /// The data window reaches outside the display window.
    #[error("{path}: its data window {crop} is not inside its {}×{} display window", frame.0, frame.1)]
    Outside {
        /// The file.
        path: PathBuf,
        /// Its data window.
        crop: Crop,
        /// Its display window's size.
        frame: (usize, usize),
    },
    /// Another frame size, or other settings, than the first part's.
    #[error("{path}: a tile of another render than {first} ({detail})")]
    OtherRender {
        /// The file.
        path: PathBuf,
        /// The first part's file.
        first: PathBuf,
        /// The first difference.
        detail: String,
    },
    /// Two parts hold the same pixels.
    #[error("{a} and {b} overlap (pixels {crop})")]
    Overlap {
        /// One part.
        a: PathBuf,
        /// The other.
        b: PathBuf,
        /// The pixels both hold.
        crop: Crop,
    },
    /// Pixels of the frame in no part.
    #[error("{missing} of the frame's {total} pixels are in no tile (the first at x {x}, y {y})")]
    Missing {
        /// How many.
        missing: usize,
        /// The frame's pixels.
        total: usize,
        /// The first missing pixel's column.
        x: usize,
        /// Its row.
        y: usize,
    },
}

/// Reads a part written by [`crate::output::write_exr_part`].
pub fn read_part(path: &Path) -> Result<Part, MergeError> {
    use exr::prelude::{AttributeValue, ReadChannels, ReadLayers, RgbChannels, Text, Vec2, read};
    let fail = |message: String| MergeError::Read { path: path.to_owned(), message };
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size: Vec2<usize>, _: &RgbChannels| (size.0, vec![[0.0f32; 3]; size.0 * size.1]),
            |px: &mut (usize, Vec<[f32; 3]>), at: Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                px.1[at.1 * px.0 + at.0] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .pedantic()
        .from_file(path)
        .map_err(|e| fail(e.to_string()))?;
    let display = image.attributes.display_window;
    let layer = &image.layer_data;
    let settings = match layer.attributes.other.get(&Text::from(SETTINGS_ATTRIBUTE)) {
        Some(AttributeValue::Text(text)) => text.to_string(),
        _ => return Err(MergeError::NotPpis { path: path.to_owned() }),
    };
    let (x0, y0) = (layer.attributes.layer_position.0, layer.attributes.layer_position.1);
    let frame = (display.size.0, display.size.1);
    let inside = display.position == Vec2(0, 0) && x0 >= 0 && y0 >= 0;
    let crop = Crop {
        x0: x0.max(0) as usize,
        y0: y0.max(0) as usize,
        x1: x0.max(0) as usize + layer.size.0,
        y1: y0.max(0) as usize + layer.size.1,
    };
    if !inside || crop.x1 > frame.0 || crop.y1 > frame.1 {
        return Err(MergeError::Outside { path: path.to_owned(), crop, frame });
    }
    Ok(Part { frame, crop, settings, pixels: image.layer_data.channel_data.pixels.1.clone() })
}

/// The frame the parts make, with the first part's settings; `parts` is (file, part) in any
/// order, at least one.
pub fn merge(parts: &[(PathBuf, Part)]) -> Result<Part, MergeError> {
    let (first_path, first) = &parts[0];
    for (path, part) in &parts[1..] {
        if let Some(detail) = difference(first, part) {
            return Err(MergeError::OtherRender { path: path.clone(), first: first_path.clone(), detail });
        }
    }
    for (i, (a, pa)) in parts.iter().enumerate() {
        for (b, pb) in &parts[i + 1..] {
            if let Some(crop) = pa.crop.intersection(&pb.crop) {
                return Err(MergeError::Overlap { a: a.clone(), b: b.clone(), crop });
            }
        }
    }
    let (w, h) = first.frame;
    let mut pixels = vec![[0.0f32; 3]; w * h];
    let mut covered = vec![false; w * h];
    for (_, part) in parts {
        let c = part.crop;
        for y in c.y0..c.y1 {
            let row = &part.pixels[(y - c.y0) * c.width()..(y - c.y0 + 1) * c.width()];
            pixels[y * w + c.x0..y * w + c.x1].copy_from_slice(row);
            covered[y * w + c.x0..y * w + c.x1].fill(true);
        }
    }
    let missing = covered.iter().filter(|c| !**c).count();
    if let Some(first_missing) = covered.iter().position(|c| !c) {
        return Err(MergeError::Missing { missing, total: w * h, x: first_missing % w, y: first_missing / w });
    }
    Ok(Part { frame: first.frame, crop: Crop::full(w, h), settings: first.settings.clone(), pixels })
}

/// How `b` differs from `a` in frame or settings (the first differing setting), if it does.
fn difference(a: &Part, b: &Part) -> Option<String> {
    if a.frame != b.frame {
        return Some(format!("a {}×{} frame against {}×{}", b.frame.0, b.frame.1, a.frame.0, a.frame.1));
    }
    if a.settings == b.settings {
        return None;
    }
    let (la, lb): (Vec<&str>, Vec<&str>) = (a.settings.lines().collect(), b.settings.lines().collect());
    let at = (0..la.len().max(lb.len())).find(|&i| la.get(i) != lb.get(i)).unwrap_or(0);
    Some(format!("{} against {}", lb.get(at).unwrap_or(&"nothing"), la.get(at).unwrap_or(&"nothing")))
}
