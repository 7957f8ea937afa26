//! The scene format's `lights` (docs/scene-format.md, "lights"): point, sphere, rectangle,
//! disk, mesh and distant lights, as the core's lights, each but the distant one optionally
//! shaped (`json_shaping.rs`). A mesh light becomes one triangle light per face with an area.
//! Every value is checked: a light that cannot be built is an error naming it and what is wrong.

use crate::scene::json_shaping::JsonShaping;
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
        #[serde(default)]
        shaping: Option<JsonShaping>,
    },
    Sphere {
        center: [f32; 3],
        radius: f32,
        radiance: [f32; 3],
        #[serde(default)]
        shaping: Option<JsonShaping>,
    },
    Rectangle {
        p0: [f32; 3],
        e1: [f32; 3],
        e2: [f32; 3],
        radiance: [f32; 3],
        #[serde(default)]
        shaping: Option<JsonShaping>,
    },
    Disk {
        center: [f32; 3],
        normal: [f32; 3],
        radius: f32,
        radiance: [f32; 3],
        #[serde(default)]
        shaping: Option<JsonShaping>,
    },
    Mesh {
        file: PathBuf,
        #[serde(default)]
        to_world: Option<[[f32; 4]; 4]>,
        radiance: [f32; 3],
        #[serde(default)]
        shaping: Option<JsonShaping>,
    },
    Distant {
        direction: [f32; 3],
        irradiance: [f32; 3],
        #[serde(default)]
        angle_deg: f32,
    },
}

impl JsonLight {
    /// The files this light reads (relative to the scene file): a mesh light's mesh, a shaped
    /// light's IES profile.
    pub(super) fn files(&self) -> impl Iterator<Item = &Path> {
        let (mesh, shaping) = match self {
            JsonLight::Mesh { file, shaping, .. } => (Some(file.as_path()), shaping.as_ref()),
            JsonLight::Point { shaping, .. }
            | JsonLight::Sphere { shaping, .. }
            | JsonLight::Rectangle { shaping, .. }
            | JsonLight::Disk { shaping, .. } => (None, shaping.as_ref()),
            JsonLight::Distant { .. } => (None, None),
        };
        mesh.into_iter().chain(shaping.and_then(JsonShaping::file))
    }
}

/// The core's shaping of `shaping` (none: [`Shaping::NONE`]), about `front` by default.
fn shaping_of(shaping: Option<&JsonShaping>, front: Option<Vec3>, dir: &Path) -> Result<Shaping, String> {
    shaping.map_or(Ok(Shaping::NONE), |s| s.build(front, dir))
}

/// The core's lights for one entry (several for a mesh), with relative mesh and IES paths
/// resolved against `dir`; or what is wrong with it.
pub(super) fn lights_of(light: JsonLight, dir: &Path) -> Result<Vec<SceneLight>, String> {
    let v = Vec3::from_array;
    let bad = |e: sampler_core::light::LightError| e.to_string();
    Ok(match light {
        JsonLight::Point { position, intensity, shaping } => {
            let s = shaping_of(shaping.as_ref(), None, dir)?;
            vec![PointLight::new(v(position), v(intensity)).map_err(bad)?.with_shaping(s).into()]
        }
        JsonLight::Sphere { center, radius, radiance, shaping } => {
            let s = shaping_of(shaping.as_ref(), None, dir)?;
            vec![SphereLight::new(v(center), radius, v(radiance)).map_err(bad)?.with_shaping(s).into()]
        }
        JsonLight::Rectangle { p0, e1, e2, radiance, shaping } => {
            let rect = RectLight::new(v(p0), v(e1), v(e2), v(radiance)).map_err(bad)?;
            let s = shaping_of(shaping.as_ref(), Some(rect.normal()), dir)?;
            vec![rect.with_shaping(s).into()]
        }
        JsonLight::Disk { center, normal, radius, radiance, shaping } => {
            let disk = DiskLight::new(v(center), v(normal), radius, v(radiance)).map_err(bad)?;
            let s = shaping_of(shaping.as_ref(), Some(v(normal).normalize()), dir)?;
            vec![disk.with_shaping(s).into()]
        }
        JsonLight::Distant { direction, irradiance, angle_deg } => {
            if !angle_deg.is_finite() {
                return Err(format!("angle_deg must be finite, got {angle_deg}"));
            }
            vec![DistantLight::new(v(direction), v(irradiance), angle_deg.to_radians()).map_err(bad)?.into()]
        }
        JsonLight::Mesh { file, to_world, radiance, shaping } => {
            let s = shaping_of(shaping.as_ref(), None, dir)?;
            mesh_light(&dir.join(file), to_world, v(radiance), s)?
        }
    })
}

/// The triangles of a mesh light, each a light (faces without an area are left out).
fn mesh_light(
    file: &Path,
    to_world: Option<[[f32; 4]; 4]>,
    radiance: Vec3,
    shaping: Shaping,
) -> Result<Vec<SceneLight>, String> {
    let (positions, triangles) = mesh::load_placed(file, to_world).map_err(|e| e.to_string())?;
    let mut lights = Vec::with_capacity(triangles.len());
    match push_triangle_lights(&positions, &triangles, radiance, false, shaping, &mut lights) {
        Ok(0) => Err(format!("{}: no face of the mesh has an area", file.display())),
        Ok(_) => Ok(lights),
        Err(e) => Err(format!("{}: {e}", file.display())),
    }
}
