//! The settings of a product build and why a build can fail.

use super::quadtree::{Leaves, ProductKind};

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
    /// How the tree is built and combined: the quadtree average with its leaves and
    /// refinement, or the Haar wavelet product.
    pub kind: ProductKind,
}

impl Default for ProductParams {
    fn default() -> Self {
        Self { brdf_samples: 256, max_depth: 14, defensive: 0.02, kind: ProductKind::QUADTREE }
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
            kind: ProductKind::Quadtree { leaves: Leaves::Probed, refine_share: 1.0 / brdf_samples.max(1) as f32 },
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
