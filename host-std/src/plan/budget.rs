//! How a pixel's budget of visibility samples (spp) is spent: P primary rays (shading points),
//! each with spp/P light samples. Light noise falls with spp however it is split, but the
//! pixel footprint — edges, textures, a sun seen in a glossy reflection — is integrated only by
//! the primary rays: with P fixed, every method stops converging at the footprint's error.
//! So P grows with spp, and each method keeps the few light samples per shading point that
//! pay for what a shading point costs it (docs/tuning.md, "Shading points per pixel").

use crate::plan::Method;
use crate::plan::method::Lighting;

/// How many shading points a pixel gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadingPoints {
    /// spp / the method's [`samples_per_point_under`](Method::samples_per_point_under) the
    /// scene's lighting.
    Rule,
    /// Exactly this many (a render checks that it divides spp; a sweep takes the largest
    /// divisor of each spp up to it).
    Given(usize),
    /// spp / this many light samples per shading point.
    PerPoint(usize),
}

impl ShadingPoints {
    /// P for a render of `method` at `spp` under `lighting`: a divisor of spp, at least 1.
    #[must_use]
    pub fn resolve(self, method: Method, spp: usize, lighting: Lighting) -> usize {
        let target = match self {
            ShadingPoints::Rule => spp / method.samples_per_point_under(lighting),
            ShadingPoints::Given(p) => p,
            ShadingPoints::PerPoint(v) => spp / v.max(1),
        };
        largest_divisor_up_to(spp, target)
    }
}

/// The largest divisor of `n` that is at most `bound` (1 if `bound` is 0).
fn largest_divisor_up_to(n: usize, bound: usize) -> usize {
    (1..=bound.min(n)).rev().find(|d| n.is_multiple_of(*d)).unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shading_points_grow_with_spp_and_divide_it() {
        for spp in [16, 64, 256, 1024] {
            assert_eq!(
                ShadingPoints::Rule.resolve(Method::Mis, spp, Lighting::OneKind),
                spp / 4,
                "two pairs per point"
            );
            assert_eq!(ShadingPoints::Rule.resolve(Method::Env, spp, Lighting::OneKind), spp);
            assert_eq!(ShadingPoints::Rule.resolve(Method::Product, spp, Lighting::OneKind), (spp / 16).max(1));
        }
        assert_eq!(ShadingPoints::Rule.resolve(Method::Mis, 1, Lighting::OneKind), 1);
        assert_eq!(ShadingPoints::Rule.resolve(Method::Mis, 7, Lighting::OneKind), 1, "7 has no divisor up to 1 but 1");
        assert_eq!(ShadingPoints::Rule.resolve(Method::Mis, 12, Lighting::OneKind), 3);
        assert_eq!(ShadingPoints::Rule.resolve(Method::Mis, 20, Lighting::OneKind), 5);
        assert_eq!(ShadingPoints::Given(4).resolve(Method::Mis, 6, Lighting::OneKind), 3);
        assert_eq!(ShadingPoints::Given(4).resolve(Method::Mis, 2, Lighting::OneKind), 2);
        assert_eq!(ShadingPoints::PerPoint(16).resolve(Method::Mis, 256, Lighting::OneKind), 16);
        assert_eq!(ShadingPoints::PerPoint(16).resolve(Method::Mis, 8, Lighting::OneKind), 1);
    }

    #[test]
    fn an_environment_with_lights_gives_the_mis_methods_more_samples_per_point() {
        let both = Lighting::of(true, 3);
        assert_eq!(Lighting::of(true, 0), Lighting::OneKind);
        assert_eq!(Lighting::of(false, 3), Lighting::OneKind);
        for m in [Method::Mis, Method::ProductMis, Method::Auto] {
            assert_eq!(ShadingPoints::Rule.resolve(m, 256, both), 16, "{m}");
            assert_eq!(ShadingPoints::Rule.resolve(m, 16, both), 1, "{m}");
        }
        assert_eq!(ShadingPoints::Rule.resolve(Method::Env, 256, both), 256);
        assert_eq!(ShadingPoints::Given(64).resolve(Method::Mis, 256, both), 64, "--shading-points still forces P");
        assert_eq!(ShadingPoints::PerPoint(4).resolve(Method::Mis, 256, both), 64);
    }

    #[test]
    fn every_method_has_a_rule() {
        for m in Method::ALL {
            let v = m.samples_per_point();
            assert!(v.is_power_of_two() && v <= 64, "{m}: {v}");
        }
    }
}
