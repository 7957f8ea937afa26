//! The scene format's `lights` (docs/scene-format.md, "lights"): point, sphere, rectangle,
//! disk, mesh and distant lights, as the core's lights. A mesh light becomes one triangle light
//! per face with an area. Every value is checked: a light that cannot be built is an error
//! naming it and what is wrong.

use crate::scene::mesh;
use crate::scene::mesh_light::push_triangle_lights;
use sampler_core::glam::Vec3;
use sampler_core::light::{DiskLight, DistantLight, PointLight, RectLight, SceneLight, Shaping, SphereLight};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// One entry of `lights`.
#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub(super) enum JsonLight {
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
    },
    Sphere {
        center: [f32; 3],
        radius: f32,
        radiance: [f32; 3],
    },
    Rectangle {
        p0: [f32; 3],
        e1: [f32; 3],
        e2: [f32; 3],
        radiance: [f32; 3],
    },
    Disk {
        center: [f32; 3],
        normal: [f32; 3],
        radius: f32,
        radiance: [f32; 3],
    },
    Mesh {
        file: PathBuf,
        #[serde(default)]
        to_world: Option<[[f32; 4]; 4]>,
        radiance: [f32; 3],
    },
    Distant {
        direction: [f32; 3],
        irradiance: [f32; 3],
        #[serde(default)]
        angle_deg: f32,
    },
}

impl JsonLight {
    /// The mesh file this light reads, if it is a mesh light (relative to the scene file).
    pub(super) fn file(&self) -> Option<&Path> {
        match self {
            JsonLight::Mesh { file, .. } => Some(file),
            _ => None,
        }
    }
}

/// The core's lights for one entry (several for a mesh), with relative mesh paths resolved
/// against `dir`; or what is wrong with it.
pub(super) fn lights_of(light: JsonLight, dir: &Path) -> Result<Vec<SceneLight>, String> {
    let v = Vec3::from_array;
    let bad = |e: sampler_core::light::LightError| e.to_string();
    Ok(match light {
        JsonLight::Point { position, intensity } => {
            vec![PointLight::new(v(position), v(intensity)).map_err(bad)?.into()]
        }
        JsonLight::Sphere { center, radius, radiance } => {
            vec![SphereLight::new(v(center), radius, v(radiance)).map_err(bad)?.into()]
        }
        JsonLight::Rectangle { p0, e1, e2, radiance } => {
            vec![RectLight::new(v(p0), v(e1), v(e2), v(radiance)).map_err(bad)?.into()]
        }
        JsonLight::Disk { center, normal, radius, radiance } => {
            vec![DiskLight::new(v(center), v(normal), radius, v(radiance)).map_err(bad)?.into()]
        }
        JsonLight::Distant { direction, irradiance, angle_deg } => {
            if !angle_deg.is_finite() {
                return Err(format!("angle_deg must be finite, got {angle_deg}"));
            }
            vec![DistantLight::new(v(direction), v(irradiance), angle_deg.to_radians()).map_err(bad)?.into()]
        }
        JsonLight::Mesh { file, to_world, radiance } => mesh_light(&dir.join(file), to_world, v(radiance))?,
    })
}

/// The triangles of a mesh light, each a light (faces without an area are left out).
fn mesh_light(file: &Path, to_world: Option<[[f32; 4]; 4]>, radiance: Vec3) -> Result<Vec<SceneLight>, String> {
    let (positions, triangles) = mesh::load_placed(file, to_world).map_err(|e| e.to_string())?;
    let mut lights = Vec::with_capacity(triangles.len());
    match push_triangle_lights(&positions, &triangles, radiance, false, Shaping::NONE, &mut lights) {
        Ok(0) => Err(format!("{}: no face of the mesh has an area", file.display())),
        Ok(_) => Ok(lights),
        Err(e) => Err(format!("{}: {e}", file.display())),
    }
}
