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
//! excellent (small Var against μ²); docs/perf.md#defensive-mixture has the measured cost.
//! The default is ε = 0.02.

use crate::bilinear::{self, BilinearCell, Corners, Masses};
use crate::brdf::{Brdf, BrdfDraw};
use crate::env::{EnvHierarchy, luminance};
use crate::frame::Frame;
use crate::mapping::{SPHERE_AREA, sphere_to_square_batch, square_to_sphere};
use crate::points::sobol02_shifted;
use crate::quadtree::{COORD_BITS, Node, ProductKind, TreeBuilder, quantize, sort_key};
use crate::warp::{
    ONE_MINUS_EPSILON, child_offset, choose_child, choose_grandchild, grandchild_index, grandchild_probability,
    inverse_area, point_in_cell,
};
use glam::{DVec2, Mat3, Vec2, Vec3};
use heapless::Vec;

/// Settings of the per-shading-point product.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProductParams {
    /// BRDF samples drawn to build B̃ (at most the arena's capacity K: more is an error).
    pub brdf_samples: usize,
    /// Depth cap of the quadtree (≤ 24): coincident samples cannot split forever. Default 14
    /// (cells of 6e-5 of the square, ~2e-4 rad): deeper leaves shrink towards the f32 direction's
    /// resolution, and then the density a BRDF sample's `pdf(ω)` lookup finds is not always the
    /// product's density at ω — MIS weights stop summing to one (docs/perf.md#depth-cap).
    pub max_depth: u32,
    /// Defensive environment-sampling fraction ε ∈ (0, 1].
    pub defensive: f32,
    /// Combine rule: quadtree average or Haar wavelet product.
    pub kind: ProductKind,
    /// Probe B at the centre of each leaf that holds samples and keep the larger of that and the
    /// samples' value. Off by default: B̃ from the BRDF samples' own values, as in the paper.
    /// Hosts turn it on for product-MIS, where it lowers the error on glossy surfaces
    /// (docs/perf.md#product-mis-preset); plain product sampling without BRDF-sampling MIS
    /// keeps a heavy tail on car paint at grazing views either way.
    pub probe_leaves: bool,
    /// Split leaves that hold more than this share of the product's mass, B probed at the new
    /// children's centres, until none does (or the depth cap or the arena stops it): B̃ then
    /// follows B where the light concentrates the product, e.g. a sun in the lobe's tail. 0
    /// (the default) builds the paper's tree.
    pub refine_share: f32,
    /// B̃ bilinear in each leaf between B·cos at the leaf's corners (five evaluations per
    /// split), instead of one sample's value: B/B̃ then varies smoothly inside a leaf and B̃ is
    /// continuous across leaves, which the (0,2)-nets reward. Below a leaf the walk through the
    /// environment's levels weighs each cell by L·B̃ at its centre and the final texel is
    /// sampled ∝ B̃ inside. Off by default (the paper's piecewise-constant B̃) and in
    /// [`ProductParams::for_mis`]: per sample it is far better (`examples/product_variance`),
    /// but every sample and every density walks the environment's levels weighing cells by
    /// B̃, which costs more than it saves where rays are cheap and one build serves a pixel
    /// (docs/perf.md#product-mis-preset). Worth it where rays cost more than those lookups.
    pub bilinear: bool,
}

impl Default for ProductParams {
    fn default() -> Self {
        Self {
            brdf_samples: 256,
            max_depth: 14,
            defensive: 0.02,
            kind: ProductKind::Quadtree,
            probe_leaves: false,
            refine_share: 0.0,
            bilinear: false,
        }
    }
}

impl ProductParams {
    /// Settings for a product sampler used in MIS with BRDF sampling (`estimator::sampled_mis`;
    /// docs/perf.md#product-mis-preset): leaves probed at their centres, leaves heavier than
    /// one BRDF sample's share (1/K of the mass) refined, and a defensive fraction of 0.25 —
    /// the BRDF half already covers the lobe, so environment samples are what the pair lacks
    /// where the light peaks in the lobe's tail (a sun beside a sharp lobe).
    #[must_use]
    pub fn for_mis(brdf_samples: usize) -> Self {
        Self {
            brdf_samples,
            defensive: 0.25,
            probe_leaves: true,
            refine_share: 1.0 / brdf_samples.max(1) as f32,
            ..Self::default()
        }
    }
}

/// Why a product sampler could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProductError {
    /// More BRDF samples were asked for than the arena holds (its `K`).
    AboveCapacity {
        /// [`ProductParams::brdf_samples`].
        asked: usize,
        /// The arena's `K`.
        capacity: usize,
    },
}

impl core::fmt::Display for ProductError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::AboveCapacity { asked, capacity } => {
                write!(f, "{asked} BRDF samples asked of a product arena that holds {capacity}")
            }
        }
    }
}

impl core::error::Error for ProductError {}

/// Scratch memory for one shading point at a time: K BRDF samples and up to NODES tree nodes.
/// Reused from point to point; never allocates. `size_of::<ProductArena<K, NODES>>()` is about
/// 48·K + 16·NODES bytes: each node's 8 bytes and its path probability's 8. The default NODES
/// holds the largest trees that 256 samples make (docs/perf.md#tree-size-and-memory); when
/// NODES is exhausted, splitting stops and leaves keep the mean of their samples (still exact
/// sampling). A bilinear B̃ (`ProductParams::bilinear`) also stores four corner values per node
/// and needs CORNERS ≥ NODES (+16·NODES bytes); with the
/// default CORNERS = 0 nobody pays for it and B̃ stays piecewise constant
/// ([`ProductSampler::is_bilinear`] says which was built).
pub struct ProductArena<const K: usize = 256, const NODES: usize = 2048, const CORNERS: usize = 0> {
    /// BRDF sample points, then the samples' points of the equal-area square.
    points: [Vec2; K],
    /// The BRDF's draws (shading frame).
    draws: [BrdfDraw; K],
    /// Usable samples' directions in the map frame.
    dirs: [Vec3; K],
    /// Usable samples' B·cos (luminance).
    values: [f32; K],
    keys: Vec<u64, K>,
    nodes: Vec<Node, NODES>,
    /// Per node, the probability that the warp reaches it (see `path_probabilities`).
    paths: Vec<f64, NODES>,
    /// B̃ at each node's corners (bilinear B̃ only: needs CORNERS ≥ NODES).
    corners: Vec<Corners, CORNERS>,
    /// The last build's defensive fraction and usable BRDF samples (`None` before the first).
    built: Option<(f32, usize)>,
}

impl<const K: usize, const NODES: usize, const CORNERS: usize> Default for ProductArena<K, NODES, CORNERS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const K: usize, const NODES: usize, const CORNERS: usize> ProductArena<K, NODES, CORNERS> {
    const CAPACITY_OK: () = assert!(K >= 1 && K <= 1 << 16 && NODES >= 1);

    /// An empty arena (large: place it in a `static`, a `Box` or a thread's stack).
    #[must_use]
    pub const fn new() -> Self {
        let () = Self::CAPACITY_OK;
        Self {
            points: [Vec2::ZERO; K],
            draws: [BrdfDraw { wi: Vec3::ZERO, value: 0.0 }; K],
            dirs: [Vec3::ZERO; K],
            values: [0.0; K],
            keys: Vec::new(),
            nodes: Vec::new(),
            paths: Vec::new(),
            corners: Vec::new(),
            built: None,
        }
    }

    /// Builds the product sampler of one shading point. `wo` is the world-space direction
    /// towards the viewer, `frame` the shading frame, `seed` randomises the BRDF samples. More
    /// BRDF samples than the arena's `K` is an error, never a silent clamp.
    pub fn build<'a, 'e, B: Brdf + ?Sized>(
        &'a mut self,
        env: &'a EnvHierarchy<'e>,
        brdf: &B,
        frame: &Frame,
        wo: Vec3,
        params: &ProductParams,
        seed: u64,
    ) -> Result<ProductSampler<'a, 'e>, ProductError> {
        if params.brdf_samples > K {
            return Err(ProductError::AboveCapacity { asked: params.brdf_samples, capacity: K });
        }
        let wo_local = frame.to_local(wo);
        let k = params.brdf_samples;
        self.keys.clear();
        let mut count = 0;
        if !env.is_black() && k > 0 {
            // K BRDF samples from a randomised (0,2)-sequence, in one call.
            sobol02_shifted(seed, 0, &mut self.points[..k]);
            let drawn = brdf.sample_batch(wo_local, &self.points[..k], &mut self.draws[..k]);
            // Shading frame → map frame in one matrix.
            let local_to_map = env.world_to_map() * Mat3::from_cols(frame.s, frame.t, frame.n);
            for d in &self.draws[..drawn.min(k)] {
                let ok = |v: f32| v.is_finite() && v >= 0.0;
                if ok(d.value) && d.wi.is_finite() {
                    self.dirs[count] = local_to_map * d.wi;
                    self.values[count] = d.value;
                    count += 1;
                }
            }
            let uvs = &mut self.points[..count];
            sphere_to_square_batch(&self.dirs[..count], uvs);
            for (idx, uv) in uvs.iter().enumerate() {
                let _ = self.keys.push(sort_key(uv.x, uv.y, idx));
            }
            self.keys.sort_unstable();
        }
        // B·cos at a point of the square, for the empty cells that need it.
        let map_to_local = (env.world_to_map() * Mat3::from_cols(frame.s, frame.t, frame.n)).transpose();
        let eval = |uv: Vec2| luminance(brdf.eval(wo_local, map_to_local * square_to_sphere(uv)));
        let mut builder = TreeBuilder {
            keys: &self.keys,
            values: &self.values[..count],
            env,
            nodes: &mut self.nodes,
            max_depth: params.max_depth.min(COORD_BITS),
            kind: params.kind,
            eval,
            probe_leaves: params.probe_leaves,
            refine_share: if params.kind == ProductKind::Quadtree { params.refine_share } else { 0.0 },
            bilinear: params.bilinear && params.kind == ProductKind::Quadtree && CORNERS >= NODES,
            corners: &mut self.corners,
        };
        builder.build();
        path_probabilities(&self.nodes, &mut self.paths);
        let root = self.nodes.first().map_or(0.0, |n| n.product);
        let has_product = root > 0.0 && root.is_finite();
        let defensive = if has_product { params.defensive.clamp(0.0, 1.0) } else { 1.0 };
        self.built = Some((defensive, count));
        let built: &'a Self = self;
        Ok(built.last_built(env).expect("just built"))
    }

    /// The sampler the last [`build`](Self::build) made, again, without rebuilding it (the arena
    /// holds it until the next build): for hosts that reuse one B̃ at nearby shading points.
    /// `env` must be the environment it was built on. `None` before the first build.
    #[must_use]
    pub fn last_built<'a, 'e>(&'a self, env: &'a EnvHierarchy<'e>) -> Option<ProductSampler<'a, 'e>> {
        let (defensive, brdf_samples) = self.built?;
        Some(ProductSampler {
            env,
            nodes: &self.nodes,
            paths: &self.paths,
            corners: &self.corners,
            defensive,
            brdf_samples,
        })
    }
}

/// Each node's path probability: the product of the branch probabilities from the root down to
/// it, multiplied in the warp's order (so bit for bit what a descent would multiply). Computed
/// once per build, top-down (children always follow their parent in `nodes`), so that the warp
/// and the density read it at the leaf instead of dividing at every level.
fn path_probabilities<const N: usize>(nodes: &[Node], paths: &mut Vec<f64, N>) {
    paths.clear();
    let _ = paths.resize(nodes.len(), 0.0);
    if let Some(root) = paths.first_mut() {
        *root = 1.0;
    }
    for (i, n) in nodes.iter().enumerate() {
        if n.is_leaf() {
            continue;
        }
        let first = n.child as usize;
        let c = &nodes[first..first + 4];
        let mass = [c[0].product, c[1].product, c[2].product, c[3].product];
        for k in 0..4 {
            paths[first + k] = paths[i] * branch_probability(mass, k);
        }
    }
}

/// Probability that the warp picks child `k` among four of masses `mass`: the column, then the
/// row — m_k / Σm, computed as the warp's own two ratios.
#[inline]
pub(crate) fn branch_probability(mass: [f32; 4], k: usize) -> f64 {
    let m = mass.map(f64::from);
    let (dx, dy) = (k & 1, k >> 1);
    let total = m[0] + m[1] + m[2] + m[3];
    let column = m[dx] + m[dx + 2];
    if total <= 0.0 || column <= 0.0 {
        return 0.0;
    }
    (column / total) * (m[dx + 2 * dy] / column)
}

pub use crate::direction::DirectionSample;

/// The product distribution of one shading point, borrowing its arena.
#[derive(Clone, Copy, Debug)]
pub struct ProductSampler<'a, 'e> {
    pub(crate) env: &'a EnvHierarchy<'e>,
    pub(crate) nodes: &'a [Node],
    /// Per node, the probability that the warp reaches it.
    pub(crate) paths: &'a [f64],
    /// Per node, B̃ at its corners; empty unless B̃ is bilinear.
    pub(crate) corners: &'a [Corners],
    pub(crate) defensive: f32,
    brdf_samples: usize,
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

    /// True when B̃ is bilinear in the leaves (asked for, quadtree kind, arena with corners).
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
            let (x, y) = self.env.warp_down(0, 0, 0, &mut xi)?;
            let uv = point_in_cell(x, y, self.env.finest_level(), xi);
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
        let (mut i, mut depth, mut x, mut y) = (0usize, 0u32, 0u32, 0u32);
        while !self.nodes[i].is_leaf() {
            let first = self.nodes[i].child as usize;
            let c = &self.nodes[first..first + 4];
            let child = choose_child([c[0].product, c[1].product, c[2].product, c[3].product], xi)?;
            let (dx, dy) = child_offset(child);
            (i, depth, x, y) = (first + child, depth + 1, 2 * x + dx, 2 * y + dy);
        }
        let path = self.paths[i];
        let finest = self.env.finest_level();
        if !self.corners.is_empty() {
            return self.warp_bilinear(i, path, depth, x, y, xi);
        }
        let texel = if depth < finest { self.env.warp_down(depth, x, y, xi)? } else { (x, y) };
        Some(self.land(path, depth, x, y, texel, *xi))
    }

    /// Where a product sample that reached leaf (depth, x, y) with probability `path` lands,
    /// with ξ uniform in the last cell: in `texel` (chosen below the leaf by the env's levels)
    /// when the leaf is coarser than the map, in the leaf itself otherwise. Returns the point,
    /// the product's density per unit area there and the texel's relative importance.
    pub(crate) fn land(&self, path: f64, depth: u32, x: u32, y: u32, texel: (u32, u32), xi: DVec2) -> (Vec2, f64, f32) {
        let finest = self.env.finest_level();
        let (uv, importance) = if depth < finest {
            // `point_in_cell` keeps the point in the texel the descent chose, so the texel is
            // known: `leaf_density`'s result without its lookups.
            (point_in_cell(texel.0, texel.1, finest, xi), self.env.node_relative(finest, texel.0, texel.1))
        } else {
            let uv = point_in_cell(x, y, depth, xi);
            (uv, self.env.pdf_square(uv))
        };
        (uv, self.leaf_density(path, depth, x, y, importance), importance)
    }

    /// Below leaf `leaf` (cell (depth, x, y), reached with probability `path`) with a bilinear
    /// B̃: down the environment's levels by L·B̃ at each cell's centre, then inside the texel
    /// (or the leaf, when it is finer than a texel) ∝ B̃. Returns what `warp_product` does.
    fn warp_bilinear(
        &self,
        leaf: usize,
        path: f64,
        depth: u32,
        x: u32,
        y: u32,
        xi: &mut DVec2,
    ) -> Option<(Vec2, f64, f32)> {
        let w = &self.corners[leaf];
        let (cell, path) = self.walk_bilinear(w, path, depth, x, y, |masses, _| match masses {
            Masses::Sixteen(m) => choose_grandchild(m, xi).map(|(k, _, _)| k),
            Masses::Four(m) => choose_child(m, xi),
        })?;
        let corners = bilinear::sub_corners(w, cell.s, cell.t, cell.size);
        let uv = point_in_cell(cell.x, cell.y, cell.level, bilinear::sample(&corners, *xi));
        let texel = self.env.cell_relative(cell.level, cell.x, cell.y);
        // The density at the point as stored (f32), as `pdf_square` will find it.
        Some((uv, cell.density(path, &corners, uv), texel))
    }

    /// The walk below a bilinear leaf (cell (depth, x, y), reached with probability `path`)
    /// down to the finest level: two levels per step over the 16 grandchildren (one cache
    /// line), then one if left, each cell weighed by L·B̃ at its centre. `pick` chooses the
    /// next cell from the masses (`warp_bilinear` by its point, `bilinear_density` by the
    /// bits of `uv`) — one walk, so the warp and its pdf weigh every cell alike. Returns the
    /// final cell and the probability of reaching it; `None` when `pick` finds no mass.
    fn walk_bilinear(
        &self,
        w: &Corners,
        mut path: f64,
        depth: u32,
        x: u32,
        y: u32,
        mut pick: impl FnMut(Masses<'_>, &BilinearCell) -> Option<usize>,
    ) -> Option<(BilinearCell, f64)> {
        let finest = self.env.finest_level();
        let mut cell = BilinearCell { level: depth, x, y, s: 0.0, t: 0.0, size: 1.0 };
        while cell.level + 2 <= finest {
            let mass = self.bilinear_grandchild_masses(w, &cell);
            let k = pick(Masses::Sixteen(&mass), &cell)?;
            path *= grandchild_probability(&mass, k);
            // Morton index → (column, row) of the grandchild.
            let (gx, gy) = ((k & 1 | (k >> 1) & 2) as u32, ((k >> 1) & 1 | (k >> 2) & 2) as u32);
            cell.descend_two(gx, gy);
        }
        if cell.level < finest {
            let mass = self.bilinear_masses(w, &cell);
            let child = pick(Masses::Four(mass), &cell)?;
            path *= branch_probability(mass, child);
            cell.descend(child);
        }
        Some((cell, path))
    }

    /// The environment's 16 grandchildren of `cell` (Morton order, see `choose_grandchild`),
    /// each weighed by B̃ at its centre: B̃ = a + b·s + c·t + d·s·t along each row of four.
    #[inline]
    fn bilinear_grandchild_masses(&self, w: &Corners, cell: &BilinearCell) -> [f32; 16] {
        let g = self.env.grandchildren_raw(cell.level, cell.x, cell.y);
        let (a, b, c, d) = (w[0], w[1] - w[0], w[2] - w[0], (w[3] - w[2]) - (w[1] - w[0]));
        let q = 0.25 * cell.size;
        let centre = |o: f32, i: u32| o + (i as f32 + 0.5) * q;
        let mut mass = [0.0f32; 16];
        for gy in 0..4u32 {
            let t = centre(cell.t, gy);
            let (row, slope) = (a + c * t, b + d * t);
            for gx in 0..4u32 {
                let k = grandchild_index(gx, gy);
                mass[k] = g[k] * (row + slope * centre(cell.s, gx));
            }
        }
        mass
    }

    /// The environment's four children of `cell`, each weighed by B̃ at its centre.
    #[inline]
    fn bilinear_masses(&self, w: &Corners, cell: &BilinearCell) -> [f32; 4] {
        let l = self.env.children_relative(cell.level, cell.x, cell.y);
        let h = 0.25 * cell.size;
        let (s0, s1, t0, t1) = (cell.s + h, cell.s + 3.0 * h, cell.t + h, cell.t + 3.0 * h);
        [
            l[0] * bilinear::bilinear(w, s0, t0),
            l[1] * bilinear::bilinear(w, s1, t0),
            l[2] * bilinear::bilinear(w, s0, t1),
            l[3] * bilinear::bilinear(w, s1, t1),
        ]
    }

    /// The bilinear product's density at `uv` inside leaf `leaf` (cell (depth, x, y), reached
    /// with probability `path`): the walk `warp_bilinear` takes, replayed by `uv`'s bits.
    fn bilinear_density(&self, leaf: usize, path: f64, depth: u32, x: u32, y: u32, uv: Vec2) -> f64 {
        let w = &self.corners[leaf];
        let (qx, qy) = (quantize(uv.x), quantize(uv.y));
        // The bits of `uv` that choose among the 2^n × 2^n cells below a cell of `level`.
        let bits = |level: u32, n: u32| {
            let shift = COORD_BITS - level - n;
            let mask = (1 << n) - 1;
            ((qx >> shift) & mask, (qy >> shift) & mask)
        };
        let walked = self.walk_bilinear(w, path, depth, x, y, |masses, cell| match masses {
            Masses::Sixteen(_) => {
                let (gx, gy) = bits(cell.level, 2);
                Some(grandchild_index(gx, gy))
            }
            Masses::Four(_) => {
                let (dx, dy) = bits(cell.level, 1);
                Some((dx + 2 * dy) as usize)
            }
        });
        let Some((cell, path)) = walked else { return 0.0 };
        cell.density(path, &bilinear::sub_corners(w, cell.s, cell.t, cell.size), uv)
    }

    /// Density per unit square area inside the leaf (depth, x, y) reached with probability
    /// `path`, at a point whose texel has relative importance `texel`: the leaf's share spread
    /// over its area, and below it the environment's texels in proportion to their importance.
    pub(crate) fn leaf_density(&self, path: f64, depth: u32, x: u32, y: u32, texel: f32) -> f64 {
        let area = inverse_area(depth);
        if depth < self.env.finest_level() {
            let leaf_env = self.env.node_relative(depth, x, y) as f64;
            if leaf_env > 0.0 { path * area * texel as f64 / leaf_env } else { 0.0 }
        } else {
            path * area
        }
    }

    /// The product's density per unit square area at `uv`, from the product of the branch
    /// probabilities the warp takes to reach its leaf (kept per node by the build): exactly the density the warp realises, however
    /// the node values were computed (the Haar product's cancellation makes its node values
    /// differ from the means of their children at extreme dynamic range). `texel`: the env's
    /// relative importance at `uv` (`EnvHierarchy::pdf_square`), which the caller has already.
    fn product_density(&self, uv: Vec2, texel: f32) -> f64 {
        let Some(root) = self.nodes.first() else { return 0.0 };
        let (qx, qy) = (quantize(uv.x), quantize(uv.y));
        let (mut node, mut index, mut depth, mut x, mut y) = (*root, 0usize, 0u32, 0u32, 0u32);
        while !node.is_leaf() {
            let shift = COORD_BITS - 1 - depth;
            let (dx, dy) = ((qx >> shift) & 1, (qy >> shift) & 1);
            let k = (dx + 2 * dy) as usize;
            index = node.child as usize + k;
            node = self.nodes[index];
            (depth, x, y) = (depth + 1, 2 * x + dx, 2 * y + dy);
        }
        let path = self.paths[index];
        if !self.corners.is_empty() {
            return self.bilinear_density(index, path, depth, x, y, uv);
        }
        self.leaf_density(path, depth, x, y, texel)
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
        let env_relative = self.env.pdf_square(uv);
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
