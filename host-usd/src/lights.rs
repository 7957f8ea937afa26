//! UsdLux lights besides the dome, as plain data in the renderer's frame, and the inputs every
//! light shares (LightAPI): emitted radiance L = intensity · 2^exposure · color ·
//! blackbody(colorTemperature) (when enabled) / sizeFactor, where sizeFactor is the light's
//! world-space area for area lights and π sin²θmax for an angular DistantLight when
//! `normalize` is on, and 1 otherwise (the schema's "Quantities and units"). Each input is
//! read as `inputs:<name>`, or by its pre-21.02 name without the prefix.
//!
//! The geometry of each kind is built by `import/lights.rs`; this file holds what they share.

use crate::blackbody;
use crate::stage::{PrimPath, Stage, Value};
use glam::{DVec3, Vec3};

/// Prim types read as lights here (the DomeLight is `dome.rs`'s).
pub const KINDS: [&str; 5] = ["SphereLight", "RectLight", "DiskLight", "DistantLight", "CylinderLight"];

/// What a light emits and where, in the renderer's frame (Y up, scene units).
#[derive(Clone, Debug, PartialEq)]
pub enum Emitter {
    /// A point: a SphereLight with `treatAsPoint`, of the sphere's intensity π r² L.
    Point {
        /// Position.
        position: Vec3,
        /// Radiant intensity (RGB, per steradian).
        intensity: Vec3,
    },
    /// A SphereLight emitting outwards.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius in world units.
        radius: f32,
        /// Radiance leaving its surface.
        radiance: Vec3,
    },
    /// A RectLight: `p0 + s·e1 + t·e2`, s, t ∈ [0, 1], emitting towards `e1 × e2` (its local −Z).
    Rect {
        /// A corner.
        p0: Vec3,
        /// First edge.
        e1: Vec3,
        /// Second edge.
        e2: Vec3,
        /// Radiance leaving its front.
        radiance: Vec3,
    },
    /// A DiskLight emitting along `normal` (its local −Z).
    Disk {
        /// Centre.
        center: Vec3,
        /// Unit front normal.
        normal: Vec3,
        /// Radius in world units.
        radius: f32,
        /// Radiance leaving its front.
        radiance: Vec3,
    },
    /// Emitting triangles: a mesh with MeshLightAPI, or a CylinderLight's tessellated side.
    Triangles {
        /// Points in world space.
        positions: Vec<Vec3>,
        /// Counter-clockwise seen from the emitting side.
        triangles: Vec<[u32; 3]>,
        /// Radiance leaving each triangle's front.
        radiance: Vec3,
        /// Both sides emit (a `doubleSided` mesh).
        two_sided: bool,
    },
    /// A DistantLight.
    Distant {
        /// Unit direction from the scene towards the light (its local +Z).
        direction: Vec3,
        /// Irradiance on a surface facing the light.
        irradiance: Vec3,
        /// Full angular diameter in degrees, in [0, 180).
        angle_deg: f32,
    },
}

/// A light the import renders.
#[derive(Clone, Debug, PartialEq)]
pub struct UsdLight {
    /// The light's prim.
    pub path: String,
    /// Its prim type (`SphereLight`, …, or `Mesh` for a mesh with MeshLightAPI).
    pub prim_type: String,
    /// What it emits, where.
    pub emitter: Emitter,
    /// Its ShapingAPI cone and focus (points, spheres, rectangles and disks).
    pub shaping: Option<crate::shaping::LightShaping>,
    /// A RectLight's `texture:file`, placed on the rectangle.
    pub texture: Option<RectTexture>,
    /// Its ShapingAPI IES profile (every kind but a DistantLight).
    pub ies: Option<crate::shaping::IesShaping>,
}

/// A RectLight's texture and where it lies. The schema puts the image's first texel (its
/// top-left corner) at the rectangle's local (+X, +Y) corner and its last one at (−X, −Y):
/// seen from the front (from the emitting side, local −Z, with +Y up) the image is upright
/// and unmirrored. Image column fractions run along `across`, rows (top to bottom) along `down`.
#[derive(Clone, Debug, PartialEq)]
pub struct RectTexture {
    /// The resolved asset path (inside a package: `pkg.usdz[tex/a.png]`).
    pub name: String,
    /// The encoded image.
    pub bytes: Vec<u8>,
    /// Where the image's top-left corner lies: the world image of local (+w/2, +h/2, 0).
    pub corner: Vec3,
    /// From that corner across the image's top row: the world image of (−w, 0, 0).
    pub across: Vec3,
    /// From that corner down the image's first column: the world image of (0, −h, 0).
    pub down: Vec3,
}

/// A light input: `inputs:<name>`, or the pre-21.02 `<name>`.
pub fn input(stage: &Stage, prim: &PrimPath, name: &str) -> Result<Option<Value>, String> {
    match stage.value(prim, &format!("inputs:{name}"))? {
        Some(v) => Ok(Some(v)),
        None => stage.value(prim, name),
    }
}

/// A scalar light input with its schema fallback; a value that is not finite is an error.
pub fn scalar(stage: &Stage, prim: &PrimPath, name: &str, fallback: f64) -> Result<f64, String> {
    let v = input(stage, prim, name)?.and_then(|v| v.scalar()).unwrap_or(fallback);
    if v.is_finite() { Ok(v) } else { Err(format!("inputs:{name} is {v}, not a finite number")) }
}

/// The LightAPI inputs of a light: its scalar emission (intensity · 2^exposure · color ·
/// blackbody) before any size normalisation, and whether `normalize` is on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    /// intensity · 2^exposure · color (· the blackbody colour).
    pub rgb: DVec3,
    /// `inputs:normalize`: divide by the light's size.
    pub normalize: bool,
}

impl Emission {
    /// Reads the LightAPI inputs of `prim` (`intensity` falls back to `fallback_intensity`:
    /// 50000 for a DistantLight, 1 for the others). A value that is not finite, a negative
    /// intensity or colour component is an error naming the input.
    pub fn read(stage: &Stage, prim: &PrimPath, fallback_intensity: f64) -> Result<Self, String> {
        let intensity = scalar(stage, prim, "intensity", fallback_intensity)?;
        let exposure = scalar(stage, prim, "exposure", 0.0)?;
        if intensity < 0.0 {
            return Err(format!("inputs:intensity is negative ({intensity})"));
        }
        let color = match input(stage, prim, "color")? {
            Some(Value::Numbers { values, .. }) if values.len() >= 3 => DVec3::new(values[0], values[1], values[2]),
            _ => DVec3::ONE,
        };
        if !color.is_finite() || color.min_element() < 0.0 {
            return Err(format!("inputs:color {:?} has a negative or non-finite component", color.to_array()));
        }
        let mut rgb = color * intensity * exposure.exp2();
        if scalar(stage, prim, "enableColorTemperature", 0.0)? != 0.0 {
            rgb *= blackbody::rgb(scalar(stage, prim, "colorTemperature", blackbody::WHITE_KELVIN)?);
        }
        if !rgb.is_finite() {
            return Err(format!("intensity {intensity} · 2^{exposure} overflows"));
        }
        let normalize = scalar(stage, prim, "normalize", 0.0)? != 0.0;
        Ok(Emission { rgb, normalize })
    }

    /// The radiance of an area light of world-space area `area`.
    pub fn radiance(&self, area: f64) -> Vec3 {
        let size = if self.normalize { area } else { 1.0 };
        (self.rgb / size).as_vec3()
    }
}

/// The light authors its collection `name` (LightAPI's `lightLink` or `shadowLink`) to leave
/// some prims out: includes or excludes, or `includeRoot` off.
fn linked(stage: &Stage, prim: &PrimPath, name: &str) -> Result<bool, String> {
    let base = format!("collection:{name}");
    let listed = !stage.targets(prim, &format!("{base}:includes"))?.is_empty()
        || !stage.targets(prim, &format!("{base}:excludes"))?.is_empty();
    let root_off = stage.value(prim, &format!("{base}:includeRoot"))?.and_then(|v| v.scalar()) == Some(0.0);
    Ok(listed || root_off)
}

/// The light kinds whose ShapingAPI cone, focus and IES profile are not rendered (every other
/// kind's are, a CylinderLight's and a mesh light's faces about the light's axis).
pub const UNSHAPED_KINDS: [&str; 1] = ["DistantLight"];

/// What a light's prim authors that the renderer does not honour, one note each: ShapingAPI's
/// cone, focus and IES profile on [`UNSHAPED_KINDS`], light filters, the
/// diffuse and specular multipliers, shadow controls, and (for `type_name`) a CylinderLight's
/// `treatAsLine`. A RectLight's texture renders (`RectTexture`).
pub fn unrendered(stage: &Stage, prim: &PrimPath, type_name: &str) -> Result<Vec<String>, String> {
    let mut notes = Vec::new();
    let authored =
        |name: &str| -> Result<Option<f64>, String> { Ok(input(stage, prim, name)?.and_then(|v| v.scalar())) };
    if UNSHAPED_KINDS.contains(&type_name) {
        if authored("shaping:cone:angle")?.is_some_and(|a| a < 180.0) {
            notes.push(format!("ShapingAPI cone angle not rendered on a {type_name}"));
        }
        if authored("shaping:focus")?.is_some_and(|f| f > 0.0) {
            notes.push(format!("ShapingAPI focus not rendered on a {type_name}"));
        }
    }
    if let Some(Value::Asset { authored, .. }) = input(stage, prim, "shaping:ies:file")?
        && !authored.is_empty()
        && UNSHAPED_KINDS.contains(&type_name)
    {
        notes.push(format!("IES profile {authored} not rendered on a {type_name}"));
    }
    if !stage.targets(prim, "light:filters")?.is_empty() {
        notes.push("light filters not rendered".into());
    }
    for (collection, what) in [("lightLink", "light linking"), ("shadowLink", "shadow linking")] {
        if linked(stage, prim, collection)? {
            notes.push(format!("{what} (collection:{collection}) not honoured: the light reaches every prim"));
        }
    }
    for (name, what) in [("diffuse", "diffuse multiplier"), ("specular", "specular multiplier")] {
        if authored(name)?.is_some_and(|v| v != 1.0) {
            notes.push(format!("inputs:{name} ({what}) not rendered; the light is physical"));
        }
    }
    if stage.value(prim, "inputs:shadow:enable")?.and_then(|v| v.scalar()) == Some(0.0) {
        notes.push("ShadowAPI shadow:enable = false not honoured (the light casts shadows)".into());
    }
    if type_name == "CylinderLight" && stage.value(prim, "treatAsLine")?.and_then(|v| v.scalar()) == Some(1.0) {
        notes.push("treatAsLine ignored (rendered as the cylinder)".into());
    }
    Ok(notes)
}
