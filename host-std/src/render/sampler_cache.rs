//! The samplers a tile builds and keeps: the arena of the product sampler built per shading
//! point, and per material the product-MIS sampler built last, reused by the tile's next pixels
//! while their shading points stay within the material's reuse angle.
//!
//! Product-MIS shares one sampler per pixel and material, built from the group's first shading
//! point: MIS with BRDF sampling covers where another point's lobe leaves the shared B̃. Plain
//! product, wavelet and two-stage build per shading point: shared, they grow fireflies near
//! silhouettes and on sharp lobes, where only the defensive mixture covers the mismatch. How
//! much sharing saves is measured in docs/tuning.md Sampler reuse across pixels", "Tried and
//! not kept").

use crate::render::Context;
use crate::render::primary::Hit;
use crate::render::product_arena::SizedArena;
use crate::render::shade::Sampling;
use crate::render::strategy::{MaterialPlan, Strategy};
use sampler_core::brdf::Brdf;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::ShadingPoint;
use sampler_core::glam::Vec3;
use sampler_core::quadtree::ProductKind;
use sampler_core::sampler::{ProductParams, ProductSampler};
use sampler_core::two_level::{TwoLevelArena, TwoLevelSampler};
use sampler_core::two_stage::TwoStageSampler;

/// Share of a material's lobe width within which the tile's next pixels reuse a product-MIS
/// sampler (normals and mirror directions both that close to the one it was built at). A
/// smaller share rebuilds more often for no less error; a larger one raises the error on
/// glossy surfaces (docs/tuning.md, "Sampler reuse across pixels").
pub const REUSE_SHARE: f32 = 0.5;

/// Widest lobe (radians) the reuse angle follows; diffuse surfaces reuse within
/// [`REUSE_SHARE`] of it.
const WIDEST_REUSED_LOBE: f32 = 0.4;

/// Cosine of the largest angle at which a product-MIS sampler built at one shading point is
/// reused at another of the same material: [`REUSE_SHARE`] of its sharpest lobe's width
/// ([`Brdf::lobe_width`]), and at most of `WIDEST_REUSED_LOBE` (diffuse). Sharing stays unbiased whatever the angle (MIS
/// with BRDF sampling and the defensive part cover every direction); the angle trades build
/// time for variance.
#[must_use]
pub fn reuse_cosine(brdf: &dyn Brdf) -> f32 {
    (REUSE_SHARE * brdf.lobe_width().min(WIDEST_REUSED_LOBE)).cos()
}

/// Every material's K is at most the largest arena's capacity: the command line checks it
/// (`product_arena::check_brdf_samples`) before it renders.
const BRDF_SAMPLES_FIT: &str = "--brdf-samples within the product arenas' capacity";

/// A sampler's arena kept for the next pixels of the tile, with the normal and mirror
/// direction of the shading point it was built at.
struct Shared<A> {
    arena: A,
    normal: Vec3,
    mirror: Vec3,
}

impl<A> Shared<A> {
    /// Whether a sampler built here serves a shading point of `normal` and `mirror` within the
    /// reuse angle whose cosine is `cos`.
    fn near(&self, normal: Vec3, mirror: Vec3, cos: f32) -> bool {
        self.normal.dot(normal) >= cos && self.mirror.dot(mirror) >= cos
    }
}

/// A product-MIS sampler kept for the next pixels of the tile.
type SharedSampler = Shared<SizedArena>;

/// The shading point a sampler is built at: its hit, its shading point and the seed of the
/// build's BRDF samples.
pub(crate) struct Lead<'a> {
    /// The primary hit.
    pub hit: &'a Hit,
    /// Its shading point.
    pub sp: &'a ShadingPoint<'a, dyn Brdf + 'a>,
    /// The seed of the build's BRDF samples.
    pub seed: u64,
}

/// A tile's samplers, reused from pixel to pixel.
pub(crate) struct SamplerCache {
    /// For the product samplers built per shading point.
    arena: Option<SizedArena>,
    /// For the two-level samplers, built per shading point.
    two_level: Option<Box<TwoLevelArena>>,
    /// Per material, the product-MIS sampler built last and where.
    shared: Vec<Option<SharedSampler>>,
    /// Per material, the two-level-MIS sampler built last and where.
    shared_two_level: Vec<Option<Shared<Box<TwoLevelArena>>>>,
}

impl SamplerCache {
    /// An empty cache for a scene of `materials` materials.
    pub fn new(materials: usize) -> Self {
        Self {
            arena: None,
            two_level: None,
            shared: (0..materials).map(|_| None).collect(),
            shared_two_level: (0..materials).map(|_| None).collect(),
        }
    }

    /// The sampling of `lead`'s material at its shading point, with the sampler it needs built
    /// (or, for product-MIS, reused when built near enough).
    pub fn sampling<'s, 'e>(
        &'s mut self,
        ctx: &Context<'s, 'e>,
        env: &'s EnvHierarchy<'e>,
        lead: &Lead<'_>,
    ) -> Sampling<'s, 'e> {
        let plan = &ctx.plans[lead.hit.material];
        let sp = lead.sp;
        match plan.strategy {
            Strategy::Env => Sampling::Env,
            Strategy::Brdf => Sampling::Brdf,
            Strategy::Mis { env_share } => Sampling::Mis { env_share, sampler: env.compensated() },
            Strategy::Ris => Sampling::Ris,
            Strategy::Product => Sampling::Product(self.product(env, plan, ProductKind::QUADTREE, lead)),
            Strategy::Wavelet => Sampling::Product(self.product(env, plan, ProductKind::WAVELET, lead)),
            Strategy::ProductMis { product_share } => {
                Sampling::ProductMis { sampler: self.shared_product(env, plan, lead), product_share }
            }
            Strategy::TwoStage => {
                let sat = ctx.sat.expect("the summed-area table is built when a material is sampled two-stage");
                Sampling::TwoStage(TwoStageSampler::new(env, sat, sp.brdf, &sp.frame, sp.wo))
            }
            Strategy::TwoLevel => Sampling::TwoLevel(self.two_level(ctx, env, lead)),
            Strategy::TwoLevelMis { two_level_share } => {
                Sampling::TwoLevelMis { sampler: self.shared_two_level(ctx, env, plan, lead), two_level_share }
            }
            Strategy::Sis => {
                Sampling::Sis(ctx.strata.expect("the strata are built when a material is shaded with SIS"))
            }
            // Points on a plane sample its pyramid (`pixel::sample_light`); the rest, MIS pairs.
            Strategy::PlaneProduct => Sampling::Mis { env_share: 0.5, sampler: env.compensated() },
            Strategy::Lightcuts => {
                unreachable!("Lightcuts shades through shade_cuts, never the environment's estimators")
            }
        }
    }

    /// The two-level sampler of `lead`'s shading point.
    fn two_level<'s, 'e>(
        &'s mut self,
        ctx: &Context<'s, 'e>,
        env: &'s EnvHierarchy<'e>,
        lead: &Lead<'_>,
    ) -> TwoLevelSampler<'s, 'e> {
        let cones = ctx.cones.expect("the cell cones are built when a material is sampled two-level");
        let arena = self.two_level.get_or_insert_with(Box::default);
        let sp = lead.sp;
        arena.build(env, cones.for_lobe(sp.brdf.lobe_width()), sp.brdf, &sp.frame, sp.wo).expect(CONES_FIT)
    }

    /// A product sampler of the paper's estimator, built for `lead` alone from its material's K.
    fn product<'s, 'e>(
        &'s mut self,
        env: &'s EnvHierarchy<'e>,
        plan: &MaterialPlan,
        kind: ProductKind,
        lead: &Lead<'_>,
    ) -> ProductSampler<'s, 'e> {
        let params = ProductParams { brdf_samples: plan.brdf_samples, kind, ..ProductParams::default() };
        // Materials of different K share the arena: it grows when one needs more.
        if self.arena.as_ref().is_none_or(|a| a.capacity() < params.brdf_samples) {
            self.arena = Some(SizedArena::for_samples(params.brdf_samples).expect(BRDF_SAMPLES_FIT));
        }
        let arena = self.arena.as_mut().expect("sized above");
        let sp = lead.sp;
        arena.build(env, sp.brdf, &sp.frame, sp.wo, &params, lead.seed).expect(BRDF_SAMPLES_FIT)
    }

    /// The product-MIS sampler of `lead`'s material: the kept one if it was built within the
    /// material's reuse angle (and the material is not textured), otherwise built anew and kept.
    fn shared_product<'s, 'e>(
        &'s mut self,
        env: &'s EnvHierarchy<'e>,
        plan: &MaterialPlan,
        lead: &Lead<'_>,
    ) -> ProductSampler<'s, 'e> {
        let sp = lead.sp;
        let params = ProductParams::for_mis(plan.brdf_samples);
        let new = || SizedArena::for_samples(params.brdf_samples).expect(BRDF_SAMPLES_FIT);
        let build = |a: &mut SizedArena| {
            a.build(env, sp.brdf, &sp.frame, sp.wo, &params, lead.seed).expect(BRDF_SAMPLES_FIT);
        };
        let kept = kept_or_built(&mut self.shared[lead.hit.material], lead.hit, plan.reuse_cosine, new, build);
        kept.arena.last_built(env).expect("built")
    }

    /// The two-level-MIS sampler of `lead`'s material: the kept one if it was built within the
    /// material's reuse angle (and the material is not textured), otherwise built anew and kept.
    /// As for product-MIS, MIS with BRDF sampling covers where another point's lobe leaves the
    /// shared cells' bounds, and the cells the compensation leaves without weight.
    fn shared_two_level<'s, 'e>(
        &'s mut self,
        ctx: &Context<'s, 'e>,
        env: &'s EnvHierarchy<'e>,
        plan: &MaterialPlan,
        lead: &Lead<'_>,
    ) -> TwoLevelSampler<'s, 'e> {
        let cones = ctx.cones.expect("the cell cones are built when a material is sampled two-level");
        let sp = lead.sp;
        let build = |a: &mut Box<TwoLevelArena>| {
            a.build_for_mis(env, cones.for_lobe(sp.brdf.lobe_width()), sp.brdf, &sp.frame, sp.wo).expect(CONES_FIT);
        };
        let slot = &mut self.shared_two_level[lead.hit.material];
        let kept = kept_or_built(slot, lead.hit, plan.reuse_cosine, Box::default, build);
        kept.arena.last_built(env).expect("built")
    }
}

/// The sampler kept in `slot` if it was built within the reuse angle of cosine `cos` of `hit`
/// (and `hit`'s material is not textured), otherwise `build` into its arena (a `new` one for an
/// empty slot), kept with `hit`'s normal and mirror direction.
fn kept_or_built<'s, A>(
    slot: &'s mut Option<Shared<A>>,
    hit: &Hit,
    cos: f32,
    new: impl FnOnce() -> A,
    build: impl FnOnce(&mut A),
) -> &'s Shared<A> {
    let (normal, mirror) = (hit.frame.n, reflect(hit.wo, hit.frame.n));
    if hit.bsdf.is_some() || !slot.as_ref().is_some_and(|c| c.near(normal, mirror, cos)) {
        let c = slot.get_or_insert_with(|| Shared { arena: new(), normal, mirror });
        build(&mut c.arena);
        (c.normal, c.mirror) = (normal, mirror);
    }
    let slot: &'s Option<Shared<A>> = slot;
    slot.as_ref().expect("kept or built above")
}

/// The cell cones are of a level the map and the two-level arena hold.
const CONES_FIT: &str = "the cones are of a level the map and the arena hold";

/// The mirror direction of `wo` about `n`.
fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Bsdf;
    use sampler_core::brdf::{Lambert, RoughConductor};

    #[test]
    fn samplers_are_reused_within_half_the_sharpest_lobe() {
        let close = |bsdf: &Bsdf, angle: f32| (reuse_cosine(bsdf.as_brdf()) - angle.cos()).abs() < 1e-6;
        assert!(close(&Bsdf::Conductor(RoughConductor::new(0.05, Vec3::ONE)), 0.025));
        assert!(close(&Bsdf::Diffuse(Lambert::new(Vec3::ONE)), 0.2));
        let paint = sampler_core::brdf::CarPaint::default();
        assert!(close(&Bsdf::CarPaint(paint), 0.5 * paint.coat_ggx.alpha()));
        let no_coat = sampler_core::brdf::CarPaint { coat: 0.0, ..paint };
        assert!(close(&Bsdf::CarPaint(no_coat), 0.5 * paint.flake_ggx.alpha()));
    }
}
