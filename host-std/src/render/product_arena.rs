//! The product arena a render builds its samplers in, sized for the render's K (BRDF samples
//! per sampler): the core's arena has its capacity as a const generic, so the renderer keeps
//! two sizes and takes the smaller that holds K. K ≤ 256 — the paper's default and every
//! render's unless asked — runs in the default arena; larger K, up to
//! [`MAX_BRDF_SAMPLES`], in an arena four times as large (~180 KB).

use sampler_core::brdf::Brdf;
use sampler_core::env::EnvHierarchy;
use sampler_core::frame::Frame;
use sampler_core::glam::Vec3;
use sampler_core::sampler::{ProductArena, ProductError, ProductParams, ProductSampler};

/// BRDF samples the default arena holds (`ProductArena`'s default K).
pub const DEFAULT_CAPACITY: usize = 256;

/// The most BRDF samples a render's product sampler is built from (the large arena's K).
pub const MAX_BRDF_SAMPLES: usize = 1024;

/// Tree nodes of the large arena: four times the default arena's, as for its samples. Trees
/// from 1024 samples stay well inside it (docs/perf.md#tree-size-and-memory); were a tree to
/// fill it, its leaves would keep their samples' mean, still sampled exactly.
const LARGE_NODES: usize = 8192;

/// The large arena.
type LargeArena = ProductArena<MAX_BRDF_SAMPLES, LARGE_NODES>;

/// A product arena that holds K BRDF samples: the default one for K ≤ 256, else the large one.
pub enum SizedArena {
    /// K ≤ [`DEFAULT_CAPACITY`].
    Default(Box<ProductArena>),
    /// [`DEFAULT_CAPACITY`] < K ≤ [`MAX_BRDF_SAMPLES`].
    Large(Box<LargeArena>),
}

/// Whether a render can build its product samplers from `brdf_samples` BRDF samples: at most
/// [`MAX_BRDF_SAMPLES`], else the error naming both.
pub fn check_brdf_samples(brdf_samples: usize) -> Result<(), ProductError> {
    if brdf_samples > MAX_BRDF_SAMPLES {
        return Err(ProductError::AboveCapacity { asked: brdf_samples, capacity: MAX_BRDF_SAMPLES });
    }
    Ok(())
}

impl SizedArena {
    /// The smallest arena that holds `brdf_samples`; above [`MAX_BRDF_SAMPLES`], the error
    /// naming both.
    pub fn for_samples(brdf_samples: usize) -> Result<Self, ProductError> {
        check_brdf_samples(brdf_samples)?;
        Ok(if brdf_samples <= DEFAULT_CAPACITY {
            Self::Default(Box::new(ProductArena::new()))
        } else {
            Self::Large(Box::new(ProductArena::new()))
        })
    }

    /// BRDF samples this arena holds.
    #[must_use]
    pub fn capacity(&self) -> usize {
        match self {
            Self::Default(_) => DEFAULT_CAPACITY,
            Self::Large(_) => MAX_BRDF_SAMPLES,
        }
    }

    /// [`ProductArena::build`] in whichever arena this is.
    pub fn build<'a, 'e, B: Brdf + ?Sized>(
        &'a mut self,
        env: &'a EnvHierarchy<'e>,
        brdf: &B,
        frame: &Frame,
        wo: Vec3,
        params: &ProductParams,
        seed: u64,
    ) -> Result<ProductSampler<'a, 'e>, ProductError> {
        match self {
            Self::Default(a) => a.build(env, brdf, frame, wo, params, seed),
            Self::Large(a) => a.build(env, brdf, frame, wo, params, seed),
        }
    }

    /// [`ProductArena::last_built`] of whichever arena this is.
    #[must_use]
    pub fn last_built<'a, 'e>(&'a self, env: &'a EnvHierarchy<'e>) -> Option<ProductSampler<'a, 'e>> {
        match self {
            Self::Default(a) => a.last_built(env),
            Self::Large(a) => a.last_built(env),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sampler_core::brdf::RoughConductor;
    use sampler_core::env::{build_pyramid, pyramid_len};

    #[test]
    fn the_smallest_arena_that_holds_k_is_taken_and_more_is_an_error_naming_both() {
        let capacity = |k| SizedArena::for_samples(k).map(|a| a.capacity());
        assert_eq!(capacity(1), Ok(256));
        assert_eq!(capacity(256), Ok(256));
        assert_eq!(capacity(257), Ok(1024));
        assert_eq!(capacity(1024), Ok(1024));
        let err = capacity(1025).unwrap_err();
        assert_eq!(err, ProductError::AboveCapacity { asked: 1025, capacity: 1024 });
        assert!(err.to_string().contains("1025") && err.to_string().contains("1024"), "{err}");
        assert_eq!(check_brdf_samples(1024), Ok(()));
    }

    #[test]
    fn a_large_k_builds_from_all_its_samples() {
        let level = 5;
        let n = 1usize << level;
        let rgb = vec![[0.5f32; 3]; n * n];
        let mut pyramid = vec![0.0; pyramid_len(level)];
        build_pyramid(level, &rgb, &mut pyramid).unwrap();
        let env = EnvHierarchy::new(level, &pyramid, &rgb).unwrap();
        let brdf = RoughConductor::new(0.3, Vec3::ONE);
        let frame = Frame::from_normal(Vec3::Z);
        let wo = Vec3::new(0.6, 0.0, 0.8);
        for k in [16, 256, 700, 1024] {
            let mut arena = SizedArena::for_samples(k).unwrap();
            let params = ProductParams { brdf_samples: k, ..ProductParams::default() };
            let sampler = arena.build(&env, &brdf, &frame, wo, &params, 3).unwrap();
            // GGX α 0.3 seen at 37° from the normal: every draw is usable.
            assert_eq!(sampler.brdf_samples(), k);
            assert!(sampler.node_count() > k, "a tree over {k} samples has more nodes than samples");
            assert_eq!(arena.last_built(&env).map(|s| s.brdf_samples()), Some(k));
        }
    }
}
