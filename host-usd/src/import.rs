//! The importer: walks the composed stage once and turns what it renders into a
//! [`UsdScene`], recording everything it leaves out.

use crate::error::UsdError;
use crate::inherit::Hidden;
use crate::scene::{Counts, Skip, UpAxis, UsdScene};
use crate::stage::{PrimPath, Stage, TimeCode, Value};
use crate::xform::{WorldTransforms, up_axis_conversion};
use crate::{camera, dome, render_settings};
use glam::DMat4;
use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

mod geometry_light;
mod gprim;
mod lights;
mod material_binding;
mod prototypes;
mod walk;

use prototypes::{Prototypes, prototype_roots};
use walk::Stop;

/// Import options.
#[derive(Clone, Debug)]
pub struct Options {
    /// The camera prim to use (default: the render settings' camera, else the stage's first).
    pub camera: Option<String>,
    /// The RenderSettings prim to use (default: the layer's `renderSettingsPrimPath`).
    pub render_settings: Option<String>,
    /// Leave the stage (its layers) allocated when the import returns instead of freeing
    /// it: work that a process about to exit (`ppis info`) need not do. The stage's memory
    /// is never returned.
    pub leak_stage: bool,
    /// The time code the stage is read at (default: [`TimeCode::Earliest`], as `usdrecord`
    /// renders without a frame).
    pub time: TimeCode,
}

impl Default for Options {
    fn default() -> Self {
        Self { camera: None, render_settings: None, leak_stage: false, time: TimeCode::Earliest }
    }
}

/// Gprim types the importer renders.
pub const GPRIMS: [&str; 7] = ["Mesh", "Sphere", "Cube", "Cylinder", "Cone", "Capsule", "Plane"];
/// Prim types that carry no geometry of their own.
const STRUCTURE: [&str; 10] = [
    "",
    "Xform",
    "Scope",
    "Material",
    "Shader",
    "NodeGraph",
    "GeomSubset",
    "Camera",
    "RenderSettings",
    "RenderProduct",
];
/// Lights not rendered (the others are `crate::lights::KINDS`, the dome, MeshLightAPI and
/// GeometryLight).
const OTHER_LIGHTS: [&str; 2] = ["PortalLight", "PluginLight"];
const SKELETAL: [&str; 4] = ["SkelRoot", "Skeleton", "SkelAnimation", "BlendShape"];

struct Importer<'a> {
    stage: &'a Stage,
    conversion: DMat4,
    worlds: WorldTransforms,
    hidden: Hidden,
    scene: UsdScene,
    materials: HashMap<String, usize>,
    /// PointInstancer prototypes, the gprims under them and the instancers waiting for them.
    prototypes: Prototypes,
    /// The Camera prims in walk order: the one rendered is chosen after the walk, once the
    /// render settings (which may name it) are read.
    cameras: Vec<PrimPath>,
    /// The RenderSettings prims in walk order.
    settings: Vec<PrimPath>,
    /// The gprims GeometryLights have made lights, which the walk does not also import as
    /// surfaces, each with whether it is a Mesh prim.
    light_geometry: HashMap<String, bool>,
}

/// Imports a USD file with default options.
pub fn load(file: &Path) -> Result<UsdScene, UsdError> {
    load_with(file, &Options::default())
}

/// Opens the stage to read at `time`, with errors naming the file. A layer, reference or
/// payload that cannot be found or read does not stop the import (Pixar's library opens such
/// stages too): the import lists it among the skips.
pub fn open(file: &Path, time: TimeCode) -> Result<Stage, UsdError> {
    if !file.is_file() {
        return Err(UsdError::NotFound { file: file.to_owned() });
    }
    crate::guard::guarded(file, || {
        Stage::open(file, time).map_err(|message| UsdError::Open { file: file.to_owned(), message })
    })
}

/// Imports a USD file. A corrupt file that makes the USD reader panic is an error too.
pub fn load_with(file: &Path, options: &Options) -> Result<UsdScene, UsdError> {
    crate::guard::guarded(file, || load_unguarded(file, options))
}

fn load_unguarded(file: &Path, options: &Options) -> Result<UsdScene, UsdError> {
    let t0 = Instant::now();
    let stage = open(file, options.time)?;
    let at = |prim: &str| {
        let (file, prim) = (file.to_owned(), prim.to_string());
        move |message: String| UsdError::Prim { file, prim, message }
    };
    let mut skipped: Vec<Skip> = stage
        .composition_errors()
        .into_iter()
        .map(|e| Skip { path: "/".into(), what: format!("composition: {e} (the prims it would bring are absent)") })
        .collect();
    let up = stage.metadata("upAxis").map_err(at("/"))?;
    let up_axis = match up.as_ref().and_then(Value::token) {
        Some("Z") => UpAxis::Z,
        None | Some("Y") => UpAxis::Y,
        Some(other) => {
            skipped.push(Skip { path: "/".into(), what: format!("upAxis {other:?} is not Y or Z; treated as Y") });
            UpAxis::Y
        }
    };
    let meters_per_unit = stage.metadata("metersPerUnit").map_err(at("/"))?.and_then(|v| v.scalar()).unwrap_or(0.01);
    let opened_skips = skipped.len();
    let scene = UsdScene {
        file: file.to_owned(),
        up_axis,
        meters_per_unit,
        time_code: stage.time(),
        time_code_range: stage.time_code_range(),
        layers: Vec::new(),
        meshes: Vec::new(),
        instanced: Default::default(),
        spheres: Vec::new(),
        materials: Vec::new(),
        dome: None,
        lights: Vec::new(),
        camera: None,
        render_settings: None,
        bounds: None,
        skipped,
        counts: Counts::default(),
        import_seconds: 0.0,
    };
    let fail = |(prim, message): Failure| UsdError::Prim { file: file.to_owned(), prim, message };
    let mut imp = walk(&stage, scene).map_err(fail)?;
    let (settings, notes) =
        render_settings::read(&stage, &imp.settings, options.render_settings.as_deref()).map_err(fail)?;
    let where_ = settings.as_ref().map_or("/", |s| s.path.as_str()).to_string();
    let at_notes = imp.scene.skipped.len().min(opened_skips);
    let notes = notes.into_iter().map(|n| Skip { path: where_.clone(), what: n });
    imp.scene.skipped.splice(at_notes..at_notes, notes);
    let mut options = options.clone();
    if let Some(s) = settings {
        options.camera = options.camera.or_else(|| s.camera.clone());
        imp.scene.render_settings = Some(s);
    }
    imp.camera(options.camera.as_deref()).map_err(fail)?;
    let mut scene = imp.scene;
    scene.layers = stage.layers();
    if let Some(name) = &options.camera
        && scene.camera.as_ref().is_none_or(|c| &c.path != name)
    {
        let by = scene.render_settings.as_ref().filter(|s| s.camera.as_ref() == Some(name));
        let message = by.map_or_else(|| "no such camera".into(), |s| format!("no such camera (named by {})", s.path));
        return Err(UsdError::Prim { file: file.to_owned(), prim: name.clone(), message });
    }
    if scene.camera.is_none()
        && let Some(b) = scene.bounds
    {
        scene.camera = Some(camera::framing(b));
    }
    scene.import_seconds = t0.elapsed().as_secs_f64();
    if options.leak_stage {
        std::mem::forget(stage);
    }
    Ok(scene)
}

type Failure = (String, String);

/// The stage's prims imported into `scene` by one walk, or two when a PointInstancer names a
/// prototype that the first walk has already imported in place.
fn walk<'a>(stage: &'a Stage, scene: UsdScene) -> Result<Importer<'a>, Failure> {
    let mut imp = Importer::new(stage, scene.clone(), Prototypes::default());
    match imp.walk() {
        Ok(()) => Ok(imp),
        Err(Stop::Restart) => {
            let mut imp = Importer::new(stage, scene, Prototypes::known(prototype_roots(stage)?));
            imp.walk().map_err(Stop::failure)?;
            Ok(imp)
        }
        Err(stop) => Err(stop.failure()),
    }
}

/// The failure of `prim` with message `m`, for `map_err`: the path is written out only
/// on failure (it is as long as the prim is deep).
fn fail(prim: &PrimPath) -> impl FnOnce(String) -> Failure + '_ {
    move |m| (prim.to_string(), m)
}

impl<'a> Importer<'a> {
    fn new(stage: &'a Stage, scene: UsdScene, prototypes: Prototypes) -> Self {
        Importer {
            stage,
            conversion: up_axis_conversion(scene.up_axis == UpAxis::Z),
            worlds: WorldTransforms::default(),
            hidden: Hidden::default(),
            scene,
            materials: HashMap::new(),
            prototypes,
            cameras: Vec::new(),
            settings: Vec::new(),
            light_geometry: HashMap::new(),
        }
    }

    /// The camera rendered: the first Camera prim the walk met, or the one `wanted` names.
    fn camera(&mut self, wanted: Option<&str>) -> Result<(), Failure> {
        let stage = self.stage;
        let cameras = std::mem::take(&mut self.cameras);
        let Some(prim) = cameras.iter().find(|c| wanted.is_none_or(|w| *w == c.to_string())) else {
            return Ok(());
        };
        let world = self.conversion * self.worlds.world(stage, prim).map_err(fail(prim))?;
        let (c, notes) = camera::read(stage, prim, &world).map_err(fail(prim))?;
        notes.into_iter().for_each(|n| self.skip(prim, n));
        self.scene.camera = Some(c);
        Ok(())
    }

    fn skip(&mut self, path: &(impl std::fmt::Display + ?Sized), what: impl Into<String>) {
        self.scene.skipped.push(Skip { path: path.to_string(), what: what.into() });
    }

    /// Invisible, or a proxy/guide purpose.
    fn hidden(&mut self, prim: &PrimPath) -> Result<bool, String> {
        self.hidden.hidden(self.stage, prim)
    }
}
