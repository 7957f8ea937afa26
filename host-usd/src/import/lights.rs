//! UsdLux lights into the scene, each under its world transform (the up-axis conversion
//! included): DistantLight, SphereLight (a point with `treatAsPoint`), RectLight, DiskLight,
//! CylinderLight (its side tessellated into emitting triangles) and meshes with MeshLightAPI.
//! Every light but a DistantLight carries its ShapingAPI cone, focus and IES profile (a
//! CylinderLight's and a mesh light's about the light's −Z, not each face's normal). A light
//! that emits nothing (zero intensity, colour or size) is a note, as the schema makes it dark;
//! a value that cannot be a light (not finite, negative) is an error naming the prim.

use super::Importer;
use crate::lights::{self, Emission, Emitter, RectTexture, UsdLight};
use crate::shapes;
use crate::shaping::{self, IesShaping, LightShaping};
use crate::stage::{PrimPath, Stage, Value};
use crate::xform::uniform_scale;
use glam::{DMat3, DMat4, DVec3, Vec3};
use std::f64::consts::PI;

/// Segments around a CylinderLight's axis.
const CYLINDER_SEGMENTS: usize = 64;

/// A light built, or why it emits nothing (a note).
type Built = Result<Emitter, String>;

impl Importer<'_> {
    /// A light prim of one of [`lights::KINDS`].
    pub(super) fn light(&mut self, prim: &PrimPath, type_name: &str) -> Result<(), String> {
        if self.hidden(prim)? {
            self.skip(prim, format!("invisible {type_name}: not rendered"));
            return Ok(());
        }
        let m = self.conversion * self.worlds.world(self.stage, prim)?;
        self.light_at(prim, type_name, &m, &prim.to_string())
    }

    /// The light `prim` under the renderer-frame transform `m`, named `label` (its path, or
    /// for a PointInstancer's instance the path and the instance).
    pub(super) fn light_at(&mut self, prim: &PrimPath, type_name: &str, m: &DMat4, label: &str) -> Result<(), String> {
        let (stage, m) = (self.stage, *m);
        let fallback = if type_name == "DistantLight" { 50000.0 } else { 1.0 };
        let emission = Emission::read(stage, prim, fallback)?;
        lights::unrendered(stage, prim, type_name)?.into_iter().for_each(|n| self.skip(prim, n));
        let size = |name: &str, fallback: f64| -> Result<f64, String> {
            let v = lights::scalar(stage, prim, name, fallback)?;
            if v < 0.0 { Err(format!("inputs:{name} is negative ({v})")) } else { Ok(v) }
        };
        let mut texture = None;
        let built = match type_name {
            "DistantLight" => distant(lights::scalar(stage, prim, "angle", 0.53)?, &m, &emission)?,
            "SphereLight" => {
                let point = stage.value(prim, "treatAsPoint")?.and_then(|v| v.scalar()).is_some_and(|v| v != 0.0);
                let (built, note) = sphere(size("radius", 0.5)?, point, &m, &emission);
                note.into_iter().for_each(|n| self.skip(prim, n));
                built
            }
            "RectLight" => {
                let (width, height) = (size("width", 1.0)?, size("height", 1.0)?);
                texture = rect_texture(stage, prim, width, height, &m)?;
                rect(width, height, &m, &emission)
            }
            "DiskLight" => {
                let (built, note) = disk(size("radius", 0.5)?, &m, &emission);
                note.into_iter().for_each(|n| self.skip(prim, n));
                built
            }
            "CylinderLight" => cylinder(size("radius", 0.5)?, size("length", 1.0)?, &m, &emission),
            _ => return Err(format!("{type_name} is not a light kind read here")),
        };
        let (shaping, ies) = if lights::UNSHAPED_KINDS.contains(&type_name) {
            (None, None)
        } else {
            (shaping::read(stage, prim, &m)?, shaping::read_ies(stage, prim, &m)?)
        };
        self.add_light(prim, label, type_name, built, Shaped { shaping, ies, texture });
        Ok(())
    }

    /// A gprim with MeshLightAPI: its triangles emit (front faces, both sides when
    /// `doubleSided`); it is not also a surface, and its material is not rendered.
    pub(super) fn mesh_light(&mut self, prim: &PrimPath, type_name: &str) -> Result<(), String> {
        let m = self.conversion * self.worlds.world(self.stage, prim)?;
        self.mesh_light_at(prim, type_name, &m, &prim.to_string())
    }

    /// The mesh light `prim` under the renderer-frame transform `m`, named `label`.
    pub(super) fn mesh_light_at(
        &mut self,
        prim: &PrimPath,
        type_name: &str,
        m: &DMat4,
        label: &str,
    ) -> Result<(), String> {
        let light = LightPrim { prim, type_name, world: m };
        self.emitting_gprim(&light, prim, type_name, m, label)
    }

    /// The gprim `geometry` of `type_name` under the renderer-frame transform `m` as a light
    /// with the LightAPI inputs and shaping of `light` (the gprim itself for MeshLightAPI, a
    /// GeometryLight prim targeting it otherwise), named `label`. Its triangles emit (front
    /// faces, both sides when the gprim is `doubleSided`); its material is not rendered.
    pub(super) fn emitting_gprim(
        &mut self,
        light: &LightPrim,
        geometry: &PrimPath,
        type_name: &str,
        m: &DMat4,
        label: &str,
    ) -> Result<(), String> {
        let stage = self.stage;
        let emission = Emission::read(stage, light.prim, 1.0)?;
        lights::unrendered(stage, light.prim, light.type_name)?.into_iter().for_each(|n| self.skip(light.prim, n));
        if stage.bound_material(geometry)?.is_some() {
            self.skip(geometry, "its material is not rendered (a mesh light emits and reflects nothing)");
        }
        let local = if type_name == "Mesh" {
            crate::mesh::read(stage, geometry, None)?
        } else {
            shapes::tessellate(stage, geometry, type_name)?.unwrap_or_default()
        };
        let two_sided = stage.value(geometry, "doubleSided")?.and_then(|v| v.scalar()).is_some_and(|v| v != 0.0);
        let built = triangles(&local.positions, &local.triangles, m, &emission, two_sided);
        let shaping = shaping::read(stage, light.prim, light.world)?;
        let ies = shaping::read_ies(stage, light.prim, light.world)?;
        self.add_light(light.prim, label, light.type_name, built, Shaped { shaping, ies, texture: None });
        Ok(())
    }

    fn add_light(&mut self, prim: &PrimPath, label: &str, type_name: &str, built: Built, shaped: Shaped) {
        let emitter = match built {
            Ok(e) if dark(&e) => Err("emits nothing (intensity or color 0): not rendered".to_string()),
            other => other,
        };
        match emitter {
            Ok(emitter) => {
                for p in extent(&emitter) {
                    self.grow(p);
                }
                let path = label.to_string();
                let prim_type = type_name.into();
                let Shaped { shaping, ies, texture } = shaped;
                self.scene.lights.push(UsdLight { path, prim_type, emitter, shaping, texture, ies });
            }
            Err(note) => self.skip(prim, format!("{type_name} {note}")),
        }
    }
}

/// The prim whose LightAPI inputs and shaping a light takes, with its type and its
/// renderer-frame transform (which places its shaping axis).
pub(super) struct LightPrim<'p> {
    pub(super) prim: &'p PrimPath,
    pub(super) type_name: &'p str,
    pub(super) world: &'p DMat4,
}

/// What varies a light's emission over its surface or its directions.
#[derive(Default)]
struct Shaped {
    shaping: Option<LightShaping>,
    ies: Option<IesShaping>,
    texture: Option<RectTexture>,
}

/// The light's emission is zero in every channel.
fn dark(e: &Emitter) -> bool {
    let v = match e {
        Emitter::Point { intensity, .. } => *intensity,
        Emitter::Distant { irradiance, .. } => *irradiance,
        Emitter::Sphere { radiance, .. }
        | Emitter::Rect { radiance, .. }
        | Emitter::Disk { radiance, .. }
        | Emitter::Triangles { radiance, .. } => *radiance,
    };
    v.max_element() <= 0.0
}

/// Points that bound an area light (none for points and distant lights, which nothing sees).
fn extent(e: &Emitter) -> Vec<Vec3> {
    match e {
        Emitter::Sphere { center, radius, .. } => vec![*center - *radius, *center + *radius],
        Emitter::Rect { p0, e1, e2, .. } => vec![*p0, *p0 + *e1, *p0 + *e2, *p0 + *e1 + *e2],
        Emitter::Disk { center, radius, .. } => vec![*center - *radius, *center + *radius],
        Emitter::Triangles { positions, .. } => positions.clone(),
        Emitter::Point { .. } | Emitter::Distant { .. } => Vec::new(),
    }
}

/// The unit world direction of a local plane's normal `n` under `m` (inverse transpose).
fn world_normal(m: &DMat4, n: DVec3) -> Option<DVec3> {
    let m3 = DMat3::from_mat4(*m);
    let det = m3.determinant();
    (det.is_finite() && det != 0.0).then(|| (m3.inverse().transpose() * n).normalize())
}

/// DistantLight: light from the light's local +Z (it travels along −Z). The schema's radiance
/// L = emission / sizeFactor fills a disc of half-angle θ = angle/2, delivering E = π sin²θ · L
/// on a surface facing it; with `normalize` sizeFactor = π sin²θ, so E is the emission itself.
/// At angle 0 (a delta light) sizeFactor is 1 and E is the emission. Angles from 180° (a cap
/// wider than a hemisphere) are not rendered.
fn distant(angle: f64, m: &DMat4, emission: &Emission) -> Result<Built, String> {
    // The schema clips the angle to [0, 360): a negative one is a delta light.
    let angle = angle.max(0.0);
    if angle >= 180.0 {
        return Ok(Err(format!("of angle {angle}° (wider than a hemisphere) not rendered")));
    }
    let direction = m.transform_vector3(DVec3::Z).normalize_or_zero();
    if direction == DVec3::ZERO || !direction.is_finite() {
        return Err("the DistantLight's world transform has no direction (singular)".into());
    }
    let half = (0.5 * angle).to_radians();
    let irradiance =
        if angle == 0.0 || emission.normalize { emission.rgb } else { emission.rgb * PI * half.sin().powi(2) };
    let (direction, irradiance) = (direction.as_vec3(), irradiance.as_vec3());
    Ok(Ok(Emitter::Distant { direction, irradiance, angle_deg: angle as f32 }))
}

/// SphereLight of local radius `r`: an exact sphere of the world radius (the cube root of the
/// volume scale, with a note, under a non-uniform scale), or with `point` a point light of the
/// sphere's intensity π r² L.
fn sphere(r: f64, point: bool, m: &DMat4, emission: &Emission) -> (Built, Option<String>) {
    let center = m.transform_point3(DVec3::ZERO).as_vec3();
    let (scale, note) = match uniform_scale(m) {
        Some(s) => (s, None),
        None => {
            let s = DMat3::from_mat4(*m).determinant().abs().cbrt();
            (s, Some("non-uniform scale: rendered as a sphere of the same volume".to_string()))
        }
    };
    let radius = r * scale;
    if point {
        // π r² · L, and with `normalize` (L = emission / 4π r²) emission / 4 at any radius.
        let intensity = if emission.normalize { emission.rgb / 4.0 } else { emission.rgb * PI * radius * radius };
        return (Ok(Emitter::Point { position: center, intensity: intensity.as_vec3() }), note);
    }
    let radiance = emission.radiance(4.0 * PI * radius * radius);
    if radius <= 0.0 {
        return (Err("of radius 0 emits nothing: not rendered".into()), note);
    }
    (Ok(Emitter::Sphere { center, radius: radius as f32, radiance }), note)
}

/// A RectLight's `texture:file` under `m`, read from its (resolved) asset; `None` when none
/// is authored, an error naming the file when it cannot be found or read.
fn rect_texture(
    stage: &Stage,
    prim: &PrimPath,
    width: f64,
    height: f64,
    m: &DMat4,
) -> Result<Option<RectTexture>, String> {
    let Some(Value::Asset { authored, resolved }) = lights::input(stage, prim, "texture:file")? else {
        return Ok(None);
    };
    if authored.is_empty() {
        return Ok(None);
    }
    let name = resolved.ok_or_else(|| format!("texture:file {authored} not found"))?;
    let bytes = stage.read_asset(&name).map_err(|e| format!("texture:file {name}: {e}"))?;
    let corner = m.transform_point3(DVec3::new(0.5 * width, 0.5 * height, 0.0)).as_vec3();
    let across = m.transform_vector3(DVec3::new(-width, 0.0, 0.0)).as_vec3();
    let down = m.transform_vector3(DVec3::new(0.0, -height, 0.0)).as_vec3();
    Ok(Some(RectTexture { name, bytes, corner, across, down }))
}

/// RectLight: `width` along local X, `height` along local Y, centred, emitting towards the
/// world image of its local −Z side. A shear that makes its edges oblique is not rendered.
fn rect(width: f64, height: f64, m: &DMat4, emission: &Emission) -> Built {
    if width <= 0.0 || height <= 0.0 {
        return Err(format!("of size {width} × {height} has no area: not rendered"));
    }
    let p0 = m.transform_point3(DVec3::new(-0.5 * width, -0.5 * height, 0.0));
    let (mut e1, mut e2) = (m.transform_vector3(DVec3::Y * height), m.transform_vector3(DVec3::X * width));
    let front = world_normal(m, -DVec3::Z).ok_or("with a singular world transform has no area: not rendered")?;
    if e1.cross(e2).dot(front) < 0.0 {
        std::mem::swap(&mut e1, &mut e2);
    }
    if e1.dot(e2).abs() > 1e-6 * e1.length() * e2.length() {
        return Err("sheared into a parallelogram: not rendered".into());
    }
    let radiance = emission.radiance(e1.cross(e2).length());
    Ok(Emitter::Rect { p0: p0.as_vec3(), e1: e1.as_vec3(), e2: e2.as_vec3(), radiance })
}

/// DiskLight of local radius `r` in its local XY plane, emitting along its local −Z; under a
/// scale that makes it an ellipse, a disk of the same area (with a note).
fn disk(r: f64, m: &DMat4, emission: &Emission) -> (Built, Option<String>) {
    if r <= 0.0 {
        return (Err("of radius 0 emits nothing: not rendered".into()), None);
    }
    let (a, b) = (m.transform_vector3(DVec3::X), m.transform_vector3(DVec3::Y));
    let Some(normal) = world_normal(m, -DVec3::Z) else {
        return (Err("with a singular world transform has no area: not rendered".into()), None);
    };
    let circular = (a.length() - b.length()).abs() <= 1e-6 * a.length() && a.dot(b).abs() <= 1e-6 * a.length_squared();
    let note = (!circular).then(|| "non-uniform scale: rendered as a disk of the same area".to_string());
    let radius = r * a.cross(b).length().sqrt();
    let radiance = emission.radiance(PI * radius * radius);
    let center = m.transform_point3(DVec3::ZERO).as_vec3();
    (Ok(Emitter::Disk { center, normal: normal.as_vec3(), radius: radius as f32, radiance }), note)
}

/// CylinderLight: `radius`, `length` along local X, emitting outwards from its side (not its
/// caps), tessellated into [`CYLINDER_SEGMENTS`] facets whose circumradius makes the prism's
/// perimeter, and so its area and power, the cylinder's.
fn cylinder(radius: f64, length: f64, m: &DMat4, emission: &Emission) -> Built {
    if radius <= 0.0 || length <= 0.0 {
        return Err(format!("of radius {radius} and length {length} has no area: not rendered"));
    }
    let n = CYLINDER_SEGMENTS;
    let step = 2.0 * PI / n as f64;
    let r = radius * PI / (n as f64 * (PI / n as f64).sin());
    let h = 0.5 * length;
    let mut positions = Vec::with_capacity(2 * n);
    for i in 0..n {
        let (s, c) = (i as f64 * step).sin_cos();
        positions.push(DVec3::new(-h, r * c, r * s));
        positions.push(DVec3::new(h, r * c, r * s));
    }
    let mut tris = Vec::with_capacity(2 * n);
    for i in 0..n as u32 {
        let j = (i + 1) % n as u32;
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * j + 1, 2 * j);
        // Counter-clockwise seen from outside.
        tris.push([a, c, b]);
        tris.push([a, d, c]);
    }
    triangles(&positions, &tris, m, emission, false)
}

/// Local triangles under `m` as an emitter (winding reversed under a mirroring transform),
/// the emission normalised by their world surface area (one side's, as the schema's
/// sizeFactor is the surface area whichever sides emit); triangles without an area are kept out of
/// that area and are dropped by the renderer.
fn triangles(local: &[DVec3], tris: &[[u32; 3]], m: &DMat4, emission: &Emission, two_sided: bool) -> Built {
    let mirror = DMat3::from_mat4(*m).determinant() < 0.0;
    let world: Vec<DVec3> = local.iter().map(|p| m.transform_point3(*p)).collect();
    if world.iter().any(|p| !p.is_finite()) {
        return Err("has a point that is not finite under its transform: not rendered".into());
    }
    let mut area = 0.0;
    let mut out = Vec::with_capacity(tris.len());
    for &t in tris {
        if t.iter().any(|&i| i as usize >= world.len()) {
            return Err("has a face index out of range: not rendered".into());
        }
        let [a, b, c] = t.map(|i| world[i as usize]);
        area += 0.5 * (b - a).cross(c - a).length();
        out.push(if mirror { [t[0], t[2], t[1]] } else { t });
    }
    if area <= 0.0 {
        return Err("has no face with an area: not rendered".into());
    }
    let radiance = emission.radiance(area);
    let positions = world.iter().map(|p| p.as_vec3()).collect();
    Ok(Emitter::Triangles { positions, triangles: out, radiance, two_sided })
}
