//! The one walk over the stage: each prim is read when the walk enters it, so the stage
//! composes each prim once and frees it when the walk leaves it (`Stage::walk`). What
//! needs more than the prim and its ancestors waits: the camera until the render settings
//! are read after the walk, a PointInstancer until the prims of its prototypes have been
//! walked.

use super::{Failure, GPRIMS, Importer, OTHER_LIGHTS, SKELETAL, STRUCTURE, UpAxis, dome, fail};
use crate::stage::{PrimPath, Step};

/// Why a walk stops before the end.
pub(super) enum Stop {
    /// A prim cannot be imported.
    Failed(Failure),
    /// A PointInstancer names a prototype the walk has already imported in place.
    Restart,
}

impl From<String> for Stop {
    fn from(message: String) -> Self {
        Stop::Failed(("/".into(), message))
    }
}

impl From<Failure> for Stop {
    fn from(f: Failure) -> Self {
        Stop::Failed(f)
    }
}

impl Stop {
    /// The failure, for a walk that cannot restart.
    pub(super) fn failure(self) -> Failure {
        match self {
            Stop::Failed(f) => f,
            Stop::Restart => ("/".into(), "the PointInstancers' prototypes are not known after a full walk".into()),
        }
    }
}

impl Importer<'_> {
    /// Walks the stage once, importing every prim.
    pub(super) fn walk(&mut self) -> Result<(), Stop> {
        let stage = self.stage;
        stage.walk(|step| match step {
            Step::Enter(prim) => self.enter(&prim),
            Step::Leave(prim) => Ok(self.instancers_after(Some(&prim))?),
        })?;
        self.instancers_after(None)?;
        self.drop_light_surfaces();
        Ok(())
    }

    fn enter(&mut self, prim: &PrimPath) -> Result<(), Stop> {
        let stage = self.stage;
        self.scene.counts.prims += 1;
        let t = stage.type_name(prim).map_err(fail(prim))?;
        let t = t.as_str();
        if t == "PointInstancer" {
            // Registered even inside a prototype: its own prototypes render only through it.
            self.register_instancer(prim)?;
        }
        if self.prototypes.contains(prim) {
            let kept = GPRIMS.contains(&t) || crate::lights::KINDS.contains(&t);
            if kept && !self.hidden(prim).map_err(fail(prim))? {
                self.prototype_gprim(prim, t).map_err(fail(prim))?;
            } else if !kept && !STRUCTURE.contains(&t) && t != "PointInstancer" {
                // A dome, GeometryLight, portal or any other prim an instance cannot carry.
                self.skip(prim, format!("{t} inside a PointInstancer prototype: not rendered"));
            }
            return Ok(());
        }
        if GPRIMS.contains(&t) || t == "PointInstancer" {
            if self.hidden(prim).map_err(fail(prim))? {
                self.scene.counts.hidden += 1;
                return Ok(());
            }
            let world = self.worlds.world(stage, prim).map_err(fail(prim))?;
            if t == "PointInstancer" {
                self.prototypes.wait(prim, world);
            } else {
                let proxy = stage.is_instance_proxy(prim).map_err(fail(prim))?;
                self.scene.counts.instances += usize::from(proxy);
                if stage.applied_schemas(prim).map_err(fail(prim))?.iter().any(|s| s == "MeshLightAPI") {
                    return Ok(self.mesh_light(prim, t).map_err(fail(prim))?);
                }
                if !self.light_geometry.is_empty() && self.light_geometry.contains_key(&prim.to_string()) {
                    // A GeometryLight met earlier made it a light.
                    return Ok(());
                }
                self.gprim(prim, t, &prim.to_string(), &(self.conversion * world)).map_err(fail(prim))?;
            }
        } else if t == "Camera" {
            self.cameras.push(prim.clone());
        } else if t == "RenderSettings" {
            self.settings.push(prim.clone());
        } else if t == "DomeLight" || t == "DomeLight_1" {
            if self.scene.dome.is_some() {
                self.skip(prim, "a second DomeLight; only the first lights the scene");
                return Ok(());
            }
            if self.hidden(prim).map_err(fail(prim))? {
                self.skip(prim, "invisible DomeLight");
                return Ok(());
            }
            let world = self.worlds.world(stage, prim).map_err(fail(prim))?;
            let z_up = self.scene.up_axis == UpAxis::Z;
            let (d, notes) = dome::read(stage, prim, t, z_up, &world, &self.conversion).map_err(fail(prim))?;
            notes.into_iter().for_each(|n| self.skip(prim, n));
            self.scene.dome = Some(d);
        } else if crate::lights::KINDS.contains(&t) {
            self.light(prim, t).map_err(fail(prim))?;
        } else if t == "GeometryLight" {
            self.geometry_light(prim).map_err(fail(prim))?;
        } else if OTHER_LIGHTS.contains(&t) {
            self.skip(prim, format!("{t} not rendered"));
        } else if SKELETAL.contains(&t) {
            self.skip(prim, format!("{t}: skinning not applied (meshes render in their rest pose)"));
        } else if !STRUCTURE.contains(&t) {
            self.skip(prim, format!("prim type {t} not rendered"));
        }
        Ok(())
    }
}
