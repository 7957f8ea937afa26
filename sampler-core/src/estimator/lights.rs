//! Direct light from a scene's lights besides the environment (points, spheres, rectangles,
//! disks, mesh triangles, distant lights): a light picked in proportion to its power and sampled
//! by solid angle, and a BRDF sample that receives whatever emitter its ray meets first, the two
//! weighted by the balance heuristic (Veach 1997) so that a small bright light and a sharp lobe
//! are each found by the technique that suits them. Delta lights (points, distant lights of
//! angle 0) are found by light sampling only and take no weight.
//!
//! The estimate covers the lights' emission only; added to an estimate of the environment's
//! light (any of the environment's estimators, whose rays area lights occlude), it is an
//! unbiased estimate of the whole direct light.

use super::{ShadingPoint, times};
use crate::brdf::Brdf;
use crate::light::{Light, LightTree, PowerSelector, SceneLight, SelectedLight};
use glam::{DVec2, DVec3, Vec2, Vec3};

/// What a ray from the shading point meets first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FirstHit {
    /// Nothing: the ray leaves the scene, where distant lights with an angular size are seen.
    Escapes,
    /// The surface of light `index` of the [`LightSet`] (either side).
    Emitter(usize),
    /// Any other surface.
    Blocked,
}

/// The scene as the lights' estimator queries it, from one shading point.
pub trait LightRays {
    /// Nothing blocks the ray along the unit `dir` for distances in (0, `distance`).
    fn unoccluded(&mut self, dir: Vec3, distance: f32) -> bool;
    /// What the ray along the unit `dir` meets first.
    fn first_hit(&mut self, dir: Vec3) -> FirstHit;
}

/// How a light is picked for a shading point.
#[derive(Clone, Copy, Debug)]
enum Selection<'a> {
    /// In proportion to power, wherever the point is.
    Power(PowerSelector<'a>),
    /// The tree or one of the lights at infinity in proportion to power, then within the tree
    /// by each subtree's importance for the point.
    Tree {
        /// The lights with a position.
        tree: LightTree<'a>,
        /// Over the tree (slot 0) and the lights at infinity (slot k + 1: `distant[k]`).
        top: PowerSelector<'a>,
        /// The lights at infinity.
        distant: &'a [u32],
    },
}

/// A scene's lights, ready to sample: the lights, how one is picked for a shading point, and
/// which of them an escaping ray can see.
#[derive(Clone, Copy, Debug)]
pub struct LightSet<'a> {
    lights: &'a [SceneLight],
    selection: Selection<'a>,
    infinite: &'a [u32],
    any_area: bool,
}

impl<'a> LightSet<'a> {
    /// The set of `lights` picked by `selector` (built over them), where `infinite` lists the
    /// indices of the lights [`SceneLight::is_infinite_area`] holds for. `None` when the
    /// selector's length is not the number of lights or an index is out of range.
    #[must_use]
    pub fn new(lights: &'a [SceneLight], selector: PowerSelector<'a>, infinite: &'a [u32]) -> Option<Self> {
        let valid = selector.len() == lights.len() && Self::infinite_valid(lights, infinite);
        let any_area = lights.iter().any(|l| !l.is_delta());
        valid.then_some(Self { lights, selection: Selection::Power(selector), infinite, any_area })
    }

    /// The set of `lights` picked through `tree` (over the lights with a position): `top`
    /// picks the tree (slot 0) or the light at infinity `distant[k]` (slot k + 1), in proportion
    /// to power. `infinite` as for [`LightSet::new`]. `None` when the lengths disagree or an
    /// index is out of range.
    #[must_use]
    pub fn with_tree(
        lights: &'a [SceneLight],
        tree: LightTree<'a>,
        top: PowerSelector<'a>,
        distant: &'a [u32],
        infinite: &'a [u32],
    ) -> Option<Self> {
        let valid = top.len() == distant.len() + 1
            && distant.iter().all(|&i| (i as usize) < lights.len())
            && Self::infinite_valid(lights, infinite);
        let any_area = lights.iter().any(|l| !l.is_delta());
        valid.then_some(Self { lights, selection: Selection::Tree { tree, top, distant }, infinite, any_area })
    }

    fn infinite_valid(lights: &[SceneLight], infinite: &[u32]) -> bool {
        infinite.iter().all(|&i| lights.get(i as usize).is_some_and(SceneLight::is_infinite_area))
    }

    /// A light for the point `p` of shading normal `n`, with the uniform `u`; `None` where no
    /// light can light the point.
    #[must_use]
    pub fn pick(&self, u: f64, p: Vec3, n: Vec3) -> Option<SelectedLight> {
        match self.selection {
            Selection::Power(selector) => Some(selector.pick(u)),
            Selection::Tree { tree, top, distant } => {
                let slot = top.pick(u);
                if slot.index == 0 {
                    tree.pick(slot.u_remapped, p, n).map(|s| SelectedLight { pmf: s.pmf * slot.pmf, ..s })
                } else {
                    Some(SelectedLight { index: distant[slot.index - 1] as usize, ..slot })
                }
            }
        }
    }

    /// The probability that [`LightSet::pick`] returns light `index` at `p` with normal `n`.
    #[must_use]
    pub fn pmf(&self, index: usize, p: Vec3, n: Vec3) -> f64 {
        match self.selection {
            Selection::Power(selector) => selector.pmf(index),
            Selection::Tree { tree, top, distant } => match distant.iter().position(|&d| d as usize == index) {
                Some(k) => top.pmf(k + 1),
                None => top.pmf(0) * tree.pmf(index, p, n),
            },
        }
    }

    /// The lights.
    #[must_use]
    pub fn lights(&self) -> &'a [SceneLight] {
        self.lights
    }

    /// Some light is not a delta light, so that BRDF samples can find light.
    #[must_use]
    pub fn has_area_lights(&self) -> bool {
        self.any_area
    }
}

/// The largest f32 below 1: uniforms stay in [0, 1).
const BELOW_ONE: f32 = 1.0 - f32::EPSILON / 2.0;

/// Shadow rays towards an area light stop this fraction of the distance short of it, so that
/// the light's own surface does not occlude it.
const SHADOW_SHORTFALL: f32 = 1e-4;

/// One light sample from the point `p` (where shadow rays start) with the uniform point `u`:
/// `u.x` picks the light and, rescaled, samples it with `u.y`. With `mis`, weighted by the
/// balance heuristic against one BRDF sample ([`brdf_sample`]); without, the plain estimate.
pub fn light_sample<B: Brdf + ?Sized>(
    set: &LightSet<'_>,
    p: Vec3,
    sp: &ShadingPoint<'_, B>,
    u: DVec2,
    mis: bool,
    rays: &mut impl LightRays,
) -> DVec3 {
    let Some(pick) = set.pick(u.x, p, sp.frame.n) else { return DVec3::ZERO };
    let light = &set.lights[pick.index];
    let u_light = Vec2::new((pick.u_remapped as f32).min(BELOW_ONE), (u.y as f32).min(BELOW_ONE));
    let Some(s) = light.sample(p, u_light) else { return DVec3::ZERO };
    let (b, p_brdf) = sp.eval_pdf(s.dir);
    let f = times(s.radiance, b);
    let p_light = pick.pmf * s.pdf as f64;
    let density = if s.delta || !mis { p_light } else { p_light + p_brdf as f64 };
    if !(density > 0.0 && density.is_finite() && f.cmpgt(DVec3::ZERO).any()) {
        return DVec3::ZERO;
    }
    let extent = if s.distance.is_finite() { s.distance * (1.0 - SHADOW_SHORTFALL) } else { f32::INFINITY };
    if rays.unoccluded(s.dir, extent) { f / density } else { DVec3::ZERO }
}

/// One BRDF sample from the point `p` with the uniform point `u`, receiving the light of the
/// emitter its ray meets first (or of the distant lights, if it escapes), weighted by the
/// balance heuristic against light sampling ([`light_sample`] with `mis`).
pub fn brdf_sample<B: Brdf + ?Sized>(
    set: &LightSet<'_>,
    p: Vec3,
    sp: &ShadingPoint<'_, B>,
    u: Vec2,
    rays: &mut impl LightRays,
) -> DVec3 {
    let Some(s) = sp.brdf.sample(sp.frame.to_local(sp.wo), u) else { return DVec3::ZERO };
    if !(s.pdf > 0.0 && s.value.cmpgt(Vec3::ZERO).any()) {
        return DVec3::ZERO;
    }
    let dir = sp.frame.to_world(s.wi);
    let received = |index: usize| {
        let light = &set.lights[index];
        let Some(hit) = light.eval(p, dir) else { return DVec3::ZERO };
        let p_light = set.pmf(index, p, sp.frame.n) * light.pdf(p, dir) as f64;
        times(hit.radiance, s.value) / (s.pdf as f64 + p_light)
    };
    match rays.first_hit(dir) {
        FirstHit::Blocked => DVec3::ZERO,
        FirstHit::Emitter(index) => received(index),
        FirstHit::Escapes => set.infinite.iter().map(|&i| received(i as usize)).sum(),
    }
}

/// The balance-heuristic pair: one light sample (`u_light`) and one BRDF sample (`u_brdf`),
/// their weighted values summed; where every light is a delta light, the light sample alone
/// (no BRDF sample can find light).
pub fn light_pair<B: Brdf + ?Sized>(
    set: &LightSet<'_>,
    p: Vec3,
    sp: &ShadingPoint<'_, B>,
    u_light: DVec2,
    u_brdf: Vec2,
    rays: &mut impl LightRays,
) -> DVec3 {
    if !set.any_area {
        return light_sample(set, p, sp, u_light, false, rays);
    }
    light_sample(set, p, sp, u_light, true, rays) + brdf_sample(set, p, sp, u_brdf, rays)
}
