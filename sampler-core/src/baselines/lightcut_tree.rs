//! The light tree of Lightcuts (Walter, Fernandez, Arbree, Bala, Donikian & Greenberg,
//! SIGGRAPH 2005): directional lights (an environment's strata, delta distant lights) and point
//! lights, each kind in its own binary tree as in the paper. Every node holds its lights' total
//! intensity, a representative light drawn among its children's representatives in proportion
//! to their intensities, and the bounds the cut's error bounds read: a box of positions (point
//! lights) or a box and a cone of directions (directional lights).
//!
//! The paper clusters bottom-up, merging the pair of least cluster size; this tree splits
//! top-down at the median of the widest axis of the lights' positions (or directions), which
//! builds in O(n log n) into caller buffers and gives clusters of the same kind: compact in
//! space or in direction.

use crate::cone::Cone;
use crate::env::luminance;
use crate::rng::hash_combine;
use glam::Vec3;

/// What a light of the tree is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CutLightKind {
    /// Light from one direction, at infinity: `at` is the unit direction towards it and
    /// `intensity` the irradiance it delivers to a surface facing it.
    Directional,
    /// An isotropic point light: `at` is its position and `intensity` its radiant intensity.
    Point,
}

/// A light of the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutLight {
    /// Directional or point.
    pub kind: CutLightKind,
    /// Unit direction towards a directional light; a point light's position.
    pub at: Vec3,
    /// Irradiance (directional) or radiant intensity (point), RGB.
    pub intensity: Vec3,
}

/// A node of the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutNode {
    /// Corner of the box of the lights' `at`.
    pub min: Vec3,
    /// Opposite corner.
    pub max: Vec3,
    /// Its lights' kind (one tree per kind).
    pub kind: CutLightKind,
    /// Directional nodes: the cone of the lights' directions (unused for point nodes).
    pub cone: Cone,
    /// Total intensity (RGB).
    pub intensity: Vec3,
    /// The representative light's index.
    pub rep: u32,
    /// An inner node's second child (its first child follows it); unused for a leaf.
    pub second: u32,
    /// Lights below (1: a leaf).
    pub count: u32,
}

impl Default for CutNode {
    fn default() -> Self {
        Self {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
            kind: CutLightKind::Directional,
            cone: Cone::default(),
            intensity: Vec3::ZERO,
            rep: 0,
            second: 0,
            count: 0,
        }
    }
}

/// Why a tree cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CutTreeError {
    /// A buffer is shorter than [`LightcutTree::build`] needs.
    BufferTooSmall,
    /// More lights than 2³¹.
    TooManyLights,
}

/// A built tree: the lights, the nodes and the roots of the directional and the point tree.
#[derive(Clone, Copy, Debug)]
pub struct LightcutTree<'a> {
    lights: &'a [CutLight],
    nodes: &'a [CutNode],
    roots: [Option<u32>; 2],
}

/// Seed of the representatives' draws.
const REP_SEED: u64 = 0x11c0_75ee;

impl<'a> LightcutTree<'a> {
    /// Nodes [`LightcutTree::build`] needs for `lights` lights.
    #[must_use]
    pub fn nodes_len(lights: usize) -> usize {
        2 * lights
    }

    /// Builds the trees over `lights` (dark lights included: they weigh nothing). `order`
    /// needs one entry per light, `nodes` [`LightcutTree::nodes_len`].
    pub fn build(lights: &'a [CutLight], order: &mut [u32], nodes: &'a mut [CutNode]) -> Result<Self, CutTreeError> {
        let n = lights.len();
        if n > 1 << 31 {
            return Err(CutTreeError::TooManyLights);
        }
        if order.len() < n || nodes.len() < Self::nodes_len(n) {
            return Err(CutTreeError::BufferTooSmall);
        }
        let order = &mut order[..n];
        for (k, o) in order.iter_mut().enumerate() {
            *o = k as u32;
        }
        // Directional lights first.
        order.sort_unstable_by_key(|&i| lights[i as usize].kind == CutLightKind::Point);
        let split = order.iter().position(|&i| lights[i as usize].kind == CutLightKind::Point).unwrap_or(n);
        let mut builder = Builder { lights, nodes, used: 0 };
        let (dir_lights, point_lights) = order.split_at_mut(split);
        let dir_root = (!dir_lights.is_empty()).then(|| builder.node(dir_lights) as u32);
        let point_root = (!point_lights.is_empty()).then(|| builder.node(point_lights) as u32);
        let Builder { nodes, used, .. } = builder;
        Ok(Self { lights, nodes: &nodes[..used], roots: [dir_root, point_root] })
    }

    /// A tree [`LightcutTree::build`] made, from its parts ([`LightcutTree::nodes`],
    /// [`LightcutTree::roots`]); `None` where they cannot be one.
    #[must_use]
    pub fn from_parts(lights: &'a [CutLight], nodes: &'a [CutNode], roots: [Option<u32>; 2]) -> Option<Self> {
        let valid = roots.iter().flatten().all(|&r| (r as usize) < nodes.len())
            && nodes.iter().enumerate().all(|(k, node)| {
                (node.rep as usize) < lights.len()
                    && node.count > 0
                    && (node.count == 1 || (node.second as usize > k + 1 && (node.second as usize) < nodes.len()))
            });
        valid.then_some(Self { lights, nodes, roots })
    }

    /// The lights.
    #[must_use]
    pub fn lights(&self) -> &'a [CutLight] {
        self.lights
    }

    /// The nodes.
    #[must_use]
    pub fn nodes(&self) -> &'a [CutNode] {
        self.nodes
    }

    /// The roots of the directional tree and of the point tree, where there are such lights.
    #[must_use]
    pub fn roots(&self) -> [Option<u32>; 2] {
        self.roots
    }

    /// The children of an inner node.
    #[must_use]
    pub fn children(&self, node: u32) -> (u32, u32) {
        (node + 1, self.nodes[node as usize].second)
    }
}

struct Builder<'b, 'a> {
    lights: &'b [CutLight],
    nodes: &'a mut [CutNode],
    used: usize,
}

impl Builder<'_, '_> {
    /// Writes the subtree of `lights` (non-empty) at the next free node; returns its index.
    fn node(&mut self, lights: &mut [u32]) -> usize {
        let at = self.used;
        self.used += 1;
        if lights.len() == 1 {
            let l = &self.lights[lights[0] as usize];
            let cone = Cone::new(l.at.try_normalize().unwrap_or(Vec3::Z), 0.0);
            self.nodes[at] = CutNode {
                min: l.at,
                max: l.at,
                kind: l.kind,
                cone,
                intensity: l.intensity,
                rep: lights[0],
                second: 0,
                count: 1,
            };
            return at;
        }
        let (min, max) = lights.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
            let p = self.lights[i as usize].at;
            (lo.min(p), hi.max(p))
        });
        let extent = max - min;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = lights.len() / 2;
        let lights_ref = self.lights;
        lights.select_nth_unstable_by(mid, |&a, &b| {
            lights_ref[a as usize].at[axis].total_cmp(&lights_ref[b as usize].at[axis]).then(a.cmp(&b))
        });
        let (first, second) = lights.split_at_mut(mid);
        let a = self.node(first);
        let b = self.node(second);
        let (na, nb) = (self.nodes[a], self.nodes[b]);
        let intensity = na.intensity + nb.intensity;
        let (wa, wb) = (luminance(na.intensity).max(0.0), luminance(nb.intensity).max(0.0));
        let u = (hash_combine(REP_SEED, at as u64) >> 11) as f64 / (1u64 << 53) as f64;
        let rep = if wa + wb > 0.0 && u * (wa + wb) as f64 >= wa as f64 { nb.rep } else { na.rep };
        let cone = self.direction_cone(first, second, &na, &nb);
        let kind = na.kind;
        self.nodes[at] = CutNode { min, max, kind, cone, intensity, rep, second: b as u32, count: lights.len() as u32 };
        at
    }

    /// The cone of the directions of two groups' lights: about the sum of the children's axes,
    /// as wide as its farthest light (only meaningful for directional lights).
    fn direction_cone(&self, first: &[u32], second: &[u32], a: &CutNode, b: &CutNode) -> Cone {
        if self.lights[first[0] as usize].kind == CutLightKind::Point {
            return Cone::default();
        }
        let Some(axis) = (a.cone.axis + b.cone.axis).try_normalize() else { return Cone::default() };
        let cos = first
            .iter()
            .chain(second)
            .map(|&i| self.lights[i as usize].at.dot(axis))
            .fold(1.0f32, f32::min)
            .clamp(-1.0, 1.0);
        // Widened by a hair so that rounding never leaves a member outside.
        Cone::new(axis, libm::acosf(cos) + 1e-5)
    }
}
