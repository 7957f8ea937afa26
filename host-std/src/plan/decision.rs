//! How `auto`'s pilot turns pixel pairs into a choice: each candidate's score (relative variance
//! × cost), and the rules' plan against the best score by the margins (`plan::pilot`'s note says
//! why each margin is what it is).

use crate::plan::candidates::PLANS;
use crate::plan::pilot::{COSTLIER_OVERRIDE_MARGIN, OVERRIDE_MARGIN};
use crate::render::strategy::Strategy;

/// The rule's plan unless another scores [`OVERRIDE_MARGIN`]× better, or
/// [`COSTLIER_OVERRIDE_MARGIN`]× where it costs more than the rule's (or the rule's was not
/// measured or not trusted: then the best); env-only sampling only where it also scores
/// [`OVERRIDE_MARGIN`]× better than every plan with BRDF samples (see the module's note).
/// `None` when nothing was scored.
pub(crate) fn decide(scores: &[Option<f64>], rule: Option<usize>, samples_per_point: usize) -> Option<usize> {
    let scores = &without_unproven_env(scores);
    let (best, best_score) =
        scores.iter().enumerate().filter_map(|(c, s)| s.map(|s| (c, s))).min_by(|a, b| a.1.total_cmp(&b.1))?;
    match rule.and_then(|r| scores[r].map(|s| (r, s))) {
        Some((r, s)) => {
            let costlier = PLANS[best].cost_at(samples_per_point) > PLANS[r].cost_at(samples_per_point);
            let margin = if costlier { COSTLIER_OVERRIDE_MARGIN } else { OVERRIDE_MARGIN };
            Some(if best_score * margin >= s { r } else { best })
        }
        None => Some(best),
    }
}

/// `scores` without env-only sampling's where a plan with BRDF samples scores within
/// [`OVERRIDE_MARGIN`] of it.
fn without_unproven_env(scores: &[Option<f64>]) -> Vec<Option<f64>> {
    let with_brdf_samples = |c: usize| {
        matches!(PLANS[c].strategy, Strategy::Mis { .. } | Strategy::ProductMis { .. } | Strategy::TwoLevelMis { .. })
    };
    let best_with_brdf_samples =
        scores.iter().enumerate().filter(|&(c, _)| with_brdf_samples(c)).filter_map(|(_, s)| *s).reduce(f64::min);
    scores
        .iter()
        .enumerate()
        .map(|(c, &s)| match (PLANS[c].strategy, s, best_with_brdf_samples) {
            (Strategy::Env, Some(e), Some(b)) if e * OVERRIDE_MARGIN >= b => None,
            _ => s,
        })
        .collect()
}

/// Per candidate of [`PLANS`], relative variance × cost from its pixel pairs (`measured`: the
/// candidates that ran and their pairs per pixel), or `None` when it did not run or its mean
/// over the pilot pixels disagrees with the median candidate's by more than its own noise
/// allows (a candidate that missed a rare bright sample in every pilot pixel looks noiseless).
pub(crate) fn score(
    measured: &[(usize, &[[[f64; 3]; 2]])],
    pixels: usize,
    samples_per_point: usize,
) -> Vec<Option<f64>> {
    let values: Vec<&[[[f64; 3]; 2]]> = measured.iter().map(|m| m.1).collect();
    // Per pixel and channel, the mean over every candidate's two values: the normaliser.
    let reference: Vec<[f64; 3]> = (0..pixels)
        .map(|p| {
            let mut r = [0.0; 3];
            for v in &values {
                for (ch, r) in r.iter_mut().enumerate() {
                    *r += (v[p][0][ch] + v[p][1][ch]) / (2 * values.len()) as f64;
                }
            }
            r
        })
        .collect();
    let totals: Vec<f64> = values.iter().map(|v| v.iter().flatten().flatten().sum::<f64>()).collect();
    let mut sorted = totals.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let mut scores = vec![None; PLANS.len()];
    for ((v, &total), &(c, _)) in values.iter().zip(&totals).zip(measured) {
        let cost = PLANS[c].cost_at(samples_per_point);
        scores[c] = {
            let (mut rel, mut spread) = (0.0, 0.0);
            for (pair, r) in v.iter().zip(&reference) {
                for ch in 0..3 {
                    let d = pair[0][ch] - pair[1][ch];
                    // Var of one value ≈ d²/2; relMSE's denominator.
                    rel += d * d / 2.0 / (r[ch] * r[ch] + 0.01);
                    spread += d * d / 2.0;
                }
            }
            // The total's standard error from the pairs (2 values × 3 channels per pixel).
            let se = (2.0 * spread).sqrt();
            let trusted = total.is_finite() && (total - median).abs() <= 0.05 * median.abs() + 4.0 * se;
            trusted.then_some(rel / (3 * pixels) as f64 * cost)
        };
    }
    scores
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `pixels` pixel pairs per candidate: value ± spread/2 around `mean` (grey).
    fn pairs(mean: f64, spread: f64, pixels: usize) -> Vec<[[f64; 3]; 2]> {
        (0..pixels)
            .map(|p| {
                let s = if p % 2 == 0 { spread } else { -spread };
                [[mean + s / 2.0; 3], [mean - s / 2.0; 3]]
            })
            .collect()
    }

    #[test]
    fn the_quietest_plan_per_cost_scores_lowest_and_a_plan_that_missed_the_light_is_not_trusted() {
        let n = 16;
        // In PLANS' order: env, brdf, mis, mis 3:1, product-mis, product-mis 3:1, two-level-mis.
        let values = [
            pairs(1.0, 0.5, n),
            pairs(0.02, 0.001, n), // BRDF samples that never found the sun: quiet and wrong
            pairs(1.0, 0.2, n),
            pairs(1.0, 0.1, n),
            pairs(1.0, 0.1, n),
            pairs(1.0, 0.3, n),
        ];
        let measured: Vec<(usize, &[[[f64; 3]; 2]])> = values.iter().map(|v| v.as_slice()).enumerate().collect();
        let s = score(&measured, n, 4);
        assert!(s[1].is_none(), "{s:?}");
        let s: Vec<f64> = s.iter().map(|s| s.unwrap_or(f64::INFINITY)).collect();
        // Equal variance, cheaper: MIS 3:1 before product-MIS.
        assert!(s[3] < s[4] && s[4] < s[2] && s[2] < s[0] && s[5] < s[0], "{s:?}");
        // A value's variance d²/2 over relMSE's r² + 0.01, r the mean of all candidates, times
        // the plan's cost.
        let r = (5.0 + 0.02) / 6.0;
        let expected = 0.1f64.powi(2) / 2.0 / (r * r + 0.01) * PLANS[3].cost;
        assert!((s[3] / expected - 1.0).abs() < 1e-12, "{} vs {expected}", s[3]);
    }

    #[test]
    fn the_rules_plan_stands_unless_another_is_measured_better_by_the_margin() {
        // In PLANS' order: env, brdf, mis, mis 3:1, product-mis, product-mis 3:1, two-level-mis.
        let scores = [Some(4.0), None, Some(9.0), Some(5.1), None, Some(5.2)];
        assert_eq!(decide(&scores, Some(3), 4), Some(0), "5.1 against 4.0: overridden");
        let scores = [Some(4.0), None, Some(9.0), Some(5.1), None, Some(4.9)];
        assert_eq!(decide(&scores, Some(5), 4), Some(5), "4.9 against 4.0: kept");
        let close = [Some(4.5), None, Some(9.0), Some(5.6), None, None];
        assert_eq!(decide(&close, Some(3), 4), Some(3), "5.6 against 4.5: kept");
        let clear = [Some(4.0), None, Some(9.0), Some(5.6), None, None];
        // Product-MIS costs more than MIS: it replaces the rule's MIS only when twice as good.
        let product = [None, None, Some(9.0), None, Some(5.0), None];
        assert_eq!(decide(&product, Some(2), 4), Some(2), "5.0 against 9.0, costlier: kept");
        let product = [None, None, Some(9.0), None, Some(4.4), None];
        assert_eq!(decide(&product, Some(2), 4), Some(4), "4.4 against 9.0, costlier: overridden");
        // MIS costs less than product-MIS: it replaces the rule's product-MIS at the lower margin.
        let cheaper = [None, None, Some(5.0), None, Some(6.5), None];
        assert_eq!(decide(&cheaper, Some(4), 4), Some(2), "5.0 against 6.5, cheaper: overridden");
        assert_eq!(decide(&clear, Some(1), 4), Some(0), "the rule's plan not trusted: the best");
        assert_eq!(decide(&clear, None, 4), Some(0), "no rule: the best");
        assert_eq!(decide(&[None; 7], Some(2), 4), None);
        // Two-level-MIS, built per shading point, costs more than MIS at any split: it
        // replaces the rule's MIS only when twice as good.
        let two_level = [None, None, Some(9.0), None, None, None, Some(5.0)];
        assert_eq!(decide(&two_level, Some(2), 16), Some(2), "5.0 against 9.0, costlier: kept");
        let two_level = [None, None, Some(9.0), None, None, None, Some(4.4)];
        assert_eq!(decide(&two_level, Some(2), 16), Some(6), "4.4 against 9.0, costlier: overridden");
    }

    #[test]
    fn env_only_sampling_must_beat_every_plan_with_brdf_samples_by_the_margin() {
        // In PLANS' order: env, brdf, mis, mis 3:1, product-mis, product-mis 3:1, two-level-mis.
        // A diffuse ground under a low sun: env looks 1.2× better than MIS in the pilot, and
        // MIS 1:1 1.4× better than the rule's MIS 3:1.
        let ground = [Some(2.1), None, Some(2.5), Some(3.5), Some(5.5), None, None];
        assert_eq!(decide(&ground, Some(3), 4), Some(2), "MIS 1:1, not env");
        assert_eq!(without_unproven_env(&ground)[0], None);
        // Clearly ahead of every plan with BRDF samples, env sampling replaces the rule's plan.
        let open_sky = [Some(2.1), None, Some(5.0), Some(3.5), Some(5.5), None, None];
        assert_eq!(decide(&open_sky, Some(3), 4), Some(0));
        // A product-MIS plan within the margin also holds env sampling back.
        let glossy = [Some(2.1), None, Some(5.0), Some(3.5), Some(2.4), None, None];
        assert_eq!(decide(&glossy, Some(3), 4), Some(3), "env held back; product-MIS costlier, not 2× better");
        // Without any plan with BRDF samples scored, env sampling stands on its own score.
        let alone = [Some(2.1), Some(9.0), None, None, None, None, None];
        assert_eq!(decide(&alone, Some(1), 4), Some(0));
    }
}
