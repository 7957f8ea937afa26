//! A UsdLux RectLight's `texture:file` as emitters: the rectangle cut into one rectangle per
//! cell of the image, each emitting the light's radiance times its cell's mean texel. Up to
//! [`MAX_CELLS`] texels along a side a cell is one texel, so the light emits the image exactly
//! (nearest texel, as Pixar's HdEmbree looks it up; why not bilinear: docs/usd.md, "RectLight");
//! a larger image is box-filtered down to that many cells. Each cell is an
//! ordinary rectangle light, sampled by solid angle and picked by its power, so the texture
//! steers light selection and the estimates stay unbiased; cells of a black texel emit
//! nothing and are left out.

use crate::light::image_file::{self, RgbImage};
use host_usd::lights::RectTexture;
use sampler_core::glam::Vec3;
use sampler_core::light::{LightError, RectLight, SceneLight, Shaping};
use std::path::Path;

/// The most cells along either side of a textured rectangle.
pub const MAX_CELLS: usize = 128;

/// Decodes the texture of a RectLight (its name gives the format).
pub(crate) fn decode(t: &RectTexture) -> Result<RgbImage, String> {
    let name = crate::scene::usd::texture_name(&t.name);
    image_file::load_bytes(Path::new(&name), &t.bytes).map_err(|e| e.to_string())
}

/// The mean texel of columns `cols` and rows `rows` of `image`.
fn cell_mean(image: &RgbImage, cols: std::ops::Range<usize>, rows: std::ops::Range<usize>) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for y in rows.clone() {
        for x in cols.clone() {
            sum += Vec3::from_array(image.texels[y * image.width + x]);
        }
    }
    sum / (cols.len() * rows.len()) as f32
}

/// The cells of `texture` on the rectangle whose front normal is `front`, each emitting
/// `radiance` times its mean texel and shaped by `shaping`, pushed onto `out`; how many.
pub(crate) fn push_cells(
    t: &RectTexture,
    image: &RgbImage,
    front: Vec3,
    radiance: Vec3,
    shaping: Shaping,
    out: &mut Vec<SceneLight>,
) -> Result<usize, LightError> {
    let (nx, ny) = (image.width.min(MAX_CELLS), image.height.min(MAX_CELLS));
    let (a, b) = (t.across / nx as f32, t.down / ny as f32);
    let (e1, e2) = if a.cross(b).dot(front) >= 0.0 { (a, b) } else { (b, a) };
    let mut pushed = 0;
    for j in 0..ny {
        let rows = j * image.height / ny..(j + 1) * image.height / ny;
        for i in 0..nx {
            let cols = i * image.width / nx..(i + 1) * image.width / nx;
            let l = radiance * cell_mean(image, cols, rows.clone());
            if l.max_element() <= 0.0 {
                continue;
            }
            let p0 = t.corner + a * i as f32 + b * j as f32;
            out.push(RectLight::new(p0, e1, e2, l)?.with_shaping(shaping).into());
            pushed += 1;
        }
    }
    Ok(pushed)
}
