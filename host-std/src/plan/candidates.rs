//! The plans `auto`'s pilot may choose and what each costs per visibility sample: a fixed
//! weight per plan, measured once (docs/perf.md, "Cost per visibility sample") — a constant,
//! so that the pilot's choice, and the image, depend only on the scene, the settings and the
//! seed. Every plan's sampler is the environment's or one shared by a pixel and its
//! neighbours, so no plan pays a build per shading point.

use crate::render::strategy::{MaterialPlan, Strategy};

/// A plan the pilot may choose, with its cost.
#[derive(Clone, Copy, Debug)]
pub struct Candidate {
    /// The strategy.
    pub strategy: Strategy,
    /// Time per visibility sample relative to MIS's pairs at two samples per shading point,
    /// measured once over the benchmark scenes (docs/perf.md, "Cost per visibility sample"),
    /// the shared samplers' builds included. Product-MIS's is measured at each material's K
    /// from its lobes (`render::brdf_samples`); a K set for every material by `--brdf-samples`
    /// keeps it.
    pub cost: f64,
}

impl Candidate {
    /// Light samples per shading point that cost about what MIS's `samples_per_point` cost:
    /// as many for a plan no costlier per sample than MIS, fewer for a costlier one — the
    /// fewest whose time reaches MIS's, so that a split plan keeps samples of both its
    /// techniques (product-MIS 3:1 at two samples of four would be 1:1 at half the samples).
    /// `auto` gives each material its plan's budget, so that a material whose plan costs more
    /// per sample takes about the share of the render's time it takes under MIS, and the
    /// other materials' time stays MIS's (docs/perf.md, "`auto` and its pilot").
    #[must_use]
    pub fn equal_cost_budget(&self, samples_per_point: usize) -> usize {
        let v = samples_per_point.max(1);
        if self.cost <= 1.0 {
            return v;
        }
        (v as f64 / self.cost).ceil().clamp(1.0, v as f64) as usize
    }

    /// Time per shading point at [`equal_cost_budget`](Self::equal_cost_budget), relative to
    /// MIS's at `samples_per_point`.
    #[must_use]
    pub fn cost_per_point(&self, samples_per_point: usize) -> f64 {
        let v = samples_per_point.max(1);
        let b = self.equal_cost_budget(v);
        b as f64 * self.cost / v as f64
    }
}

/// `plan` at its strategy's [`equal_cost_budget`](Candidate::equal_cost_budget) of
/// `samples_per_point` environment samples (a strategy not among [`PLANS`] keeps the
/// render's).
#[must_use]
pub fn at_equal_cost(plan: MaterialPlan, samples_per_point: usize) -> MaterialPlan {
    let env_budget = candidate_of(plan.strategy).map(|c| PLANS[c].equal_cost_budget(samples_per_point));
    MaterialPlan { env_budget, ..plan }
}

/// The candidate of [`PLANS`] that samples with `strategy`, if any.
#[must_use]
pub fn candidate_of(strategy: Strategy) -> Option<usize> {
    PLANS.iter().position(|p| p.strategy == strategy)
}

/// The candidates.
pub const PLANS: [Candidate; 7] = [
    Candidate { strategy: Strategy::Env, cost: 1.0 },
    Candidate { strategy: Strategy::Brdf, cost: 0.78 },
    Candidate { strategy: Strategy::Mis { env_share: 0.5 }, cost: 1.0 },
    Candidate { strategy: Strategy::Mis { env_share: 0.75 }, cost: 1.0 },
    Candidate { strategy: Strategy::ProductMis { product_share: 0.5 }, cost: 1.45 },
    Candidate { strategy: Strategy::ProductMis { product_share: 0.75 }, cost: 1.67 },
    Candidate { strategy: Strategy::TwoLevelMis { two_level_share: 0.5 }, cost: 1.12 },
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_costlier_plan_takes_fewer_samples_per_shading_point_for_about_mis_s_time() {
        let mis = candidate_of(Strategy::Mis { env_share: 0.5 }).unwrap();
        let product_mis = candidate_of(Strategy::ProductMis { product_share: 0.5 }).unwrap();
        let brdf = candidate_of(Strategy::Brdf).unwrap();
        for v in [1, 2, 4, 16, 64] {
            assert_eq!(PLANS[mis].equal_cost_budget(v), v);
            assert_eq!(PLANS[brdf].equal_cost_budget(v), v, "cheaper plans keep the render's budget");
            assert!((PLANS[mis].cost_per_point(v) - 1.0).abs() < 1e-12);
        }
        // 4 / 1.45 ≈ 2.8 samples: three, at 1.09× MIS's time per shading point; 4 / 1.67 ≈
        // 2.4: three too (two would split 1:1).
        assert_eq!(PLANS[product_mis].equal_cost_budget(4), 3);
        assert!((PLANS[product_mis].cost_per_point(4) - 3.0 * 1.45 / 4.0).abs() < 1e-12);
        assert_eq!(PLANS[product_mis + 1].equal_cost_budget(4), 3);
        assert_eq!(PLANS[product_mis].equal_cost_budget(1), 1, "at least one sample");
        for (c, plan) in PLANS.iter().enumerate() {
            for v in [4, 16, 64] {
                let p = plan.cost_per_point(v);
                assert!(p <= 1.0 || p - 1.0 < plan.cost / v as f64, "{c} at {v}: {p}");
            }
        }
        // 4 / 1.12 ≈ 3.6: two-level-MIS keeps all four, at 1.12× MIS's time per shading point.
        let two_level = PLANS.iter().position(|p| p.strategy.is_two_level()).unwrap();
        assert_eq!(PLANS[two_level].equal_cost_budget(4), 4);
    }
}
