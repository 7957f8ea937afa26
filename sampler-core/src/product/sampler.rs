//! The product sampler of one shading point: draws K BRDF samples, builds the quadtree product
//! with the environment in a caller-owned arena, then warps points to directions with density
//! ∝ B̃·L (down to the environment's texels) and evaluates that density for any direction.
//!
//! **Unbiasedness guard.** B̃ can be 0 where B·L > 0: a leaf whose only sample has B = 0 (e.g.
//! below the horizon) may still straddle directions with B > 0, all BRDF samples can fail at
//! grazing views, and the product can vanish where the lobe sees only black sky. The sampler is
//! therefore a defensive mixture
//!
//!   p(ω) = (1 − ε)·p_product(ω) + ε·p_env(ω),
//!
//! with p_env the environment-only density through the same hierarchy. p > 0 wherever L > 0,
//! hence wherever L·B > 0, and the weight f/p ≤ f/(ε·p_env) is bounded. When the product has no
//! mass at all, ε becomes 1 (plain environment sampling).
//!
//! Cost: the second moment of f/p grows by at most 1/(1 − ε), so the variance by at most
//! Var/(1 − ε) + μ²·ε/(1 − ε) — the relative cost is largest where product sampling is already
//! excellent (small Var against μ²); docs/perf.md#per-sample-variance has the measured cost.
//! The default is ε = 0.02.

use super::bilinear::Corners;
use super::quadtree::{COORD_BITS, Node, ProductKind, quantize};
use crate::cell::Cell;
use crate::env::EnvHierarchy;
use crate::mapping::SPHERE_AREA;
use crate::warp::{ONE_MINUS_EPSILON, choose_child};
use glam::{DVec2, Vec2, Vec3};

pub use super::arena::ProductArena;
pub use super::params::{ProductError, ProductParams};
pub use crate::direction::DirectionSample;

/// The product distribution of one shading point, borrowing its arena.
#[derive(Clone, Copy, Debug)]
pub struct ProductSampler<'a, 'e> {
    pub(crate) env: &'a EnvHierarchy<'e>,
    pub(crate) nodes: &'a [Node],
    /// Per node, the probability that the warp picks it among its siblings; a descent's product
    /// of them from the root down is its path probability.
    pub(crate) branches: &'a [f64],
    /// Per node, B̃ at its corners; empty unless B̃ is bilinear.
    pub(crate) corners: &'a [Corners],
    pub(crate) defensive: f32,
    pub(super) brdf_samples: usize,
    /// The kind as built.
    pub(super) kind: ProductKind,
}

impl<'e> ProductSampler<'_, 'e> {
    /// The environment this sampler was built on.
    #[must_use]
    pub fn env(&self) -> &EnvHierarchy<'e> {
        self.env
    }

    /// Nodes in the tree (0 when no BRDF sample was usable).
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// BRDF samples that went into B̃.
    #[must_use]
    pub fn brdf_samples(&self) -> usize {
        self.brdf_samples
    }

    /// What was built: the kind asked for, except that bilinear leaves asked of an arena
    /// without corners' storage are built from the samples ([`ProductArena::buildable`]).
    #[must_use]
    pub fn kind(&self) -> ProductKind {
        self.kind
    }

    /// True when B̃ is bilinear in the leaves (asked for, of an arena with corners, and a tree
    /// was built).
    #[must_use]
    pub fn is_bilinear(&self) -> bool {
        !self.corners.is_empty()
    }

    /// Effective defensive fraction ε (1 when the product has no mass).
    #[must_use]
    pub fn defensive(&self) -> f32 {
        self.defensive
    }

    /// ∫ B̃ · L̂ over the square, with L̂ = L / mean L (the paper's L_ns up to the map's mean
    /// and the 4π of the solid angle).
    #[must_use]
    pub fn product_mean(&self) -> f32 {
        self.nodes.first().map_or(0.0, |n| n.product)
    }

    /// Draws a direction; `None` only when the environment is black.
    pub fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        let mut xi = u.clamp(DVec2::ZERO, DVec2::splat(ONE_MINUS_EPSILON));
        let eps = self.defensive as f64;
        let (uv, pdf_square) = if xi.x < eps {
            xi.x = (xi.x / eps).min(ONE_MINUS_EPSILON);
            let uv = self.env.warp_down(Cell::ROOT, &mut xi)?.point(xi);
            (uv, self.pdf_square(uv))
        } else {
            xi.x = ((xi.x - eps) / (1.0 - eps)).clamp(0.0, ONE_MINUS_EPSILON);
            let (uv, product, texel) = self.warp_product(&mut xi)?;
            // The warp knows its path and its texel: no second descent, no lookup for the pdf.
            (uv, self.mixture(product, texel))
        };
        Some(DirectionSample { dir: self.env.dir_of(uv), uv, pdf: pdf_square / SPHERE_AREA })
    }

    /// Warps through the product tree, then below the leaf through the environment's levels.
    /// Returns the point, the product's density per unit square area there and the relative
    /// importance of its texel (the env's density per unit square area).
    fn warp_product(&self, xi: &mut DVec2) -> Option<(Vec2, f64, f32)> {
        let (mut i, mut leaf, mut path) = (0usize, Cell::ROOT, 1.0f64);
        while !self.nodes[i].is_leaf() {
            let first = self.nodes[i].child as usize;
            let c = &self.nodes[first..first + 4];
            let child = choose_child([c[0].product, c[1].product, c[2].product, c[3].product], xi)?;
            (i, leaf) = (first + child, leaf.child(child));
            path *= self.branches[i];
        }
        if !self.corners.is_empty() {
            return self.warp_bilinear(i, path, leaf, xi);
        }
        let texel = if leaf.level < self.env.finest_level() { self.env.warp_down(leaf, xi)? } else { leaf };
        Some(self.land(path, leaf, texel, *xi))
    }

    /// Where a product sample that reached `leaf` with probability `path` lands, with ξ
    /// uniform in the last cell: in `texel` (chosen below the leaf by the env's levels) when the
    /// leaf is coarser than the map, in the leaf itself otherwise (then `texel` is the leaf).
    /// Returns the point, the product's density per unit area there and the texel's relative
    /// importance.
    pub(crate) fn land(&self, path: f64, leaf: Cell, texel: Cell, xi: DVec2) -> (Vec2, f64, f32) {
        let (uv, importance) = if leaf.level < self.env.finest_level() {
            // `Cell::point` keeps the point in the texel the descent chose, so the texel is
            // known: `leaf_density`'s result without its lookups.
            (texel.point(xi), self.env.node_relative(texel))
        } else {
            let uv = leaf.point(xi);
            (uv, self.env.texel_relative(uv))
        };
        (uv, self.leaf_density(path, leaf, importance), importance)
    }

    /// Density per unit square area inside `leaf`, reached with probability `path`, at a point
    /// whose texel has relative importance `texel`: the leaf's share spread over its area, and
    /// below it the environment's texels in proportion to their importance.
    pub(crate) fn leaf_density(&self, path: f64, leaf: Cell, texel: f32) -> f64 {
        if leaf.level < self.env.finest_level() {
            self.density_below_leaf(path, leaf, self.env.node_relative(leaf), texel)
        } else {
            path * leaf.inverse_area()
        }
    }

    /// [`leaf_density`](Self::leaf_density) in a leaf coarser than the map whose environment
    /// (relative to the mean) is `leaf_env`, for callers that know it.
    #[inline]
    pub(crate) fn density_below_leaf(&self, path: f64, leaf: Cell, leaf_env: f32, texel: f32) -> f64 {
        let (area, leaf_env) = (leaf.inverse_area(), leaf_env as f64);
        if leaf_env > 0.0 { path * area * texel as f64 / leaf_env } else { 0.0 }
    }

    /// The product's density per unit square area at `uv`, from the product of the branch
    /// probabilities the warp takes to reach its leaf (kept per node by the build): exactly the
    /// density the warp realises, however the node values were computed (the Haar product's
    /// cancellation makes its node values differ from the means of their children at extreme
    /// dynamic range). `texel`: the env's relative importance at `uv`
    /// (`EnvHierarchy::pdf_square`), which the caller has already.
    fn product_density(&self, uv: Vec2, texel: f32) -> f64 {
        let Some(root) = self.nodes.first() else { return 0.0 };
        let (qx, qy) = (quantize(uv.x), quantize(uv.y));
        let (mut node, mut index, mut leaf, mut path) = (*root, 0usize, Cell::ROOT, 1.0f64);
        while !node.is_leaf() {
            let shift = COORD_BITS - 1 - leaf.level;
            let k = (((qx >> shift) & 1) + 2 * ((qy >> shift) & 1)) as usize;
            index = node.child as usize + k;
            node = self.nodes[index];
            leaf = leaf.child(k);
            path *= self.branches[index];
        }
        if !self.corners.is_empty() {
            return self.bilinear_density(index, path, leaf, uv);
        }
        self.leaf_density(path, leaf, texel)
    }

    /// The mixture density per unit square area, from the product's density and the texel's
    /// relative importance.
    #[inline]
    pub(crate) fn mixture(&self, product: f64, env_relative: f32) -> f32 {
        if self.defensive >= 1.0 {
            return env_relative;
        }
        ((1.0 - self.defensive as f64) * product + self.defensive as f64 * env_relative as f64) as f32
    }

    /// The leaf containing a point of the square, and its depth.
    #[must_use]
    pub fn leaf_at(&self, uv: Vec2) -> Option<(Node, u32)> {
        let root = self.nodes.first()?;
        let (qx, qy) = (quantize(uv.x), quantize(uv.y));
        let (mut node, mut depth) = (*root, 0u32);
        while !node.is_leaf() {
            let shift = COORD_BITS - 1 - depth;
            let c = ((qx >> shift) & 1) + 2 * ((qy >> shift) & 1);
            node = self.nodes[node.child as usize + c as usize];
            depth += 1;
        }
        Some((node, depth))
    }

    /// Depth of the dyadic cell around `uv` on which the density is constant: the deeper of
    /// the B̃ leaf and the environment's finest level. Lets tests and tools integrate the
    /// density exactly.
    #[must_use]
    pub fn constant_depth_at(&self, uv: Vec2) -> u32 {
        let leaf = self.leaf_at(uv).map_or(0, |(_, d)| d);
        leaf.max(self.env.finest_level())
    }

    /// Density per unit area of the square at `uv` (the mixture; integrates to 1 over the unit square).
    #[must_use]
    pub fn pdf_square(&self, uv: Vec2) -> f32 {
        let env_relative = self.env.texel_relative(uv);
        if self.defensive >= 1.0 {
            return env_relative;
        }
        self.mixture(self.product_density(uv, env_relative), env_relative)
    }

    /// Density with respect to solid angle of world direction `dir`.
    #[must_use]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        self.pdf_square(self.env.square_of(dir)) / SPHERE_AREA
    }
}
