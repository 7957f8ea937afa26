//! The caller-owned scratch memory of the product and its build: K BRDF samples drawn from a
//! randomised (0,2)-sequence, then the quadtree over their points with the product and each
//! node's branch probability computed in the same traversal.

use super::bilinear::Corners;
use super::keys::sort_keys;
use super::params::{ProductError, ProductParams};
use super::quadtree::{COORD_BITS, Leaves, Node, ProductKind, TreeBuilder};
use super::sampler::ProductSampler;
use crate::brdf::{Brdf, BrdfDraw};
use crate::env::{EnvHierarchy, luminance};
use crate::frame::Frame;
use crate::mapping::{sphere_to_square_batch, square_to_sphere, square_to_sphere_x4};
use crate::points::sobol02_shifted;
use glam::{Mat3, Vec2, Vec3, Vec4};
use heapless::Vec;

/// Scratch memory for one shading point at a time: K BRDF samples and up to NODES tree nodes.
/// Reused from point to point; never allocates. `size_of::<ProductArena<K, NODES>>()` is about
/// 48·K + 16·NODES bytes: each node's 8 bytes and its branch probability's 8. The default NODES
/// holds the largest trees that 256 samples make (docs/perf.md#tree-size-and-memory); when
/// NODES is exhausted, splitting stops and leaves keep the mean of their samples (still exact
/// sampling). A bilinear B̃ ([`Leaves::Bilinear`]) also stores four corner values per node and
/// needs CORNERS ≥ NODES (+16·NODES bytes); with the default CORNERS = 0 nobody pays for it and
/// B̃ stays piecewise constant ([`ProductSampler::kind`] says what was built).
pub struct ProductArena<const K: usize = 256, const NODES: usize = 2048, const CORNERS: usize = 0> {
    /// BRDF sample points, then the samples' points of the equal-area square.
    points: [Vec2; K],
    /// The BRDF's draws (shading frame).
    draws: [BrdfDraw; K],
    /// Usable samples' directions in the map frame.
    dirs: [Vec3; K],
    /// Usable samples' B·cos (luminance).
    values: [f32; K],
    /// The usable samples' sort keys (`keys.rs`), sorted.
    keys: [u64; K],
    nodes: Vec<Node, NODES>,
    /// Per node, the probability that the warp picks it among its parent's children (see
    /// [`branch_probabilities`]).
    branches: [f64; NODES],
    /// B̃ at each node's corners (bilinear B̃ only: needs CORNERS ≥ NODES).
    corners: Vec<Corners, CORNERS>,
    /// What the last build made (`None` before the first).
    built: Option<Built>,
}

/// What a build made, kept for [`ProductArena::last_built`].
#[derive(Clone, Copy, Debug)]
struct Built {
    /// The effective defensive fraction.
    defensive: f32,
    /// The usable BRDF samples.
    brdf_samples: usize,
    /// The kind as built ([`ProductArena::buildable`]).
    kind: ProductKind,
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
            keys: [0; K],
            nodes: Vec::new(),
            branches: [0.0; NODES],
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
        let kind = Self::buildable(params.kind);
        let wo_local = frame.to_local(wo);
        let k = params.brdf_samples;
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
            sort_keys(uvs, &mut self.keys[..count]);
            self.keys[..count].sort_unstable();
        }
        // B·cos at a point of the square, and at four side by side (each lane as `eval` gives
        // it), for the cells the build probes.
        let map_to_local = (env.world_to_map() * Mat3::from_cols(frame.s, frame.t, frame.n)).transpose();
        let eval = |uv: Vec2| luminance(brdf.eval(wo_local, map_to_local * square_to_sphere(uv)));
        let eval4 = |u: Vec4, v: Vec4| {
            let [x, y, z] = square_to_sphere_x4(u, v);
            let m = map_to_local;
            // `Mat3 * Vec3`'s order: the columns scaled by x, y, z and summed in turn.
            let row = |k: usize| {
                let c = |axis: Vec3| Vec4::splat(axis[k]);
                c(m.x_axis) * x + c(m.y_axis) * y + c(m.z_axis) * z
            };
            brdf.eval_luminance_x4(wo_local, [row(0), row(1), row(2)])
        };
        let mut builder = TreeBuilder {
            keys: &self.keys[..count],
            values: &self.values[..count],
            env,
            nodes: &mut self.nodes,
            branches: &mut self.branches,
            max_depth: params.max_depth.min(COORD_BITS),
            wavelet: kind.is_wavelet(),
            eval,
            eval4,
            probe_leaves: kind.leaves() == Leaves::Probed,
            refine_share: kind.refine_share(),
            bilinear: kind.leaves() == Leaves::Bilinear,
            corners: &mut self.corners,
        };
        builder.build();
        let root = self.nodes.first().map_or(0.0, |n| n.product);
        let has_product = root > 0.0 && root.is_finite();
        let defensive = if has_product { params.defensive.clamp(0.0, 1.0) } else { 1.0 };
        self.built = Some(Built { defensive, brdf_samples: count, kind });
        let built: &'a Self = self;
        Ok(built.last_built(env).expect("just built"))
    }

    /// The kind this arena builds when asked for `kind`: bilinear leaves need the corners'
    /// storage (CORNERS ≥ NODES), and without it the leaves are built from the samples.
    #[must_use]
    pub const fn buildable(kind: ProductKind) -> ProductKind {
        match kind {
            ProductKind::Quadtree { leaves: Leaves::Bilinear, refine_share } if CORNERS < NODES => {
                ProductKind::Quadtree { leaves: Leaves::Sampled, refine_share }
            }
            kind => kind,
        }
    }

    /// The sampler the last [`build`](Self::build) made, again, without rebuilding it (the arena
    /// holds it until the next build): for hosts that reuse one B̃ at nearby shading points.
    /// `env` must be the environment it was built on. `None` before the first build.
    #[must_use]
    pub fn last_built<'a, 'e>(&'a self, env: &'a EnvHierarchy<'e>) -> Option<ProductSampler<'a, 'e>> {
        let Built { defensive, brdf_samples, kind } = self.built?;
        Some(ProductSampler {
            env,
            nodes: &self.nodes,
            branches: &self.branches[..self.nodes.len()],
            corners: &self.corners,
            defensive,
            brdf_samples,
            kind,
        })
    }
}

/// The branch probabilities of four children of masses `mass`: `branch_probability` for each,
/// each column's share computed once. The build calls it wherever it sets a parent's children
/// (children always follow their parent in the arena's nodes); a descent multiplies them from
/// the root down, so a leaf's path probability is the product of its branches in the warp's
/// order. On x86-64 the six divisions run as three two-wide ones (the same correctly rounded
/// quotients): they occupy the divider once per internal node of every build.
#[inline]
pub(crate) fn branch_probabilities(mass: [f32; 4]) -> [f64; 4] {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        branch_probabilities_sse2(mass)
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        branch_probabilities_scalar(mass)
    }
}

/// [`branch_probabilities`] one division at a time.
#[cfg_attr(all(target_arch = "x86_64", target_feature = "sse2"), allow(dead_code))]
#[inline]
fn branch_probabilities_scalar(mass: [f32; 4]) -> [f64; 4] {
    let m = mass.map(f64::from);
    let total = m[0] + m[1] + m[2] + m[3];
    let mut out = [0.0; 4];
    for dx in 0..2 {
        let column = m[dx] + m[dx + 2];
        // Written as `branch_probability`'s test, so that NaN masses give what it gives.
        if total <= 0.0 || column <= 0.0 {
            continue;
        }
        let share = column / total;
        (out[dx], out[dx + 2]) = (share * (m[dx] / column), share * (m[dx + 2] / column));
    }
    out
}

/// [`branch_probabilities_scalar`] with both columns in the lanes of SSE2 registers: every
/// quotient and product computed as there, a column that test skips set to 0 by a mask.
#[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
#[inline(always)]
#[allow(unused_unsafe)]
fn branch_probabilities_sse2(mass: [f32; 4]) -> [f64; 4] {
    use core::arch::x86_64::*;
    let m = mass.map(f64::from);
    let total = m[0] + m[1] + m[2] + m[3];
    let mut out = [0.0; 4];
    // SAFETY: SSE2 is enabled (the cfg); the stores write `out`'s four values.
    unsafe {
        let (top, bottom) = (_mm_set_pd(m[1], m[0]), _mm_set_pd(m[3], m[2]));
        let column = _mm_add_pd(top, bottom);
        let total = _mm_set1_pd(total);
        let share = _mm_div_pd(column, total);
        let zero = _mm_setzero_pd();
        let skip = _mm_or_pd(_mm_cmple_pd(total, zero), _mm_cmple_pd(column, zero));
        let branch = |rows: __m128d| _mm_andnot_pd(skip, _mm_mul_pd(share, _mm_div_pd(rows, column)));
        _mm_storeu_pd(out.as_mut_ptr(), branch(top));
        _mm_storeu_pd(out.as_mut_ptr().add(2), branch(bottom));
    }
    out
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The four branches are `branch_probability`'s, bit for bit, including children of a
    /// parent whose column (or whole mass) is zero.
    #[test]
    fn branches_are_the_branch_probabilities() {
        for mass in [
            [0.3, 0.0, 0.7, 1e-7],
            [0.0, 0.1, 0.0, 3.0],
            [0.0; 4],
            [1.0, 2.0, 3.0, 4.0],
            [5.0, 0.0, 0.0, 0.0],
            [f32::NAN, 1.0, 0.0, 2.0],
            [f32::INFINITY, 1.0, 0.0, 2.0],
            [1e-45, 0.0, 3e38, 3e38],
            [-1.0, 2.0, 0.5, 0.0],
        ] {
            let got = branch_probabilities(mass);
            let scalar = branch_probabilities_scalar(mass);
            assert_eq!(got.map(f64::to_bits), scalar.map(f64::to_bits), "{mass:?}");
            for (k, g) in got.iter().enumerate() {
                assert_eq!(g.to_bits(), branch_probability(mass, k).to_bits(), "{mass:?}, child {k}");
            }
        }
    }
}
