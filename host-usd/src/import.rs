//! The importer: walks the composed stage once and turns what it renders into a
//! [`UsdScene`], recording everything it leaves out.

use crate::error::UsdError;
use crate::inherit::Hidden;
use crate::scene::{Counts, Skip, UpAxis, UsdScene};
use crate::stage::{PrimPath, Stage, TimeCode, Value};
use crate::xform::{WorldTransforms, up_axis_conversion};
use crate::{camera, dome, instancer, render_settings};
use glam::DMat4;
use std::collections::HashMap;
use std::path::Path;
use std::time::Instant;

mod gprim;
mod material_binding;

/// Import options.
#[derive(Clone, Debug)]
pub struct Options {
    /// The camera prim to use (default: the render settings' camera, else the stage's first).
    pub camera: Option<String>,
    /// The RenderSettings prim to use (default: the layer's `renderSettingsPrimPath`).
    pub render_settings: Option<String>,
    /// Leave the composed stage allocated when the import returns instead of freeing it.
    /// Freeing a large stage is a tenth to a fifth of its import; a process about to exit
    /// (`ppis info`) need not pay it. The stage's memory is never returned.
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
const OTHER_LIGHTS: [&str; 7] =
    ["SphereLight", "RectLight", "DiskLight", "DistantLight", "CylinderLight", "GeometryLight", "PortalLight"];
const SKELETAL: [&str; 4] = ["SkelRoot", "Skeleton", "SkelAnimation", "BlendShape"];

struct Importer<'a> {
    stage: &'a Stage,
    conversion: DMat4,
    worlds: WorldTransforms,
    hidden: Hidden,
    scene: UsdScene,
    materials: HashMap<String, usize>,
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
    let scene = UsdScene {
        file: file.to_owned(),
        up_axis,
        meters_per_unit,
        time_code: stage.time(),
        time_code_range: stage.time_code_range(),
        layers: Vec::new(),
        meshes: Vec::new(),
        spheres: Vec::new(),
        materials: Vec::new(),
        dome: None,
        camera: None,
        render_settings: None,
        bounds: None,
        skipped,
        counts: Counts::default(),
        import_seconds: 0.0,
    };
    let mut imp = Importer {
        stage: &stage,
        conversion: up_axis_conversion(up_axis == UpAxis::Z),
        worlds: WorldTransforms::default(),
        hidden: Hidden::default(),
        scene,
        materials: HashMap::new(),
    };
    let prims = stage.prims().map_err(at("/"))?;
    let fail = |(prim, message)| UsdError::Prim { file: file.to_owned(), prim, message };
    let (settings, notes) = render_settings::read(&stage, &prims, options.render_settings.as_deref()).map_err(fail)?;
    let where_ = settings.as_ref().map_or("/", |s| s.path.as_str()).to_string();
    notes.into_iter().for_each(|n| imp.skip(&where_, n));
    let mut options = options.clone();
    if let Some(s) = settings {
        options.camera = options.camera.or_else(|| s.camera.clone());
        imp.scene.render_settings = Some(s);
    }
    imp.walk(&prims, &options).map_err(fail)?;
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

/// The failure of `prim` with message `m`, for `map_err`: the path is written out only
/// on failure (it is as long as the prim is deep).
fn fail(prim: &PrimPath) -> impl FnOnce(String) -> Failure + '_ {
    move |m| (prim.to_string(), m)
}

impl Importer<'_> {
    fn skip(&mut self, path: &(impl std::fmt::Display + ?Sized), what: impl Into<String>) {
        self.scene.skipped.push(Skip { path: path.to_string(), what: what.into() });
    }

    fn walk(&mut self, prims: &[PrimPath], options: &Options) -> Result<(), Failure> {
        let stage = self.stage;
        // Each prim's type, read once for both passes.
        let types = prims.iter().map(|p| stage.type_name(p).map_err(fail(p))).collect::<Result<Vec<_>, _>>()?;
        // Prototypes render only through their instancers.
        let mut prototypes: Vec<PrimPath> = Vec::new();
        for (prim, t) in prims.iter().zip(&types) {
            if t == "PointInstancer" {
                prototypes.extend(stage.targets(prim, "prototypes").map_err(fail(prim))?);
            }
        }
        let in_prototype = |p: &PrimPath| prototypes.iter().any(|r| p.is_at_or_below(r));
        for (prim, type_name) in prims.iter().zip(&types) {
            self.scene.counts.prims += 1;
            if in_prototype(prim) {
                continue;
            }
            let t = type_name.as_str();
            if GPRIMS.contains(&t) || t == "PointInstancer" {
                if self.hidden(prim).map_err(fail(prim))? {
                    self.scene.counts.hidden += 1;
                    continue;
                }
                let world = self.worlds.world(stage, prim).map_err(fail(prim))?;
                if t == "PointInstancer" {
                    self.instancer(prim, prims, &world)?;
                } else {
                    let proxy = stage.is_instance_proxy(prim).map_err(fail(prim))?;
                    self.scene.counts.instances += usize::from(proxy);
                    self.gprim(prim, t, &prim.to_string(), &(self.conversion * world)).map_err(fail(prim))?;
                }
            } else if t == "Camera" {
                let wanted = options.camera.as_deref().is_none_or(|c| *c == prim.to_string());
                if self.scene.camera.is_none() && wanted {
                    let world = self.conversion * self.worlds.world(stage, prim).map_err(fail(prim))?;
                    let (c, notes) = camera::read(stage, prim, &world).map_err(fail(prim))?;
                    notes.into_iter().for_each(|n| self.skip(prim, n));
                    self.scene.camera = Some(c);
                }
            } else if t == "DomeLight" || t == "DomeLight_1" {
                if self.scene.dome.is_some() {
                    self.skip(prim, "a second DomeLight; only the first lights the scene");
                    continue;
                }
                if self.hidden(prim).map_err(fail(prim))? {
                    self.skip(prim, "invisible DomeLight");
                    continue;
                }
                let world = self.worlds.world(stage, prim).map_err(fail(prim))?;
                let z_up = self.scene.up_axis == UpAxis::Z;
                let (d, notes) = dome::read(stage, prim, t, z_up, &world, &self.conversion).map_err(fail(prim))?;
                notes.into_iter().for_each(|n| self.skip(prim, n));
                self.scene.dome = Some(d);
            } else if OTHER_LIGHTS.contains(&t) {
                self.skip(prim, format!("{t} not rendered (only a DomeLight lights the scene)"));
            } else if SKELETAL.contains(&t) {
                self.skip(prim, format!("{t}: skinning not applied (meshes render in their rest pose)"));
            } else if !STRUCTURE.contains(&t) {
                self.skip(prim, format!("prim type {t} not rendered"));
            }
        }
        Ok(())
    }

    /// Invisible, or a proxy/guide purpose.
    fn hidden(&mut self, prim: &PrimPath) -> Result<bool, String> {
        self.hidden.hidden(self.stage, prim)
    }

    fn instancer(&mut self, prim: &PrimPath, prims: &[PrimPath], world: &DMat4) -> Result<(), Failure> {
        let stage = self.stage;
        let (protos, instances) = instancer::read(stage, prim).map_err(fail(prim))?;
        // Each prototype's renderable prims, with their transform relative to the
        // prototype root's parent.
        let mut parts: Vec<Vec<(PrimPath, String, DMat4)>> = Vec::new();
        for root in &protos {
            let mut list = Vec::new();
            for p in prims.iter().filter(|p| p.is_at_or_below(root)) {
                let t = stage.type_name(p).map_err(fail(p))?;
                if GPRIMS.contains(&t.as_str()) && !self.hidden(p).map_err(fail(p))? {
                    let rel = self.worlds.relative_to(stage, p, root).map_err(fail(p))?;
                    list.push((p.clone(), t, rel));
                }
            }
            parts.push(list);
        }
        for inst in &instances {
            for (p, t, rel) in &parts[inst.prototype] {
                let m = self.conversion * *world * inst.transform * *rel;
                let label = format!("{p}[{prim}:{}]", inst.index);
                self.gprim(p, t, &label, &m).map_err(fail(p))?;
            }
        }
        self.scene.counts.instances += instances.len();
        Ok(())
    }
}
