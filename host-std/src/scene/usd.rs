//! USD scenes through host-usd: the imported plain data becomes the renderer's [`Scene`].
//! Textures feeding a UsdPreviewSurface input (diffuse and specular colour, metallic,
//! roughness) are decoded and looked up at each hit's texture coordinates; every skip is
//! reported.

use crate::light::environment::{EnvSource, Placement};
use crate::light::image_file;
use crate::scene::texture::{ImageTexture, Wrap};
use crate::scene::{
    Bsdf, CameraSpec, Instances, InstancesHandle, Material, Object, Scene, Shape, TextureHandle, Textured,
};
pub use host_usd::TimeCode;
use host_usd::{Lobes, TextureInput, UsdScene};
use sampler_core::brdf::{CarPaint, Lambert, RoughConductor};
use sampler_core::glam::{Mat3, Vec2, Vec3};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Image width of a USD scene's render; the height follows the camera's aperture.
pub const DEFAULT_WIDTH: u32 = 640;

/// A converted scene and the notes to show the user (skips, texture reductions).
pub struct Converted {
    /// The renderer's scene.
    pub scene: Scene,
    /// What the import left out or reduced, one line each.
    pub notes: Vec<String>,
    /// The import, without its meshes and instances (their geometry is in `scene`; `usd.counts`
    /// counts them).
    pub usd: UsdScene,
    /// Every file the import read: its layers, the textures and the dome's map (a package
    /// once for everything inside it), sorted.
    pub files: Vec<PathBuf>,
}

/// How a USD scene is to be imported and framed: the command line's choices.
#[derive(Clone, Debug)]
pub struct Options {
    /// The camera prim (default: the render settings', else the stage's first camera).
    pub camera: Option<String>,
    /// The RenderSettings prim (default: the layer's `renderSettingsPrimPath`).
    pub render_settings: Option<String>,
    /// Image width, overriding the render settings' resolution.
    pub width: Option<u32>,
    /// Image height, overriding the render settings' resolution.
    pub height: Option<u32>,
    /// Leave the composed stage allocated after the import (host-usd's
    /// `Options::leak_stage`): for a process that exits once it has shown the import.
    pub leak_stage: bool,
    /// The time code the stage is read at (default: the earliest, as host-usd's).
    pub time: TimeCode,
}

impl Default for Options {
    fn default() -> Self {
        let time = host_usd::Options::default().time;
        Self { camera: None, render_settings: None, width: None, height: None, leak_stage: false, time }
    }
}

/// Imports `path` and converts it.
pub fn load(path: &Path, options: &Options) -> anyhow::Result<Converted> {
    let import = host_usd::Options {
        camera: options.camera.clone(),
        render_settings: options.render_settings.clone(),
        leak_stage: options.leak_stage,
        time: options.time,
    };
    let usd = host_usd::load_with(path, &import)?;
    convert(usd, (options.width, options.height))
}

/// The image size: `size`'s overrides, else the render settings' resolution, else
/// [`DEFAULT_WIDTH`] wide; a dimension that neither gives follows the aperture's aspect.
fn image_size(usd: &UsdScene, cam: &host_usd::Camera, size: (Option<u32>, Option<u32>)) -> (u32, u32) {
    if let Some(s) = &usd.render_settings {
        return (size.0.unwrap_or(s.resolution.0), size.1.unwrap_or(s.resolution.1));
    }
    let aspect = cam.horizontal_aperture / cam.vertical_aperture;
    match size {
        (Some(w), Some(h)) => (w, h),
        (Some(w), None) => (w, ((w as f32 / aspect).round() as u32).max(1)),
        (None, Some(h)) => (((h as f32 * aspect).round() as u32).max(1), h),
        (None, None) => (DEFAULT_WIDTH, ((DEFAULT_WIDTH as f32 / aspect).round() as u32).max(1)),
    }
}

/// The files behind the stage's layers, textures and dome map: an asset inside a package
/// (`pkg.usdz[tex/a.png]`) is the package's file; identifiers that are not files (anonymous
/// layers) are left out.
fn files_read(usd: &UsdScene) -> Vec<PathBuf> {
    let textures = usd.materials.iter().flat_map(|m| &m.textures).filter_map(|t| t.source.resolved.as_deref());
    let dome = usd.dome.iter().filter_map(|d| d.texture.as_ref().map(|(name, _)| name.as_str()));
    let lights = usd.lights.iter().flat_map(|l| {
        let texture = l.texture.as_ref().map(|t| t.name.as_str());
        texture.into_iter().chain(l.ies.as_ref().map(|i| i.name.as_str()))
    });
    let mut files: Vec<PathBuf> = (usd.layers.iter().map(String::as_str).chain(textures).chain(dome).chain(lights))
        .map(|id| PathBuf::from(id.split_once('[').map_or(id, |(file, _)| file)))
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files.dedup();
    files
}

/// A texture's file name with a usable extension (`pkg.usdz[tex/a.png]` → `pkg.usdz/tex/a.png`).
pub(crate) fn texture_name(resolved: &str) -> PathBuf {
    PathBuf::from(resolved.replace('[', "/").replace(']', ""))
}

/// Which of a texture's outputs an input reads.
#[derive(Clone, Copy, Debug)]
enum Channel {
    Rgb,
    One(usize),
    /// Alpha is not decoded: the texture reads as opaque (1).
    Alpha,
}

/// One textured input of a UsdPreviewSurface.
#[derive(Debug)]
struct Map {
    input: TextureInput,
    texture: ImageTexture,
    scale: [f32; 4],
    bias: [f32; 4],
    channel: Channel,
}

impl Map {
    fn decode(t: &host_usd::Texture) -> Result<Self, String> {
        let bytes = t.bytes.as_ref().map_err(Clone::clone)?;
        let src = &t.source;
        let name = texture_name(src.resolved.as_deref().unwrap_or(&src.authored));
        let srgb = match src.color_space.as_str() {
            "raw" => Some(false),
            "sRGB" => Some(true),
            _ => None,
        };
        let image = image_file::load_bytes_as(&name, bytes, srgb).map_err(|e| e.to_string())?;
        let channel = match src.channel.as_str() {
            "r" => Channel::One(0),
            "g" => Channel::One(1),
            "b" => Channel::One(2),
            "a" => Channel::Alpha,
            _ => Channel::Rgb,
        };
        let wrap = [Wrap::from_usd(&src.wrap[0]), Wrap::from_usd(&src.wrap[1])];
        Ok(Map { input: t.input, texture: ImageTexture { image, wrap }, scale: src.scale, bias: src.bias, channel })
    }

    /// The input's value from texel value `rgb`.
    fn value(&self, rgb: [f32; 3]) -> [f32; 3] {
        let v: [f32; 3] = std::array::from_fn(|c| rgb[c] * self.scale[c] + self.bias[c]);
        match self.channel {
            Channel::Rgb => v,
            Channel::One(c) => [v[c]; 3],
            Channel::Alpha => [self.scale[3] + self.bias[3]; 3],
        }
    }

    fn apply(&self, m: &mut host_usd::Material, v: [f32; 3]) {
        match self.input {
            TextureInput::DiffuseColor => m.diffuse_color = Vec3::from_array(v),
            TextureInput::SpecularColor => m.specular_color = Vec3::from_array(v),
            TextureInput::Metallic => m.metallic = v[0],
            TextureInput::Roughness => m.roughness = v[0],
        }
    }

    /// The input's mean over the texture (for surfaces without texture coordinates).
    fn mean(&self) -> [f32; 3] {
        let mean = crate::light::resample::equal_area_mean(&self.texture.image.texels);
        self.value(mean.map(|m| m as f32))
    }
}

/// A UsdPreviewSurface whose inputs are read from textures at each hit.
#[derive(Debug)]
struct TexturedPreview {
    base: host_usd::Material,
    maps: Vec<Map>,
}

impl Textured for TexturedPreview {
    fn bsdf_at(&self, st: Vec2) -> Bsdf {
        let b = &self.base;
        let mut m = host_usd::Material { name: String::new(), textures: Vec::new(), ..*b };
        for map in &self.maps {
            map.apply(&mut m, map.value(map.texture.eval(st)));
        }
        bsdf(&m.lobes())
    }
}

/// The core BRDF for a UsdPreviewSurface's lobes: the cheapest one that represents them.
/// The lobes' α are GGX roughness already (roughness², `host_usd::Lobes`), which is what the
/// core's constructors take.
fn bsdf(l: &Lobes) -> Bsdf {
    let zero = |v: Vec3| v.max_element() <= 0.0;
    if l.clearcoat <= 0.0 && zero(l.specular) {
        Bsdf::Diffuse(Lambert::new(l.diffuse))
    } else if l.clearcoat <= 0.0 && zero(l.diffuse) {
        Bsdf::Conductor(RoughConductor::new(l.alpha, l.specular))
    } else {
        Bsdf::CarPaint(CarPaint::new(l.diffuse, l.specular, l.alpha, l.clearcoat, l.clearcoat_alpha))
    }
}

/// A USD scene's PointInstancer instances, placed as the import placed meshes.
#[derive(Debug)]
struct UsdInstances(host_usd::Instanced);

impl Instances for UsdInstances {
    fn mesh(&self, instance: u32, group: u32) -> Shape {
        let m = self.0.placed(instance as usize, group as usize);
        Shape::Mesh { positions: m.positions, triangles: m.triangles, normals: m.normals, uvs: m.uvs }
    }

    fn triangle_count(&self, instance: u32, group: u32) -> usize {
        let inst = &self.0.instances[instance as usize];
        self.0.prototypes[inst.prototype as usize].groups[group as usize].1.len()
    }

    fn count_triangles(&self, instance: u32, group: u32, counted: &dyn Fn([Vec3; 3]) -> bool) -> usize {
        thread_local! {
            static POINTS: std::cell::RefCell<Vec<Vec3>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let mut n = 0;
        POINTS.with_borrow_mut(|points| {
            self.0.for_each_triangle(instance as usize, group as usize, points, |t| n += usize::from(counted(t)))
        });
        n
    }
}

/// Converts an imported USD scene, rendered at `size` (width, height) where given; an error
/// when a light's IES file cannot be parsed.
pub fn convert(mut usd: UsdScene, size: (Option<u32>, Option<u32>)) -> anyhow::Result<Converted> {
    let files = files_read(&usd);
    let mut notes: Vec<String> = usd.skipped.iter().map(|s| format!("{}: {}", s.path, s.what)).collect();
    // Decode each material's textures; the material's plain BRDF is its value at their means.
    let mut textured: Vec<Option<TextureHandle>> = Vec::with_capacity(usd.materials.len());
    for m in &mut usd.materials {
        let mut maps = Vec::new();
        for t in std::mem::take(&mut m.textures) {
            match Map::decode(&t) {
                Ok(map) => maps.push(map),
                Err(e) => {
                    notes.push(format!("{}: texture {} not used ({e}); fallback value", m.name, t.source.authored))
                }
            }
        }
        for map in &maps {
            let v = map.mean();
            map.apply(m, v);
        }
        textured.push((!maps.is_empty()).then(|| {
            let base = host_usd::Material { name: m.name.clone(), textures: Vec::new(), ..*m };
            TextureHandle(Arc::new(TexturedPreview { base, maps }))
        }));
    }
    // One renderer material per (USD material, sidedness).
    let mut materials = Vec::new();
    let mut index: HashMap<(usize, bool), usize> = HashMap::new();
    let mut material = |m: usize, twosided: bool| {
        *index.entry((m, twosided)).or_insert_with(|| {
            let texture = textured[m].clone();
            materials.push(Material { bsdf: bsdf(&usd.materials[m].lobes()), twosided, texture });
            materials.len() - 1
        })
    };
    let spheres: Vec<Object> = usd
        .spheres
        .iter()
        .map(|s| Object {
            shape: Shape::Sphere { center: s.center, radius: s.radius },
            material: material(s.material, s.double_sided),
        })
        .collect();
    // The geometry moves into the scene: a large mesh is held once. The meshes become
    // objects in their own list's memory (an object is no larger than a mesh record), so
    // the two lists of a stage of many small meshes are not held at once; the spheres
    // go first, as they always have.
    let meshes = std::mem::take(&mut usd.meshes);
    let instanced = std::mem::take(&mut usd.instanced);
    let mesh_object = |m: host_usd::Mesh, material: &mut dyn FnMut(usize, bool) -> usize| {
        let shape = Shape::Mesh { positions: m.positions, triangles: m.triangles, normals: m.normals, uvs: m.uvs };
        Object { shape, material: material(m.material, m.double_sided) }
    };
    let objects = if instanced.instances.is_empty() {
        let meshes: Vec<Object> = meshes.into_iter().map(|m| mesh_object(m, &mut material)).collect();
        if spheres.is_empty() {
            meshes
        } else {
            let mut all = spheres;
            all.reserve_exact(meshes.len());
            all.extend(meshes);
            all
        }
    } else {
        // Each instance's objects among the meshes, where the import met it.
        let mut all = spheres;
        let mut meshes = meshes.into_iter();
        let mut taken = 0;
        let set = Arc::new(UsdInstances(instanced));
        let handle = InstancesHandle(set.clone());
        // Each prototype's groups' materials, found on its first instance (materials are
        // numbered in the order objects first use them).
        let mut group_materials: Vec<Vec<usize>> = vec![Vec::new(); set.0.prototypes.len()];
        for (i, inst) in set.0.instances.iter().enumerate() {
            let upto = inst.after_meshes as usize;
            all.extend(meshes.by_ref().take(upto - taken).map(|m| mesh_object(m, &mut material)));
            taken = upto;
            let proto = &set.0.prototypes[inst.prototype as usize];
            let found = &mut group_materials[inst.prototype as usize];
            if found.is_empty() {
                found.extend(proto.groups.iter().map(|(m, _)| material(*m, proto.double_sided)));
            }
            for (g, &m) in found.iter().enumerate() {
                let shape = Shape::Instance { set: handle.clone(), instance: i as u32, group: g as u32 };
                all.push(Object { shape, material: m });
            }
        }
        all.extend(meshes.map(|m| mesh_object(m, &mut material)));
        all
    };
    let cam = usd.camera.clone().unwrap_or_else(|| host_usd::camera::framing((Vec3::splat(-1.0), Vec3::ONE)));
    let (width, height) = image_size(&usd, &cam, size);
    let (pixel_aspect, conform) =
        usd.render_settings.as_ref().map_or((1.0, Default::default()), |s| (s.pixel_aspect, s.conform));
    let (fov_y_deg, pixel_aspect) = cam.conformed(width, height, pixel_aspect, conform);
    let camera = CameraSpec {
        origin: cam.origin,
        target: cam.origin + cam.forward,
        up: cam.up,
        fov_y_deg,
        width,
        height,
        pixel_aspect,
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
    let lights = crate::scene::usd_lights::convert(&usd.lights, &mut notes).map_err(anyhow::Error::msg)?;
    let scene = Scene { name, camera, objects, materials, env, lights, hide_emitters: false };
    Ok(Converted { scene, notes, usd, files })
}
