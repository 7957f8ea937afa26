//! What a shading point takes in time under each plan: a part per point and a part per sample,
//! in MIS samples (one MIS sample with its shadow ray: 1), measured once with one material on
//! every surface (docs/perf.md, "Cost per visibility sample"; the plane product's on the
//! scenes' floors alone, less its build, "The products against MIS at equal time"). `auto`'s pilot scores and budgets its
//! plans by [`PLANS`](super::candidates::PLANS)' simpler weights; this model says what the
//! chosen budgets then cost, for [`pace`](super::pace).

use crate::plan::carrier::POINT_COST;
use crate::render::strategy::Strategy;

/// Time to build a plane product's pyramid per finest texel of the map, in MIS samples
/// (docs/perf.md, "Plane products": its build's CPU time over a MIS sample's).
pub const PLANE_BUILD_COST: f64 = 0.5;

/// A plan's time per sample and its shading point's time beyond MIS's, in MIS samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanTime {
    /// Per visibility sample.
    pub per_sample: f64,
    /// Per shading point, beyond MIS's [`POINT_COST`].
    pub per_point: f64,
}

/// The measured time of `strategy`'s samples and points; MIS's for a strategy not measured.
#[must_use]
pub fn plan_time(strategy: Strategy) -> PlanTime {
    let (per_sample, per_point) = match strategy {
        Strategy::Mis { env_share } if env_share > 0.5 => (1.17, 0.0),
        Strategy::Env => (1.27, 0.0),
        Strategy::Brdf => (0.75, 0.0),
        Strategy::ProductMis { product_share } if product_share > 0.5 => (2.23, 0.95),
        Strategy::ProductMis { .. } => (1.88, 2.07),
        Strategy::TwoLevelMis { .. } => (1.11, 3.2),
        Strategy::PlaneProduct => (1.35, 0.0),
        _ => (1.0, 0.0),
    };
    PlanTime { per_sample, per_point }
}

/// Time per shading point of `strategy` at `budget` samples, relative to MIS's at
/// `samples_per_point`.
#[must_use]
pub fn time_per_point(strategy: Strategy, budget: usize, samples_per_point: usize) -> f64 {
    let t = plan_time(strategy);
    (POINT_COST + t.per_point + budget as f64 * t.per_sample) / (POINT_COST + samples_per_point.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mis_is_the_unit_and_the_other_plans_cost_their_samples_and_points() {
        let mis = Strategy::Mis { env_share: 0.5 };
        for v in [1, 2, 8, 64] {
            assert!((time_per_point(mis, v, v) - 1.0).abs() < 1e-12);
        }
        // Product-MIS 3:1 at five samples of eight: its samples and its point's part.
        let product = Strategy::ProductMis { product_share: 0.75 };
        let t = plan_time(product);
        let want = (POINT_COST + t.per_point + 5.0 * t.per_sample) / (POINT_COST + 8.0);
        assert!((time_per_point(product, 5, 8) - want).abs() < 1e-12 && want > 1.0);
        // BRDF sampling is cheaper than MIS; env samples dearer than BRDF samples, so env-only,
        // MIS 3:1 and the plane product cost more than MIS at MIS's budget.
        assert!(time_per_point(Strategy::Brdf, 8, 8) < 1.0);
        for s in [Strategy::Env, Strategy::Mis { env_share: 0.75 }, Strategy::PlaneProduct] {
            assert!(time_per_point(s, 8, 8) > 1.0, "{s:?}");
        }
        // More samples take more time.
        assert!(time_per_point(Strategy::PlaneProduct, 9, 8) > time_per_point(Strategy::PlaneProduct, 8, 8));
    }
}
