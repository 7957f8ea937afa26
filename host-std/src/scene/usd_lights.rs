//! A USD stage's UsdLux lights (host-usd's [`host_usd::lights::UsdLight`], radiometry already
//! per the schema) as the core's lights: a mesh light or a CylinderLight becomes one triangle
//! light per face with an area; a ShapingAPI cone and focus shape a point, sphere, rectangle or
//! disk; a RectLight's `texture:file` cuts it into one rectangle per texel (`scene/rect_texture.rs`).
//! A light the core cannot build is a note naming its prim.

use crate::scene::mesh_light::push_triangle_lights;
use crate::scene::rect_texture;
use host_usd::lights::{Emitter, UsdLight};
use host_usd::shaping::LightShaping;
use sampler_core::light::{
    DiskLight, DistantLight, LightError, PointLight, RectLight, SceneLight, Shaping, SphereLight,
};

/// The core's lights for `lights`, with a note in `notes` for each one that cannot be built.
pub(crate) fn convert(lights: &[UsdLight], notes: &mut Vec<String>) -> Vec<SceneLight> {
    let mut out = Vec::new();
    for l in lights {
        if let (Some(t), Emitter::Rect { e1, e2, radiance, .. }) = (&l.texture, &l.emitter) {
            match rect_texture::decode(t) {
                Ok(image) => {
                    let pushed = core_shaping(l.shaping.as_ref())
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
        if let Err(e) = push(&l.emitter, l.shaping.as_ref(), &mut out) {
            notes.push(format!("{}: {} not rendered ({e})", l.path, l.prim_type));
        }
    }
    out
}

/// The core's shaping for a light's ShapingAPI inputs.
fn core_shaping(s: Option<&LightShaping>) -> Result<Shaping, LightError> {
    match s {
        Some(s) => Shaping::new(s.axis, s.cone_angle_deg.to_radians(), s.cone_softness, s.focus, s.focus_tint),
        None => Ok(Shaping::NONE),
    }
}

fn push(e: &Emitter, shaping: Option<&LightShaping>, out: &mut Vec<SceneLight>) -> Result<(), LightError> {
    let shaping = core_shaping(shaping)?;
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
            push_triangle_lights(positions, triangles, *radiance, *two_sided, out)?;
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
    format!("{}{shaped}{textured}", emitter_line(l))
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
