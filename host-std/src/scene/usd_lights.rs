//! A USD stage's UsdLux lights (host-usd's [`host_usd::lights::UsdLight`], radiometry already
//! per the schema) as the core's lights: a mesh light or a CylinderLight becomes one triangle
//! light per face with an area; a ShapingAPI cone, focus and IES profile (`shaping:ies:file`,
//! parsed by `scene/ies.rs`) shape any of them but a distant light (a mesh's faces about the
//! light's axis); a RectLight's `texture:file` cuts it into one rectangle per texel
//! (`scene/rect_texture.rs`). A light the core cannot build is a note naming its prim; an IES
//! file that is not one is an error naming it.

use crate::scene::mesh_light::push_triangle_lights;
use crate::scene::rect_texture;
use host_usd::lights::{Emitter, UsdLight};
use host_usd::shaping::{IesShaping, LightShaping};
use sampler_core::light::{
    DiskLight, DistantLight, IntensityProfile, LightError, PointLight, RectLight, SceneLight, Shaping, SphereLight,
};
use std::collections::HashMap;

/// Each IES file's profile, parsed once however many lights use it.
type Profiles = HashMap<String, &'static IntensityProfile<'static>>;

/// The core's lights for `lights`, with a note in `notes` for each one that cannot be built;
/// an error naming the file and the light when an IES file cannot be parsed.
pub(crate) fn convert(lights: &[UsdLight], notes: &mut Vec<String>) -> Result<Vec<SceneLight>, String> {
    let mut out = Vec::new();
    let mut profiles = Profiles::new();
    for l in lights {
        let profile = match &l.ies {
            Some(ies) => Some(profile(ies, &mut profiles).map_err(|e| format!("{e} (the IES profile of {})", l.path))?),
            None => None,
        };
        let shaping = core_shaping(l.shaping.as_ref(), l.ies.as_ref().zip(profile));
        if let (Some(t), Emitter::Rect { e1, e2, radiance, .. }) = (&l.texture, &l.emitter) {
            match rect_texture::decode(t) {
                Ok(image) => {
                    let pushed = shaping
                        .and_then(|s| rect_texture::push_cells(t, &image, e1.cross(*e2), *radiance, s, &mut out));
                    match pushed {
                        Ok(0) => notes.push(format!("{}: its texture {} is black: not rendered", l.path, t.name)),
                        Ok(_) => {}
                        Err(e) => notes.push(format!("{}: {} not rendered ({e})", l.path, l.prim_type)),
                    }
                    continue;
                }
                Err(e) => {
                    notes.push(format!("{}: texture:file not used ({e}); the rectangle emits its colour", l.path))
                }
            }
        }
        if let Err(e) = shaping.and_then(|s| push(&l.emitter, s, &mut out)) {
            notes.push(format!("{}: {} not rendered ({e})", l.path, l.prim_type));
        }
    }
    Ok(out)
}

/// The profile of an IES file, parsed the first time it is met; an error names the file.
fn profile(ies: &IesShaping, profiles: &mut Profiles) -> Result<&'static IntensityProfile<'static>, String> {
    if let Some(p) = profiles.get(&ies.name) {
        return Ok(p);
    }
    let file = crate::scene::ies::parse(&ies.bytes).map_err(|e| format!("{}: {e}", ies.name))?;
    let p = file.profile();
    profiles.insert(ies.name.clone(), p);
    Ok(p)
}

/// The core's shaping for a light's ShapingAPI inputs: its cone and focus, times its IES
/// profile where it has one.
fn core_shaping(
    s: Option<&LightShaping>,
    ies: Option<(&IesShaping, &'static IntensityProfile<'static>)>,
) -> Result<Shaping, LightError> {
    let base = match (s, ies) {
        (Some(s), _) => Shaping::new(s.axis, s.cone_angle_deg.to_radians(), s.cone_softness, s.focus, s.focus_tint)?,
        (None, Some((i, _))) => Shaping::new(i.axis, std::f32::consts::PI, 0.0, 0.0, sampler_core::glam::Vec3::ONE)?,
        (None, None) => Shaping::NONE,
    };
    match ies {
        Some((i, p)) => base.with_profile(p, i.x, i.y, i.angle_scale, i.normalize),
        None => Ok(base),
    }
}

fn push(e: &Emitter, shaping: Shaping, out: &mut Vec<SceneLight>) -> Result<(), LightError> {
    match e {
        Emitter::Point { position, intensity } => {
            out.push(PointLight::new(*position, *intensity)?.with_shaping(shaping).into())
        }
        Emitter::Sphere { center, radius, radiance } => {
            out.push(SphereLight::new(*center, *radius, *radiance)?.with_shaping(shaping).into())
        }
        Emitter::Rect { p0, e1, e2, radiance } => {
            out.push(RectLight::new(*p0, *e1, *e2, *radiance)?.with_shaping(shaping).into())
        }
        Emitter::Disk { center, normal, radius, radiance } => {
            out.push(DiskLight::new(*center, *normal, *radius, *radiance)?.with_shaping(shaping).into())
        }
        Emitter::Distant { direction, irradiance, angle_deg } => {
            out.push(DistantLight::new(*direction, *irradiance, angle_deg.to_radians())?.into())
        }
        Emitter::Triangles { positions, triangles, radiance, two_sided } => {
            push_triangle_lights(positions, triangles, *radiance, *two_sided, shaping, out)?;
        }
    }
    Ok(())
}

/// One line per light for `ppis info`: its prim, kind, what it emits and how it is shaped.
pub fn describe(l: &UsdLight) -> String {
    let shaped = l.shaping.map_or(String::new(), |s| {
        format!(
            "; shaped: cone {}°, softness {}, focus {}, focus tint {:?}",
            s.cone_angle_deg,
            s.cone_softness,
            s.focus,
            s.focus_tint.to_array()
        )
    });
    let textured = l.texture.as_ref().map_or(String::new(), |t| format!("; textured by {}", t.name));
    let ies = l.ies.as_ref().map_or(String::new(), |i| {
        let table = crate::scene::ies::parse(&i.bytes).map_or_else(|e| format!("not a profile: {e}"), |f| f.describe());
        let normalized = if i.normalize { ", normalized" } else { "" };
        format!("; IES profile {} ({table}; angleScale {}{normalized})", i.name, i.angle_scale)
    });
    format!("{}{shaped}{textured}{ies}", emitter_line(l))
}

fn emitter_line(l: &UsdLight) -> String {
    let v = |v: sampler_core::glam::Vec3| format!("{:?}", v.to_array());
    match &l.emitter {
        Emitter::Point { position, intensity } => {
            format!("{} {}: point (treatAsPoint) at {}, intensity {}", l.prim_type, l.path, v(*position), v(*intensity))
        }
        Emitter::Sphere { center, radius, radiance } => {
            format!("{} {}: sphere at {}, radius {radius}, radiance {}", l.prim_type, l.path, v(*center), v(*radiance))
        }
        Emitter::Rect { e1, e2, radiance, .. } => format!(
            "{} {}: rectangle {} × {}, radiance {}",
            l.prim_type,
            l.path,
            e2.length(),
            e1.length(),
            v(*radiance)
        ),
        Emitter::Disk { center, radius, radiance, .. } => {
            format!("{} {}: disk at {}, radius {radius}, radiance {}", l.prim_type, l.path, v(*center), v(*radiance))
        }
        Emitter::Distant { direction, irradiance, angle_deg } => format!(
            "{} {}: distant from {}, angle {angle_deg}°, irradiance {}",
            l.prim_type,
            l.path,
            v(*direction),
            v(*irradiance)
        ),
        Emitter::Triangles { triangles, radiance, two_sided, .. } => format!(
            "{} {}: {} emitting triangles{}{}, radiance {}",
            l.prim_type,
            l.path,
            triangles.len(),
            if l.prim_type == "CylinderLight" { " (the cylinder's side, tessellated)" } else { "" },
            if *two_sided { ", both sides" } else { "" },
            v(*radiance)
        ),
    }
}
