//! `auto`'s rules: per material, the strategy expected to be cheapest at equal error, from
//! the material's lobe and how peaked the lighting is — its plan before the pilot
//! (`plan::pilot`) checks it on the scene, and its plan where the image is too small for a
//! pilot. The thresholds and splits come from equal-time sweeps per material region
//! (`ppis report`; docs/perf.md, "Headline: error at equal time"; docs/tuning.md, "Budget splits").
//!
//! * Glossy BRDFs whose sharpest lobe is of moderate width (`Brdf::lobe_width`, GGX α, in
//!   [`PRODUCT_ALPHA`]): product-MIS — the lobe is wide enough to span bright detail of the map
//!   and narrow enough that one B̃ per pixel fits its shading points.
//! * Under extended bright regions rather than a sun (`env_peak` below [`SUN_PEAK`]), wider
//!   lobes too, in [`PRODUCT_ALPHA_EXTENDED`]: B varies across the bright region, which the
//!   product follows, while a sun is found exactly by env sampling alone.
//! * Everything else: MIS of env and BRDF sampling — sharper lobes (a car paint's coat among
//!   them), diffuse.
//!   Env-only sampling can win on diffuse surfaces under extended light but falls far behind
//!   under a sun, so the rules do not pick it (the pilot may); instead MIS on diffuse surfaces
//!   under extended light leans on env samples ([`auto_env_share`]).
//! * Smooth lighting (`env_peak`, the brightest 6.4° block of the map over the mean, below
//!   [`SMOOTH_LIGHTING_PEAK`]): BRDF sampling for every material — the product is the lobe
//!   within that factor, so BRDF sampling draws nearly the product without building it.

use crate::render::strategy::Strategy;
use crate::scene::Bsdf;

/// Lobe widths (GGX α; `Brdf::lobe_width`) where `auto` samples the product (with BRDF
/// sampling, MIS).
pub const PRODUCT_ALPHA: std::ops::RangeInclusive<f32> = 0.03..=0.1;

/// The range under extended bright regions (`env_peak` below [`SUN_PEAK`]).
pub const PRODUCT_ALPHA_EXTENDED: std::ops::RangeInclusive<f32> = 0.03..=0.3;

/// Peak (max / mean of the map over 32×32 blocks) from which the light counts as a sun.
pub const SUN_PEAK: f32 = 100.0;

/// Below this peak (max / mean of the map over 32×32 blocks) `auto` samples the BRDF only.
pub const SMOOTH_LIGHTING_PEAK: f32 = 4.0;

/// Share of a product-MIS budget spent on product samples on GGX conductors at least
/// [`WIDE_LOBE`] wide under extended light (`env_peak` below [`SUN_PEAK`]); elsewhere half.
/// Under a sun, and on sharper lobes, more product samples lose; diffuse surfaces stay at half
/// because a sun near the horizon, where the cosine changes fastest across a B̃ leaf, loses
/// with more.
pub const WIDE_LOBE_PRODUCT_SHARE: f64 = 0.75;

/// Lobe width (GGX α) from which product-MIS leans on product samples (see [`WIDE_LOBE_PRODUCT_SHARE`]).
pub const WIDE_LOBE: f32 = 0.1;

/// Share of an MIS budget that `auto` spends on env samples on diffuse surfaces under extended
/// light (`env_peak` below [`SUN_PEAK`]); elsewhere, and for `--method mis` (Mitsuba's
/// `direct`, the baseline), half. A cosine-weighted BRDF sample finds the bright regions of
/// such a map less often than an env sample.
pub const AUTO_DIFFUSE_ENV_SHARE: f64 = 0.75;

/// `auto`'s strategy for a material of `bsdf` under a map of peak `env_peak` (see the module's
/// note).
#[must_use]
pub fn auto_strategy(bsdf: &Bsdf, env_peak: f32) -> Strategy {
    if env_peak < SMOOTH_LIGHTING_PEAK {
        return Strategy::Brdf;
    }
    let range = if env_peak < SUN_PEAK { PRODUCT_ALPHA_EXTENDED } else { PRODUCT_ALPHA };
    let brdf = bsdf.as_brdf();
    if !brdf.is_diffuse() && range.contains(&brdf.lobe_width()) {
        Strategy::ProductMis { product_share: product_share(bsdf, env_peak) }
    } else {
        Strategy::Mis { env_share: auto_env_share(bsdf, env_peak) }
    }
}

/// Whether `auto` samples a material of `bsdf` whose objects are all flat (`on_planes`) by the
/// plane product (`render::plane_products`), under a map of peak `env_peak`: where the BRDF is
/// diffuse and the light extended (`env_peak` below [`SUN_PEAK`]). There the product of the
/// map and the plane's cosine is exact, so env-only sampling of it leaves only visibility to
/// vary the estimate, at env sampling's cost, and such a material has no pilot. Under a sun
/// nearly every sample goes to the sun, and in a shadow the sky's light is left to rare
/// samples, which BRDF samples find more often (docs/perf.md, "Plane products").
#[must_use]
pub fn samples_plane_product(bsdf: &Bsdf, on_planes: bool, env_peak: f32) -> bool {
    on_planes && env_peak < SUN_PEAK && bsdf.as_brdf().is_diffuse()
}

/// The share of a material's product-MIS budget spent on product samples (the rest are BRDF
/// samples; see [`WIDE_LOBE_PRODUCT_SHARE`]).
#[must_use]
pub fn product_share(bsdf: &Bsdf, env_peak: f32) -> f64 {
    let brdf = bsdf.as_brdf();
    if !brdf.is_diffuse() && env_peak < SUN_PEAK && brdf.lobe_width() >= WIDE_LOBE {
        WIDE_LOBE_PRODUCT_SHARE
    } else {
        0.5
    }
}

/// The share of an MIS budget `auto` spends on env samples (see [`AUTO_DIFFUSE_ENV_SHARE`]).
#[must_use]
pub fn auto_env_share(bsdf: &Bsdf, env_peak: f32) -> f64 {
    if bsdf.as_brdf().is_diffuse() && env_peak < SUN_PEAK { AUTO_DIFFUSE_ENV_SHARE } else { 0.5 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::method::Method;
    use sampler_core::brdf::{Lambert, RoughConductor};
    use sampler_core::glam::Vec3;

    fn conductor(alpha: f32) -> Bsdf {
        Bsdf::Conductor(RoughConductor::new(alpha, Vec3::ONE))
    }

    /// The method `auto` resolves to, its split aside.
    fn auto(bsdf: &Bsdf, env_peak: f32) -> Method {
        Method::of(Method::Auto.strategy(bsdf, env_peak))
    }

    #[test]
    fn the_rules_read_the_brdf_s_sharpest_lobe_whatever_its_kind() {
        use sampler_core::brdf::{CarPaint, Phong};
        // Phong n = 998: a lobe width of √(2/1000) ≈ 0.045, inside the range.
        let phong = Bsdf::Phong(Phong::new(Vec3::splat(0.1), Vec3::splat(0.8), 998.0));
        assert_eq!(auto(&phong, 713.0), Method::ProductMis);
        assert_eq!(auto(&Bsdf::Phong(Phong::new(Vec3::splat(0.1), Vec3::splat(0.8), 1e5)), 713.0), Method::Mis);
        // A car paint by its coat: the default's α = 0.005 is sharper than the range; a rougher
        // coat is inside it.
        assert_eq!(auto(&Bsdf::CarPaint(CarPaint::default()), 67.0), Method::Mis);
        let rough_coat = CarPaint::new(Vec3::splat(0.02), Vec3::splat(0.2), 0.25, 1.0, 0.05);
        assert_eq!(auto(&Bsdf::CarPaint(rough_coat), 67.0), Method::ProductMis);
        // A Phong without a specular part is diffuse.
        let matte = Bsdf::Phong(Phong::new(Vec3::splat(0.5), Vec3::ZERO, 998.0));
        assert_eq!(auto(&matte, 713.0), Method::Mis);
    }

    #[test]
    fn auto_samples_the_product_on_moderately_glossy_conductors_only() {
        assert_eq!(auto(&conductor(0.05), 67.0), Method::ProductMis);
        assert_eq!(auto(&conductor(0.1), 713.0), Method::ProductMis);
        assert_eq!(auto(&conductor(0.01), 67.0), Method::Mis);
        // Wider lobes only under extended light, not under a sun.
        assert_eq!(auto(&conductor(0.3), 67.0), Method::ProductMis);
        assert_eq!(auto(&conductor(0.15), 713.0), Method::Mis);
        assert_eq!(auto(&conductor(0.5), 67.0), Method::Mis);
        assert_eq!(auto(&conductor(0.05), 1.6), Method::Brdf, "smooth light");
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
        assert_eq!(
            Method::ProductMis.strategy(&conductor(0.3), 67.0),
            Strategy::ProductMis { product_share: WIDE_LOBE_PRODUCT_SHARE },
            "--method product-mis takes the rules' split"
        );
    }

    #[test]
    fn auto_leans_on_env_samples_on_diffuse_surfaces_under_extended_light() {
        let diffuse = Bsdf::Diffuse(Lambert::new(Vec3::ONE));
        assert_eq!(auto_env_share(&diffuse, 21.0), AUTO_DIFFUSE_ENV_SHARE);
        assert_eq!(auto_env_share(&diffuse, 713.0), 0.5, "sun");
        assert_eq!(auto_env_share(&conductor(0.01), 21.0), 0.5, "sharp lobe");
        assert_eq!(Method::Mis.strategy(&diffuse, 21.0), Strategy::Mis { env_share: 0.5 }, "--method mis: pairs");
    }

    #[test]
    fn auto_samples_the_plane_product_on_diffuse_planes_under_extended_light() {
        let diffuse = Bsdf::Diffuse(Lambert::new(Vec3::ONE));
        assert!(samples_plane_product(&diffuse, true, 21.0));
        assert!(samples_plane_product(&diffuse, true, 1.6), "smooth light too");
        assert!(!samples_plane_product(&diffuse, false, 21.0), "not only on planes");
        assert!(!samples_plane_product(&diffuse, true, 713.0), "a sun");
        assert!(!samples_plane_product(&conductor(0.1), true, 21.0), "glossy");
    }

    #[test]
    fn auto_samples_the_brdf_only_under_smooth_lighting() {
        let b = Bsdf::Diffuse(Lambert::new(Vec3::splat(0.5)));
        assert_eq!(auto(&b, 1.6), Method::Brdf);
        assert_eq!(auto(&b, 21.0), Method::Mis);
        assert_eq!(auto(&b, f32::MAX), Method::Mis);
        for m in Method::ALL.into_iter().filter(|&m| m != Method::Auto) {
            assert_eq!(Method::of(m.strategy(&b, 1.0)), m, "fixed methods stay");
        }
    }
}
