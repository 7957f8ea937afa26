//! What a material's shading points sample the light with, resolved before the render (by
//! `plan`): the strategy, with the share of the budget a two-technique strategy spends on its
//! first technique.

use crate::render::brdf_samples::BrdfSamples;
use crate::render::sampler_cache::reuse_cosine;
use crate::scene::Bsdf;

/// How a material's shading points sample the light. Every method but `auto` is one of these
/// for every material; `auto` picks one per material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Strategy {
    /// Product importance sampling, quadtree product (the paper).
    Product,
    /// Product importance sampling, Haar wavelet product.
    Wavelet,
    /// Environment-only importance sampling through the same hierarchy.
    Env,
    /// BRDF importance sampling.
    Brdf,
    /// MIS (balance heuristic) of env and BRDF sampling. At an `env_share` of ½ the budget is
    /// spent in pairs, one sample per technique, as Mitsuba's `direct` integrator; otherwise
    /// `env_share` of it on env samples and the rest on BRDF samples.
    Mis {
        /// Share of the budget spent on env samples.
        env_share: f64,
    },
    /// MIS of product and BRDF sampling, with a product sampler shared per pixel and material
    /// and reused by the tile's next pixels.
    ProductMis {
        /// Share of the budget spent on product samples.
        product_share: f64,
    },
    /// Resampled importance sampling: [`RIS_CANDIDATES`](crate::render::shade::RIS_CANDIDATES)
    /// env/BRDF candidates, one shadow ray.
    Ris,
    /// Two-stage importance sampling (Cline et al. 2006, reconstructed in sampler-core's
    /// `two_stage.rs`): a BRDF-driven partition weighted through a summed-area table.
    TwoStage,
    /// The two-level product (`sampler_core::two_level`): cells of a coarse level of the map
    /// ([`TWO_LEVEL_LEVEL`], or [`TWO_LEVEL_FINE_LEVEL`]) drawn ∝ the BRDF's bound × their
    /// light, then a texel ∝ light.
    TwoLevel,
    /// MIS of the two-level product and BRDF samples, built per shading point.
    TwoLevelMis {
        /// Share of the budget spent on two-level samples; ½ spends it in pairs.
        two_level_share: f64,
    },
    /// Structured importance sampling: every stratum of the map a directional light
    /// ([`Context::strata`](crate::render::Context::strata)).
    Sis,
    /// On planes (`render::plane_products`), env-only sampling ∝ the map × the plane's cosine,
    /// from a pyramid per plane built once: the product a diffuse plane integrates, exactly.
    /// Shading points off the scene's planes sample as MIS pairs.
    PlaneProduct,
    /// Lightcuts: a cut through the light tree per shading point
    /// ([`Context::lightcuts`](crate::render::Context::lightcuts)), covering the map and the
    /// point lights.
    Lightcuts,
}

/// The coarse level of the two-level product: 16 × 16 cells of the equal-area square (clamped
/// to the map's finest level).
pub const TWO_LEVEL_LEVEL: u32 = 4;

/// The two-level product's finer coarse level, 32 × 32 cells, for the lobes of
/// [`FINE_CELL_LOBES`] under extended light: such a lobe is narrower than a 16 × 16 cell and
/// follows the bright regions' detail within it. Under a sun the sun's cell carries the
/// product and finer cells cost more builds than they recover; sharper lobes rebuild their
/// shared sampler nearly every pixel, and wider ones and diffuse surfaces gain nothing
/// (docs/perf.md, "The two products").
pub const TWO_LEVEL_FINE_LEVEL: u32 = 5;

/// Lobe widths (`Brdf::lobe_width`, GGX α) drawn from [`TWO_LEVEL_FINE_LEVEL`]'s cells under
/// extended light.
pub const FINE_CELL_LOBES: std::ops::RangeInclusive<f32> = 0.03..=0.2;

impl Strategy {
    /// Whether its shading points draw from the two-level product.
    #[must_use]
    pub fn is_two_level(self) -> bool {
        matches!(self, Strategy::TwoLevel | Strategy::TwoLevelMis { .. })
    }
}

/// How a material is shaded, resolved once per render.
#[derive(Clone, Copy, Debug)]
pub struct MaterialPlan {
    /// What its shading points sample the light with.
    pub strategy: Strategy,
    /// Cosine of the angle within which a product-MIS sampler is reused (see
    /// [`reuse_cosine`]).
    pub reuse_cosine: f32,
    /// BRDF samples its product samplers are built from.
    pub brdf_samples: usize,
    /// Visibility samples from the environment per shading point where the plan sets its own
    /// (`auto`: fewer for a plan that costs more per sample, `plan::candidates`; more for one
    /// that costs no more than MIS where other materials' plans do, `plan::pace`); `None`: the
    /// render's.
    pub env_budget: Option<usize>,
}

impl MaterialPlan {
    /// The plan that samples `bsdf` with `strategy`, its product samplers built from
    /// `brdf_samples`' K for it.
    #[must_use]
    pub fn new(strategy: Strategy, bsdf: &Bsdf, brdf_samples: BrdfSamples) -> Self {
        Self {
            strategy,
            reuse_cosine: reuse_cosine(bsdf.as_brdf()),
            brdf_samples: brdf_samples.for_bsdf(bsdf),
            env_budget: None,
        }
    }
}
