//! GeometryLight (deprecated by UsdLux in favour of MeshLightAPI, still in the schema): the
//! gprims its `geometry` relationship targets emit with the GeometryLight's LightAPI inputs
//! and shaping, as a MeshLightAPI mesh with those inputs would. Each targeted gprim is a
//! light only, not also a surface (as a MeshLightAPI mesh is), whichever of the two prims the
//! walk meets first.

use super::lights::LightPrim;
use super::{GPRIMS, Importer};
use crate::stage::PrimPath;
use std::collections::HashMap;

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
            self.light_geometry.insert(target.to_string(), t == "Mesh");
            let m = self.conversion * self.worlds.world(stage, target)?;
            let light = LightPrim { prim, type_name: "GeometryLight", world: &light_world };
            let label = if targets.len() == 1 { prim.to_string() } else { format!("{prim} ({target})") };
            self.emitting_gprim(&light, target, &t, &m, &label)?;
        }
        Ok(())
    }

    /// A GeometryLight's target is a light only: takes back, in one pass after the walk, the
    /// surfaces the walk imported for targets before it met their GeometryLight (the walk
    /// leaves out the targets it meets after, by [`Importer::light_geometry`]). One pass keeps
    /// a stage of many GeometryLights linear in its gprims.
    pub(super) fn drop_light_surfaces(&mut self) {
        if self.light_geometry.is_empty() {
            return;
        }
        let targets = &self.light_geometry;
        // Triangles taken back per target path.
        let mut dropped: HashMap<&str, usize> = HashMap::new();
        // Meshes kept before each place, for the instances' places among them.
        let mut kept_before = Vec::with_capacity(self.scene.meshes.len() + 1);
        kept_before.push(0u32);
        self.scene.meshes.retain(|m| {
            let kept = match targets.get_key_value(m.path.as_str()) {
                Some((path, _)) => {
                    *dropped.entry(path).or_default() += m.triangles.len();
                    false
                }
                None => true,
            };
            kept_before.push(kept_before[kept_before.len() - 1] + u32::from(kept));
            kept
        });
        for inst in &mut self.scene.instanced.instances {
            inst.after_meshes = kept_before[inst.after_meshes as usize];
        }
        self.scene.spheres.retain(|s| match targets.get_key_value(s.path.as_str()) {
            Some((path, _)) => {
                dropped.entry(path).or_default();
                false
            }
            None => true,
        });
        let counts = &mut self.scene.counts;
        for (path, triangles) in dropped {
            counts.gprims -= 1;
            counts.meshes -= usize::from(targets[path]);
            counts.triangles -= triangles;
        }
    }
}
