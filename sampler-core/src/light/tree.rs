//! A light tree for many-light sampling (Conty Estevez & Kulla, HPG 2018): a binary hierarchy
//! over the lights' [`LightBounds`], built in caller-owned buffers by binned splits that minimise
//! power × box area × orientation spread (the cost pbrt-v4's `BVHLightSampler` documents). A
//! shading point picks a light by descending from the root, taking each child with probability
//! proportional to its importance for that point, so lights far away or facing away are rarely
//! picked; the probability of any light is recomputed by the same descent along the light's
//! recorded path, which MIS needs.

use super::bounds::LightBounds;
use super::select::SelectedLight;

/// A node of the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightNode {
    /// Bounds of every light below.
    pub bounds: LightBounds,
    /// A leaf's light index; an inner node's second child (its first child follows it).
    pub index: u32,
    /// It holds one light.
    pub leaf: bool,
}

/// The deepest path [`LightTree::build`] makes: a light's path is kept in 64 bits.
pub const MAX_DEPTH: usize = 64;

/// Depth past which splits are by count, so that any number of lights up to 2³² stays within
/// [`MAX_DEPTH`].
const MEDIAN_DEPTH: usize = 31;

/// Bins per axis of the split search.
const BINS: usize = 12;

/// A built tree, borrowing its nodes and the lights' paths.
#[derive(Clone, Copy, Debug)]
pub struct LightTree<'a> {
    nodes: &'a [LightNode],
    /// Per light index, its path from the root (bit k: second child at depth k); `u64::MAX`
    /// for a light not in the tree.
    paths: &'a [u64],
}

/// Why a tree cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TreeError {
    /// No light has bounds (all at infinity or dark).
    Empty,
    /// A buffer is smaller than [`LightTree::build`] needs.
    BufferTooSmall,
}

impl<'a> LightTree<'a> {
    /// Builds the tree over the lights whose bounds are given (`bounds[i]`: `Some` for light i
    /// in the tree). `order` needs one entry per light in the tree, `nodes` 2·that − 1 and
    /// `paths` one per light (`bounds.len()`).
    pub fn build(
        bounds: &[Option<LightBounds>],
        order: &mut [u32],
        nodes: &'a mut [LightNode],
        paths: &'a mut [u64],
    ) -> Result<Self, TreeError> {
        let n = bounds.iter().filter(|b| b.is_some()).count();
        if n == 0 {
            return Err(TreeError::Empty);
        }
        if order.len() < n || nodes.len() < 2 * n - 1 || paths.len() < bounds.len() {
            return Err(TreeError::BufferTooSmall);
        }
        let mut k = 0;
        for (i, b) in bounds.iter().enumerate() {
            if b.is_some() {
                order[k] = i as u32;
                k += 1;
            }
        }
        paths.iter_mut().for_each(|p| *p = u64::MAX);
        let mut builder = Builder { bounds, nodes, paths, used: 0 };
        builder.node(&mut order[..n], 0, 0);
        let Builder { nodes, paths, used, .. } = builder;
        Ok(Self { nodes: &nodes[..used], paths })
    }

    /// A tree [`LightTree::build`] made before, from its nodes ([`LightTree::nodes`]) and paths,
    /// kept by the caller; `None` when they cannot be one (no nodes, a child out of range).
    #[must_use]
    pub fn from_parts(nodes: &'a [LightNode], paths: &'a [u64]) -> Option<Self> {
        let valid = !nodes.is_empty()
            && nodes.iter().enumerate().all(|(k, n)| {
                if n.leaf {
                    (n.index as usize) < paths.len()
                } else {
                    (n.index as usize) > k + 1 && (n.index as usize) < nodes.len()
                }
            });
        valid.then_some(Self { nodes, paths })
    }

    /// The nodes, root first.
    #[must_use]
    pub fn nodes(&self) -> &'a [LightNode] {
        self.nodes
    }

    /// The root's bounds: every light in the tree.
    #[must_use]
    pub fn root(&self) -> &LightBounds {
        &self.nodes[0].bounds
    }

    /// A light for the point `p` of shading normal `n`, with the uniform `u` ∈ [0, 1); `None`
    /// where no light in the tree can light it.
    #[must_use]
    pub fn pick(&self, u: f64, p: glam::Vec3, n: glam::Vec3) -> Option<SelectedLight> {
        let (mut node, mut pmf, mut u) = (0usize, 1.0f64, u);
        loop {
            let here = &self.nodes[node];
            if here.leaf {
                return Some(SelectedLight { index: here.index as usize, pmf, u_remapped: u });
            }
            let (first, second, p_first) = self.children(node, p, n)?;
            if u < p_first {
                (node, pmf, u) = (first, pmf * p_first, (u / p_first).min(ONE_BELOW));
            } else {
                (node, pmf, u) = (second, pmf * (1.0 - p_first), ((u - p_first) / (1.0 - p_first)).min(ONE_BELOW));
            }
        }
    }

    /// The probability that [`LightTree::pick`] returns light `index` at `p` with normal `n`.
    #[must_use]
    pub fn pmf(&self, index: usize, p: glam::Vec3, n: glam::Vec3) -> f64 {
        let Some(&path) = self.paths.get(index).filter(|&&p| p != u64::MAX) else { return 0.0 };
        let (mut node, mut pmf) = (0usize, 1.0f64);
        for depth in 0..MAX_DEPTH {
            let here = &self.nodes[node];
            if here.leaf {
                return if here.index as usize == index { pmf } else { 0.0 };
            }
            let Some((first, second, p_first)) = self.children(node, p, n) else { return 0.0 };
            if path >> depth & 1 == 0 {
                (node, pmf) = (first, pmf * p_first);
            } else {
                (node, pmf) = (second, pmf * (1.0 - p_first));
            }
        }
        0.0
    }

    /// The children of the inner node `node` and the probability of descending into the first
    /// at `p` with normal `n`, in proportion to their importances there; `None` where neither
    /// can light the point.
    #[inline]
    fn children(&self, node: usize, p: glam::Vec3, n: glam::Vec3) -> Option<(usize, usize, f64)> {
        let (first, second) = (node + 1, self.nodes[node].index as usize);
        let a = self.nodes[first].bounds.importance(p, n) as f64;
        let b = self.nodes[second].bounds.importance(p, n) as f64;
        let total = a + b;
        (total > 0.0 && !total.is_nan()).then(|| (first, second, a / total))
    }
}

/// The largest f64 below 1.
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;

struct Builder<'b, 'a> {
    bounds: &'b [Option<LightBounds>],
    nodes: &'a mut [LightNode],
    paths: &'a mut [u64],
    used: usize,
}

impl Builder<'_, '_> {
    fn of(&self, light: u32) -> LightBounds {
        self.bounds[light as usize].expect("only lights with bounds are ordered")
    }

    /// Writes the subtree of `lights` at the next free node, reached by `path` at `depth`;
    /// returns its node index.
    fn node(&mut self, lights: &mut [u32], path: u64, depth: usize) -> usize {
        let at = self.used;
        self.used += 1;
        let bounds = lights[1..].iter().fold(self.of(lights[0]), |b, &l| b.union(&self.of(l)));
        if lights.len() == 1 {
            self.nodes[at] = LightNode { bounds, index: lights[0], leaf: true };
            self.paths[lights[0] as usize] = path;
            return at;
        }
        let mid = self.split(lights, &bounds, depth);
        let (first, second) = lights.split_at_mut(mid);
        self.node(first, path, depth + 1);
        let second_at = self.node(second, path | 1 << depth, depth + 1);
        self.nodes[at] = LightNode { bounds, index: second_at as u32, leaf: false };
        at
    }

    /// Reorders `lights` into two non-empty groups and returns the first's length: the binned
    /// split of least cost along any axis, or halves by count along the widest axis where no
    /// split helps or the tree is deep.
    fn split(&self, lights: &mut [u32], bounds: &LightBounds, depth: usize) -> usize {
        let centre = |l: u32| self.of(l).centre();
        let (lo, hi) = lights
            .iter()
            .fold((centre(lights[0]), centre(lights[0])), |(lo, hi), &l| (lo.min(centre(l)), hi.max(centre(l))));
        let extent = hi - lo;
        let widest = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mut best: Option<(f32, usize, usize)> = None;
        if depth < MEDIAN_DEPTH {
            for axis in 0..3 {
                if extent[axis] > 0.0
                    && let Some((cost, bin)) = self.best_bin(lights, axis, lo[axis], extent[axis], bounds)
                    && best.is_none_or(|b| cost < b.0)
                {
                    best = Some((cost, axis, bin));
                }
            }
        }
        if let Some((_, axis, bin)) = best {
            let bin_of = |l: u32| bin_index(centre(l)[axis], lo[axis], extent[axis]);
            let mid = partition(lights, |l| bin_of(l) <= bin);
            if mid > 0 && mid < lights.len() {
                return mid;
            }
        }
        // By count: the lower half of the centres along the widest axis.
        let mid = lights.len() / 2;
        lights.select_nth_unstable_by(mid, |&a, &b| centre(a)[widest].total_cmp(&centre(b)[widest]));
        mid
    }

    /// The cheapest split after bin k along `axis` (cost, k), if any bin split is possible.
    fn best_bin(
        &self,
        lights: &[u32],
        axis: usize,
        lo: f32,
        extent: f32,
        bounds: &LightBounds,
    ) -> Option<(f32, usize)> {
        let mut bins: [Option<LightBounds>; BINS] = [None; BINS];
        for &l in lights {
            let b = self.of(l);
            let k = bin_index(b.centre()[axis], lo, extent);
            bins[k] = Some(bins[k].map_or(b, |x| x.union(&b)));
        }
        // The bounds of bins k + 1 and up, for every k, in one sweep from the last bin: a
        // split's two sides then cost one union each instead of a fold over their bins.
        let mut above: [Option<LightBounds>; BINS] = [None; BINS];
        let mut acc: Option<LightBounds> = None;
        for k in (1..BINS).rev() {
            acc = merge(bins[k], acc);
            above[k - 1] = acc;
        }
        let mut best: Option<(f32, usize)> = None;
        let mut below: Option<LightBounds> = None;
        for k in 0..BINS - 1 {
            below = merge(below, bins[k]);
            let (Some(left), Some(right)) = (below, above[k]) else { continue };
            let cost = cost(&left, bounds) + cost(&right, bounds);
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, k));
            }
        }
        best
    }
}

/// The bounds of two optional groups together.
fn merge(a: Option<LightBounds>, b: Option<LightBounds>) -> Option<LightBounds> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.union(&b)),
        (a, b) => a.or(b),
    }
}

/// The bin of a centre coordinate.
fn bin_index(x: f32, lo: f32, extent: f32) -> usize {
    (((x - lo) / extent * BINS as f32) as usize).min(BINS - 1)
}

/// Moves the lights for which `first` holds to the front; returns how many.
fn partition(lights: &mut [u32], first: impl Fn(u32) -> bool) -> usize {
    let mut k = 0;
    for i in 0..lights.len() {
        if first(lights[i]) {
            lights.swap(i, k);
            k += 1;
        }
    }
    k
}

/// The split cost of a child: power × box area × the solid angle its normals and emission
/// spread over, the box's area taken relative to the parent's so that flat groups of lights
/// are not favoured.
fn cost(b: &LightBounds, parent: &LightBounds) -> f32 {
    let pi = core::f32::consts::PI;
    let theta_o = libm::acosf(b.cos_normals.clamp(-1.0, 1.0));
    let theta_e = libm::acosf(b.cos_emission.clamp(-1.0, 1.0));
    let theta_w = (theta_o + theta_e).min(pi);
    let (sin_o, cos_o) = (libm::sinf(theta_o), libm::cosf(theta_o));
    let m_omega = 2.0 * pi * (1.0 - cos_o)
        + 0.5 * pi * (2.0 * theta_w * sin_o - libm::cosf(theta_o - 2.0 * theta_w) - 2.0 * theta_o * sin_o + cos_o);
    let area = |b: &LightBounds| {
        let d = b.max - b.min;
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    };
    let parent_area = area(parent).max(1e-30);
    b.power * m_omega * (area(b) / parent_area).max(1e-12)
}
