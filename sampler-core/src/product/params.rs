//! The settings of a product build — the options of the tree that exist only together are the
//! variants of [`ProductKind`] — and why a build can fail.

/// What B̃ is inside a leaf of the quadtree product.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Leaves {
    /// The mean of the leaf's BRDF samples' values, as in the paper.
    #[default]
    Sampled,
    /// The samples' mean or B at the leaf's centre, the larger. Hosts use it for product-MIS,
    /// where it lowers the error on glossy surfaces (docs/tuning.md#product-mis-preset); plain
    /// product sampling without BRDF-sampling MIS keeps a heavy tail on car paint at grazing
    /// views either way.
    Probed,
    /// Bilinear between B·cos at the leaf's corners (five evaluations per split), instead of
    /// one sample's value: B/B̃ then varies smoothly inside a leaf and B̃ is continuous across
    /// leaves, which the (0,2)-nets reward. Below a leaf the walk through the environment's
    /// levels weighs each cell by L·B̃ at its centre and the final texel is sampled ∝ B̃
    /// inside. Per sample it is far better (`examples/product_variance`), but every sample and
    /// every density walks the environment's levels weighing cells by B̃, which costs more than
    /// it saves where rays are cheap and one build serves a pixel
    /// (docs/tuning.md#product-mis-preset): worth it where rays cost more than those lookups.
    /// Needs an arena with `CORNERS ≥ NODES`; an arena without builds [`Leaves::Sampled`]
    /// leaves, and the sampler says so (`ProductSampler::kind`).
    Bilinear,
}

/// How the tree is built and its nodes combine their children: the options that exist only
/// together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProductKind {
    /// Average of the four children's products (Clarberg & Akenine-Möller 2008).
    Quadtree {
        /// What B̃ is inside a leaf.
        leaves: Leaves,
        /// Split leaves that hold more than this share of the product's mass, B probed at the
        /// new children's centres (or B̃ bilinear there), until none does (or the depth cap or
        /// the arena stops it): B̃ then follows B where the light concentrates the product, e.g.
        /// a sun in the lobe's tail. 0 builds the paper's tree.
        refine_share: f32,
    },
    /// Product of the nonstandard Haar expansions of B̃ and L (wavelet importance sampling,
    /// Clarberg et al. 2005). Equal to `Quadtree` in exact arithmetic: a cross-check, with
    /// piecewise-constant leaves and the paper's tree only.
    Wavelet {
        /// B̃ as [`Leaves::Probed`] makes it (otherwise [`Leaves::Sampled`]).
        probe_leaves: bool,
    },
}

impl ProductKind {
    /// The paper's product: the quadtree average, B̃ from the samples, no refinement.
    pub const QUADTREE: Self = Self::Quadtree { leaves: Leaves::Sampled, refine_share: 0.0 };
    /// The Haar wavelet product, B̃ from the samples.
    pub const WAVELET: Self = Self::Wavelet { probe_leaves: false };

    /// What B̃ is inside a leaf.
    #[must_use]
    pub fn leaves(&self) -> Leaves {
        match *self {
            Self::Quadtree { leaves, .. } => leaves,
            Self::Wavelet { probe_leaves: true } => Leaves::Probed,
            Self::Wavelet { probe_leaves: false } => Leaves::Sampled,
        }
    }

    /// The share of the product's mass above which leaves are refined (0: never).
    #[must_use]
    pub fn refine_share(&self) -> f32 {
        match *self {
            Self::Quadtree { refine_share, .. } => refine_share,
            Self::Wavelet { .. } => 0.0,
        }
    }

    /// True for the Haar wavelet product.
    #[must_use]
    pub fn is_wavelet(&self) -> bool {
        matches!(self, Self::Wavelet { .. })
    }
}

impl Default for ProductKind {
    fn default() -> Self {
        Self::QUADTREE
    }
}

/// Settings of the per-shading-point product.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProductParams {
    /// BRDF samples drawn to build B̃ (at most the arena's capacity K: more is an error).
    pub brdf_samples: usize,
    /// Depth cap of the quadtree (≤ 24): coincident samples cannot split forever. Default 14
    /// (cells of 6e-5 of the square, ~2e-4 rad): deeper leaves shrink towards the f32 direction's
    /// resolution, and then the density a BRDF sample's `pdf(ω)` lookup finds is not always the
    /// product's density at ω — MIS weights stop summing to one (docs/tuning.md#depth-cap).
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
    /// docs/tuning.md#product-mis-preset): leaves probed at their centres, leaves heavier than
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
