//! `auto`'s budgets for the materials whose plan is no costlier than MIS: more samples where
//! the other materials' plans make the image costlier, so that those materials do not fall
//! behind MIS at equal time.
//!
//! `auto` compares with MIS over the whole image's time. A material whose plan costs more per
//! shading point than MIS's (a product, the plane product and its pyramid's build) wins on its
//! own pixels and takes time from every other pixel: where another material's plan is MIS's
//! own, that material has MIS's error at MIS's samples but the costlier image's time, and falls
//! behind MIS at equal time by the image's cost over MIS's (docs/perf.md, "The products against
//! MIS at equal time"). With the cheap materials at `k` × their samples and the costly ones at
//! a mean cost `c̄` per shading point (MIS's 1), a cheap material's error at the image's time is
//! `(f k + (1 − f) c̄ + o) / k` of MIS's, `f` the cheap materials' share of the shading points
//! and `o` the pilot's time: `k = c̄ + o / (1 − f)` brings it to MIS's, and slows the image by
//! `k` over `f + (1 − f) c̄ + o`: little where the cheap materials are few, too much where they
//! hold most of the image ([`MAX_SLOWDOWN`]). The costs are a fixed model of each plan's time
//! ([`time_per_point`]) and the shares the centre rays' hits, so that the budgets, and the
//! image, depend only on the scene, the settings and the seed.

use crate::plan::time_model::time_per_point;
use crate::render::strategy::{MaterialPlan, Strategy};

/// The most the cheap materials' extra samples may slow the image: each costlier material's
/// lead over MIS at equal time shrinks by as much. Where the cheap materials hold most of the
/// image, making up the others' cost would take most of that lead (a sunset's sphere under
/// MIS beside its floor's plane product: 1.24×), and `auto` leaves them at MIS's budget.
pub const MAX_SLOWDOWN: f64 = 1.05;

/// Work a render does once, each as a share of the time MIS takes for the pixels it is spread
/// over.
#[derive(Clone, Copy, Debug, Default)]
pub struct FixedCosts {
    /// The plane pyramids' build, over the plane product's pixels (part of its cost).
    pub plane_build: f64,
    /// The pilot's renders, over every pixel that meets a surface.
    pub pilot: f64,
}

/// `plans` with each plan that costs no more than MIS per shading point at `samples_per_point`
/// samples given as many more as keep it level with MIS at the image's time ([`pace`]), rounded
/// up to a whole budget; `pixels` holds each material's share of the image. The costlier plans
/// are unchanged.
#[must_use]
pub fn keep_pace(
    plans: &[MaterialPlan],
    pixels: &[usize],
    samples_per_point: usize,
    fixed: FixedCosts,
) -> Vec<MaterialPlan> {
    let v = samples_per_point.max(1);
    let cost = |p: &MaterialPlan| {
        let build = if p.strategy == Strategy::PlaneProduct { fixed.plane_build } else { 0.0 };
        time_per_point(p.strategy, p.env_budget.unwrap_or(v), v) + build
    };
    let costs: Vec<f64> = plans.iter().map(cost).collect();
    let Some(k) = pace(&costs, pixels, fixed.pilot) else { return plans.to_vec() };
    plans
        .iter()
        .zip(&costs)
        .map(
            |(p, &c)| {
                if c > 1.0 { *p } else { MaterialPlan { env_budget: Some(paced_budget(p.strategy, v, k)), ..*p } }
            },
        )
        .collect()
}

/// The factor on the cheap plans' samples from each material's cost per shading point (`costs`,
/// MIS's 1) and share of the image (`pixels`), and the pilot's time (`pilot`, a share of MIS's
/// for the image): `None` where no plan costs more than MIS, or where the cheap materials hold
/// so much of the image that their extra samples would slow it by more than [`MAX_SLOWDOWN`].
fn pace(costs: &[f64], pixels: &[usize], pilot: f64) -> Option<f64> {
    let (mut all, mut costly, mut cost) = (0.0, 0.0, 0.0);
    for (&c, &n) in costs.iter().zip(pixels) {
        all += n as f64;
        if c > 1.0 {
            (costly, cost) = (costly + n as f64, cost + n as f64 * c);
        }
    }
    if costly == 0.0 {
        return None;
    }
    let costly_share = costly / all;
    let (mean, f) = (cost / costly, 1.0 - costly_share);
    let k = mean + pilot / costly_share;
    // The image's time at k over its time before: f k + (1 - f) c̄ + o against f + (1 - f) c̄ + o.
    let before = f + costly_share * mean + pilot;
    ((before + f * (k - 1.0)) / before <= MAX_SLOWDOWN).then_some(k)
}

/// At least `k` × `v` samples, rounded up to what `strategy` spends whole (pairs for plain MIS).
fn paced_budget(strategy: Strategy, v: usize, k: f64) -> usize {
    let whole = match strategy {
        Strategy::Mis { env_share: 0.5 } => 2,
        _ => 1,
    };
    // The guard keeps an exact product (k = 1.5 at v = 4) from rounding up past it.
    let b = (v as f64 * k / whole as f64 - 1e-9).ceil() as usize * whole;
    b.max(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::time_model::time_per_point;

    fn plan(strategy: Strategy, env_budget: Option<usize>) -> MaterialPlan {
        MaterialPlan { strategy, reuse_cosine: 1.0, brdf_samples: 16, env_budget }
    }

    fn budgets(plans: &[MaterialPlan]) -> Vec<Option<usize>> {
        plans.iter().map(|p| p.env_budget).collect()
    }

    #[test]
    fn cheap_plans_keep_pace_with_the_costly_ones_and_nothing_else_moves() {
        let mis = plan(Strategy::Mis { env_share: 0.5 }, Some(8));
        let brdf = plan(Strategy::Brdf, Some(8));
        let plane = plan(Strategy::PlaneProduct, None);
        // Without a costlier plan nothing changes.
        let cheap = [mis, brdf];
        assert_eq!(budgets(&keep_pace(&cheap, &[10, 90], 8, FixedCosts::default())), budgets(&cheap));
        // A plane product on nine tenths of the pixels: the cheap plans take its cost in samples.
        let paced = keep_pace(&[mis, brdf, plane], &[5, 5, 90], 8, FixedCosts { plane_build: 0.05, pilot: 0.0 });
        let k = time_per_point(Strategy::PlaneProduct, 8, 8) + 0.05;
        assert!(k > 1.2, "{k}");
        assert_eq!(paced[1].env_budget, Some((8.0 * k).ceil() as usize));
        assert_eq!(paced[0].env_budget, Some(2 * (4.0 * k).ceil() as usize), "MIS pairs stay whole");
        assert_eq!((paced[2].strategy, paced[2].env_budget), (plane.strategy, plane.env_budget));
        // Plain MIS's error at the image's time is MIS's own or less: f + (1 - f) c̄ / k', k'
        // its budget over 8.
        let ratio = 0.1 + 0.9 * k / (paced[0].env_budget.unwrap() as f64 / 8.0);
        assert!(ratio <= 1.0 && ratio > 0.9, "{ratio}");
    }

    #[test]
    fn budgets_round_to_whole_samples_and_never_fall() {
        let brdf = plan(Strategy::Brdf, Some(8));
        let two_level = plan(Strategy::TwoLevelMis { two_level_share: 0.5 }, Some(8));
        let k = time_per_point(two_level.strategy, 8, 8);
        assert_eq!(
            keep_pace(&[brdf, two_level], &[1, 9], 8, FixedCosts::default())[0].env_budget,
            Some((8.0 * k).ceil() as usize)
        );
        // A material without pixels weighs nothing.
        assert_eq!(keep_pace(&[brdf, two_level], &[1, 0], 8, FixedCosts::default())[0].env_budget, Some(8));
        // Never fewer than the render's samples, and an exact product is not rounded up.
        assert_eq!(paced_budget(Strategy::Brdf, 4, 0.9), 4);
        assert_eq!(paced_budget(Strategy::Mis { env_share: 0.5 }, 4, 1.5), 6);
        assert_eq!(paced_budget(Strategy::Mis { env_share: 0.5 }, 4, 1.26), 6);
        assert_eq!(pace(&[1.0, 0.8], &[50, 50], 0.0), None);
    }

    #[test]
    fn cheap_materials_that_hold_most_of_the_image_keep_mis_s_budget() {
        // A tenth of the image cheap: the image slows by 1.3 / (0.1 + 0.9 · 1.3) = 1.024.
        assert_eq!(pace(&[1.0, 1.3], &[10, 90], 0.0), Some(1.3));
        // Two thirds cheap: 1.3 / (0.67 + 0.33 · 1.3) = 1.2, more than MAX_SLOWDOWN.
        assert_eq!(pace(&[1.0, 1.3], &[67, 33], 0.0), None);
    }

    #[test]
    fn the_pilot_s_time_is_made_up_over_the_costly_share() {
        // A tenth cheap, the rest at 1.3, the pilot 3% of MIS's time: k = 1.3 + 0.03 / 0.9.
        let k = pace(&[1.0, 1.3], &[10, 90], 0.03).unwrap();
        assert!((k - (1.3 + 0.03 / 0.9)).abs() < 1e-12, "{k}");
        // The cheap tenth's error at the image's time, (0.1 k + 0.9 · 1.3 + 0.03) / k, is MIS's.
        assert!(((0.1 * k + 0.9 * 1.3 + 0.03) / k - 1.0).abs() < 1e-12);
    }
}
