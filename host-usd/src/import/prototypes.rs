//! PointInstancers in a one-pass walk. A prototype renders only through its instancers, so
//! the prims under a prototype root are not imported in place but kept (their renderable
//! gprims, each with its transform relative to the root's parent) until the instancer that
//! names the root is expanded: when the walk leaves the instancer if every prototype lies
//! below it (the usual layout), otherwise after the walk. A prototype root that the walk
//! passed before reaching its instancer cannot be taken back: the import then walks again
//! knowing every instancer's prototypes from a first walk ([`prototype_roots`]).

#![allow(clippy::mutable_key_type, reason = "a path's interior mutability is its text cache, outside Eq and Hash")]

use super::gprim::{GprimSource, InstanceOf};
use super::{Failure, Importer, Stop, fail};
use crate::instancer;
use crate::stage::{PrimMap, PrimPath, Stage, Step};
use glam::DMat4;
use std::collections::hash_map::Entry;

/// A renderable gprim or a light under a prototype root: its path, type, transform relative
/// to the root's parent, and whether it is a mesh light (MeshLightAPI).
type Part = (PrimPath, String, DMat4, bool);

/// The prototype roots known so far, what lies under each, and the instancers not yet
/// expanded.
#[derive(Default)]
pub(super) struct Prototypes {
    roots: Vec<PrimPath>,
    /// Each root's place in `roots`: a prim finds the roots over it by its ancestors, not by
    /// a scan of every root, so a stage of many prototypes stays linear in them.
    index: PrimMap<usize>,
    /// The shallowest root's depth: no prim above it lies in a prototype.
    min_depth: usize,
    parts: Vec<Vec<Part>>,
    /// Visible instancers met by the walk, with their world transforms.
    waiting: Vec<(PrimPath, DMat4)>,
}

impl Prototypes {
    /// Knowing `roots` from the start.
    pub(super) fn known(roots: Vec<PrimPath>) -> Self {
        let mut known = Self::default();
        roots.into_iter().for_each(|r| known.add(r));
        known
    }

    /// Adds `root` unless it is known.
    fn add(&mut self, root: PrimPath) {
        if self.index.contains_key(&root) {
            return;
        }
        self.min_depth = if self.roots.is_empty() { root.depth() } else { self.min_depth.min(root.depth()) };
        self.index.insert(root.clone(), self.roots.len());
        self.roots.push(root);
        self.parts.push(Vec::new());
    }

    /// The place in `roots` of each root at or above `prim`, nearest first.
    fn over(&self, prim: &PrimPath) -> impl Iterator<Item = usize> + '_ {
        let mut next = (!self.roots.is_empty()).then(|| prim.clone());
        std::iter::from_fn(move || {
            while let Some(p) = next.take() {
                if p.depth() > self.min_depth {
                    next = p.parent();
                }
                if let Some(&i) = self.index.get(&p) {
                    return Some(i);
                }
            }
            None
        })
    }

    /// Whether `prim` is at or below a prototype root.
    pub(super) fn contains(&self, prim: &PrimPath) -> bool {
        self.over(prim).next().is_some()
    }

    /// Expands `instancer` (at `world`) once its prototypes are walked.
    pub(super) fn wait(&mut self, instancer: &PrimPath, world: DMat4) {
        self.waiting.push((instancer.clone(), world));
    }
}

/// Every PointInstancer's prototype roots, by a walk of the stage that reads nothing else.
pub(super) fn prototype_roots(stage: &Stage) -> Result<Vec<PrimPath>, Failure> {
    let mut roots: Vec<PrimPath> = Vec::new();
    let mut seen = PrimMap::default();
    let walked = stage.walk(|step| -> Result<(), Stop> {
        let Step::Enter(prim) = step else { return Ok(()) };
        if stage.type_name(&prim).map_err(fail(&prim))? == "PointInstancer" {
            for target in stage.targets(&prim, "prototypes").map_err(fail(&prim))? {
                if seen.insert(target.clone(), ()).is_none() {
                    roots.push(target);
                }
            }
        }
        Ok(())
    });
    walked.map_err(Stop::failure)?;
    Ok(roots)
}

/// Whether the walk, now at `current`, has already passed `root`: an ancestor of
/// `current`, or a subtree of an earlier sibling of one of `current`'s ancestors. `order`
/// keeps each common ancestor's children's places, read once for all of an instancer's
/// roots (a stage of many prototypes beside their instancer stays linear in them).
fn walked_before(
    stage: &Stage,
    root: &PrimPath,
    current: &PrimPath,
    order: &mut PrimMap<PrimMap<usize>>,
) -> Result<bool, String> {
    if current.is_at_or_below(root) {
        return Ok(true);
    }
    if root.is_at_or_below(current) {
        return Ok(false);
    }
    let mut common = root.parent().unwrap_or_else(PrimPath::root);
    while !current.is_at_or_below(&common) {
        common = common.parent().unwrap_or_else(PrimPath::root);
    }
    let depth = common.depth() + 1;
    let (r, c) = (root.ancestor_at(depth), current.ancestor_at(depth));
    let places = match order.entry(common) {
        Entry::Occupied(e) => e.into_mut(),
        Entry::Vacant(e) => {
            let children = stage.children(e.key())?;
            e.insert(children.into_iter().enumerate().map(|(i, p)| (p, i)).collect())
        }
    };
    Ok(matches!((places.get(&r), places.get(&c)), (Some(r), Some(c)) if r < c))
}

impl Importer<'_> {
    /// Learns the prototype roots `instancer` names; a root already walked past restarts
    /// the import.
    pub(super) fn register_instancer(&mut self, instancer: &PrimPath) -> Result<(), Stop> {
        let stage = self.stage;
        let mut order = PrimMap::default();
        for root in stage.targets(instancer, "prototypes").map_err(fail(instancer))? {
            if self.prototypes.index.contains_key(&root) {
                continue;
            }
            if walked_before(stage, &root, instancer, &mut order).map_err(fail(instancer))? {
                return Err(Stop::Restart);
            }
            self.prototypes.add(root);
        }
        Ok(())
    }

    /// Keeps a visible gprim or light under prototype roots for their instancers.
    pub(super) fn prototype_gprim(&mut self, prim: &PrimPath, type_name: &str) -> Result<(), String> {
        let stage = self.stage;
        let mesh_light = !crate::lights::KINDS.contains(&type_name)
            && stage.applied_schemas(prim)?.iter().any(|s| s == "MeshLightAPI");
        let over: Vec<usize> = self.prototypes.over(prim).collect();
        for i in over {
            let root = &self.prototypes.roots[i];
            let rel = self.worlds.relative_to(stage, prim, root)?;
            self.prototypes.parts[i].push((prim.clone(), type_name.to_string(), rel, mesh_light));
        }
        Ok(())
    }

    /// Expands the waiting instancers that can be: those at `left` whose prototypes all
    /// lie below it (the walk has just left it), or, after the walk (`None`), all of them.
    pub(super) fn instancers_after(&mut self, left: Option<&PrimPath>) -> Result<(), Failure> {
        let waiting = &self.prototypes.waiting;
        if waiting.is_empty() || left.is_some_and(|l| waiting.iter().all(|(p, _)| p != l)) {
            return Ok(());
        }
        let stage = self.stage;
        for (prim, world) in std::mem::take(&mut self.prototypes.waiting) {
            let due = match left {
                None => true,
                Some(l) => {
                    prim == *l && {
                        let targets = stage.targets(&prim, "prototypes").map_err(fail(&prim))?;
                        targets.iter().all(|t| t.is_at_or_below(&prim))
                    }
                }
            };
            if due {
                self.instancer(&prim, &world)?;
            } else {
                self.prototypes.waiting.push((prim, world));
            }
        }
        Ok(())
    }

    fn instancer(&mut self, prim: &PrimPath, world: &DMat4) -> Result<(), Failure> {
        let stage = self.stage;
        let (protos, instances) = instancer::read(stage, prim).map_err(fail(prim))?;
        let known = &self.prototypes.index;
        let index: Vec<Option<usize>> = protos.iter().map(|p| known.get(p).copied()).collect();
        // Out of `self` while `gprim` adds to the scene.
        let parts = std::mem::take(&mut self.prototypes.parts);
        // Each prototype gprim read from the stage once, on its first instance, and placed
        // at every instance.
        let mut sources: Vec<Vec<Option<GprimSource>>> = Vec::new();
        sources.resize_with(parts.len(), Vec::new);
        let instancer = self.scene.instanced.instancers.len() as u32;
        let to_world = self.conversion * *world;
        self.scene.instanced.instancers.push(prim.to_string());
        let expanded = instances.iter().try_for_each(|inst| {
            let Some(i) = index.get(inst.prototype).copied().flatten() else { return Ok(()) };
            if sources[i].is_empty() {
                sources[i].resize_with(parts[i].len(), || None);
            }
            let of = InstanceOf { instancer, index: inst.index as u32 };
            parts[i].iter().zip(&mut sources[i]).try_for_each(|((p, t, rel, mesh_light), source)| {
                let m = to_world * inst.transform * *rel;
                self.prototype_part(p, t, *mesh_light, of, &m, source).map_err(fail(p))
            })
        });
        self.prototypes.parts = parts;
        expanded?;
        self.scene.counts.instances += instances.len();
        Ok(())
    }

    /// One prim kept under a prototype root, for one instance at `m`: a light, a mesh light
    /// (MeshLightAPI) or a gprim (read into `source` on its first instance).
    fn prototype_part(
        &mut self,
        prim: &PrimPath,
        type_name: &str,
        mesh_light: bool,
        of: InstanceOf,
        m: &DMat4,
        source: &mut Option<GprimSource>,
    ) -> Result<(), String> {
        if crate::lights::KINDS.contains(&type_name) {
            return self.light_at(prim, type_name, m, &self.instance_label(prim, of));
        }
        if mesh_light {
            return self.mesh_light_at(prim, type_name, m, &self.instance_label(prim, of));
        }
        let source = match source {
            Some(s) => s,
            empty => empty.insert(self.gprim_source(prim, type_name)?),
        };
        self.place_instance(source, of, m)
    }
}
