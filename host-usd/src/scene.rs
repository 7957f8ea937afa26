//! What an import yields: plain data in the renderer's frame (Y up, scene units), with no
//! openusd types, so host-std converts it without knowing USD.

pub use crate::instanced::{Instance, Instanced, Prototype};
pub use crate::material::{Lobes, Material, Texture, TextureInput};
use crate::render_settings::Conform;
use glam::{DMat3, Vec2, Vec3};
use std::path::PathBuf;

/// The stage's up axis. A Z-up stage is rotated once into the renderer's Y-up frame
/// (geometry, camera and lights alike): (x, y, z) → (x, z, −y).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpAxis {
    /// Y up: the renderer's own frame.
    Y,
    /// Z up: rotated into Y up on import.
    Z,
}

/// A triangle mesh in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// The prim it came from (an instance proxy or a PointInstancer instance is named by
    /// its prim path, with `[i]` for the instance).
    pub path: String,
    /// Points in world space.
    pub positions: Box<[Vec3]>,
    /// Counter-clockwise front faces (USD's `orientation` and negative-determinant
    /// transforms already applied).
    pub triangles: Box<[[u32; 3]]>,
    /// Per-triangle corner shading normals, or empty for face normals.
    pub normals: Box<[[Vec3; 3]]>,
    /// Per-triangle corner texture coordinates (read only when a material on the mesh is
    /// textured), or empty.
    pub uvs: Box<[[Vec2; 3]]>,
    /// Index into [`UsdScene::materials`].
    pub material: usize,
    /// `doubleSided`: back faces shade like front faces.
    pub double_sided: bool,
}

// A stage of many small meshes holds one record per mesh until the renderer takes them:
// its lists are exactly their length, with no capacity word.
const _: () = assert!(std::mem::size_of::<Mesh>() == 104);

/// An exact sphere (a UsdGeomSphere under a similarity transform).
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    /// The Sphere prim (or instance) it came from.
    pub path: String,
    /// Centre in world space.
    pub center: Vec3,
    /// Radius in world units.
    pub radius: f32,
    /// Index into [`UsdScene::materials`].
    pub material: usize,
    /// `doubleSided`: back faces shade like front faces.
    pub double_sided: bool,
}

/// The DomeLight: radiance = texture · color · intensity · 2^exposure.
#[derive(Clone, Debug, PartialEq)]
pub struct Dome {
    /// The DomeLight prim.
    pub path: String,
    /// A lat-long image (name for messages, and its bytes); `None` for a constant dome.
    pub texture: Option<(String, Vec<u8>)>,
    /// color · intensity · 2^exposure.
    pub radiance: Vec3,
    /// Maps the lat-long's local frame (top pole +Y, centre +Z, u = ¼ → +X) to the
    /// renderer's world: the up-axis conversion · the light's world rotation · the pole
    /// axis correction.
    pub map_to_world: DMat3,
}

/// The camera in world space; field of view from focal length and apertures.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// The Camera prim.
    pub path: String,
    /// Position in world space.
    pub origin: Vec3,
    /// Viewing direction (unit).
    pub forward: Vec3,
    /// Up direction (unit, orthogonal to `forward`).
    pub up: Vec3,
    /// `focalLength`, in the apertures' units.
    pub focal_length: f32,
    /// `horizontalAperture`.
    pub horizontal_aperture: f32,
    /// `verticalAperture`.
    pub vertical_aperture: f32,
    /// Near clipping distance (`clippingRange`'s first value), in world units.
    pub near: f32,
}

impl Camera {
    /// Vertical field of view (degrees) for an image of `aspect` = width/height, conforming
    /// the aperture by expanding it (UsdRender's default `expandAperture`).
    pub fn fov_y_deg(&self, aspect: f32) -> f32 {
        let (_, v, _) = Conform::ExpandAperture.apply((self.horizontal_aperture, self.vertical_aperture), 1, 1, aspect);
        self.fov_y_from_aperture(v)
    }

    /// The vertical field of view (degrees) and pixel aspect ratio of an image of `width` ×
    /// `height` pixels of aspect `pixel_aspect`, the aperture fitted to it by `conform`.
    pub fn conformed(&self, width: u32, height: u32, pixel_aspect: f32, conform: Conform) -> (f32, f32) {
        let aperture = (self.horizontal_aperture, self.vertical_aperture);
        let (_, v, pixel_aspect) = conform.apply(aperture, width, height, pixel_aspect);
        (self.fov_y_from_aperture(v), pixel_aspect)
    }

    fn fov_y_from_aperture(&self, vertical_aperture: f32) -> f32 {
        (2.0 * (0.5 * vertical_aperture / self.focal_length).atan()).to_degrees()
    }
}

/// A prim or feature the importer did not render, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct Skip {
    /// The prim (or property) left out.
    pub path: String,
    /// What was left out and why, one line.
    pub what: String,
}

/// Counts for `ppis info` and the import summary.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Counts {
    /// Prims traversed (prototypes' included).
    pub prims: usize,
    /// Mesh prims rendered.
    pub meshes: usize,
    /// Gprims of every kind rendered.
    pub gprims: usize,
    /// Triangles of every mesh.
    pub triangles: usize,
    /// Instance proxies and PointInstancer instances that were rendered.
    pub instances: usize,
    /// Gprims and instancers not rendered: invisible, or of a purpose not rendered.
    pub hidden: usize,
}

/// An imported scene.
#[derive(Clone, Debug, PartialEq)]
pub struct UsdScene {
    /// The file imported.
    pub file: PathBuf,
    /// The stage's `upAxis`.
    pub up_axis: UpAxis,
    /// The stage's `metersPerUnit`.
    pub meters_per_unit: f64,
    /// The time code values were read at.
    pub time_code: crate::stage::TimeCode,
    /// The stage's `startTimeCode` and `endTimeCode`, when both are authored.
    pub time_code_range: Option<(f64, f64)>,
    /// The identifiers of every layer the import read (the root layer, its sublayers, the
    /// layers of references and payloads; `pkg.usdz[inner.usdc]` inside a package).
    pub layers: Vec<String>,
    /// Triangle meshes in world space.
    pub meshes: Vec<Mesh>,
    /// PointInstancer instances not made meshes: their prototypes' triangles, read once, and
    /// where each instance places them ([`UsdScene::all_meshes`] places them).
    pub instanced: Instanced,
    /// Exact spheres.
    pub spheres: Vec<Sphere>,
    /// Every material a mesh or sphere refers to.
    pub materials: Vec<Material>,
    /// The DomeLight, if the stage has one.
    pub dome: Option<Dome>,
    /// The other UsdLux lights rendered (distant, sphere, rect, disk, cylinder, mesh lights).
    pub lights: Vec<crate::lights::UsdLight>,
    /// The camera to render through, if the stage has one.
    pub camera: Option<Camera>,
    /// The UsdRenderSettings that apply (`render_settings`), if the stage has any.
    pub render_settings: Option<crate::render_settings::RenderSettings>,
    /// World bounds of the geometry (min, max), Y up.
    pub bounds: Option<(Vec3, Vec3)>,
    /// Everything left out, with why.
    pub skipped: Vec<Skip>,
    /// What was imported, counted.
    pub counts: Counts,
    /// Wall time of the import.
    pub import_seconds: f64,
}

impl UsdScene {
    /// Every mesh, the instances' placed, in the order the import met them.
    pub fn all_meshes(&self) -> Vec<Mesh> {
        let instanced = &self.instanced;
        let mut all = Vec::with_capacity(self.meshes.len() + instanced.instances.len());
        let mut taken = 0;
        for (i, inst) in instanced.instances.iter().enumerate() {
            let upto = inst.after_meshes as usize;
            all.extend_from_slice(&self.meshes[taken..upto]);
            taken = upto;
            all.extend((0..instanced.groups(i)).map(|g| instanced.mesh(i, g)));
        }
        all.extend_from_slice(&self.meshes[taken..]);
        all
    }
}
