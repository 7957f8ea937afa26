//! How `auto`'s pilot turns pixel pairs into a choice: each candidate's score (relative variance
//! × cost per shading point), and the rules' plan against the best score by the margins and by
//! the scores' own standard error (`plan::pilot`'s note says why each margin is what it is).

use crate::plan::candidates::{PLANS, candidate_of};
use crate::plan::pilot::{COSTLIER_FROM, COSTLIER_OVERRIDE_MARGIN, OVERRIDE_MARGIN, SEPARATION};
use crate::render::strategy::Strategy;

/// A candidate's pilot score: relative variance × cost per shading point, the mean of its
/// per-pixel terms.
#[derive(Clone, Debug)]
pub(crate) struct Score {
    /// The mean of `terms`.
    pub value: f64,
    /// Per pilot pixel, its pair's relative variance (the mean over channels) × cost.
    terms: Vec<f64>,
}

impl Score {
    fn new(terms: Vec<f64>) -> Self {
        Self { value: terms.iter().sum::<f64>() / terms.len().max(1) as f64, terms }
    }

    /// Whether this score exceeds `better`'s by more than [`SEPARATION`] standard errors of
    /// the mean of their per-pixel differences (the candidates share their pilot pixels and
    /// film positions, so the difference is paired). A score led by a few bright pixels has a
    /// large standard error, and does not separate.
    fn above(&self, better: &Score) -> bool {
        let n = self.terms.len().min(better.terms.len());
        if n < 2 {
            return false;
        }
        let d: Vec<f64> = self.terms.iter().zip(&better.terms).map(|(a, b)| a - b).collect();
        let mean = d.iter().sum::<f64>() / n as f64;
        let var = d.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64;
        mean > SEPARATION * (var / n as f64).sqrt()
    }
}

/// The rule's plan unless another scores [`OVERRIDE_MARGIN`]× better, or
/// [`COSTLIER_OVERRIDE_MARGIN`]× where it costs more per sample than the rule's, and better by
/// [`SEPARATION`] standard errors; plain MIS, the baseline, by the margin alone (moving to the
/// baseline risks at most the rule's gain over it, which the margin says is not there);
/// env-only sampling only where it also scores [`OVERRIDE_MARGIN`]× better than every plan
/// with BRDF samples (see the module's note). Where the rule's plan was not measured or not
/// trusted, the best, unless it does not separate from plain MIS: then MIS. `None` when
/// nothing was scored.
pub(crate) fn decide(scores: &[Option<Score>], rule: Option<usize>) -> Option<usize> {
    let values = without_unproven_env(&scores.iter().map(|s| s.as_ref().map(|s| s.value)).collect::<Vec<_>>());
    let (best, best_value) =
        values.iter().enumerate().filter_map(|(c, s)| s.map(|s| (c, s))).min_by(|a, b| a.1.total_cmp(&b.1))?;
    let separated = |worse: usize, better: usize| match (&scores[worse], &scores[better]) {
        (Some(w), Some(b)) => w.above(b),
        _ => false,
    };
    let mis = candidate_of(Strategy::Mis { env_share: 0.5 }).filter(|&m| values[m].is_some());
    match rule.and_then(|r| values[r].map(|s| (r, s))) {
        Some((r, rule_value)) => {
            let margin = |c: usize| {
                let costlier = PLANS[c].cost > COSTLIER_FROM * PLANS[r].cost;
                if costlier { COSTLIER_OVERRIDE_MARGIN } else { OVERRIDE_MARGIN }
            };
            let beats_rule = |c: usize, value: f64| value * margin(c) < rule_value;
            Some(match mis.and_then(|m| values[m].map(|v| (m, v))) {
                _ if best != r && beats_rule(best, best_value) && separated(r, best) => best,
                Some((m, v)) if m != r && beats_rule(m, v) => m,
                _ => r,
            })
        }
        None => Some(match mis {
            Some(m) if m != best && !separated(m, best) => m,
            _ => best,
        }),
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

/// Per candidate of [`PLANS`], relative variance × cost per shading point from its pixel
/// pairs (`measured`: the candidates that ran and their pairs per pixel; each at its
/// [`equal_cost_budget`](crate::plan::candidates::Candidate::equal_cost_budget) of
/// `samples_per_point`), or `None` when it did not run or its mean over the pilot pixels
/// disagrees with the median candidate's by more than its own noise allows (a candidate that
/// missed a rare bright sample in every pilot pixel looks noiseless).
pub(crate) fn score(
    measured: &[(usize, &[[[f64; 3]; 2]])],
    pixels: usize,
    samples_per_point: usize,
) -> Vec<Option<Score>> {
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
        let cost = PLANS[c].cost_per_point(samples_per_point);
        let mut spread = 0.0;
        let terms: Vec<f64> = v
            .iter()
            .zip(&reference)
            .map(|(pair, r)| {
                let mut rel = 0.0;
                for ch in 0..3 {
                    let d = pair[0][ch] - pair[1][ch];
                    // Var of one value ≈ d²/2; relMSE's denominator.
                    rel += d * d / 2.0 / (r[ch] * r[ch] + 0.01);
                    spread += d * d / 2.0;
                }
                rel / 3.0 * cost
            })
            .collect();
        // The total's standard error from the pairs (2 values × 3 channels per pixel).
        let se = (2.0 * spread).sqrt();
        let trusted = total.is_finite() && (total - median).abs() <= 0.05 * median.abs() + 4.0 * se;
        scores[c] = trusted.then(|| Score::new(terms));
    }
    scores
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scores of as many pixels, each pixel's term the score.
    fn scored(values: &[Option<f64>]) -> Vec<Option<Score>> {
        values.iter().map(|v| v.map(|v| Score::new(vec![v; 16]))).collect()
    }

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
        let s: Vec<f64> = s.iter().map(|s| s.as_ref().map_or(f64::INFINITY, |s| s.value)).collect();
        // Equal variance, cheaper: MIS 3:1 before product-MIS.
        assert!(s[3] < s[4] && s[4] < s[2] && s[2] < s[0] && s[5] < s[0], "{s:?}");
        // A value's variance d²/2 over relMSE's r² + 0.01, r the mean of all candidates, times
        // the plan's cost.
        let r = (5.0 + 0.02) / 6.0;
        let expected = 0.1f64.powi(2) / 2.0 / (r * r + 0.01) * PLANS[3].cost;
        assert!((s[3] / expected - 1.0).abs() < 1e-12, "{} vs {expected}", s[3]);
        // Product-MIS at its equal-cost budget: three samples at 1.45 against MIS's four.
        let expected = 0.1f64.powi(2) / 2.0 / (r * r + 0.01) * 3.0 * PLANS[4].cost / 4.0;
        assert!((s[4] / expected - 1.0).abs() < 1e-12, "{} vs {expected}", s[4]);
    }

    #[test]
    fn a_plan_better_only_by_a_few_bright_pixels_does_not_replace_the_rule_s() {
        // In PLANS' order: env, brdf, mis, mis 3:1, product-mis, product-mis 3:1, two-level-mis.
        let steady = |v: f64| Some(Score::new(vec![v; 32]));
        let lucky = |at: f64| {
            let mut t = vec![0.0; 32];
            t[7] = 32.0 * at;
            Some(Score::new(t))
        };
        // The rule's MIS scores 2.5 on every pixel; product-MIS 1.0 on average, from one pixel.
        let scores = [None, None, steady(2.5), None, lucky(1.0), None, None];
        assert_eq!(decide(&scores, Some(2)), Some(2), "2.5× as good, but not separated");
        let scores = [None, None, steady(2.5), None, steady(1.0), None, None];
        assert_eq!(decide(&scores, Some(2)), Some(4), "2.5× as good on every pixel");
        // Towards plain MIS, the baseline, the margin alone decides.
        let scores = [None, None, lucky(1.0), steady(2.0), None, None, None];
        assert_eq!(decide(&scores, Some(3)), Some(2), "MIS 1:1 against the rule's MIS 3:1");
        let scores = [None, None, lucky(1.7), steady(2.0), None, None, None];
        assert_eq!(decide(&scores, Some(3)), Some(3), "within the margin: the rule's");
        // A plan the rule's beats by far, and MIS past the margin: MIS.
        let scores = [None, None, steady(1.5), steady(2.0), lucky(0.8), None, None];
        assert_eq!(decide(&scores, Some(3)), Some(2), "product-MIS not separated; MIS by the margin");
        // The rule's plan not trusted: plain MIS unless the best separates from it.
        let mut lucky = vec![0.5; 32];
        lucky[3] = 10.0;
        let scores = [Some(Score::new(lucky)), None, steady(1.2), None, None, None, None];
        assert_eq!(decide(&scores, Some(1)), Some(2), "env not separated from MIS: MIS");
        let scores = [steady(0.5), None, steady(1.2), None, None, None, None];
        assert_eq!(decide(&scores, Some(1)), Some(0), "env separated: env");
    }

    #[test]
    fn the_rules_plan_stands_unless_another_is_measured_better_by_the_margin() {
        // In PLANS' order: env, brdf, mis, mis 3:1, product-mis, product-mis 3:1, two-level-mis.
        let scores = [Some(4.0), None, Some(9.0), Some(5.1), None, Some(5.2)];
        assert_eq!(decide(&scored(&scores), Some(3)), Some(0), "5.1 against 4.0: overridden");
        let scores = [Some(4.0), None, Some(9.0), Some(5.1), None, Some(4.9)];
        assert_eq!(decide(&scored(&scores), Some(5)), Some(5), "4.9 against 4.0: kept");
        let close = [Some(4.5), None, Some(9.0), Some(5.6), None, None];
        assert_eq!(decide(&scored(&close), Some(3)), Some(3), "5.6 against 4.5: kept");
        let clear = [Some(4.0), None, Some(9.0), Some(5.6), None, None];
        // Product-MIS costs more than MIS: it replaces the rule's MIS only when twice as good.
        let product = [None, None, Some(9.0), None, Some(5.0), None];
        assert_eq!(decide(&scored(&product), Some(2)), Some(2), "5.0 against 9.0, costlier: kept");
        let product = [None, None, Some(9.0), None, Some(4.4), None];
        assert_eq!(decide(&scored(&product), Some(2)), Some(4), "4.4 against 9.0, costlier: overridden");
        // MIS costs less than product-MIS: it replaces the rule's product-MIS at the lower margin.
        let cheaper = [None, None, Some(5.0), None, Some(6.5), None];
        assert_eq!(decide(&scored(&cheaper), Some(4)), Some(2), "5.0 against 6.5, cheaper: overridden");
        assert_eq!(decide(&scored(&clear), Some(1)), Some(0), "the rule's plan not trusted: the best");
        assert_eq!(decide(&scored(&clear), None), Some(0), "no rule: the best");
        assert_eq!(decide(&scored(&[None; 7]), Some(2)), None);
        // Two-level-MIS costs little more per sample than MIS: it replaces the rule's MIS at the
        // lower margin, as its score carries its cost.
        let two_level = [None, None, Some(9.0), None, None, None, Some(7.5)];
        assert_eq!(decide(&scored(&two_level), Some(2)), Some(2), "7.5 against 9.0: kept");
        let two_level = [None, None, Some(9.0), None, None, None, Some(7.0)];
        assert_eq!(decide(&scored(&two_level), Some(2)), Some(6), "7.0 against 9.0: overridden");
    }

    #[test]
    fn env_only_sampling_must_beat_every_plan_with_brdf_samples_by_the_margin() {
        // In PLANS' order: env, brdf, mis, mis 3:1, product-mis, product-mis 3:1, two-level-mis.
        // A diffuse ground under a low sun: env looks 1.2× better than MIS in the pilot, and
        // MIS 1:1 1.4× better than the rule's MIS 3:1.
        let ground = [Some(2.1), None, Some(2.5), Some(3.5), Some(5.5), None, None];
        assert_eq!(decide(&scored(&ground), Some(3)), Some(2), "MIS 1:1, not env");
        assert_eq!(without_unproven_env(&ground)[0], None);
        // Clearly ahead of every plan with BRDF samples, env sampling replaces the rule's plan.
        let open_sky = [Some(2.1), None, Some(5.0), Some(3.5), Some(5.5), None, None];
        assert_eq!(decide(&scored(&open_sky), Some(3)), Some(0));
        // A product-MIS plan within the margin also holds env sampling back.
        let glossy = [Some(2.1), None, Some(5.0), Some(3.5), Some(2.4), None, None];
        assert_eq!(decide(&scored(&glossy), Some(3)), Some(3), "env held back; product-MIS costlier, not 2× better");
        // Without any plan with BRDF samples scored, env sampling stands on its own score.
        let alone = [Some(2.1), Some(9.0), None, None, None, None, None];
        assert_eq!(decide(&scored(&alone), Some(1)), Some(0));
    }
}
