//! `auto`'s choice of method per material, checked on the scene: a pilot render of a few of
//! each material's pixels with every candidate plan, twice with independent samples, at the
//! render's own spp and shading points, scored by variance × cost — the variance from the
//! pixel pairs' squared differences (relMSE's normalisation), the cost a fixed per-sample
//! weight per plan measured once (`PLANS`), not the pilot's clock, so that the choice, and the
//! image, depend only on the scene, the settings and the seed. The pilot's samples are
//! independent of the render's (their own seeds), so choosing from them keeps every pixel's
//! estimate unbiased.
//!
//! The pilot overrides the rule-based plan (`Method::for_material`, measured on five scenes)
//! only when another plan scores [`OVERRIDE_MARGIN`]× better: a variance estimate from tens
//! of pixel pairs is dominated by its few brightest pixels and is good to tens of per cent
//! at best (seeds 0–2 on s2: product-MIS 3:1 against MIS on the α = 0.1 sphere scored 54 /
//! 45, 13 / 25 and 15 / 22), while an env map whose light is unlike those five scenes' makes
//! a plan win by several times (studio's diffuse walls: env sampling 3.7× ahead of the rule's
//! MIS 3:1).
//!
//! A pilot cannot see rare large samples it did not draw: BRDF sampling under a sun looks quiet
//! in a pilot that never hit the sun, and then leaves fireflies across the image. So only plans
//! whose sample weights are bounded for the material and lighting compete ([`eligible`]): the
//! MIS plans always (each sample is weighted against a technique that covers the light), env
//! sampling where B·cos is bounded (its weight is B·cos × the map's total power), BRDF sampling
//! where the lighting is (its weight is L × B·cos/p). And each MIS method competes with the
//! rules' split only: the splits differ by less than the pilot can tell apart
//! ([`OVERRIDE_MARGIN`]), and every candidate fewer leaves more pixels for the others.

use crate::integrator::{Method, SMOOTH_LIGHTING_PEAK, auto_env_share, product_share};
use crate::render::{MaterialPlan, Scratch, Settings, pixel};
use crate::scene::{Bsdf, Scene};
use crate::trace::bvh::Bvh;
use crate::trace::camera::Camera;
use rayon::prelude::*;
use sampler_core::env::EnvHierarchy;
use sampler_core::points::permutation_element;
use sampler_core::rng::hash_combine;

/// The candidates: method, share of the first technique (see `MaterialPlan::split`), and the
/// time per visibility sample relative to MIS's pairs (`ppis render --method M --spp 1024
/// --shading-points 64 --threads 1`, 128², mean over the default scene, s1, s2, s3 and studio
/// of the faster of two runs: env 1.09–1.30, BRDF 0.67–0.77, product-MIS 1.45–1.84; the 3:1
/// splits from those per-sample costs and the measured 1.15× of product-MIS at 3:1;
/// docs/perf.md, session 9).
pub const PLANS: [(Method, f64, f64); 6] = [
    (Method::Env, 0.5, 1.15),
    (Method::Brdf, 0.5, 0.72),
    (Method::Mis, 0.5, 1.0),
    (Method::Mis, 0.75, 1.04),
    (Method::ProductMis, 0.5, 1.68),
    (Method::ProductMis, 0.75, 1.93),
];

/// How much better than the rule's plan another must score to replace it.
pub const OVERRIDE_MARGIN: f64 = 2.0;

/// Share of the render's work (in MIS pixels, the candidates weighted by their cost) the pilot
/// aims to spend, both repetitions of every candidate, and the most it may spend: with fewer
/// than [`MIN_PIXELS`] per material within that, the rules decide alone. (At 4% of the pixels
/// and every split a candidate, the default scene, whose plans the pilot keeps, measured 15%
/// behind MIS at equal time: its error falls faster than 1/t there.)
const PILOT_SHARE: f64 = 0.02;
const MAX_PILOT_SHARE: f64 = 0.05;

/// Pilot pixels per material: fewer and the scores are noise (8 pixels on a 48² studio: the
/// diffuse floor's plan changed with every seed), more and the pilot costs too much.
const MIN_PIXELS: usize = 32;
const MAX_PIXELS: usize = 64;

/// Largest BRDF × cos peak (per steradian) for which env-only sampling may compete: GGX α ≥
/// 0.14, Phong n ≤ 98 (Lambert: 1/π).
const ENV_ONLY_LOBE_PEAK: f32 = 16.0;

/// Pixels looked at (centre rays) to find each material's pilot pixels.
const MAX_SCANNED: usize = 1 << 14;

/// What the pilot measured for one material.
#[derive(Clone, Debug)]
pub struct PilotResult {
    pub material: usize,
    /// Pilot pixels (each rendered twice per candidate).
    pub pixels: usize,
    /// Per candidate of [`PLANS`]: relative variance × cost (`None`: not trusted — its pilot
    /// mean disagrees with the others', the sign of rare large samples it missed).
    pub scores: Vec<Option<f64>>,
    /// The index into [`PLANS`] chosen.
    pub chosen: usize,
    /// The rule's plan (`Method::for_material`), if it is one of [`PLANS`].
    pub rule: Option<usize>,
}

/// Whether candidate `c` of [`PLANS`] may compete on `bsdf` under a map of peak `env_peak`
/// (`EnvHierarchy::peak(5)`): see the module's note.
#[must_use]
pub fn eligible(c: usize, bsdf: &Bsdf, env_peak: f32) -> bool {
    let (method, split, _) = PLANS[c];
    match method {
        Method::Env => {
            let peak = match bsdf {
                Bsdf::Diffuse(_) => std::f32::consts::FRAC_1_PI,
                Bsdf::Conductor(g) => 1.0 / (std::f32::consts::PI * g.ggx.alpha() * g.ggx.alpha()),
                Bsdf::Phong(p) => (p.exponent + 2.0) / (2.0 * std::f32::consts::PI),
                Bsdf::CarPaint(_) => f32::INFINITY,
            };
            peak <= ENV_ONLY_LOBE_PEAK
        }
        Method::Brdf => env_peak < SMOOTH_LIGHTING_PEAK,
        Method::Mis => split == auto_env_share(bsdf, env_peak),
        Method::ProductMis => split == product_share(bsdf, env_peak),
        _ => false,
    }
}

/// Runs the pilot and returns the plans (one per material; `defaults` where a material has too
/// few pixels to measure) and what was measured.
#[allow(clippy::too_many_arguments)]
pub(crate) fn choose(
    scene: &Scene,
    bvh: &Bvh,
    env: &EnvHierarchy<'_>,
    camera: &Camera,
    settings: &Settings,
    defaults: &[MaterialPlan],
    env_peak: f32,
) -> (Vec<MaterialPlan>, Vec<PilotResult>) {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let materials = scene.materials.len();
    // Each material's pixels, in a fixed pseudo-random order over the image.
    let mut found: Vec<Vec<(usize, usize)>> = vec![Vec::new(); materials];
    let n = w * h;
    let order_seed = hash_combine(settings.seed, 0x9170) as u32;
    for k in 0..n.min(MAX_SCANNED) {
        let i = permutation_element(k as u32, n as u32, order_seed) as usize;
        let (x, y) = (i % w, i / w);
        let d = camera.direction(x as f32 + 0.5, y as f32 + 0.5);
        if let Some(hit) = bvh.intersect(camera.origin, d, camera.near_clip, f32::INFINITY) {
            found[hit.material as usize].push((x, y));
        }
    }
    // Every (material, candidate) to measure, and the cost of one pilot pixel of all of them,
    // twice.
    let tasks: Vec<(usize, usize)> = (0..materials)
        .filter(|&m| found[m].len() >= MIN_PIXELS)
        .flat_map(|m| {
            (0..PLANS.len()).filter(move |&c| eligible(c, &scene.materials[m].bsdf, env_peak)).map(move |c| (m, c))
        })
        .collect();
    let cost_per_pixel: f64 = tasks.iter().map(|&(_, c)| 2.0 * PLANS[c].2).sum();
    let per_material = ((PILOT_SHARE * n as f64 / cost_per_pixel.max(1.0)) as usize).clamp(MIN_PIXELS, MAX_PIXELS);
    if per_material as f64 * cost_per_pixel > MAX_PILOT_SHARE * n as f64 {
        return (defaults.to_vec(), Vec::new());
    }
    for f in &mut found {
        f.truncate(per_material);
    }
    // Every task renders its pixels twice, in parallel; the values come back in a fixed order
    // whatever the thread count (truncating kept every measured material at ≥ MIN_PIXELS).
    // One job per (task, pixel), so that the threads share the work evenly.
    let jobs: Vec<(usize, (usize, usize))> =
        tasks.iter().enumerate().flat_map(|(t, &(m, _))| found[m].iter().map(move |&p| (t, p))).collect();
    let rendered: Vec<[[f64; 3]; 2]> = jobs
        .par_iter()
        .map(|&(t, (x, y))| {
            let (m, c) = tasks[t];
            let mut plans: Vec<MaterialPlan> = defaults.to_vec();
            let (method, split, _) = PLANS[c];
            plans[m] = MaterialPlan { method, split, ..defaults[m] };
            [0u64, 1].map(|rep| {
                let s = Settings { seed: hash_combine(settings.seed, 0x9170_0000 + rep), ..*settings };
                // A fresh scratch: no product sampler carried over from another pixel or
                // repetition (that would correlate the pair).
                let mut scratch = Scratch::new(materials, s.shading_points);
                pixel(scene, bvh, Some(env), None, camera, &s, &plans, x, y, &mut scratch).map(f64::from)
            })
        })
        .collect();
    let mut values: Vec<Vec<[[f64; 3]; 2]>> = vec![Vec::new(); tasks.len()];
    for ((t, _), v) in jobs.iter().zip(rendered) {
        values[*t].push(v);
    }
    let mut plans = defaults.to_vec();
    let mut results = Vec::new();
    for (m, pixels) in found.iter().enumerate() {
        let measured: Vec<(usize, &[[[f64; 3]; 2]])> =
            tasks.iter().zip(&values).filter(|(t, _)| t.0 == m).map(|(t, v)| (t.1, v.as_slice())).collect();
        if measured.is_empty() {
            continue;
        }
        let scores = score(&measured, pixels.len());
        let rule = PLANS.iter().position(|p| p.0 == defaults[m].method && p.1 == defaults[m].split);
        let Some(chosen) = decide(&scores, rule) else { continue };
        let (method, split, _) = PLANS[chosen];
        plans[m] = MaterialPlan { method, split, ..defaults[m] };
        results.push(PilotResult { material: m, pixels: pixels.len(), scores, chosen, rule });
    }
    (plans, results)
}

/// The rule's plan unless another scores [`OVERRIDE_MARGIN`]× better (or the rule's was not
/// measured or not trusted: then the best); `None` when nothing was scored.
fn decide(scores: &[Option<f64>], rule: Option<usize>) -> Option<usize> {
    let (best, best_score) =
        scores.iter().enumerate().filter_map(|(c, s)| s.map(|s| (c, s))).min_by(|a, b| a.1.total_cmp(&b.1))?;
    match rule.and_then(|r| scores[r].map(|s| (r, s))) {
        Some((r, s)) if best_score * OVERRIDE_MARGIN >= s => Some(r),
        _ => Some(best),
    }
}

/// Per candidate of [`PLANS`], relative variance × cost from its pixel pairs (`measured`: the
/// candidates that ran and their pairs per pixel), or `None` when it did not run or its mean
/// over the pilot pixels disagrees with the median candidate's by more than its own noise
/// allows (a candidate that missed a rare bright sample in every pilot pixel looks noiseless).
fn score(measured: &[(usize, &[[[f64; 3]; 2]])], pixels: usize) -> Vec<Option<f64>> {
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
        let cost = PLANS[c].2;
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

/// A candidate's name: the method, and its split where it is not half and half
/// ("mis 3:1" — three env samples to one BRDF sample; "product-mis 3:1").
#[must_use]
pub fn plan_name(candidate: usize) -> String {
    let (method, split, _) = PLANS[candidate];
    if split == 0.5 {
        method.name().to_string()
    } else {
        format!("{} {}:{}", method.name(), (split * 4.0).round(), ((1.0 - split) * 4.0).round())
    }
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
        // In PLANS' order: env, brdf, mis, mis 3:1, product-mis, product-mis 3:1.
        let values = [
            pairs(1.0, 0.4, n),
            pairs(0.02, 0.001, n), // BRDF samples that never found the sun: quiet and wrong
            pairs(1.0, 0.2, n),
            pairs(1.0, 0.1, n),
            pairs(1.0, 0.1, n),
            pairs(1.0, 0.3, n),
        ];
        let measured: Vec<(usize, &[[[f64; 3]; 2]])> = values.iter().map(|v| v.as_slice()).enumerate().collect();
        let s = score(&measured, n);
        assert!(s[1].is_none(), "{s:?}");
        let s: Vec<f64> = s.iter().map(|s| s.unwrap_or(f64::INFINITY)).collect();
        // Equal variance, cheaper: MIS 3:1 before product-MIS.
        assert!(s[3] < s[4] && s[4] < s[2] && s[2] < s[0] && s[5] < s[0], "{s:?}");
        // A value's variance d²/2 over relMSE's r² + 0.01, r the mean of all candidates, times
        // the plan's cost.
        let r = (5.0 + 0.02) / 6.0;
        let expected = 0.1f64.powi(2) / 2.0 / (r * r + 0.01) * PLANS[3].2;
        assert!((s[3] / expected - 1.0).abs() < 1e-12, "{} vs {expected}", s[3]);
    }

    #[test]
    fn the_rules_plan_stands_unless_another_is_measured_twice_as_good() {
        let scores = [Some(4.0), None, Some(9.0), Some(8.1), None, Some(7.9)];
        assert_eq!(decide(&scores, Some(3)), Some(0), "8.1 against 4.0: overridden");
        assert_eq!(decide(&scores, Some(5)), Some(5), "7.9 against 4.0: kept");
        let close = [Some(4.5), None, Some(9.0), Some(7.9), None, None];
        assert_eq!(decide(&close, Some(3)), Some(3), "7.9 against 4.5: kept");
        assert_eq!(decide(&close, Some(1)), Some(0), "the rule's plan not trusted: the best");
        assert_eq!(decide(&close, None), Some(0), "no rule: the best");
        assert_eq!(decide(&[None; 6], Some(2)), None);
    }
}
