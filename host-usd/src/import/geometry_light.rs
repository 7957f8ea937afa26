//! GeometryLight (deprecated by UsdLux in favour of MeshLightAPI, still in the schema): the
//! gprims its `geometry` relationship targets emit with the GeometryLight's LightAPI inputs
//! and shaping, as a MeshLightAPI mesh with those inputs would. Each targeted gprim is a
//! light only, not also a surface (as a MeshLightAPI mesh is), whichever of the two prims the
//! walk meets first.

use super::lights::LightPrim;
use super::{GPRIMS, Importer};
use crate::stage::PrimPath;

impl Importer<'_> {
    /// A GeometryLight prim: each gprim it targets becomes a mesh light (a note for a target
    /// that is missing, hidden, not a gprim or inside a PointInstancer prototype).
    pub(super) fn geometry_light(&mut self, prim: &PrimPath) -> Result<(), String> {
        if self.hidden(prim)? {
            self.skip(prim, "invisible GeometryLight: not rendered");
            return Ok(());
        }
        let stage = self.stage;
        let targets = stage.targets(prim, "geometry")?;
        if targets.is_empty() {
            self.skip(prim, "GeometryLight targets no geometry: emits nothing");
            return Ok(());
        }
        let light_world = self.conversion * self.worlds.world(stage, prim)?;
        for target in &targets {
            let t = stage.type_name(target).unwrap_or_default();
            let why = if !GPRIMS.contains(&t.as_str()) {
                Some(format!("GeometryLight geometry {target} is not a gprim (type {t:?}): not rendered"))
            } else if self.prototypes.contains(target) {
                Some(format!("GeometryLight geometry {target} is inside a PointInstancer prototype: not rendered"))
            } else if self.hidden(target)? {
                Some(format!("GeometryLight geometry {target} is invisible: not rendered"))
            } else {
                None
            };
            if let Some(why) = why {
                self.skip(prim, why);
                continue;
            }
            let name = target.to_string();
            self.drop_surface(&name, &t);
            self.light_geometry.insert(name);
            let m = self.conversion * self.worlds.world(stage, target)?;
            let light = LightPrim { prim, type_name: "GeometryLight", world: &light_world };
            let label = if targets.len() == 1 { prim.to_string() } else { format!("{prim} ({target})") };
            self.emitting_gprim(&light, target, &t, &m, &label)?;
        }
        Ok(())
    }

    /// A GeometryLight's target is a light only: takes back the surface the walk imported
    /// for it before it met the GeometryLight (nothing when the walk has not reached it yet:
    /// the walk then leaves it out by [`Importer::light_geometry`]).
    fn drop_surface(&mut self, path: &str, type_name: &str) {
        let counts = &mut self.scene.counts;
        let meshes_before = self.scene.meshes.len();
        let mut triangles = 0;
        self.scene.meshes.retain(|m| {
            let keep = m.path != path;
            if !keep {
                triangles += m.triangles.len();
            }
            keep
        });
        let spheres_before = self.scene.spheres.len();
        self.scene.spheres.retain(|s| s.path != path);
        let dropped = self.scene.meshes.len() < meshes_before || self.scene.spheres.len() < spheres_before;
        if dropped {
            counts.gprims -= 1;
            counts.meshes -= usize::from(type_name == "Mesh");
            counts.triangles -= triangles;
        }
    }
}
