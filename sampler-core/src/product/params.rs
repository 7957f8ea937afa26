//! The settings of a product build and why a build can fail.

use super::quadtree::ProductKind;

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
