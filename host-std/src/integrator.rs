//! Direct illumination from the environment at one shading point, by each method, with the
//! same budget: `budget` visibility samples (shadow rays) per shading point. MIS methods spend
//! them in pairs (one per technique), so they take ⌊budget/2⌋ pairs (at least one).

use crate::scene::Bsdf;
use sampler_core::brdf::Brdf;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::{self, BATCH, Contribution, ShadingPoint, Visibility};
use sampler_core::glam::{DVec2, DVec3, Vec2, Vec3};
use sampler_core::points::sobol02;
use sampler_core::quadtree::ProductKind;
use sampler_core::rng::hash_combine;
use sampler_core::sampler::{ProductParams, ProductSampler};
use sampler_core::two_stage::TwoStageSampler;
use std::fmt;
use std::str::FromStr;

/// How the light is sampled.
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
    /// Resampled importance sampling: `RIS_CANDIDATES` env/BRDF candidates, one shadow ray.
    Ris,
    /// Two-stage importance sampling (Cline et al. 2006, reconstructed: sampler-core's
    /// two_stage.rs): a BRDF-driven partition weighted through a summed-area table.
    TwoStage,
    /// Per material, the plan expected to be cheapest at equal error (`Method::for_material`
    /// and the splits of [`product_share`] / [`auto_env_share`]), checked by a pilot render of
    /// the material's pixels that replaces it where another plan measures twice as good
    /// (`pilot.rs`).
    Auto,
}

impl Method {
    pub const ALL: [Method; 9] = [
        Method::Product,
        Method::Wavelet,
        Method::Env,
        Method::Brdf,
        Method::Mis,
        Method::ProductMis,
        Method::Ris,
        Method::TwoStage,
        Method::Auto,
    ];

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
            Method::Auto => "auto",
        }
    }

    /// `auto`'s rules — its plan before the pilot (`pilot.rs`) checks it on the scene, and its
    /// plan where the image is too small for a pilot: per material, the method measured best
    /// at equal time (`ppis report
    /// --samples-per-point 16`, default, three shared and studio scenes, per material region;
    /// docs/perf.md, session 6):
    ///
    /// * GGX conductors of moderate gloss, α in [`PRODUCT_ALPHA`]: product-MIS — the lobe is
    ///   wide enough to span bright detail of the map and narrow enough that one B̃ per pixel fits
    ///   its shading points. Best other / product-MIS at product-MIS's 1024-spp time (`ppis
    ///   report --base product-mis --bracket --repeat 2`, session 8): s1 α = 0.05 2.5× (MIS),
    ///   studio α = 0.05 2.3× (MIS), s2 α = 0.1 1.6× (MIS; product-MIS split 3:1 there, see
    ///   [`product_share`]).
    /// * Under extended bright regions rather than a sun (`env_peak` below [`SUN_PEAK`]: the
    ///   shared maps and studio, 21–67; the built-in sky 713), wider conductors too, α in
    ///   [`PRODUCT_ALPHA_EXTENDED`]: product-MIS beats MIS there (session 8, split 3:1: studio
    ///   α = 0.15 2.3×, α = 0.3 1.8×, s1 α = 0.3 1.8× at equal time) — B varies across the bright region, which the
    ///   product follows — while under the default sky's sun, which env sampling finds exactly,
    ///   MIS stays level or ahead at α = 0.15 (product-MIS 0.84–0.99×).
    /// * Everything else: MIS of env and BRDF sampling — sharper lobes (α ≤ 0.02: product-MIS
    ///   0.72–1.12× MIS), car paint (0.69–0.81×), diffuse. Env-only sampling wins on studio's and s2's
    ///   diffuse and on α = 0.3 (studio, s1's forest) but is 3–6× behind MIS under the default
    ///   sky's sun, so it is not picked; instead MIS on diffuse surfaces under extended light
    ///   draws 3 env samples to 1 BRDF sample ([`auto_env_share`]).
    ///
    /// Smooth lighting (`env_peak`, the brightest 6.4° block of the map over the mean, below
    /// [`SMOOTH_LIGHTING_PEAK`]): BRDF sampling for every material — the product is the lobe
    /// within that factor, so BRDF sampling draws nearly the product without building it.
    /// Measured on McUsd (peak 1.6): product-MIS 2.6–8× and MIS 2.3× behind BRDF sampling at
    /// equal time; the shared maps have peaks 21 (courtyard), 29 (sunset), 67 (forest), the
    /// built-in sky 713.
    pub fn for_material(self, bsdf: &Bsdf, env_peak: f32) -> Method {
        if self != Method::Auto {
            return self;
        }
        if env_peak < SMOOTH_LIGHTING_PEAK {
            return Method::Brdf;
        }
        let range = if env_peak < SUN_PEAK { PRODUCT_ALPHA_EXTENDED } else { PRODUCT_ALPHA };
        match bsdf {
            Bsdf::Conductor(c) if range.contains(&c.ggx.alpha()) => Method::ProductMis,
            _ => Method::Mis,
        }
    }
}

/// GGX roughness range where `auto` samples the product (with BRDF sampling, MIS).
pub const PRODUCT_ALPHA: std::ops::RangeInclusive<f32> = 0.03..=0.1;

/// The range under extended bright regions (`env_peak` below [`SUN_PEAK`]).
pub const PRODUCT_ALPHA_EXTENDED: std::ops::RangeInclusive<f32> = 0.03..=0.3;

/// Peak (max / mean of the map over 32×32 blocks) from which the light counts as a sun.
pub const SUN_PEAK: f32 = 100.0;

/// Below this peak (max / mean of the map over 32×32 blocks) `auto` samples the BRDF only.
pub const SMOOTH_LIGHTING_PEAK: f32 = 4.0;

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

/// Candidates per RIS estimate (each costs an env or BRDF sample and an evaluation, no ray).
pub const RIS_CANDIDATES: usize = 8;

/// Counts the shadow rays a visibility closure traces.
pub struct CountingVisibility<F: FnMut(Vec3) -> bool> {
    pub test: F,
    pub rays: u64,
}

impl<F: FnMut(Vec3) -> bool> Visibility for CountingVisibility<F> {
    fn visible(&mut self, dir: Vec3) -> bool {
        self.rays += 1;
        (self.test)(dir)
    }
}

/// A per-shading-point (or shared) sampler that a method needs built before sampling.
pub enum Technique<'s, 'e> {
    /// Methods that need nothing built.
    None,
    Product(&'s ProductSampler<'s, 'e>),
    TwoStage(&'s TwoStageSampler<'s, 'e>),
}

/// Share of a material's lobe width within which the tile's next pixels reuse a product-MIS
/// sampler (normals and mirror directions both that close to the one it was built at).
/// Measured (docs/perf.md, s1–s3 at 256 and 1024 spp): 0.25–1 leave the error unchanged and
/// cut product-MIS's time up to 43% at 256 spp; 2 and 4 raise s1's glossy error 10–60%.
pub const REUSE_SHARE: f32 = 0.5;

/// Cosine of the largest angle at which a product-MIS sampler built at one shading point is
/// reused at another of the same material: `REUSE_SHARE` of its sharpest lobe's width, and at
/// most of 0.4 rad (diffuse). Sharing stays unbiased whatever the angle (MIS with BRDF sampling
/// and the defensive part cover every direction); the angle trades build time for variance.
pub fn reuse_cosine(bsdf: &Bsdf) -> f32 {
    (REUSE_SHARE * bsdf.lobe_width().min(0.4)).cos()
}

/// The product-sampler settings of a method: product-MIS takes the core's preset for use beside
/// BRDF sampling (probed and refined leaves, ε = 0.25; docs/perf.md); plain product and wavelet
/// stay the paper's estimators.
pub fn product_params(method: Method, brdf_samples: usize) -> ProductParams {
    match method {
        Method::ProductMis => ProductParams::for_mis(brdf_samples),
        Method::Wavelet => ProductParams { brdf_samples, kind: ProductKind::Wavelet, ..ProductParams::default() },
        _ => ProductParams { brdf_samples, ..ProductParams::default() },
    }
}

/// Share of a product-MIS budget spent on product samples on GGX conductors at least
/// [`WIDE_LOBE`] wide under extended light (`env_peak` below [`SUN_PEAK`]); elsewhere half.
/// Chosen at 1024 spp from shares ¼, ½, ¾ and ⅞ (docs/perf.md, session 8): studio α = 0.3
/// and α = 0.15, s1's α = 0.3 and s2's α = 0.1 1.2–1.3× lower error at equal samples; under
/// the built-in sky's sun every material, and the α ≤ 0.05 lobes everywhere, lose with it (and
/// with fewer product samples). Diffuse surfaces stay at half: s1's, s2's and studio's gained
/// 1.4–1.6×, but s3's lost 1.2× (1.5× unshadowed) — its sun sits near the horizon, where the
/// cosine changes fastest across a B̃ leaf.
pub const WIDE_LOBE_PRODUCT_SHARE: f64 = 0.75;

/// GGX α from which product-MIS leans on product samples (see [`WIDE_LOBE_PRODUCT_SHARE`]).
pub const WIDE_LOBE: f32 = 0.1;

/// The share of a material's product-MIS budget spent on product samples (the rest are BRDF
/// samples; see [`WIDE_LOBE_PRODUCT_SHARE`]).
pub fn product_share(bsdf: &Bsdf, env_peak: f32) -> f64 {
    match bsdf {
        Bsdf::Conductor(c) if env_peak < SUN_PEAK && c.ggx.alpha() >= WIDE_LOBE => WIDE_LOBE_PRODUCT_SHARE,
        _ => 0.5,
    }
}

/// Share of an MIS budget that `auto` spends on env samples on diffuse surfaces under extended
/// light (`env_peak` below [`SUN_PEAK`]); elsewhere, and for `--method mis` (Mitsuba's
/// `direct`, the baseline), half. Measured at 1024 spp against ½ (docs/perf.md, session 8):
/// diffuse 1.4–1.8× lower error at equal samples on studio, s1 and s2, 1.15× higher on s3
/// (its sun near the horizon) and under the built-in sun (1.08×, which stays at half); a
/// cosine-weighted BRDF sample finds the bright regions of such a map less often than an env
/// sample.
pub const AUTO_DIFFUSE_ENV_SHARE: f64 = 0.75;

/// The share of an MIS budget `auto` spends on env samples (see [`AUTO_DIFFUSE_ENV_SHARE`]).
pub fn auto_env_share(bsdf: &Bsdf, env_peak: f32) -> f64 {
    match bsdf {
        Bsdf::Diffuse(_) if env_peak < SUN_PEAK => AUTO_DIFFUSE_ENV_SHARE,
        _ => 0.5,
    }
}

/// Mean radiance reflected towards `sp.wo` by direct environment light, from `budget`
/// visibility samples of `method` (not `Auto`: resolve it per material first). `technique`
/// holds the product sampler or two-stage partition for the methods that need one; it may have
/// been built for another shading point of the same pixel and material (still unbiased: it is
/// a valid density that is positive wherever L > 0). The MIS methods spend `split` of the
/// budget on their first technique (product or env samples) and the rest on BRDF samples (at
/// least one of each); MIS at ½ is Mitsuba's pairs.
#[allow(clippy::too_many_arguments)]
pub fn shade<B: Brdf + ?Sized>(
    method: Method,
    env: &EnvHierarchy<'_>,
    sp: &ShadingPoint<'_, B>,
    budget: usize,
    split: f64,
    seed: u64,
    block: usize,
    technique: &Technique<'_, '_>,
    vis: &mut impl Visibility,
) -> DVec3 {
    let budget = budget.max(1);
    match (method, technique) {
        (Method::ProductMis, Technique::Product(p)) => {
            return shade_split(First::Product(p), sp, budget, split, seed, block, vis);
        }
        (Method::Mis, _) if split != 0.5 => return shade_split(First::Env(env), sp, budget, split, seed, block, vis),
        _ => {}
    }
    // MIS spends the budget in pairs, one sample per technique.
    let n = if method == Method::Mis { (budget / 2).max(1) } else { budget };
    // This shading point's run of the pixel's sequence: the pixel's shading points together
    // draw one (0,2)-net per technique, stratified over the whole pixel, not per point.
    let first = (block * n) as u32;
    let mut points = [DVec2::ZERO; BATCH];
    let mut others = [DVec2::ZERO; BATCH];
    let mut drawn = [None; BATCH];
    let mut product_drawn = [None; BATCH];
    let mut pairs_out = [[Contribution::default(); 2]; BATCH];
    let mut singles = [Contribution::default(); BATCH];
    let mut sum = DVec3::ZERO;
    // Points in batches (a power of two keeps each batch a (0,2)-net).
    let mut done = 0;
    while done < n {
        let m = (n - done).min(BATCH);
        sobol02(hash_combine(seed, 1), first + done as u32, &mut points[..m]);
        // The second technique's points, for MIS only.
        if method == Method::Mis {
            sobol02(hash_combine(seed, 2), first + done as u32, &mut others[..m]);
        }
        // The batch's env samples drawn together: their descents overlap.
        if matches!(method, Method::Mis | Method::Env) {
            env.sample_many(&points[..m], &mut drawn[..m]);
        }
        // BRDF points: MIS's second technique, or BRDF sampling's only one.
        let brdf_source = if method == Method::Brdf { &points } else { &others };
        let mut brdf_points = [Vec2::ZERO; BATCH];
        for (b, o) in brdf_points.iter_mut().zip(&brdf_source[..m]) {
            *b = o.as_vec2();
        }
        match (method, technique) {
            (Method::Mis, _) => estimator::mis_many(env, sp, &drawn[..m], &brdf_points[..m], vis, &mut pairs_out[..m]),
            (Method::Env, _) => estimator::env_many(env, sp, &drawn[..m], vis, &mut singles[..m]),
            (Method::Brdf, _) => estimator::brdf_many(env, sp, &brdf_points[..m], vis, &mut singles[..m]),
            (_, Technique::Product(p)) => p.sample_many(&points[..m], &mut product_drawn[..m]),
            _ => {}
        }
        for k in 0..m {
            let u = points[k];
            sum += match (method, technique) {
                (Method::Product | Method::Wavelet, Technique::Product(p)) => {
                    estimator::product_drawn(p, sp, product_drawn[k], vis).value
                }
                (Method::Mis, _) => pairs_out[k][0].value + pairs_out[k][1].value,
                (Method::TwoStage, Technique::TwoStage(t)) => estimator::two_stage(t, env, sp, u, vis).value,
                (Method::Env | Method::Brdf, _) => singles[k].value,
                (Method::Ris, _) => {
                    let mut candidates = [DVec2::ZERO; RIS_CANDIDATES];
                    sobol02(hash_combine(seed, 3 + first as u64 + (done + k) as u64), 0, &mut candidates);
                    estimator::ris(env, sp, &candidates, u.x, vis).value
                }
                _ => DVec3::ZERO,
            };
        }
        done += m;
    }
    sum / n as f64
}

/// The technique an MIS split draws beside BRDF sampling.
enum First<'s, 'e> {
    Product(&'s ProductSampler<'s, 'e>),
    Env(&'s EnvHierarchy<'e>),
}

/// MIS at one shading point with the budget split: ⌊share·budget⌉ samples of `first` and the
/// rest BRDF samples (at least one of each; a budget of one still takes one of each), each
/// technique's points this shading point's run of the pixel's (0,2)-sequence for it.
fn shade_split<B: Brdf + ?Sized>(
    first: First<'_, '_>,
    sp: &ShadingPoint<'_, B>,
    budget: usize,
    share: f64,
    seed: u64,
    block: usize,
    vis: &mut impl Visibility,
) -> DVec3 {
    let (n_p, n_b) = if budget < 2 {
        (1, 1)
    } else {
        let n_p = ((share * budget as f64).round() as usize).clamp(1, budget - 1);
        (n_p, budget - n_p)
    };
    let total = (n_p + n_b) as f64;
    let shares = ((n_p as f64 / total) as f32, (n_b as f64 / total) as f32);
    let mut sum = DVec3::ZERO;
    let (mut done_p, mut done_b) = (0, 0);
    let mut first_points = [DVec2::ZERO; BATCH];
    let mut brdf_points = [DVec2::ZERO; BATCH];
    let mut brdf_points_f32 = [Vec2::ZERO; BATCH];
    // Batches of each technique's points (a power of two keeps each batch a net).
    while done_p < n_p || done_b < n_b {
        let (m_p, m_b) = ((n_p - done_p).min(BATCH), (n_b - done_b).min(BATCH));
        sobol02(hash_combine(seed, 1), (block * n_p + done_p) as u32, &mut first_points[..m_p]);
        sobol02(hash_combine(seed, 2), (block * n_b + done_b) as u32, &mut brdf_points[..m_b]);
        for (b, o) in brdf_points_f32.iter_mut().zip(&brdf_points[..m_b]) {
            *b = o.as_vec2();
        }
        let (u_p, u_b) = (&first_points[..m_p], &brdf_points_f32[..m_b]);
        sum += match first {
            First::Product(sampler) => estimator::product_mis_split(sampler, sp, u_p, u_b, shares, vis),
            First::Env(env) => estimator::mis_split(env, sp, u_p, u_b, shares, vis),
        };
        (done_p, done_b) = (done_p + m_p, done_b + m_b);
    }
    sum / total
}

#[cfg(test)]
mod tests {
    use super::*;
    use sampler_core::brdf::{Lambert, RoughConductor};
    use sampler_core::glam::Vec3;

    fn conductor(alpha: f32) -> Bsdf {
        Bsdf::Conductor(RoughConductor::new(alpha, Vec3::ONE))
    }

    #[test]
    fn samplers_are_reused_within_half_the_sharpest_lobe() {
        let close = |bsdf: &Bsdf, angle: f32| (reuse_cosine(bsdf) - angle.cos()).abs() < 1e-6;
        assert!(close(&conductor(0.05), 0.025));
        assert!(close(&Bsdf::Diffuse(Lambert::new(Vec3::ONE)), 0.2));
        let paint = sampler_core::brdf::CarPaint::default();
        assert!(close(&Bsdf::CarPaint(paint), 0.5 * paint.coat_ggx.alpha()));
        let no_coat = sampler_core::brdf::CarPaint { coat: 0.0, ..paint };
        assert!(close(&Bsdf::CarPaint(no_coat), 0.5 * paint.flake_ggx.alpha()));
    }

    #[test]
    fn auto_samples_the_product_on_moderately_glossy_conductors_only() {
        assert_eq!(Method::Auto.for_material(&conductor(0.05), 67.0), Method::ProductMis);
        assert_eq!(Method::Auto.for_material(&conductor(0.1), 713.0), Method::ProductMis);
        assert_eq!(Method::Auto.for_material(&conductor(0.01), 67.0), Method::Mis);
        // Wider lobes only under extended light, not under a sun.
        assert_eq!(Method::Auto.for_material(&conductor(0.3), 67.0), Method::ProductMis);
        assert_eq!(Method::Auto.for_material(&conductor(0.15), 713.0), Method::Mis);
        assert_eq!(Method::Auto.for_material(&conductor(0.5), 67.0), Method::Mis);
        assert_eq!(Method::Auto.for_material(&conductor(0.05), 1.6), Method::Brdf, "smooth light");
    }

    #[test]
    fn product_mis_leans_on_product_samples_for_wide_conductors_under_extended_light() {
        let diffuse = Bsdf::Diffuse(Lambert::new(Vec3::ONE));
        assert_eq!(product_share(&conductor(0.3), 67.0), WIDE_LOBE_PRODUCT_SHARE);
        assert_eq!(product_share(&conductor(0.1), 21.0), WIDE_LOBE_PRODUCT_SHARE);
        assert_eq!(product_share(&diffuse, 21.0), 0.5, "diffuse");
        assert_eq!(product_share(&conductor(0.05), 21.0), 0.5, "moderate lobe");
        assert_eq!(product_share(&conductor(0.3), 713.0), 0.5, "sun");
        assert_eq!(product_share(&Bsdf::CarPaint(sampler_core::brdf::CarPaint::default()), 21.0), 0.5, "sharp coat");
    }

    #[test]
    fn auto_leans_on_env_samples_on_diffuse_surfaces_under_extended_light() {
        let diffuse = Bsdf::Diffuse(Lambert::new(Vec3::ONE));
        assert_eq!(auto_env_share(&diffuse, 21.0), AUTO_DIFFUSE_ENV_SHARE);
        assert_eq!(auto_env_share(&diffuse, 713.0), 0.5, "sun");
        assert_eq!(auto_env_share(&conductor(0.01), 21.0), 0.5, "sharp lobe");
    }

    #[test]
    fn auto_samples_the_brdf_only_under_smooth_lighting() {
        let b = Bsdf::Diffuse(Lambert::new(Vec3::splat(0.5)));
        assert_eq!(Method::Auto.for_material(&b, 1.6), Method::Brdf);
        assert_eq!(Method::Auto.for_material(&b, 21.0), Method::Mis);
        assert_eq!(Method::Auto.for_material(&b, f32::MAX), Method::Mis);
        for m in Method::ALL.into_iter().filter(|&m| m != Method::Auto) {
            assert_eq!(m.for_material(&b, 1.0), m, "fixed methods stay");
        }
    }
}
