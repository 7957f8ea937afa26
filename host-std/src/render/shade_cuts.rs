//! Lightcuts at the shading points of a pixel (`--method lightcuts`): a cut through the light
//! tree per point (`sampler_core::lightcuts`), one shadow ray per cluster of the cut, through the
//! BVH. The tree holds the environment as directional lights and the scene's point lights and
//! delta distant lights; the scene's other lights are left to `shade_lights`.

use crate::render::primary::{Hit, shading_point};
use crate::render::{Context, Counters};
use sampler_core::glam::{DVec3, Vec3};
use sampler_core::lightcuts::{CutEntry, DEFAULT_MAX_CUT, LightcutTree, lightcut};

/// Lightcuts' tree and its relative error bound, built once per render.
#[derive(Clone, Copy, Debug)]
pub struct Lightcuts<'a> {
    /// The light tree.
    pub tree: LightcutTree<'a>,
    /// The relative error bound per cluster.
    pub error: f32,
}

/// The sum over `hits` of each shading point's cut estimate; `heap` is the cut's buffer, grown
/// to the cap ([`DEFAULT_MAX_CUT`]) on first use.
pub(crate) fn shade_cuts(
    ctx: &Context<'_, '_>,
    cuts: &Lightcuts<'_>,
    hits: &[Hit],
    heap: &mut Vec<CutEntry>,
    counters: &mut Counters,
) -> DVec3 {
    heap.resize(DEFAULT_MAX_CUT, CutEntry::default());
    let shadows = ctx.options.shadows;
    let mut sum = DVec3::ZERO;
    for hit in hits {
        let sp = shading_point(ctx.scene, hit);
        let visible = |dir: Vec3, distance: f32| !shadows || !ctx.bvh.occluded(hit.origin, dir, 0.0, distance);
        let cut = lightcut(&cuts.tree, hit.origin, &sp, cuts.error, heap, visible);
        sum += cut.estimate;
        counters.shadow_rays += if shadows { cut.rays as u64 } else { 0 };
    }
    counters.shading_points += hits.len() as u64;
    sum
}
