//! The JSON scene format of docs/scene-format.md:
//! camera, environment, lights (`json_lights.rs`), spheres, rectangles and meshes with diffuse,
//! rough-conductor, Phong and car-paint materials. Unknown fields are errors: a misspelt key must not silently render
//! something else.

use crate::light::environment::{EnvSource, Placement};
use crate::scene::json_lights::{self, JsonLight};
use crate::scene::mesh;
use crate::scene::{Bsdf, CameraSpec, Material, Object, Scene, Shape};
use sampler_core::brdf::{CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::glam::Vec3;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Why a JSON scene cannot be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file cannot be read.
    #[error("{path}: cannot read the scene: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        error: std::io::Error,
    },
    /// The file is not valid scene JSON.
    #[error("{path}: invalid scene JSON: {message}")]
    Json {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// The file is well-formed but describes something invalid.
    #[error("{path}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A mesh the scene names cannot be loaded.
    #[error(transparent)]
    Mesh(#[from] mesh::MeshError),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonScene {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    envmap: Option<JsonEnv>,
    camera: JsonCamera,
    #[serde(default)]
    lights: Vec<JsonLight>,
    shapes: Vec<JsonShape>,
    #[serde(default)]
    hide_emitters: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonEnv {
    file: PathBuf,
    #[serde(default = "one")]
    scale: f32,
    #[serde(default)]
    rotate_y_deg: f32,
}

fn one() -> f32 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JsonCamera {
    origin: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
    fov_y_deg: f32,
    width: u32,
    height: u32,
    #[serde(default = "near")]
    near_clip: f32,
}

fn near() -> f32 {
    1e-3
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum JsonShape {
    Sphere {
        center: [f32; 3],
        radius: f32,
        material: JsonMaterial,
    },
    Rectangle {
        p0: [f32; 3],
        e1: [f32; 3],
        e2: [f32; 3],
        material: JsonMaterial,
    },
    Mesh {
        file: PathBuf,
        #[serde(default)]
        to_world: Option<[[f32; 4]; 4]>,
        #[serde(default = "yes")]
        face_normals: bool,
        material: JsonMaterial,
    },
}

fn yes() -> bool {
    true
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum JsonMaterial {
    Diffuse {
        albedo: [f32; 3],
        #[serde(default)]
        twosided: bool,
    },
    Roughconductor {
        #[serde(default = "ggx")]
        distribution: String,
        alpha: f32,
        #[serde(default = "white")]
        specular: [f32; 3],
        #[serde(default)]
        twosided: bool,
    },
    Phong {
        exponent: f32,
        #[serde(default)]
        kd: [f32; 3],
        #[serde(default = "white")]
        ks: [f32; 3],
        #[serde(default)]
        twosided: bool,
    },
    Carpaint {
        #[serde(default)]
        base: Option<[f32; 3]>,
        #[serde(default)]
        flake: Option<[f32; 3]>,
        #[serde(default)]
        flake_alpha: Option<f32>,
        #[serde(default)]
        coat: Option<f32>,
        #[serde(default)]
        coat_alpha: Option<f32>,
        #[serde(default)]
        twosided: bool,
    },
}

fn ggx() -> String {
    "ggx".into()
}

fn white() -> [f32; 3] {
    [1.0; 3]
}

/// Reads a scene file; relative paths inside it are relative to the file.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|error| SceneError::Io { path: path.to_owned(), error })?;
    parse(&text, path)
}

/// The files a scene file reads besides itself — its meshes, mesh lights, IES profiles and
/// environment map — as [`load`] resolves them.
pub fn files_read(path: &Path) -> Result<Vec<PathBuf>, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|error| SceneError::Io { path: path.to_owned(), error })?;
    let json: JsonScene =
        serde_json::from_str(&text).map_err(|e| SceneError::Json { path: path.to_owned(), message: e.to_string() })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let meshes = json.shapes.into_iter().filter_map(|s| match s {
        JsonShape::Mesh { file, .. } => Some(dir.join(file)),
        _ => None,
    });
    let mesh_lights: Vec<PathBuf> = json.lights.iter().flat_map(|l| l.files().map(|f| dir.join(f))).collect();
    Ok(meshes.chain(mesh_lights).chain(json.envmap.map(|e| dir.join(e.file))).collect())
}

/// Parses scene JSON; `path` names the file in errors and anchors relative paths.
pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let json: JsonScene =
        serde_json::from_str(text).map_err(|e| SceneError::Json { path: path.to_owned(), message: e.to_string() })?;
    let invalid = |message: String| SceneError::Invalid { path: path.to_owned(), message };
    let dir = path.parent().unwrap_or(Path::new("."));
    let v = |a: [f32; 3]| Vec3::from_array(a);
    let c = &json.camera;
    let finite = |xs: &[f32]| xs.iter().all(|x| x.is_finite());
    if c.width == 0 || c.height == 0 || c.width > 16_384 || c.height > 16_384 {
        return Err(invalid(format!("camera: width and height must be in 1..=16384, got {}×{}", c.width, c.height)));
    }
    if !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0) {
        return Err(invalid(format!("camera: fov_y_deg must be in (0, 180), got {}", c.fov_y_deg)));
    }
    let forward = v(c.target) - v(c.origin);
    if !finite(&[c.origin, c.target, c.up].concat())
        || forward.length() == 0.0
        || forward.cross(v(c.up)).length() == 0.0
    {
        return Err(invalid("camera: origin, target and up must be finite, distinct and not collinear".into()));
    }
    let camera = CameraSpec {
        origin: v(c.origin),
        target: v(c.target),
        up: v(c.up),
        fov_y_deg: c.fov_y_deg,
        width: c.width,
        height: c.height,
        pixel_aspect: 1.0,
        near_clip: c.near_clip.max(0.0),
    };
    let mut materials = Vec::new();
    let mut objects = Vec::new();
    for (k, shape) in json.shapes.into_iter().enumerate() {
        let (shape, material) = match shape {
            JsonShape::Sphere { center, radius, material } => {
                if !(radius > 0.0 && radius.is_finite() && finite(&center)) {
                    return Err(invalid(format!("shapes[{k}]: sphere needs a finite center and a radius > 0")));
                }
                (Shape::Sphere { center: v(center), radius }, material)
            }
            JsonShape::Rectangle { p0, e1, e2, material } => {
                if !finite(&[p0, e1, e2].concat()) || v(e1).cross(v(e2)).length() == 0.0 {
                    return Err(invalid(format!("shapes[{k}]: rectangle needs finite, non-parallel edges")));
                }
                (Shape::Rectangle { p0: v(p0), e1: v(e1), e2: v(e2) }, material)
            }
            JsonShape::Mesh { file, to_world, face_normals, material } => {
                if !face_normals {
                    return Err(invalid(format!("shapes[{k}]: only face normals are supported (face_normals: true)")));
                }
                let (positions, triangles) = mesh::load_placed(&dir.join(file), to_world)?;
                let shape = Shape::Mesh {
                    positions: positions.into(),
                    triangles: triangles.into(),
                    normals: Box::new([]),
                    uvs: Box::new([]),
                };
                (shape, material)
            }
        };
        materials.push(material_of(material).map_err(|m| invalid(format!("shapes[{k}].material: {m}")))?);
        objects.push(Object { shape, material: materials.len() - 1 });
    }
    let mut lights = Vec::new();
    for (k, light) in json.lights.into_iter().enumerate() {
        lights.extend(json_lights::lights_of(light, dir).map_err(|m| invalid(format!("lights[{k}]: {m}")))?);
    }
    let env = json.envmap.map(|e| {
        (
            EnvSource::File(dir.join(e.file)),
            Placement { scale: e.scale, rotate_y_deg: e.rotate_y_deg, ..Placement::default() },
        )
    });
    let name =
        json.name.unwrap_or_else(|| path.file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned()));
    Ok(Scene { name, camera, objects, materials, env, lights, hide_emitters: json.hide_emitters })
}

fn material_of(m: JsonMaterial) -> Result<Material, String> {
    let v = |a: [f32; 3]| Vec3::from_array(a);
    let colour = |name: &str, a: [f32; 3]| {
        if a.iter().all(|c| c.is_finite() && *c >= 0.0) {
            Ok(v(a))
        } else {
            Err(format!("{name} must be finite and ≥ 0"))
        }
    };
    Ok(match m {
        JsonMaterial::Diffuse { albedo, twosided } => {
            Material::new(Bsdf::Diffuse(Lambert::new(colour("albedo", albedo)?)), twosided)
        }
        JsonMaterial::Roughconductor { distribution, alpha, specular, twosided } => {
            if distribution != "ggx" {
                return Err(format!("distribution \"{distribution}\" is not supported (only \"ggx\")"));
            }
            if !(alpha > 0.0 && alpha.is_finite()) {
                return Err(format!("alpha must be > 0, got {alpha}"));
            }
            Material::new(Bsdf::Conductor(RoughConductor::new(alpha, colour("specular", specular)?)), twosided)
        }
        JsonMaterial::Phong { exponent, kd, ks, twosided } => {
            if !(exponent >= 0.0 && exponent.is_finite()) {
                return Err(format!("exponent must be ≥ 0, got {exponent}"));
            }
            Material::new(Bsdf::Phong(Phong::new(colour("kd", kd)?, colour("ks", ks)?, exponent)), twosided)
        }
        JsonMaterial::Carpaint { base, flake, flake_alpha, coat, coat_alpha, twosided } => {
            let d = CarPaint::default();
            let p = CarPaint::new(
                base.map(|b| colour("base", b)).transpose()?.unwrap_or(d.base),
                flake.map(|b| colour("flake", b)).transpose()?.unwrap_or(d.flake),
                flake_alpha.unwrap_or(d.flake_ggx.alpha()),
                coat.unwrap_or(d.coat).max(0.0),
                coat_alpha.unwrap_or(d.coat_ggx.alpha()),
            );
            Material::new(Bsdf::CarPaint(p), twosided)
        }
    })
}
