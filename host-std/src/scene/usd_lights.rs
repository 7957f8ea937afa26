//! A USD stage's UsdLux lights (host-usd's [`host_usd::lights::UsdLight`], radiometry already
//! per the schema) as the core's lights: a mesh light or a CylinderLight becomes one triangle
//! light per face with an area. A light the core cannot build is a note naming its prim.

use crate::scene::mesh_light::push_triangle_lights;
use host_usd::lights::{Emitter, UsdLight};
use sampler_core::light::{DiskLight, DistantLight, LightError, PointLight, RectLight, SceneLight, SphereLight};

/// The core's lights for `lights`, with a note in `notes` for each one that cannot be built.
pub(crate) fn convert(lights: &[UsdLight], notes: &mut Vec<String>) -> Vec<SceneLight> {
    let mut out = Vec::new();
    for l in lights {
        if let Err(e) = push(&l.emitter, &mut out) {
            notes.push(format!("{}: {} not rendered ({e})", l.path, l.prim_type));
        }
    }
    out
}

fn push(e: &Emitter, out: &mut Vec<SceneLight>) -> Result<(), LightError> {
    match e {
        Emitter::Point { position, intensity } => out.push(PointLight::new(*position, *intensity)?.into()),
        Emitter::Sphere { center, radius, radiance } => out.push(SphereLight::new(*center, *radius, *radiance)?.into()),
        Emitter::Rect { p0, e1, e2, radiance } => out.push(RectLight::new(*p0, *e1, *e2, *radiance)?.into()),
        Emitter::Disk { center, normal, radius, radiance } => {
            out.push(DiskLight::new(*center, *normal, *radius, *radiance)?.into())
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

/// One line per light for `ppis info`: its prim, kind and what it emits.
pub fn describe(l: &UsdLight) -> String {
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
