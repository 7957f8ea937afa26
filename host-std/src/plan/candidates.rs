//! The plans `auto`'s pilot may choose and what each costs per visibility sample: a fixed
//! weight per plan, measured once (docs/perf.md, "Cost per visibility sample"), plus, for a
//! plan that builds a sampler at every shading point, that build spread over the shading
//! point's samples — a function of the settings only, so that the pilot's choice, and the
//! image, depend only on the scene, the settings and the seed.

use crate::plan::pilot::COSTLIER_OVERRIDE_MARGIN;
use crate::render::strategy::Strategy;

/// A plan the pilot may choose, with its cost.
#[derive(Clone, Copy, Debug)]
pub struct Candidate {
    /// The strategy.
    pub strategy: Strategy,
    /// Time per visibility sample relative to MIS's pairs at two samples per shading point,
    /// measured once over the benchmark scenes (docs/perf.md, "Cost per visibility sample"),
    /// without [`build`](Self::build). Product-MIS's is measured at each material's K from its
    /// lobes (`render::brdf_samples`); a K set for every material by `--brdf-samples` keeps it.
    pub cost: f64,
    /// Time of the sampler built at every shading point, in the unit of [`cost`](Self::cost)
    /// (0: no sampler is built per shading point — product-MIS's serves a pixel and its
    /// neighbours).
    pub build: f64,
}

impl Candidate {
    /// Time per visibility sample, relative to MIS's pairs, at `samples_per_point` light
    /// samples per shading point.
    #[must_use]
    pub fn cost_at(&self, samples_per_point: usize) -> f64 {
        self.cost + self.build / samples_per_point.max(1) as f64
    }
}

/// The candidates.
pub const PLANS: [Candidate; 7] = [
    Candidate { strategy: Strategy::Env, cost: 1.0, build: 0.0 },
    Candidate { strategy: Strategy::Brdf, cost: 0.78, build: 0.0 },
    Candidate { strategy: Strategy::Mis { env_share: 0.5 }, cost: 1.0, build: 0.0 },
    Candidate { strategy: Strategy::Mis { env_share: 0.75 }, cost: 1.0, build: 0.0 },
    Candidate { strategy: Strategy::ProductMis { product_share: 0.5 }, cost: 1.45, build: 0.0 },
    Candidate { strategy: Strategy::ProductMis { product_share: 0.75 }, cost: 1.67, build: 0.0 },
    Candidate {
        strategy: Strategy::TwoLevelMis { two_level_share: 0.5 },
        cost: TWO_LEVEL_MIS_COST,
        build: TWO_LEVEL_MIS_BUILD,
    },
];

/// Two-level-MIS's time per visibility sample without its build (see [`Candidate::cost`]).
pub const TWO_LEVEL_MIS_COST: f64 = 1.55;

/// Two-level-MIS's build per shading point (see [`Candidate::build`]).
pub const TWO_LEVEL_MIS_BUILD: f64 = 11.7;

/// The largest gain in variance per sample over MIS that a sampler built per shading point
/// has been measured to reach (two-level-MIS, light noise alone at one shading point;
/// docs/perf.md, "The two products"). A pilot's pixels add the footprint's and visibility's
/// noise, which every plan shares, so its measured gain is smaller.
pub const PER_POINT_SAMPLER_GAIN: f64 = 6.2;

/// Whether candidate `c` of [`PLANS`] can repay its cost at `samples_per_point`, so that the
/// pilot measures it. The plans without a per-shading-point build always can. One with a
/// build replaces the rules' plan only where it scores [`COSTLIER_OVERRIDE_MARGIN`]× better,
/// and the rules' plan scores no worse than MIS where the rules chose it over MIS, so it
/// needs a gain over MIS of the margin × its cost: where that exceeds
/// [`PER_POINT_SAMPLER_GAIN`] it cannot win and the pilot spends nothing on it.
#[must_use]
pub fn affordable(c: usize, samples_per_point: usize) -> bool {
    let p = PLANS[c];
    p.build == 0.0 || COSTLIER_OVERRIDE_MARGIN * p.cost_at(samples_per_point) <= PER_POINT_SAMPLER_GAIN
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sampler_built_per_shading_point_competes_only_where_enough_samples_share_its_build() {
        let two_level = PLANS.iter().position(|p| p.strategy.is_two_level()).unwrap();
        // `auto`'s own two pairs per shading point: the build outweighs any gain measured.
        assert!(!affordable(two_level, 4));
        assert!(!affordable(two_level, 2));
        assert!(affordable(two_level, 16));
        assert!(affordable(two_level, 1024));
        assert!(PLANS[two_level].cost_at(4) > PLANS[two_level].cost_at(16));
        // Every other plan competes at every split.
        for c in (0..PLANS.len()).filter(|&c| c != two_level) {
            assert!([1, 2, 4, 16, 1024].iter().all(|&v| affordable(c, v)), "{c}");
            assert_eq!(PLANS[c].cost_at(1), PLANS[c].cost_at(64));
        }
    }
}
