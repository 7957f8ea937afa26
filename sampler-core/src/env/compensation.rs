//! MIS compensation of the environment's density (Karlík et al., "MIS compensation: optimizing
//! sampling techniques in multiple importance sampling", SIGGRAPH Asia 2019). Where env samples
//! are combined with BRDF samples by the balance heuristic, the BRDF samples already cover the
//! map's dim, even parts, and the env technique does better to sample only what stands out:
//! its density is max(0, L − L̄) instead of L, L̄ the map's mean luminance over the sphere.
//! That density is zero wherever the map is at or below its mean, so a compensated pyramid
//! may only serve a technique combined with one that reaches every direction the BRDF
//! reflects ([`EnvHierarchy::compensated`](super::EnvHierarchy::compensated)); env-only
//! sampling keeps the plain pyramid. What it gains is in docs/perf.md, "MIS compensation".

use super::EnvHierarchy;
use super::MAX_LEVEL;
use super::hierarchy::inverse_mean;
use super::pyramid::{EnvError, check_lengths, fill_pyramid, level_offset, pyramid_len};

/// Writes into `out` the compensated pyramid of `pyramid` (built by
/// [`build_pyramid`](super::build_pyramid) for a finest level `finest`): the finest level
/// less the mean (the root), clamped at zero, and its means above. Returns whether anything
/// is left above the mean; where nothing is (a constant map), `out` holds all zeros and the
/// plain pyramid should be used instead.
pub fn compensate_pyramid(finest: u32, pyramid: &[f32], out: &mut [f32]) -> Result<bool, EnvError> {
    if finest > MAX_LEVEL {
        return Err(EnvError::TooLarge { finest });
    }
    let len = pyramid_len(finest);
    for (buffer, found) in [("pyramid", pyramid.len()), ("compensated pyramid", out.len())] {
        if found != len {
            return Err(EnvError::WrongLength { buffer, expected: len, found });
        }
    }
    inverse_mean(pyramid)?;
    let mean = pyramid[0];
    let start = level_offset(finest);
    for (o, &v) in out[start..].iter_mut().zip(&pyramid[start..]) {
        *o = (v - mean).max(0.0);
    }
    fill_pyramid(finest, out);
    Ok(out[0] > 0.0)
}

impl<'a> EnvHierarchy<'a> {
    /// Attaches `pyramid`, this map's pyramid compensated for MIS by
    /// [`compensate_pyramid`](super::compensate_pyramid), for [`compensated`](Self::compensated)
    /// to return a view over.
    pub fn with_compensated(mut self, pyramid: &'a [f32]) -> Result<Self, EnvError> {
        check_lengths(self.finest, self.radiance.len(), pyramid.len())?;
        self.compensated = Some((pyramid, inverse_mean(pyramid)?));
        Ok(self)
    }

    /// The share of the map's light above its mean, Σ max(0, L − L̄) / Σ L over its texels
    /// (the compensated pyramid's root over the plain one's): near 1 where compact bright
    /// regions hold nearly all of it, lower where the light is spread. `None` without a
    /// compensated pyramid attached, or for a black map.
    #[must_use]
    pub fn excess_share(&self) -> Option<f32> {
        let (pyramid, _) = self.compensated?;
        (self.pyramid[0] > 0.0).then(|| pyramid[0] / self.pyramid[0])
    }

    /// Whether a compensated pyramid is attached.
    #[inline]
    #[must_use]
    pub fn has_compensated(&self) -> bool {
        self.compensated.is_some()
    }

    /// Writes into `out` (as long as this view's pyramid) the compensated pyramid of this
    /// view's pyramid, as [`compensate_pyramid`](super::compensate_pyramid) does; returns
    /// whether anything of the map stands above its mean (where nothing does, the plain view
    /// serves MIS as it is).
    pub fn compensate_into(&self, out: &mut [f32]) -> Result<bool, EnvError> {
        compensate_pyramid(self.finest, self.pyramid, out)
    }

    /// The view env samples combined with BRDF samples (MIS) draw from: the same map, its
    /// radiance and frame, sampled by the compensated pyramid where one is attached (its
    /// density is zero where the map is at or below its mean, so never for env-only
    /// sampling), else this view itself.
    pub fn compensated(&self) -> Self {
        let mut view = *self;
        if let Some((pyramid, inv_mean)) = self.compensated {
            (view.pyramid, view.inv_mean, view.cdf, view.compensated) = (pyramid, inv_mean, None, None);
        }
        view
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::Cell;
    use crate::env::{build_pyramid, pyramid_index};

    #[test]
    fn the_finest_level_loses_the_mean_and_the_levels_above_average_it() {
        // Luminances 0, 1, 2, 5 (mean 2): compensated 0, 0, 0, 3.
        let rgb = [[0.0; 3], [1.0; 3], [2.0; 3], [5.0; 3]];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &rgb, &mut p).unwrap();
        let mut c = [9.0f32; 5];
        assert!(compensate_pyramid(1, &p, &mut c).unwrap());
        let at = |x, y| c[pyramid_index(Cell::new(1, x, y))];
        assert_eq!([at(0, 0), at(1, 0), at(0, 1), at(1, 1)], [0.0, 0.0, 0.0, 3.0]);
        assert_eq!(c[0], 0.75);
    }

    #[test]
    fn a_view_writes_its_own_compensated_pyramid_and_attaches_it() {
        let rgb = [[0.0; 3], [1.0; 3], [2.0; 3], [5.0; 3]];
        let mut p = [0.0f32; 5];
        build_pyramid(1, &rgb, &mut p).unwrap();
        let view = EnvHierarchy::new(1, &p, &rgb).unwrap();
        assert!(!view.has_compensated());
        let (mut c, mut direct) = ([0.0f32; 5], [0.0f32; 5]);
        assert!(view.compensate_into(&mut c).unwrap());
        compensate_pyramid(1, &p, &mut direct).unwrap();
        assert_eq!(c, direct);
        let attached = view.with_compensated(&c).unwrap();
        assert!(attached.has_compensated());
        assert_eq!(attached.compensated().pdf_square(glam::Vec2::new(0.75, 0.75)), 4.0);
        // Luminances 0, 1, 2, 5: 3 of their 8 above the mean.
        assert_eq!((view.excess_share(), attached.excess_share()), (None, Some(0.375)));
        assert!(matches!(view.compensate_into(&mut c[..4]), Err(EnvError::WrongLength { .. })));
    }

    #[test]
    fn a_constant_map_leaves_nothing_and_bad_input_is_refused() {
        let rgb = [[2.0f32; 3]; 16];
        let mut p = [0.0f32; 21];
        build_pyramid(2, &rgb, &mut p).unwrap();
        let mut c = [0.0f32; 21];
        assert!(!compensate_pyramid(2, &p, &mut c).unwrap());
        assert!(c.iter().all(|&v| v == 0.0));
        assert!(matches!(compensate_pyramid(2, &p, &mut c[..20]), Err(EnvError::WrongLength { .. })));
        p[0] = f32::NAN;
        assert!(matches!(compensate_pyramid(2, &p, &mut c), Err(EnvError::NotSanitized)));
    }
}
