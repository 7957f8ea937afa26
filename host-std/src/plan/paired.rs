//! Paired pilot renders: a few of the frame's tiles rendered twice per candidate setting, with
//! independent seeds, each candidate scored by its variance (from the pixel pairs' squared
//! differences, relMSE's normalisation) times its cost (shadow rays and shading points, counted,
//! not timed). The scores depend only on the scene, the settings and the seed, and the pilot's
//! samples are not the render's, so a render that chooses from them stays unbiased. The
//! sun's carrier (`plan::carrier`) and the light samples per shading point (`plan::split`) are
//! chosen by them.

use crate::plan::{Method, Rendered, Settings, render_crop};
use crate::render::crop::Crop;
use crate::render::tiles::TILE;
use crate::scene::Scene;
use crate::trace::bvh::Bvh;
use rayon::prelude::*;
use sampler_core::env::EnvHierarchy;
use sampler_core::estimator::luminance64;
use sampler_core::glam::Vec3;
use sampler_core::rng::hash_combine;

/// One setting a pilot measures: what it renders, and a shading point's cost in shadow rays.
pub struct PilotCandidate<'a> {
    /// The scene as this candidate renders it.
    pub scene: &'a Scene,
    /// Its environment, if any.
    pub env: Option<&'a EnvHierarchy<'a>>,
    /// Its settings (the seed is replaced per render, and `auto` renders as MIS).
    pub settings: Settings,
    /// A shading point's cost in shadow rays.
    pub point_cost: f64,
}

/// Each candidate's variance × cost over `tiles`, two renders each with seeds derived from the
/// settings' seed, `salt` and the candidate's index (lower is better).
#[must_use]
pub fn paired_scores(bvh: &Bvh, candidates: &[PilotCandidate<'_>], tiles: &[Crop], salt: u64) -> Vec<f64> {
    let indices: Vec<usize> = (0..candidates.len()).collect();
    paired_scores_at(bvh, candidates, &indices, tiles, salt)
}

/// [`paired_scores`] with the seeds of the candidates at `indices` of a call with the same
/// `salt`: a candidate that differs from that call's only in how its samples are weighed draws
/// the same samples, and the two scores differ by the weighing alone, not by their samples'
/// luck.
#[must_use]
pub fn paired_scores_at(
    bvh: &Bvh,
    candidates: &[PilotCandidate<'_>],
    indices: &[usize],
    tiles: &[Crop],
    salt: u64,
) -> Vec<f64> {
    // Every (candidate, repetition, tile) is a job of its own, so that the threads share the
    // pilot as they share the render; the results are gathered in a fixed order, so the scores
    // do not depend on the thread count.
    let settings: Vec<[Settings; 2]> = candidates
        .iter()
        .zip(indices)
        .map(|(c, &k)| {
            std::array::from_fn(|rep| Settings {
                // `auto`'s own pilot would run again in every tile's render: its MIS plans
                // stand in for it.
                method: if c.settings.method == Method::Auto { Method::Mis } else { c.settings.method },
                seed: hash_combine(hash_combine(c.settings.seed, salt), 2 * k as u64 + rep as u64),
                progress: false,
                ..c.settings
            })
        })
        .collect();
    let jobs: Vec<(usize, usize, Crop)> = (0..candidates.len())
        .flat_map(|i| (0..2).flat_map(move |rep| tiles.iter().map(move |&t| (i, rep, t))))
        .collect();
    let images: Vec<Rendered> = jobs
        .par_iter()
        .map(|&(i, rep, t)| render_crop(candidates[i].scene, bvh, candidates[i].env, &settings[i][rep], t))
        .collect();
    let mut images = images.into_iter();
    let renders: Vec<[(Vec<[f32; 3]>, f64); 2]> = candidates
        .iter()
        .map(|c| {
            std::array::from_fn(|_| {
                let mut cost = 0.0;
                let mut pixels = Vec::new();
                for image in images.by_ref().take(tiles.len()) {
                    cost += image.shadow_rays as f64 + c.point_cost * image.shading_points as f64;
                    pixels.extend(image.pixels);
                }
                (pixels, cost)
            })
        })
        .collect();
    let pairs: Vec<[&[[f32; 3]]; 2]> = renders.iter().map(|r| [&r[0].0[..], &r[1].0[..]]).collect();
    let variance = pair_scores(&pairs);
    variance.iter().zip(&renders).map(|(v, r)| v * (r[0].1 + r[1].1)).collect()
}

/// The render tiles a pilot renders: about `share` of the frame's pixels, at least one tile,
/// spread over the frame on a grid of their own (the centre tile for one).
#[must_use]
pub fn pilot_tiles(width: usize, height: usize, share: f64) -> Vec<Crop> {
    let frame = Crop::full(width, height);
    let count = ((share * (width * height) as f64 / (TILE * TILE) as f64).round() as usize).max(1);
    let columns = (count as f64).sqrt().ceil() as usize;
    let rows = count.div_ceil(columns);
    let mut tiles: Vec<Crop> = (0..count)
        .filter_map(|k| {
            let x = ((k % columns) * 2 + 1) * width / (2 * columns);
            let y = ((k / columns) * 2 + 1) * height / (2 * rows);
            let (x0, y0) = (x / TILE * TILE, y / TILE * TILE);
            Crop { x0, y0, x1: x0 + TILE, y1: y0 + TILE }.intersection(&frame)
        })
        .collect();
    tiles.dedup();
    tiles
}

/// Each candidate's variance from its two renders: the mean over pixels of the pair's halved
/// squared luminance difference over the squared mean luminance of all the renders (plus 0.01,
/// relMSE's guard against dark pixels).
fn pair_scores(renders: &[[&[[f32; 3]]; 2]]) -> Vec<f64> {
    let lum = |c: [f32; 3]| luminance64(Vec3::from(c).as_dvec3());
    let n = renders.first().map_or(0, |r| r[0].len());
    let mut scores = vec![0.0; renders.len()];
    for p in 0..n {
        let values: Vec<[f64; 2]> = renders.iter().map(|r| [lum(r[0][p]), lum(r[1][p])]).collect();
        let mean = values.iter().flatten().sum::<f64>() / (2 * renders.len()) as f64;
        let norm = mean * mean + 0.01;
        for (score, v) in scores.iter_mut().zip(&values) {
            *score += 0.5 * (v[0] - v[1]).powi(2) / norm;
        }
    }
    scores.iter().map(|s| s / n.max(1) as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pilot_tiles_are_whole_tiles_spread_over_the_frame() {
        assert_eq!(pilot_tiles(128, 128, 0.01), vec![Crop { x0: 64, y0: 64, x1: 80, y1: 80 }]);
        let tiles = pilot_tiles(1024, 512, 0.01);
        assert_eq!(tiles.len(), 20);
        assert!(tiles.iter().all(|t| t.area() == TILE * TILE && t.x0 % TILE == 0 && t.y0 % TILE == 0));
        assert!(tiles.iter().any(|t| t.x0 < 256) && tiles.iter().any(|t| t.x0 >= 768));
        assert!(tiles.iter().any(|t| t.y0 < 128) && tiles.iter().any(|t| t.y0 >= 384));
        assert_eq!(pilot_tiles(10, 6, 0.01), vec![Crop::full(10, 6)]);
    }

    #[test]
    fn scores_are_the_pairs_variance_over_the_common_mean() {
        let flat = |v: f32| vec![[v; 3]; 4];
        // First candidate: pairs 1 and 3 (variance 2 per pixel); second: pairs 2 and 2 (none).
        let first = [flat(1.0), flat(3.0)];
        let second = [flat(2.0), flat(2.0)];
        let s = pair_scores(&[[&first[0], &first[1]], [&second[0], &second[1]]]);
        let norm = 4.0 + 0.01;
        assert!((s[0] - 2.0 / norm).abs() < 1e-6 && s[1] == 0.0, "{s:?}");
    }
}
