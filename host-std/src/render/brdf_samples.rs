//! How many BRDF samples (the paper's K) each material's product samplers are built from: by
//! default from the material's lobes, or one K for every material (`--brdf-samples`).
//!
//! A build's cost grows with K (its sort and tree ~linearly) and is paid in visibility samples
//! not drawn; more samples only pay where B̃ needs them to resolve the lobe. At equal time a
//! diffuse lobe is best served by a coarse B̃ (env sampling is nearly proportional to the
//! product there), a single glossy lobe by a medium one and a layered BRDF, whose B̃ must
//! place several lobes of different widths, by a finer one (docs/tuning.md, "BRDF samples per
//! sampler at equal time").

use crate::scene::Bsdf;
use sampler_core::brdf::Brdf;
use std::fmt;

/// K of a diffuse BRDF (Lambert, a Phong without a specular lobe).
pub const DIFFUSE_BRDF_SAMPLES: usize = 16;

/// K of a BRDF with one glossy lobe (a GGX conductor, a Phong without a diffuse part).
pub const GLOSSY_BRDF_SAMPLES: usize = 64;

/// K of a layered BRDF: lobes of different widths in one B̃ (car paint, a Phong with both a
/// diffuse and a specular part).
pub const LAYERED_BRDF_SAMPLES: usize = 128;

/// The K a render builds its product samplers from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BrdfSamples {
    /// Each material's own K, from its lobes ([`per_lobe`]).
    #[default]
    PerLobe,
    /// The same K for every material.
    Fixed(usize),
}

impl BrdfSamples {
    /// K of the product samplers built for `bsdf`.
    #[must_use]
    pub fn for_bsdf(self, bsdf: &Bsdf) -> usize {
        match self {
            Self::PerLobe => per_lobe(bsdf),
            Self::Fixed(k) => k,
        }
    }

    /// The largest K any material is built from.
    #[must_use]
    pub fn largest(self) -> usize {
        match self {
            Self::PerLobe => DIFFUSE_BRDF_SAMPLES.max(GLOSSY_BRDF_SAMPLES).max(LAYERED_BRDF_SAMPLES),
            Self::Fixed(k) => k,
        }
    }
}

impl fmt::Display for BrdfSamples {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::PerLobe => f.write_str("per-lobe"),
            Self::Fixed(k) => write!(f, "{k}"),
        }
    }
}

/// The K of `bsdf`'s lobes: [`DIFFUSE_BRDF_SAMPLES`], [`GLOSSY_BRDF_SAMPLES`] or
/// [`LAYERED_BRDF_SAMPLES`].
#[must_use]
pub fn per_lobe(bsdf: &Bsdf) -> usize {
    match bsdf {
        Bsdf::Diffuse(_) => DIFFUSE_BRDF_SAMPLES,
        Bsdf::Conductor(_) => GLOSSY_BRDF_SAMPLES,
        Bsdf::Phong(p) if p.is_diffuse() => DIFFUSE_BRDF_SAMPLES,
        Bsdf::Phong(p) if p.kd.max_element() <= 0.0 => GLOSSY_BRDF_SAMPLES,
        Bsdf::Phong(_) | Bsdf::CarPaint(_) => LAYERED_BRDF_SAMPLES,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::product_arena::{DEFAULT_CAPACITY, check_brdf_samples};
    use sampler_core::brdf::{CarPaint, Lambert, Phong, RoughConductor};
    use sampler_core::glam::Vec3;

    #[test]
    fn each_lobe_kind_has_its_k_and_a_fixed_k_overrides_every_one() {
        let diffuse = Bsdf::Diffuse(Lambert::new(Vec3::splat(0.5)));
        let glossy = Bsdf::Conductor(RoughConductor::new(0.1, Vec3::ONE));
        let paint = Bsdf::CarPaint(CarPaint::default());
        let phong = |kd: f32, ks: f32| Bsdf::Phong(Phong::new(Vec3::splat(kd), Vec3::splat(ks), 50.0));
        let per = |b: &Bsdf| BrdfSamples::PerLobe.for_bsdf(b);
        assert_eq!(per(&diffuse), DIFFUSE_BRDF_SAMPLES);
        assert_eq!(per(&glossy), GLOSSY_BRDF_SAMPLES);
        assert_eq!(per(&paint), LAYERED_BRDF_SAMPLES);
        assert_eq!(per(&phong(0.5, 0.0)), DIFFUSE_BRDF_SAMPLES);
        assert_eq!(per(&phong(0.0, 0.5)), GLOSSY_BRDF_SAMPLES);
        assert_eq!(per(&phong(0.3, 0.3)), LAYERED_BRDF_SAMPLES);
        for b in [&diffuse, &glossy, &paint] {
            assert_eq!(BrdfSamples::Fixed(512).for_bsdf(b), 512);
            assert!(per(b) <= BrdfSamples::PerLobe.largest());
        }
        // The rule's samplers fit the default arena, and the command line's check.
        assert!(BrdfSamples::PerLobe.largest() <= DEFAULT_CAPACITY);
        assert_eq!(check_brdf_samples(BrdfSamples::PerLobe.largest()), Ok(()));
        assert_eq!(BrdfSamples::PerLobe.to_string(), "per-lobe");
        assert_eq!(BrdfSamples::Fixed(64).to_string(), "64");
    }
}
