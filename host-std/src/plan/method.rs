//! The methods a render is asked for by name (`--method`), and what each one samples a
//! material with.

use crate::plan::rules;
use crate::render::strategy::Strategy;
use crate::scene::Bsdf;
use std::fmt;
use std::str::FromStr;

/// How the light is sampled: a fixed strategy for every material, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Product importance sampling, quadtree product (the paper).
    Product,
    /// Product importance sampling, Haar wavelet product.
    Wavelet,
    /// Environment-only importance sampling through the same hierarchy.
    Env,
    /// BRDF importance sampling.
    Brdf,
    /// MIS (balance heuristic) of env and BRDF sampling, as Mitsuba's `direct` integrator.
    Mis,
    /// MIS of product and BRDF sampling.
    ProductMis,
    /// Resampled importance sampling: env/BRDF candidates, one shadow ray.
    Ris,
    /// Two-stage importance sampling (Cline et al. 2006).
    TwoStage,
    /// The two-level product (Conty Estevez & Lecocq 2018): a coarse grid's cells weighted by
    /// the BRDF's bound, then the map's own hierarchy inside the drawn cell.
    TwoLevel,
    /// MIS of the two-level product and BRDF samples, in pairs.
    TwoLevelMis,
    /// Structured importance sampling (Agarwal et al. 2003): the map as N pre-integrated
    /// directional lights, every one shaded at every shading point. Deterministic and biased.
    Sis,
    /// Lightcuts (Walter et al. 2005): the map as directional lights and the scene's point
    /// lights in a light tree, a cut per shading point under a relative error bound.
    /// Deterministic and biased.
    Lightcuts,
    /// On diffuse planes, the map × the plane's cosine, sampled from a pyramid per plane
    /// (`render::plane_products`); everything else MIS pairs.
    PlaneProduct,
    /// Per material, the strategy of `auto`'s rules ([`rules::auto_strategy`]), checked by a
    /// pilot render of the material's pixels that replaces it where another measures
    /// [`OVERRIDE_MARGIN`](crate::plan::pilot::OVERRIDE_MARGIN)× as good (`plan::pilot`).
    Auto,
}

impl Method {
    /// Every method, in the order `--help` lists them.
    pub const ALL: [Method; 14] = [
        Method::Product,
        Method::Wavelet,
        Method::Env,
        Method::Brdf,
        Method::Mis,
        Method::ProductMis,
        Method::Ris,
        Method::TwoStage,
        Method::TwoLevel,
        Method::TwoLevelMis,
        Method::Sis,
        Method::Lightcuts,
        Method::PlaneProduct,
        Method::Auto,
    ];

    /// Whether the method's expected image is the true one. Structured importance sampling
    /// and Lightcuts are biased by design (the map as finitely many directional lights; a cut
    /// under an error bound), so unbiasedness checks leave them out and report their bias
    /// instead.
    #[must_use]
    pub fn is_unbiased(self) -> bool {
        !matches!(self, Method::Sis | Method::Lightcuts)
    }

    /// The name `--method` takes.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Method::Product => "product",
            Method::Wavelet => "wavelet",
            Method::Env => "env",
            Method::Brdf => "brdf",
            Method::Mis => "mis",
            Method::ProductMis => "product-mis",
            Method::Ris => "ris",
            Method::TwoStage => "two-stage",
            Method::TwoLevel => "two-level",
            Method::TwoLevelMis => "two-level-mis",
            Method::Sis => "sis",
            Method::Lightcuts => "lightcuts",
            Method::PlaneProduct => "plane-product",
            Method::Auto => "auto",
        }
    }

    /// Light samples per shading point where `--shading-points` is not given (so P = spp /
    /// this): two pairs for the MIS methods, whose shading point (its primary ray, hit and
    /// wavefront) costs about a pair, so that a second pair halves its share of the time
    /// where the light's noise dominates the footprint's; one sample for the single
    /// techniques whose sampler is built once per render or per pixel; and for the samplers
    /// built per shading point the power of two nearest √(build cost / sample cost), the
    /// split that minimises error × time when a point's light and its footprint vary alike
    /// (docs/tuning.md, "Shading points per pixel"). SIS and Lightcuts shade every stratum or a
    /// whole cut at each shading point, whatever the budget, so for them V only sets P = spp/V:
    /// 64, so that a point costs about what its 64 samples cost the sampling methods (a few
    /// hundred shadow rays and BRDF evaluations) and `ppis report`'s spp range suits them too.
    #[must_use]
    pub fn samples_per_point(self) -> usize {
        match self {
            Method::Env | Method::Brdf | Method::Ris => 1,
            Method::Sis | Method::Lightcuts => 64,
            Method::Mis | Method::ProductMis | Method::TwoLevelMis | Method::PlaneProduct | Method::Auto => 4,
            Method::TwoLevel => 2,
            Method::TwoStage => 4,
            Method::Product | Method::Wavelet => 16,
        }
    }

    /// [`samples_per_point`](Self::samples_per_point) under `lighting`: where an environment
    /// and other lights share each shading point, the MIS methods and `auto` take four times
    /// their pairs, since each part gets its own (at four, one pair each; docs/tuning.md,
    /// "Samples per shading point with an environment and lights").
    #[must_use]
    pub fn samples_per_point_under(self, lighting: Lighting) -> usize {
        match (self, lighting) {
            (Method::Mis | Method::ProductMis | Method::Auto, Lighting::EnvironmentAndLights) => 16,
            _ => self.samples_per_point(),
        }
    }

    /// What this method samples a material of `bsdf` with under a map of peak `env_peak`
    /// (`EnvHierarchy::peak(5)`; `f32::MAX` where not measured). Product-MIS takes its split
    /// from the rules ([`rules::product_share`]); `mis` stays Mitsuba's pairs.
    #[must_use]
    pub fn strategy(self, bsdf: &Bsdf, env_peak: f32) -> Strategy {
        match self {
            Method::Product => Strategy::Product,
            Method::Wavelet => Strategy::Wavelet,
            Method::Env => Strategy::Env,
            Method::Brdf => Strategy::Brdf,
            Method::Mis => Strategy::Mis { env_share: 0.5 },
            Method::ProductMis => Strategy::ProductMis { product_share: rules::product_share(bsdf, env_peak) },
            Method::Ris => Strategy::Ris,
            Method::TwoStage => Strategy::TwoStage,
            Method::TwoLevel => Strategy::TwoLevel,
            Method::TwoLevelMis => Strategy::TwoLevelMis { two_level_share: 0.5 },
            Method::Sis => Strategy::Sis,
            Method::Lightcuts => Strategy::Lightcuts,
            Method::PlaneProduct if bsdf.as_brdf().is_diffuse() => Strategy::PlaneProduct,
            Method::PlaneProduct => Strategy::Mis { env_share: 0.5 },
            Method::Auto => rules::auto_strategy(bsdf, env_peak),
        }
    }

    /// The fixed method that samples with `strategy` (its split aside).
    #[must_use]
    pub fn of(strategy: Strategy) -> Method {
        match strategy {
            Strategy::Product => Method::Product,
            Strategy::Wavelet => Method::Wavelet,
            Strategy::Env => Method::Env,
            Strategy::Brdf => Method::Brdf,
            Strategy::Mis { .. } => Method::Mis,
            Strategy::ProductMis { .. } => Method::ProductMis,
            Strategy::Ris => Method::Ris,
            Strategy::TwoStage => Method::TwoStage,
            Strategy::TwoLevel => Method::TwoLevel,
            Strategy::TwoLevelMis { .. } => Method::TwoLevelMis,
            Strategy::Sis => Method::Sis,
            Strategy::Lightcuts => Method::Lightcuts,
            Strategy::PlaneProduct => Method::PlaneProduct,
        }
    }

    /// Whether a render with this method builds product samplers from
    /// [`Settings::brdf_samples`](crate::plan::Settings::brdf_samples) BRDF samples (`auto`
    /// where it picks product-MIS, and its pilot).
    #[must_use]
    pub fn reads_brdf_samples(self) -> bool {
        matches!(self, Method::Product | Method::Wavelet | Method::ProductMis | Method::Auto)
    }

    /// Whether a render with this method reads the map's peak (`auto`'s rules, product-MIS's
    /// split and the two-level product's coarse level do).
    #[must_use]
    pub fn reads_env_peak(self) -> bool {
        matches!(self, Method::Auto | Method::ProductMis | Method::TwoLevel | Method::TwoLevelMis)
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Method::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| {
            let names: Vec<_> = Method::ALL.iter().map(|m| m.name()).collect();
            format!("unknown method \"{s}\" (expected one of: {})", names.join(", "))
        })
    }
}

/// A strategy's name: its method's, and its split where it is not half and half ("mis 3:1" —
/// three env samples to one BRDF sample; "product-mis 3:1").
#[must_use]
pub fn strategy_name(strategy: Strategy) -> String {
    let name = Method::of(strategy).name();
    match strategy {
        Strategy::Mis { env_share: split }
        | Strategy::ProductMis { product_share: split }
        | Strategy::TwoLevelMis { two_level_share: split }
            if split != 0.5 =>
        {
            format!("{name} {}:{}", (split * 4.0).round(), ((1.0 - split) * 4.0).round())
        }
        _ => name.to_string(),
    }
}

/// What lights a scene holds, as far as the budget per shading point is concerned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lighting {
    /// An environment alone, or other lights alone.
    OneKind,
    /// An environment and other lights, each shading point sampling both.
    EnvironmentAndLights,
}

impl Lighting {
    /// The lighting of a scene with `lights` other lights, with or without an environment.
    #[must_use]
    pub fn of(environment: bool, lights: usize) -> Self {
        if environment && lights > 0 { Lighting::EnvironmentAndLights } else { Lighting::OneKind }
    }
}
