//! The scene model: camera, shapes with materials, an optional environment light and any
//! number of other lights, as every loader fills it (the built-in scene, the JSON reader, the
//! USD importer).

use super::InstancesHandle;
use crate::light::environment::{EnvSource, Placement};
use sampler_core::brdf::{Brdf, CarPaint, Lambert, Phong, RoughConductor};
use sampler_core::glam::{Vec2, Vec3};
use sampler_core::light::{LightSurface, SceneLight};

/// A pinhole camera, the scene format's exact convention (see `camera.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpec {
    /// Eye position.
    pub origin: Vec3,
    /// The point looked at.
    pub target: Vec3,
    /// Up direction (need not be orthogonal to the view).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Pixel width over pixel height (1 for square pixels).
    pub pixel_aspect: f32,
    /// Distance below which primary hits are ignored.
    pub near_clip: f32,
}

/// Geometry of one shape.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// The points p0 + s·e1 + t·e2, s, t ∈ [0, 1]; front normal normalize(e1 × e2).
    Rectangle {
        /// A corner.
        p0: Vec3,
        /// The first edge from `p0`.
        e1: Vec3,
        /// The second edge from `p0`.
        e2: Vec3,
    },
    /// Triangles (counter-clockwise front faces); optional per-corner shading normals
    /// (empty: face normals) and texture coordinates (empty: none).
    Mesh {
        /// Vertex positions.
        positions: Box<[Vec3]>,
        /// Vertex indices per triangle.
        triangles: Box<[[u32; 3]]>,
        /// Per triangle, its corners' shading normals (empty: face normals).
        normals: Box<[[Vec3; 3]]>,
        /// Per triangle, its corners' texture coordinates (empty: none).
        uvs: Box<[[Vec2; 3]]>,
    },
    /// One material's triangles of one instance of a shared prototype, placed when a render
    /// gathers them ([`super::Instances::mesh`]).
    Instance {
        /// The set it belongs to.
        set: InstancesHandle,
        /// Which instance of the set.
        instance: u32,
        /// Which of its prototype's material groups.
        group: u32,
    },
}

/// A material: one of the core's BRDFs, one- or two-sided, optionally varying over the
/// surface with textures (then `bsdf` is its value at the textures' means).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The BRDF (where textured, its value at the textures' means).
    pub bsdf: Bsdf,
    /// Seen from the back, a one-sided surface reflects nothing.
    pub twosided: bool,
    /// Textures varying the BRDF over the surface.
    pub texture: Option<TextureHandle>,
}

impl Material {
    /// An untextured material.
    pub fn new(bsdf: Bsdf, twosided: bool) -> Self {
        Self { bsdf, twosided, texture: None }
    }
}

/// A material whose BRDF depends on texture coordinates.
pub trait Textured: std::fmt::Debug + Send + Sync {
    /// The BRDF at texture coordinate `st`.
    fn bsdf_at(&self, st: Vec2) -> Bsdf;
}

/// A shared [`Textured`] material (equal when it is the same one).
#[derive(Clone, Debug)]
pub struct TextureHandle(pub std::sync::Arc<dyn Textured>);

impl PartialEq for TextureHandle {
    fn eq(&self, other: &Self) -> bool {
        std::sync::Arc::ptr_eq(&self.0, &other.0)
    }
}

/// The built-in BRDFs, by value (enum dispatch; each is a few floats).
#[derive(Clone, Debug, PartialEq)]
pub enum Bsdf {
    /// Lambertian diffuse.
    Diffuse(Lambert),
    /// GGX rough conductor.
    Conductor(RoughConductor),
    /// Modified Phong.
    Phong(Phong),
    /// Car paint: a clear coat over flakes over a diffuse base.
    CarPaint(CarPaint),
}

impl Bsdf {
    /// The BRDF behind the enum, for the core's estimators.
    pub fn as_brdf(&self) -> &dyn Brdf {
        match self {
            Bsdf::Diffuse(b) => b,
            Bsdf::Conductor(b) => b,
            Bsdf::Phong(b) => b,
            Bsdf::CarPaint(b) => b,
        }
    }

    /// A short name for summaries.
    pub fn kind(&self) -> &'static str {
        match self {
            Bsdf::Diffuse(_) => "diffuse",
            Bsdf::Conductor(_) => "roughconductor",
            Bsdf::Phong(_) => "phong",
            Bsdf::CarPaint(_) => "carpaint",
        }
    }

    /// The kind with its lobe width where the kind has one ("roughconductor α=0.05",
    /// "phong n=200"): reports group pixels by it, since a product sampler's gain depends on
    /// how sharp the lobe is against the lighting.
    pub fn label(&self) -> String {
        match self {
            Bsdf::Conductor(c) => format!("roughconductor α={}", c.ggx.alpha()),
            Bsdf::Phong(p) => format!("phong n={}", p.exponent),
            _ => self.kind().to_string(),
        }
    }
}

/// One shape and the index of its material.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Its geometry.
    pub shape: Shape,
    /// Index into the scene's materials.
    pub material: usize,
}

/// A whole scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// For messages and reports.
    pub name: String,
    /// The camera.
    pub camera: CameraSpec,
    /// Every shape.
    pub objects: Vec<Object>,
    /// The materials objects index.
    pub materials: Vec<Material>,
    /// The environment light, if any.
    pub env: Option<(EnvSource, Placement)>,
    /// The other lights (a mesh light is one triangle light per face); area lights are
    /// surfaces too, seen by camera rays and occluding like any shape.
    pub lights: Vec<SceneLight>,
    /// Camera rays that miss return 0 instead of the environment, and area lights seen
    /// directly are black.
    pub hide_emitters: bool,
}

impl Scene {
    /// Triangles a render will intersect (rectangles count 2, spheres 0), emitters' included.
    pub fn triangle_count(&self) -> usize {
        let emitters: usize = self
            .lights
            .iter()
            .map(|l| match l.surface() {
                Some(LightSurface::Rect { .. }) => 2,
                Some(LightSurface::Triangle(_)) => 1,
                _ => 0,
            })
            .sum();
        let shapes: usize = self
            .objects
            .iter()
            .map(|o| match &o.shape {
                Shape::Mesh { triangles, .. } => triangles.len(),
                Shape::Instance { set, instance, group } => set.0.triangle_count(*instance, *group),
                Shape::Rectangle { .. } => 2,
                Shape::Sphere { .. } => 0,
            })
            .sum();
        shapes + emitters
    }

    /// There is light to shade with: an environment or another light.
    pub fn is_lit(&self) -> bool {
        self.env.is_some() || !self.lights.is_empty()
    }
}
