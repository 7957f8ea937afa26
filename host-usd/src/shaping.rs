//! UsdLux's ShapingAPI on a light: the cone (`inputs:shaping:cone:angle`, `…:softness`) and the
//! focus (`inputs:shaping:focus`, `…:focusTint`) about the light's primary axis, its local −Z,
//! and the IES profile (`inputs:shaping:ies:file`, `…:angleScale`, `…:normalize`), whose file is
//! read here and parsed by the renderer. The renderer applies them as the schema's formulas say
//! (sampler-core's `light::Shaping`).
//!
//! A light is shaped when it applies ShapingAPI or authors any of these inputs. The cone angle
//! falls back to the schema's 90° on a prim that applies ShapingAPI, and to no cutoff on one
//! that does not (then the attribute is not part of its schema: a renderer that reads it through
//! Hydra, as Pixar's HdEmbree does, sees no cone).

use crate::lights::{input, scalar};
use crate::stage::{PrimPath, Stage, Value};
use glam::{DMat4, DVec3, Vec3};

/// A light's ShapingAPI inputs, its axis in the renderer's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightShaping {
    /// Unit primary axis: the world image of the light's local −Z.
    pub axis: Vec3,
    /// `inputs:shaping:cone:angle` in degrees (180: no cutoff).
    pub cone_angle_deg: f32,
    /// `inputs:shaping:cone:softness`, as authored (the renderer clamps it to [0, 1]).
    pub cone_softness: f32,
    /// `inputs:shaping:focus` (< 0 is ignored).
    pub focus: f32,
    /// `inputs:shaping:focusTint` (RGB).
    pub focus_tint: Vec3,
}

impl LightShaping {
    /// The shaping leaves every direction's emission unchanged.
    #[must_use]
    pub fn is_identity(&self) -> bool {
        self.cone_angle_deg >= 180.0 && (self.focus <= 0.0 || self.focus_tint == Vec3::ONE)
    }
}

/// A light's IES profile: the file's bytes and how the profile sits on the light.
#[derive(Clone, Debug, PartialEq)]
pub struct IesShaping {
    /// The resolved asset path (inside a package: `pkg.usdz[lamps/a.ies]`).
    pub name: String,
    /// The file's bytes.
    pub bytes: Vec<u8>,
    /// Unit primary axis: the world image of the light's local −Z (the profile's vertical 0°).
    pub axis: Vec3,
    /// The world image of the light's local +X (the profile's horizontal 0°).
    pub x: Vec3,
    /// The world image of the light's local +Y (horizontal 90°).
    pub y: Vec3,
    /// `inputs:shaping:ies:angleScale`.
    pub angle_scale: f32,
    /// `inputs:shaping:ies:normalize`.
    pub normalize: bool,
}

/// The largest IES file read (larger ones are refused before they are parsed).
pub const MAX_IES_BYTES: usize = 16 << 20;

/// The light's IES profile under its world transform `m`; `None` when no file is authored (or
/// the path is empty). A file that cannot be found or read, or a non-finite angle scale, is an
/// error naming it.
pub fn read_ies(stage: &Stage, prim: &PrimPath, m: &DMat4) -> Result<Option<IesShaping>, String> {
    let Some(Value::Asset { authored, resolved }) = input(stage, prim, "shaping:ies:file")? else {
        return Ok(None);
    };
    if authored.is_empty() {
        return Ok(None);
    }
    let name = resolved.ok_or_else(|| format!("inputs:shaping:ies:file {authored} not found"))?;
    let bytes = stage.read_asset(&name).map_err(|e| format!("{name}: {e}"))?;
    if bytes.len() > MAX_IES_BYTES {
        return Err(format!("{name}: {} bytes, more than an IES file may hold here", bytes.len()));
    }
    let angle_scale = scalar(stage, prim, "shaping:ies:angleScale", 0.0)? as f32;
    let normalize = scalar(stage, prim, "shaping:ies:normalize", 0.0)? != 0.0;
    let axis = m.transform_vector3(DVec3::NEG_Z).normalize_or_zero();
    let (x, y) = (m.transform_vector3(DVec3::X), m.transform_vector3(DVec3::Y));
    let independent =
        axis.cross(x).length() > 1e-9 * x.length() && x.cross(y).length() > 1e-9 * x.length() * y.length();
    if axis == DVec3::ZERO || !axis.is_finite() || !independent {
        return Err("the IES-shaped light's world transform is singular".into());
    }
    let (axis, x, y) = (axis.as_vec3(), x.as_vec3(), y.as_vec3());
    Ok(Some(IesShaping { name, bytes, axis, x, y, angle_scale, normalize }))
}

/// The inputs ShapingAPI adds, besides the IES profile's.
const INPUTS: [&str; 4] = ["shaping:cone:angle", "shaping:cone:softness", "shaping:focus", "shaping:focusTint"];

/// The light's shaping under its world transform `m`; `None` when it is not shaped or the
/// shaping changes nothing. A non-finite input or a negative tint is an error naming it.
pub fn read(stage: &Stage, prim: &PrimPath, m: &DMat4) -> Result<Option<LightShaping>, String> {
    let applied = stage.applied_schemas(prim)?.iter().any(|s| s == "ShapingAPI");
    let mut authored = false;
    for name in INPUTS {
        authored |= input(stage, prim, name)?.is_some();
    }
    if !applied && !authored {
        return Ok(None);
    }
    let cone = scalar(stage, prim, "shaping:cone:angle", if applied { 90.0 } else { 180.0 })?;
    let softness = scalar(stage, prim, "shaping:cone:softness", 0.0)?;
    let focus = scalar(stage, prim, "shaping:focus", 0.0)?;
    let tint = match input(stage, prim, "shaping:focusTint")? {
        Some(Value::Numbers { values, .. }) if values.len() >= 3 => DVec3::new(values[0], values[1], values[2]),
        _ => DVec3::ZERO,
    };
    if !tint.is_finite() || tint.min_element() < 0.0 {
        return Err(format!("inputs:shaping:focusTint {:?} has a negative or non-finite component", tint.to_array()));
    }
    let axis = m.transform_vector3(DVec3::NEG_Z).normalize_or_zero();
    if axis == DVec3::ZERO || !axis.is_finite() {
        return Err("the shaped light's world transform has no axis (singular)".into());
    }
    let shaping = LightShaping {
        axis: axis.as_vec3(),
        cone_angle_deg: cone.min(180.0) as f32,
        cone_softness: softness as f32,
        focus: focus as f32,
        focus_tint: tint.as_vec3(),
    };
    Ok((!shaping.is_identity()).then_some(shaping))
}
