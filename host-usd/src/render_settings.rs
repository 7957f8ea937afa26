//! UsdRenderSettings: the image a stage asks to be rendered. The settings prim is the one the
//! caller names, else the root layer's `renderSettingsPrimPath`, else the stage's only
//! RenderSettings prim. Its first RenderProduct's authored `resolution`, `pixelAspectRatio`,
//! `aspectRatioConformPolicy` and `camera` override the settings' own (UsdRenderSettingsBase
//! is shared by both and a product is the more specific), as Hydra renderers read them.

use crate::stage::{PrimPath, Stage, Value};

/// How the camera's aperture is fitted to an image of another aspect ratio
/// (`aspectRatioConformPolicy`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Conform {
    /// Grow the aperture in the direction that is too short (the schema's fallback).
    #[default]
    ExpandAperture,
    /// Shrink the aperture in the direction that is too long.
    CropAperture,
    /// Change the horizontal aperture to fit the image's aspect.
    AdjustApertureWidth,
    /// Change the vertical aperture to fit the image's aspect.
    AdjustApertureHeight,
    /// Keep both apertures and change the pixel aspect ratio instead.
    AdjustPixelAspectRatio,
}

impl Conform {
    fn from_token(t: &str) -> Option<Self> {
        Some(match t {
            "expandAperture" => Self::ExpandAperture,
            "cropAperture" => Self::CropAperture,
            "adjustApertureWidth" => Self::AdjustApertureWidth,
            "adjustApertureHeight" => Self::AdjustApertureHeight,
            "adjustPixelAspectRatio" => Self::AdjustPixelAspectRatio,
            _ => return None,
        })
    }

    /// The apertures (horizontal, vertical) and pixel aspect ratio that fit an aperture of
    /// `aperture` to an image of `width` × `height` pixels of aspect `pixel_aspect`.
    pub fn apply(self, aperture: (f32, f32), width: u32, height: u32, pixel_aspect: f32) -> (f32, f32, f32) {
        let (h, v) = aperture;
        let image = width as f32 * pixel_aspect / height as f32;
        let wide = h / v > image;
        match self {
            Self::ExpandAperture if wide => (h, h / image, pixel_aspect),
            Self::ExpandAperture => (v * image, v, pixel_aspect),
            Self::CropAperture if wide => (v * image, v, pixel_aspect),
            Self::CropAperture => (h, h / image, pixel_aspect),
            Self::AdjustApertureWidth => (v * image, v, pixel_aspect),
            Self::AdjustApertureHeight => (h, h / image, pixel_aspect),
            Self::AdjustPixelAspectRatio => (h, v, (h / v) * height as f32 / width as f32),
        }
    }
}

/// The render settings that apply to a stage.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// The RenderSettings prim.
    pub path: String,
    /// Image size in pixels.
    pub resolution: (u32, u32),
    /// Pixel width over pixel height.
    pub pixel_aspect: f32,
    /// How the camera's aperture is fitted to the image's aspect.
    pub conform: Conform,
    /// The camera to render through, when the settings name one.
    pub camera: Option<String>,
}

/// The schema's fallback resolution.
const FALLBACK_RESOLUTION: (u32, u32) = (2048, 1080);
/// Largest image side accepted from a file (the command line's own limit).
const MAX_SIDE: f64 = 16384.0;

/// The settings prim to use (see the module docs), `None` when the stage has none, with a
/// note when the choice is not the stage's own unambiguous one. Only a prim the caller names
/// explicitly must exist; the stage's metadata naming none is a note.
fn settings_prim(
    stage: &Stage,
    all: &[PrimPath],
    wanted: Option<&str>,
) -> Result<(Option<PrimPath>, Option<String>), String> {
    let settings = |p: &str| PrimPath::new(p).ok().filter(|p| all.contains(p));
    if let Some(w) = wanted {
        return match settings(w) {
            Some(w) => Ok((Some(w), None)),
            None => Err(format!("{w}: no such RenderSettings prim")),
        };
    }
    if let Some(Value::Token(p)) = stage.metadata("renderSettingsPrimPath")?.as_ref()
        && !p.is_empty()
    {
        return Ok(match settings(p) {
            Some(p) => (Some(p), None),
            None => (None, Some(format!("renderSettingsPrimPath {p} names no RenderSettings prim; none applied"))),
        });
    }
    Ok(match all {
        [] => (None, None),
        [one] => (Some(one.clone()), None),
        [first, ..] => {
            let note = format!(
                "{} RenderSettings prims and no renderSettingsPrimPath: {first} applied (--render-settings chooses)",
                all.len()
            );
            (Some(first.clone()), Some(note))
        }
    })
}

/// One RenderSettingsBase's authored values, each `None` when unauthored.
#[derive(Default)]
struct Authored {
    resolution: Option<(u32, u32)>,
    pixel_aspect: Option<f32>,
    conform: Option<Conform>,
    camera: Option<String>,
}

fn authored(stage: &Stage, prim: &PrimPath) -> Result<Authored, String> {
    let resolution = match stage.value(prim, "resolution")? {
        None => None,
        Some(Value::Numbers { values, shape: 2, array: false })
            if values.iter().all(|&v| (1.0..=MAX_SIDE).contains(&v) && v.fract() == 0.0) =>
        {
            Some((values[0] as u32, values[1] as u32))
        }
        Some(v) => return Err(format!("{prim}.resolution: expected two integers in 1..={MAX_SIDE}, got {v:?}")),
    };
    let pixel_aspect = match stage.value(prim, "pixelAspectRatio")? {
        None => None,
        Some(v) => match v.scalar() {
            Some(a) if a.is_finite() && a > 0.0 => Some(a as f32),
            _ => return Err(format!("{prim}.pixelAspectRatio: expected a positive number, got {v:?}")),
        },
    };
    let conform = match stage.value(prim, "aspectRatioConformPolicy")? {
        None => None,
        Some(v) => match v.token().and_then(Conform::from_token) {
            Some(c) => Some(c),
            None => return Err(format!("{prim}.aspectRatioConformPolicy: unknown policy {v:?}")),
        },
    };
    let camera = stage.targets(prim, "camera")?.first().map(PrimPath::to_string);
    Ok(Authored { resolution, pixel_aspect, conform, camera })
}

/// Reads the settings that apply to the stage whose RenderSettings prims are `all` (the
/// traversed ones, in traversal order), with the notes on what of them is not honoured.
/// `wanted` names a settings prim explicitly.
pub fn read(
    stage: &Stage,
    all: &[PrimPath],
    wanted: Option<&str>,
) -> Result<(Option<RenderSettings>, Vec<String>), (String, String)> {
    let (path, note) = settings_prim(stage, all, wanted).map_err(|e| ("/".to_string(), e))?;
    let mut notes: Vec<String> = note.into_iter().collect();
    let Some(path) = path else {
        return Ok((None, notes));
    };
    let at = |prim: &PrimPath| {
        let prim = prim.to_string();
        move |e: String| (prim, e)
    };
    let mut a = authored(stage, &path).map_err(at(&path))?;
    let products = stage.targets(&path, "products").map_err(at(&path))?;
    if let Some(product) = products.first() {
        let p = authored(stage, product).map_err(at(product))?;
        a.resolution = p.resolution.or(a.resolution);
        a.pixel_aspect = p.pixel_aspect.or(a.pixel_aspect);
        a.conform = p.conform.or(a.conform);
        a.camera = p.camera.or(a.camera);
        if products.len() > 1 {
            notes.push(format!("{} render products; only the first, {product}, is rendered", products.len()));
        }
    }
    if let Some(Value::Numbers { values, .. }) = stage.value(&path, "dataWindowNDC").map_err(at(&path))?
        && values != [0.0, 0.0, 1.0, 1.0]
    {
        notes.push("dataWindowNDC ignored: the whole image is rendered".into());
    }
    let settings = RenderSettings {
        path: path.to_string(),
        resolution: a.resolution.unwrap_or(FALLBACK_RESOLUTION),
        pixel_aspect: a.pixel_aspect.unwrap_or(1.0),
        conform: a.conform.unwrap_or_default(),
        camera: a.camera,
    };
    Ok((Some(settings), notes))
}

#[cfg(test)]
mod tests {
    use super::Conform;

    #[test]
    fn conform_policies_fit_the_aperture_to_the_image() {
        // A 2:1 aperture onto a square image, and a 1:2 one.
        let (wide, tall) = ((20.0, 10.0), (10.0, 20.0));
        assert_eq!(Conform::ExpandAperture.apply(wide, 100, 100, 1.0), (20.0, 20.0, 1.0));
        assert_eq!(Conform::ExpandAperture.apply(tall, 100, 100, 1.0), (20.0, 20.0, 1.0));
        assert_eq!(Conform::CropAperture.apply(wide, 100, 100, 1.0), (10.0, 10.0, 1.0));
        assert_eq!(Conform::CropAperture.apply(tall, 100, 100, 1.0), (10.0, 10.0, 1.0));
        assert_eq!(Conform::AdjustApertureWidth.apply(wide, 100, 100, 1.0), (10.0, 10.0, 1.0));
        assert_eq!(Conform::AdjustApertureHeight.apply(wide, 100, 100, 1.0), (20.0, 20.0, 1.0));
        assert_eq!(Conform::AdjustPixelAspectRatio.apply(wide, 100, 100, 1.0), (20.0, 10.0, 2.0));
        // Non-square pixels count in the image's aspect: 100 × 100 pixels of aspect 2 are 2:1.
        assert_eq!(Conform::ExpandAperture.apply(wide, 100, 100, 2.0), (20.0, 10.0, 2.0));
    }
}
