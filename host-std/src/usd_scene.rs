//! USD scenes through host-usd: the imported plain data becomes the renderer's [`Scene`].
//! Textures feeding a UsdPreviewSurface input are decoded and reduced to their mean (the
//! tracer has no texture lookups yet); every reduction and skip is reported.

use crate::env_io;
use crate::environment::{EnvSource, Placement};
use crate::scene::{Bsdf, CameraSpec, Material, Object, Scene, Shape};
use host_usd::{Lobes, TextureInput, UsdScene};
use sampler_core::brdf::{CarPaint, Lambert, RoughConductor, microfacet::Ggx};
use sampler_core::glam::{Mat3, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Image width of a USD scene's render; the height follows the camera's aperture.
pub const DEFAULT_WIDTH: u32 = 640;

/// A converted scene and the notes to show the user (skips, texture reductions).
pub struct Converted {
    pub scene: Scene,
    pub notes: Vec<String>,
    pub usd: UsdScene,
}

/// Imports `path` and converts it.
pub fn load(path: &Path, camera: Option<String>) -> anyhow::Result<Converted> {
    let usd = host_usd::load_with(path, &host_usd::Options { camera })?;
    Ok(convert(usd))
}

/// A texture's file name with a usable extension (`pkg.usdz[tex/a.png]` → `pkg.usdz/tex/a.png`).
fn texture_name(resolved: &str) -> PathBuf {
    PathBuf::from(resolved.replace('[', "/").replace(']', ""))
}

/// The mean of a decoded texture's channel after the UsdUVTexture's scale and bias.
fn texture_mean(t: &host_usd::Texture) -> Result<[f32; 3], String> {
    let bytes = t.bytes.as_ref().map_err(Clone::clone)?;
    let name = texture_name(t.resolved.as_deref().unwrap_or(&t.authored));
    let image = env_io::load_bytes(&name, bytes).map_err(|e| e.to_string())?;
    let mean = crate::resample::equal_area_mean(&image.texels);
    let rgb: [f32; 3] = std::array::from_fn(|c| mean[c] as f32 * t.scale[c] + t.bias[c]);
    Ok(match t.channel.as_str() {
        "r" => [rgb[0]; 3],
        "g" => [rgb[1]; 3],
        "b" => [rgb[2]; 3],
        // Alpha is not decoded: opaque.
        "a" => [t.scale[3] + t.bias[3]; 3],
        _ => rgb,
    })
}

/// The core BRDF for a UsdPreviewSurface's lobes: the cheapest one that represents them.
fn bsdf(l: &Lobes) -> Bsdf {
    let zero = |v: Vec3| v.max_element() <= 0.0;
    if l.clearcoat <= 0.0 && zero(l.specular) {
        Bsdf::Diffuse(Lambert::new(l.diffuse))
    } else if l.clearcoat <= 0.0 && zero(l.diffuse) {
        Bsdf::Conductor(RoughConductor::new(l.alpha.sqrt(), l.specular))
    } else {
        Bsdf::CarPaint(CarPaint {
            base: l.diffuse,
            flake: l.specular,
            flake_ggx: Ggx::new(l.alpha.sqrt()),
            coat: l.clearcoat,
            coat_ggx: Ggx::new(l.clearcoat_alpha.sqrt()),
            coat_f0: 0.04,
        })
    }
}

/// Converts an imported USD scene.
pub fn convert(mut usd: UsdScene) -> Converted {
    let mut notes: Vec<String> = usd.skipped.iter().map(|s| format!("{}: {}", s.path, s.what)).collect();
    for m in &mut usd.materials {
        for t in std::mem::take(&mut m.textures) {
            match texture_mean(&t) {
                Ok(v) => {
                    match t.input {
                        TextureInput::DiffuseColor => m.diffuse_color = Vec3::from_array(v),
                        TextureInput::SpecularColor => m.specular_color = Vec3::from_array(v),
                        TextureInput::Metallic => m.metallic = v[0],
                        TextureInput::Roughness => m.roughness = v[0],
                    }
                    notes.push(format!("{}: texture {} reduced to its mean {:?}", m.name, t.authored, v));
                }
                Err(e) => notes.push(format!("{}: texture {} not used ({e}); fallback value", m.name, t.authored)),
            }
        }
    }
    // One renderer material per (USD material, sidedness).
    let mut materials = Vec::new();
    let mut index: HashMap<(usize, bool), usize> = HashMap::new();
    let mut material = |m: usize, twosided: bool| {
        *index.entry((m, twosided)).or_insert_with(|| {
            materials.push(Material { bsdf: bsdf(&usd.materials[m].lobes()), twosided });
            materials.len() - 1
        })
    };
    let mut objects = Vec::new();
    for s in &usd.spheres {
        let shape = Shape::Sphere { center: s.center, radius: s.radius };
        objects.push(Object { shape, material: material(s.material, s.double_sided) });
    }
    for m in &usd.meshes {
        let shape =
            Shape::Mesh { positions: m.positions.clone(), triangles: m.triangles.clone(), normals: m.normals.clone() };
        objects.push(Object { shape, material: material(m.material, m.double_sided) });
    }
    let cam = usd.camera.clone().unwrap_or_else(|| host_usd::camera::framing((Vec3::splat(-1.0), Vec3::ONE)));
    let aspect = cam.horizontal_aperture / cam.vertical_aperture;
    let height = ((DEFAULT_WIDTH as f32 / aspect).round() as u32).max(1);
    let camera = CameraSpec {
        origin: cam.origin,
        target: cam.origin + cam.forward,
        up: cam.up,
        fov_y_deg: cam.fov_y_deg(aspect),
        width: DEFAULT_WIDTH,
        height,
        near_clip: cam.near,
    };
    let env = usd.dome.as_ref().map(|d| {
        let placement = Placement {
            tint: d.radiance.to_array(),
            rotation: Mat3::from_cols_array(&d.map_to_world.to_cols_array().map(|x| x as f32)),
            ..Placement::default()
        };
        let source = match &d.texture {
            Some((name, bytes)) => {
                EnvSource::Bytes { name: texture_name(name), bytes: Arc::new(bytes.clone()), latlong: true }
            }
            None => EnvSource::Constant { level: 3 },
        };
        (source, placement)
    });
    let name = usd.file.file_name().map_or_else(|| "usd".into(), |n| n.to_string_lossy().into_owned());
    let scene = Scene { name, camera, objects, materials, env, hide_emitters: false };
    Converted { scene, notes, usd }
}
