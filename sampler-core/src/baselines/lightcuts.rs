//! Lightcuts (Walter et al., SIGGRAPH 2005): per shading point, a cut through the light tree
//! ([`LightcutTree`]) — a set of nodes that together hold every light once — each node shaded
//! as its representative light carrying the node's whole intensity, with one shadow ray.
//!
//! The cut starts at the roots and refines the node of largest error bound into its children
//! until every node's bound is below `error` × the cut's current estimate (the paper's relative
//! criterion, 2% by default: a cluster's error under Weber's threshold) or the cut reaches its
//! size cap. A node's bound is the paper's, with visibility bounded by 1 (`lightcut_bound.rs`).
//! Leaves are exact. Without shadows, |estimate − exact| is at
//! most the sum of the cut's bounds ([`Cut::bound`]); the estimate is deterministic and biased.
//!
//! The cut lives in a caller buffer (a binary heap of [`CutEntry`]) whose length is the cap.

pub use super::lightcut_tree::{CutLight, CutLightKind, CutNode, CutTreeError, LightcutTree};

use super::lightcut_bound::error_bound;
use crate::brdf::Brdf;
use crate::estimator::{ShadingPoint, luminance64};
use glam::{DVec3, Vec3};

/// The paper's relative error bound.
pub const DEFAULT_ERROR: f32 = 0.02;

/// The paper's cap on a cut's size.
pub const DEFAULT_MAX_CUT: usize = 1000;

/// The paper's number of directional lights an environment becomes.
pub const DEFAULT_ENV_LIGHTS: usize = 3000;

/// Shadow rays towards a point light stop this fraction of the distance short of it.
const SHADOW_SHORTFALL: f32 = 1e-4;

/// A node of a cut.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CutEntry {
    /// The node.
    pub node: u32,
    /// Its error bound (luminance).
    pub bound: f32,
    /// Its representative's BRDF × cosine × geometric term × visibility, per unit intensity.
    pub unit: DVec3,
}

/// What a cut estimated.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cut {
    /// Radiance reflected towards the viewer.
    pub estimate: DVec3,
    /// Nodes in the cut.
    pub size: usize,
    /// The sum of their error bounds (luminance).
    pub bound: f64,
    /// Shadow rays traced.
    pub rays: usize,
    /// The cap stopped the refinement before every bound was under the threshold.
    pub capped: bool,
}

/// The cut of `tree` at the point `p` (where shadow rays start) of shading point `sp`, under a
/// relative `error`, in `heap` (its length caps the cut, at least 2). `unoccluded(dir,
/// distance)` says whether a ray along `dir` reaches that far.
pub fn lightcut<B: Brdf + ?Sized>(
    tree: &LightcutTree<'_>,
    p: Vec3,
    sp: &ShadingPoint<'_, B>,
    error: f32,
    heap: &mut [CutEntry],
    mut unoccluded: impl FnMut(Vec3, f32) -> bool,
) -> Cut {
    let mut cut = Cut::default();
    let mut heap = Heap { entries: heap, len: 0 };
    let wo_local = sp.frame.to_local(sp.wo);
    let mut total = 0.0f64;
    let mut shade = |node: u32, rep_unit: Option<DVec3>, cut: &mut Cut| {
        let n = &tree.nodes()[node as usize];
        let unit = rep_unit.unwrap_or_else(|| {
            let (unit, traced) = light_unit(&tree.lights()[n.rep as usize], p, sp, &mut unoccluded);
            cut.rays += traced as usize;
            unit
        });
        let bound = if n.count == 1 { 0.0 } else { error_bound(n, p, sp, wo_local) };
        (CutEntry { node, bound, unit }, luminance64(unit * n.intensity.as_dvec3()))
    };
    for root in tree.roots().into_iter().flatten() {
        if heap.len < heap.entries.len() {
            let (entry, value) = shade(root, None, &mut cut);
            total += value;
            heap.push(entry);
        }
    }
    while let Some(top) = heap.peek() {
        if top.bound as f64 <= error as f64 * total.max(0.0) {
            break;
        }
        if heap.len >= heap.entries.len() {
            cut.capped = true;
            break;
        }
        let top = heap.pop().expect("peeked");
        let parent = &tree.nodes()[top.node as usize];
        total -= luminance64(top.unit * parent.intensity.as_dvec3());
        let (a, b) = tree.children(top.node);
        for child in [a, b] {
            let same_rep = tree.nodes()[child as usize].rep == parent.rep;
            let (entry, value) = shade(child, same_rep.then_some(top.unit), &mut cut);
            total += value;
            heap.push(entry);
        }
    }
    for e in &heap.entries[..heap.len] {
        cut.estimate += e.unit * tree.nodes()[e.node as usize].intensity.as_dvec3();
        cut.bound += e.bound as f64;
    }
    cut.size = heap.len;
    cut
}

/// One light's BRDF × cosine × geometric term × visibility from `p`, per unit intensity, and
/// whether a shadow ray was traced.
fn light_unit<B: Brdf + ?Sized>(
    light: &CutLight,
    p: Vec3,
    sp: &ShadingPoint<'_, B>,
    unoccluded: &mut impl FnMut(Vec3, f32) -> bool,
) -> (DVec3, bool) {
    let (dir, distance, g) = match light.kind {
        CutLightKind::Directional => (light.at, f32::INFINITY, 1.0),
        CutLightKind::Point => {
            let v = light.at - p;
            let d2 = v.length_squared();
            if !(d2 > 0.0 && d2.is_finite()) {
                return (DVec3::ZERO, false);
            }
            let d = libm::sqrtf(d2);
            (v / d, d * (1.0 - SHADOW_SHORTFALL), 1.0 / d2 as f64)
        }
    };
    let f = sp.eval(dir).as_dvec3() * g;
    if !f.cmpgt(DVec3::ZERO).any() || !f.is_finite() {
        return (DVec3::ZERO, false);
    }
    (if unoccluded(dir, distance) { f } else { DVec3::ZERO }, true)
}

/// A binary max-heap by bound over a caller slice.
struct Heap<'h> {
    entries: &'h mut [CutEntry],
    len: usize,
}

impl Heap<'_> {
    fn peek(&self) -> Option<&CutEntry> {
        (self.len > 0).then(|| &self.entries[0])
    }

    fn push(&mut self, e: CutEntry) {
        let mut k = self.len;
        self.entries[k] = e;
        self.len += 1;
        while k > 0 {
            let parent = (k - 1) / 2;
            if self.entries[parent].bound >= self.entries[k].bound {
                break;
            }
            self.entries.swap(parent, k);
            k = parent;
        }
    }

    fn pop(&mut self) -> Option<CutEntry> {
        if self.len == 0 {
            return None;
        }
        let top = self.entries[0];
        self.len -= 1;
        self.entries[0] = self.entries[self.len];
        let mut k = 0;
        loop {
            let (l, r) = (2 * k + 1, 2 * k + 2);
            let mut largest = k;
            if l < self.len && self.entries[l].bound > self.entries[largest].bound {
                largest = l;
            }
            if r < self.len && self.entries[r].bound > self.entries[largest].bound {
                largest = r;
            }
            if largest == k {
                return Some(top);
            }
            self.entries.swap(k, largest);
            k = largest;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::{Lambert, RoughConductor};
    use crate::env::{EnvHierarchy, build_pyramid, pyramid_len};
    use crate::frame::Frame;
    use crate::mapping::square_to_sphere;
    use crate::rng::Pcg32;
    use crate::sis::{SisBuffers, Stratum, build_strata, cells_len};
    use glam::Vec2;
    use std::vec;
    use std::vec::Vec;

    /// The directional lights of a map of level 6 (a sky with a sun) stratified into `n`, and
    /// `points` point lights scattered above the plane z = 0.
    fn lights(n: usize, points: usize) -> Vec<CutLight> {
        let (level, side) = (6u32, 64u32);
        let sun = Vec3::new(0.3, 0.2, 0.93).normalize();
        let rgb: Vec<[f32; 3]> = (0..side * side)
            .map(|k| {
                let uv = Vec2::new(((k % side) as f32 + 0.5) / side as f32, ((k / side) as f32 + 0.5) / side as f32);
                let d = square_to_sphere(uv);
                let l = Vec3::new(1.0, 1.1, 1.3) * (1.2 + d.z)
                    + if d.dot(sun) > 0.99 { Vec3::splat(300.0) } else { Vec3::ZERO };
                l.to_array()
            })
            .collect();
        let mut pyramid = vec![0.0; pyramid_len(level)];
        build_pyramid(level, &rgb, &mut pyramid).unwrap();
        let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
        let m = cells_len(&env);
        let (mut dirs, mut nearest, mut labels) = (vec![Vec3::ZERO; m], vec![0.0; m], vec![0u32; m]);
        let mut intensity = vec![0.0f32; m];
        let mut strata = vec![Stratum::default(); n];
        let count = build_strata(
            &env,
            SisBuffers {
                dirs: &mut dirs,
                intensity: &mut intensity,
                nearest: &mut nearest,
                labels: &mut labels,
                strata: &mut strata,
            },
        )
        .unwrap();
        let mut out: Vec<CutLight> = strata[..count]
            .iter()
            .map(|s| CutLight { kind: CutLightKind::Directional, at: s.dir, intensity: s.irradiance.as_vec3() })
            .collect();
        let mut rng = Pcg32::new(5, 1);
        for _ in 0..points {
            let at = Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 8.0 - 4.0, 0.5 + rng.next_f32() * 3.0);
            let intensity = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0;
            out.push(CutLight { kind: CutLightKind::Point, at, intensity });
        }
        out
    }

    fn tree<'a>(lights: &'a [CutLight], nodes: &'a mut Vec<CutNode>) -> LightcutTree<'a> {
        let mut order = vec![0u32; lights.len()];
        nodes.resize(LightcutTree::nodes_len(lights.len()), CutNode::default());
        LightcutTree::build(lights, &mut order, nodes).unwrap()
    }

    /// The lights below `node`.
    fn below(t: &LightcutTree<'_>, node: u32, out: &mut Vec<u32>) {
        let n = &t.nodes()[node as usize];
        if n.count == 1 {
            out.push(n.rep);
        } else {
            let (a, b) = t.children(node);
            below(t, a, out);
            below(t, b, out);
        }
    }

    #[test]
    fn every_node_bounds_its_lights_and_holds_their_intensity() {
        let lights = lights(500, 40);
        let mut nodes = Vec::new();
        let t = tree(&lights, &mut nodes);
        let mut seen = vec![0u32; lights.len()];
        for root in t.roots().into_iter().flatten() {
            let mut all = Vec::new();
            below(&t, root, &mut all);
            all.iter().for_each(|&l| seen[l as usize] += 1);
        }
        assert!(seen.iter().all(|&c| c == 1), "every light in exactly one leaf");
        for k in 0..t.nodes().len() as u32 {
            let n = &t.nodes()[k as usize];
            let mut members = Vec::new();
            below(&t, k, &mut members);
            assert_eq!(members.len(), n.count as usize);
            assert!(members.contains(&n.rep), "node {k}: its representative is one of its lights");
            let sum: Vec3 = members.iter().map(|&l| lights[l as usize].intensity).sum();
            assert!((sum - n.intensity).abs().max_element() <= 1e-4 * sum.max_element());
            for &l in &members {
                let light = &lights[l as usize];
                assert_eq!(light.kind, n.kind);
                assert!(light.at.cmpge(n.min).all() && light.at.cmple(n.max).all(), "node {k}: box");
                if n.kind == CutLightKind::Directional {
                    assert!(light.at.dot(n.cone.axis) >= n.cone.cos - 1e-6, "node {k}: cone");
                }
            }
        }
    }

    /// What every light of the tree sends to a shading point, unshadowed.
    fn exact(lights: &[CutLight], p: Vec3, sp: &ShadingPoint<'_, dyn Brdf + '_>) -> DVec3 {
        lights.iter().map(|l| light_unit(l, p, sp, &mut |_, _| true).0 * l.intensity.as_dvec3()).sum()
    }

    #[test]
    fn the_error_stays_under_the_cuts_bounds_against_the_exact_sum() {
        let lights = lights(DEFAULT_ENV_LIGHTS, 200);
        let mut nodes = Vec::new();
        let t = tree(&lights, &mut nodes);
        let mut heap = vec![CutEntry::default(); DEFAULT_MAX_CUT];
        let mut rng = Pcg32::new(9, 2);
        let (lambert, glossy) = (Lambert::new(Vec3::new(0.8, 0.6, 0.4)), RoughConductor::new(0.2, Vec3::splat(0.9)));
        let (mut within_error, mut points, mut max_cut) = (0, 0, 0);
        let mut rels = Vec::new();
        for i in 0..300 {
            let brdf: &dyn Brdf = if i % 2 == 0 { &lambert } else { &glossy };
            let p = Vec3::new(rng.next_f32() * 10.0 - 5.0, rng.next_f32() * 10.0 - 5.0, 0.0);
            let n = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 1.0).normalize();
            let wo = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, 0.7).normalize();
            let sp = ShadingPoint { frame: Frame::from_normal(n), wo, brdf };
            let truth = luminance64(exact(&lights, p, &sp));
            let cut = lightcut(&t, p, &sp, DEFAULT_ERROR, &mut heap, |_, _| true);
            let err = (luminance64(cut.estimate) - truth).abs();
            assert!(err <= cut.bound * 1.0001 + 1e-9, "point {i}: error {err} over the cut's bound {}", cut.bound);
            assert!(!cut.capped, "point {i}: the cap stopped the cut ({} nodes)", cut.size);
            points += 1;
            within_error += usize::from(err <= f64::from(DEFAULT_ERROR) * truth);
            rels.push(err / truth);
            // The paper's criterion: every cluster's bound under ε × the cut's estimate.
            let threshold = f64::from(DEFAULT_ERROR) * luminance64(cut.estimate);
            assert!(heap[..cut.size].iter().all(|e| f64::from(e.bound) <= threshold * 1.0001), "point {i}");
            max_cut = max_cut.max(cut.size);
        }
        // The clusters' errors add: the criterion bounds each, not their sum. The total error
        // stays small in practice (docs/renderer.md, "lightcuts").
        rels.sort_by(f64::total_cmp);
        let eps = f64::from(DEFAULT_ERROR);
        assert!(rels[rels.len() / 2] < 0.5 * eps && rels[rels.len() - 1] < 2.0 * eps, "{rels:?}");
        assert!(within_error * 10 >= points * 9, "{within_error} of {points} points under ε");
        assert!(max_cut < lights.len() / 4, "cuts of {max_cut} nodes out of {} lights", lights.len());
    }

    #[test]
    fn a_lambert_plane_under_a_smooth_map_is_within_the_error_bound() {
        let lights = lights(DEFAULT_ENV_LIGHTS, 0);
        let mut nodes = Vec::new();
        let t = tree(&lights, &mut nodes);
        let mut heap = vec![CutEntry::default(); DEFAULT_MAX_CUT];
        let brdf = Lambert::new(Vec3::ONE);
        for n in [Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, -0.8).normalize()] {
            let sp = ShadingPoint { frame: Frame::from_normal(n), wo: n, brdf: &brdf as &dyn Brdf };
            let truth = luminance64(exact(&lights, Vec3::ZERO, &sp));
            let cut = lightcut(&t, Vec3::ZERO, &sp, DEFAULT_ERROR, &mut heap, |_, _| true);
            // Within the cut's bound, and within twice the per-cluster criterion (a grazing
            // plane cuts many clusters at the horizon, whose errors add).
            let err = luminance64(cut.estimate) - truth;
            assert!(err.abs() <= cut.bound && err.abs() < 2.0 * f64::from(DEFAULT_ERROR) * truth, "normal {n}: {err}");
        }
    }

    #[test]
    fn the_cap_bounds_the_cut_and_shadow_rays_go_to_representatives() {
        let lights = lights(DEFAULT_ENV_LIGHTS, 20);
        let mut nodes = Vec::new();
        let t = tree(&lights, &mut nodes);
        let mut heap = vec![CutEntry::default(); 8];
        let sp = ShadingPoint {
            frame: Frame::from_normal(Vec3::Z),
            wo: Vec3::Z,
            brdf: &Lambert::new(Vec3::ONE) as &dyn Brdf,
        };
        let cut = lightcut(&t, Vec3::ZERO, &sp, 1e-6, &mut heap, |_, _| true);
        assert!(cut.capped && cut.size == 8);
        // Everything occluded: nothing arrives, and the cut refines to its cap.
        let mut rays = 0;
        let dark = lightcut(&t, Vec3::ZERO, &sp, DEFAULT_ERROR, &mut heap, |_, _| {
            rays += 1;
            false
        });
        assert_eq!(dark.estimate, DVec3::ZERO);
        assert_eq!(dark.rays, rays);
        assert!(dark.rays <= 8 + 1);
    }
}
