//! Structured importance sampling (Agarwal, Ramamoorthi, Belongie & Jensen, "Structured
//! importance sampling of environment maps", SIGGRAPH 2003): the environment stratified once
//! into N strata, each shaded as one directional light carrying the radiance integrated over
//! it (the paper's pre-integrated strata).
//!
//! The stratification follows the paper's hierarchical thresholding:
//! * the map's cells (a level of the equal-area pyramid, at most [`MAX_STRATIFY_LEVEL`], every
//!   cell the same solid angle) are cut into [`LAYERS`] layers by thresholds on their intensity
//!   at multiples of its standard deviation σ (t_j = j·σ);
//! * layer j receives a number of strata ∝ its structured importance Γ = L̄ⱼ^a · Δωⱼ^b (a = 1,
//!   b = ¼: [`IMPORTANCE_A`], [`IMPORTANCE_B`]), L̄ⱼ its mean intensity and Δωⱼ its solid angle;
//! * from the brightest layer down, each layer's centres are placed by the Hochbaum–Shmoys
//!   farthest-point rule over every cell at least as bright as the layer's threshold, starting
//!   from the centres already placed (so brighter layers keep theirs and the dimmer ones fill
//!   the space between them), the first centre at the brightest cell;
//! * every cell then belongs to its nearest centre (a Voronoi partition of the sphere), so the
//!   strata cover the map exactly once.
//!
//! A stratum's light is the integral of the finest level's radiance over its cells (∫ L dω, the
//! irradiance it delivers to a surface facing it), in the direction of the stratum's
//! luminance-weighted mean (the paper places it at the centre; the mean is the point that
//! makes a stratum's first moment exact). Directions are fixed: the estimate it gives is
//! deterministic and biased wherever the BRDF × cosine × visibility varies inside a stratum.
//!
//! Everything is built into caller buffers: [`cells_len`] cells of scratch, and N strata.

use crate::cell::Cell;
use crate::env::{EnvHierarchy, luminance};
use crate::estimator::luminance64;
use glam::{DVec3, Vec2, Vec3};

/// The sphere's solid angle, 4π.
const FULL_SPHERE: f64 = 4.0 * core::f64::consts::PI;

/// The paper's default number of strata.
pub const DEFAULT_LIGHTS: usize = 300;

/// Layers of the hierarchical thresholding.
pub const LAYERS: usize = 6;

/// Exponent of intensity in the structured importance Γ = L^a · Δω^b.
pub const IMPORTANCE_A: f64 = 1.0;

/// Exponent of solid angle in Γ (the paper's ¼: between importance sampling, 0, and area
/// stratification, 1).
pub const IMPORTANCE_B: f64 = 0.25;

/// The finest level the stratification works at (256 × 256 cells, about 0.8° each): the
/// farthest-point placement costs N × cells.
pub const MAX_STRATIFY_LEVEL: u32 = 8;

/// One stratum: a directional light.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Stratum {
    /// Unit world direction towards the light.
    pub dir: Vec3,
    /// The radiance integrated over the stratum's solid angle (RGB): the irradiance it
    /// delivers to a surface facing `dir`.
    pub irradiance: DVec3,
    /// The stratum's solid angle (steradians).
    pub solid_angle: f64,
}

/// Why strata cannot be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SisError {
    /// N is zero.
    NoStrata,
    /// A buffer is shorter than [`build_strata`] needs.
    BufferTooSmall,
}

/// The level the strata of `env` are built at.
#[must_use]
pub fn stratify_level(env: &EnvHierarchy<'_>) -> u32 {
    env.finest_level().min(MAX_STRATIFY_LEVEL)
}

/// Cells of scratch (`dirs`, `intensity`, `nearest`, `labels`) [`build_strata`] needs for
/// `env`.
#[must_use]
pub fn cells_len(env: &EnvHierarchy<'_>) -> usize {
    1 << (2 * stratify_level(env))
}

/// The caller's buffers of a stratification: per cell ([`cells_len`]) its direction, its
/// intensity, the cosine to its nearest centre, and its stratum; per stratum (N) its light.
pub struct SisBuffers<'a> {
    /// Per cell: its centre's world direction.
    pub dirs: &'a mut [Vec3],
    /// Per cell: its intensity relative to the map's mean.
    pub intensity: &'a mut [f32],
    /// Per cell: the cosine of the angle to its nearest centre.
    pub nearest: &'a mut [f32],
    /// Per cell (row-major): the stratum it belongs to.
    pub labels: &'a mut [u32],
    /// Per stratum: its light. Its length is N.
    pub strata: &'a mut [Stratum],
}

/// Stratifies `env` into at most `buffers.strata.len()` strata (fewer only where the map has
/// fewer cells, or fewer lit cells than a layer asks for); returns how many. A black map gives
/// strata of zero irradiance.
pub fn build_strata(env: &EnvHierarchy<'_>, buffers: SisBuffers<'_>) -> Result<usize, SisError> {
    let SisBuffers { dirs, intensity, nearest, labels, strata } = buffers;
    let n = strata.len();
    if n == 0 {
        return Err(SisError::NoStrata);
    }
    let level = stratify_level(env);
    let side = 1u32 << level;
    let m = (side * side) as usize;
    if dirs.len() < m || intensity.len() < m || nearest.len() < m || labels.len() < m {
        return Err(SisError::BufferTooSmall);
    }
    let (dirs, nearest, labels) = (&mut dirs[..m], &mut nearest[..m], &mut labels[..m]);
    let intensity = &mut intensity[..m];
    let inv = 1.0 / side as f32;
    for (k, (d, l)) in dirs.iter_mut().zip(intensity.iter_mut()).enumerate() {
        let (x, y) = (k as u32 % side, k as u32 / side);
        *d = env.dir_of(Vec2::new((x as f32 + 0.5) * inv, (y as f32 + 0.5) * inv));
        *l = env.node_relative(Cell::new(level, x, y));
    }
    nearest.iter_mut().for_each(|c| *c = -2.0);
    let sigma = std_dev(intensity);
    let quotas = layer_quotas(intensity, n, sigma);
    let mut centres = 0usize;
    let mut carry = 0usize;
    for j in (0..LAYERS).rev() {
        let mut quota = quotas[j] + carry;
        let eligible = |k: usize| layer(intensity[k], sigma) >= j;
        // The first centre of a layer by a scan; the next ones found while the nearest
        // cosines are updated.
        let mut next = farthest(centres, nearest, intensity, eligible);
        while quota > 0 && centres < n {
            let Some(k) = next else { break };
            (nearest[k], labels[k]) = (CENTRE, centres as u32);
            let c = dirs[k];
            let mut best: Option<(f32, usize)> = None;
            for (i, d) in dirs.iter().enumerate() {
                let cos = d.dot(c);
                if cos > nearest[i] {
                    (nearest[i], labels[i]) = (cos, centres as u32);
                }
                if nearest[i] < CENTRE && best.is_none_or(|(b, _)| nearest[i] < b) && eligible(i) {
                    best = Some((nearest[i], i));
                }
            }
            next = best.map(|(_, i)| i);
            strata[centres] = Stratum { dir: c, ..Stratum::default() };
            centres += 1;
            quota -= 1;
        }
        carry = quota;
    }
    integrate(env, level, labels, &mut strata[..centres]);
    Ok(centres)
}

/// The standard deviation of the cells' intensities.
fn std_dev(intensity: &[f32]) -> f32 {
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for &l in intensity {
        s += l as f64;
        s2 += l as f64 * l as f64;
    }
    let m = intensity.len() as f64;
    let mean = s / m;
    libm::sqrt((s2 / m - mean * mean).max(0.0)) as f32
}

/// The layer of a cell of intensity `l`: ⌊l/σ⌋, at most the last.
fn layer(l: f32, sigma: f32) -> usize {
    if sigma > 0.0 { ((l / sigma) as usize).min(LAYERS - 1) } else { 0 }
}

/// Strata per layer: N in proportion to each layer's Γ = L̄^a Δω^b, by largest remainders.
fn layer_quotas(intensity: &[f32], n: usize, sigma: f32) -> [usize; LAYERS] {
    let m = intensity.len();
    let (mut count, mut sum) = ([0usize; LAYERS], [0.0f64; LAYERS]);
    for &l in intensity {
        let j = layer(l, sigma);
        count[j] += 1;
        sum[j] += l as f64;
    }
    let cell_solid_angle = FULL_SPHERE / m as f64;
    let mut gamma = [0.0f64; LAYERS];
    for j in 0..LAYERS {
        if count[j] > 0 {
            let mean = sum[j] / count[j] as f64;
            let omega = count[j] as f64 * cell_solid_angle;
            gamma[j] = libm::pow(mean, IMPORTANCE_A) * libm::pow(omega, IMPORTANCE_B);
        }
    }
    let total: f64 = gamma.iter().sum();
    let mut quotas = [0usize; LAYERS];
    if total.is_nan() || total <= 0.0 {
        quotas[0] = n;
        return quotas;
    }
    let mut given = 0;
    let mut remainders = [0.0f64; LAYERS];
    for j in 0..LAYERS {
        let share = n as f64 * gamma[j] / total;
        quotas[j] = share as usize;
        remainders[j] = share - quotas[j] as f64;
        given += quotas[j];
    }
    while given < n {
        let j = (0..LAYERS).fold(0, |best, j| if remainders[j] > remainders[best] { j } else { best });
        quotas[j] += 1;
        remainders[j] = -1.0;
        given += 1;
    }
    quotas
}

/// The nearest-centre cosine that marks a centre (above any cosine).
const CENTRE: f32 = 2.0;

/// The next centre among the cells `eligible` holds for: the first centre at the brightest
/// cell, then the cell farthest from every centre so far (the smallest cosine to its nearest;
/// the lowest index among equals). `None` where every eligible cell is a centre.
fn farthest(placed: usize, nearest: &[f32], intensity: &[f32], eligible: impl Fn(usize) -> bool) -> Option<usize> {
    let mut best: Option<(f32, usize)> = None;
    for (k, &cos) in nearest.iter().enumerate() {
        if cos >= CENTRE || !eligible(k) {
            continue;
        }
        // Before any centre, the brightest cell is the farthest.
        let key = if placed == 0 { -intensity[k] } else { cos };
        if best.is_none_or(|(b, _)| key < b) {
            best = Some((key, k));
        }
    }
    best.map(|(_, k)| k)
}

/// Each stratum's light: the finest level's radiance × solid angle summed over its texels,
/// towards the luminance-weighted mean of their directions (its centre where it is dark).
fn integrate(env: &EnvHierarchy<'_>, level: u32, labels: &[u32], strata: &mut [Stratum]) {
    let (side, shift) = (env.resolution(), env.finest_level() - level);
    let texel_solid_angle = FULL_SPHERE / (side as f64 * side as f64);
    let inv = 1.0 / side as f32;
    let stratum_of = |x: u32, y: u32| labels[((y >> shift) << level | (x >> shift)) as usize] as usize;
    for y in 0..side {
        for x in 0..side {
            let s = &mut strata[stratum_of(x, y)];
            s.irradiance += env.radiance_texel(x, y).as_dvec3() * texel_solid_angle;
            s.solid_angle += texel_solid_angle;
        }
    }
    // The mean direction accumulates in `dir`, each texel weighted by its share of the
    // stratum's luminance (so the sum stays within the unit ball, exact enough in f32).
    let lit = |s: &Stratum| luminance64(s.irradiance) > 0.0;
    strata.iter_mut().filter(|s| lit(s)).for_each(|s| s.dir = Vec3::ZERO);
    for y in 0..side {
        for x in 0..side {
            let l = luminance(env.radiance_texel(x, y)) as f64;
            let s = &mut strata[stratum_of(x, y)];
            if l > 0.0 && lit(s) {
                let d = env.dir_of(Vec2::new((x as f32 + 0.5) * inv, (y as f32 + 0.5) * inv));
                s.dir += d * (l * texel_solid_angle / luminance64(s.irradiance)) as f32;
            }
        }
    }
    for s in strata.iter_mut().filter(|s| lit(s)) {
        s.dir = s.dir.try_normalize().unwrap_or(Vec3::Z);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::env::{build_pyramid, pyramid_len};
    use crate::mapping::square_to_sphere;
    use std::vec;
    use std::vec::Vec;

    /// An equal-area map of level `level` from a function of the map's directions.
    fn map(level: u32, radiance: impl Fn(Vec3) -> Vec3) -> (Vec<f32>, Vec<[f32; 3]>) {
        let side = 1u32 << level;
        let rgb: Vec<[f32; 3]> = (0..side * side)
            .map(|k| {
                let uv = Vec2::new(((k % side) as f32 + 0.5) / side as f32, ((k / side) as f32 + 0.5) / side as f32);
                radiance(square_to_sphere(uv)).to_array()
            })
            .collect();
        let mut pyramid = vec![0.0; pyramid_len(level)];
        build_pyramid(level, &rgb, &mut pyramid).unwrap();
        (pyramid, rgb)
    }

    fn strata(env: &EnvHierarchy<'_>, n: usize) -> (Vec<Stratum>, Vec<u32>) {
        let m = cells_len(env);
        let (mut dirs, mut nearest, mut labels) = (vec![Vec3::ZERO; m], vec![0.0; m], vec![0u32; m]);
        let mut intensity = vec![0.0f32; m];
        let mut strata = vec![Stratum::default(); n];
        let buffers = SisBuffers {
            dirs: &mut dirs,
            intensity: &mut intensity,
            nearest: &mut nearest,
            labels: &mut labels,
            strata: &mut strata,
        };
        let count = build_strata(env, buffers).unwrap();
        strata.truncate(count);
        (strata, labels)
    }

    /// A sky that brightens upwards, with a small sun.
    fn sky(d: Vec3) -> Vec3 {
        let sun = Vec3::new(0.3, 0.2, 0.93).normalize();
        Vec3::new(1.0, 1.2, 1.5) * (1.2 + d.z) + if d.dot(sun) > 0.998 { Vec3::splat(2.0e3) } else { Vec3::ZERO }
    }

    #[test]
    fn strata_cover_the_map_once_and_carry_its_integral() {
        let (pyramid, rgb) = map(7, sky);
        let env = EnvHierarchy::new(7, &pyramid, &rgb).unwrap();
        let (strata, labels) = strata(&env, 300);
        assert_eq!(strata.len(), 300);
        // Every cell in exactly one stratum (one label each, in range), every stratum non-empty.
        assert!(labels.iter().all(|&l| (l as usize) < strata.len()));
        let mut cells = vec![0usize; strata.len()];
        labels.iter().for_each(|&l| cells[l as usize] += 1);
        assert!(cells.iter().all(|&c| c > 0), "a stratum holds at least its centre");
        let omega: f64 = strata.iter().map(|s| s.solid_angle).sum();
        assert!((omega - 4.0 * core::f64::consts::PI).abs() < 1e-9, "{omega}");
        let texel = 4.0 * core::f64::consts::PI / rgb.len() as f64;
        let integral: DVec3 = rgb.iter().map(|c| Vec3::from_array(*c).as_dvec3() * texel).sum();
        let sum: DVec3 = strata.iter().map(|s| s.irradiance).sum();
        assert!((sum - integral).abs().max_element() < 1e-9 * integral.max_element(), "{sum} vs {integral}");
        assert!(strata.iter().all(|s| (s.dir.length() - 1.0).abs() < 1e-5));
        // The sun's layer gets strata of its own: more than its share of the sphere's area.
        let sun = Vec3::new(0.3, 0.2, 0.93).normalize();
        let near_sun = strata.iter().filter(|s| s.dir.dot(sun) > 0.99).count();
        assert!(near_sun >= 3, "{near_sun} strata near the sun");
    }

    #[test]
    fn a_lambert_plane_under_a_smooth_map_matches_quadrature_within_the_stated_bias() {
        let (pyramid, rgb) = map(7, |d| Vec3::new(1.0, 0.8, 0.6) * (1.5 + d.z + 0.5 * d.x * d.y));
        let env = EnvHierarchy::new(7, &pyramid, &rgb).unwrap();
        let (strata, _) = strata(&env, DEFAULT_LIGHTS);
        // Reflected radiance of a white Lambert plane: 1/π ∫ L cos⁺ dω. The quadrature splits
        // each texel 4 × 4 so that cos⁺ is integrated finer than the map is constant.
        let side = env.resolution();
        for n in [Vec3::Z, Vec3::X, Vec3::new(0.3, -0.5, -0.8).normalize()] {
            let mut exact = 0.0f64;
            let sub = 4;
            for y in 0..side * sub {
                for x in 0..side * sub {
                    let uv = Vec2::new((x as f32 + 0.5) / (side * sub) as f32, (y as f32 + 0.5) / (side * sub) as f32);
                    let l = luminance(env.radiance_at(uv)) as f64;
                    exact += l * env.dir_of(uv).dot(n).max(0.0) as f64;
                }
            }
            exact *= 4.0 / ((side * sub) as f64).powi(2);
            let sis: f64 = strata.iter().map(|s| luminance64(s.irradiance) * s.dir.dot(n).max(0.0) as f64).sum::<f64>()
                / core::f64::consts::PI;
            let bias = (sis - exact) / exact;
            // The stated bias of 300 strata on a smooth map (docs/renderer.md, "sis").
            assert!(bias.abs() < 2e-3, "normal {n}: sis {sis} vs quadrature {exact} ({bias:+.2e})");
        }
    }

    #[test]
    fn bad_requests_are_errors_and_small_maps_give_fewer_strata() {
        let (pyramid, rgb) = map(2, sky);
        let env = EnvHierarchy::new(2, &pyramid, &rgb).unwrap();
        let (strata, labels) = strata(&env, 100);
        assert_eq!((strata.len(), labels.len()), (16, 16), "one stratum per cell at most");
        let (mut d, mut c, mut l) = (vec![Vec3::ZERO; 16], vec![0.0; 16], vec![0; 16]);
        let mut i = vec![0.0f32; 16];
        let empty = SisBuffers { dirs: &mut d, intensity: &mut i, nearest: &mut c, labels: &mut l, strata: &mut [] };
        assert_eq!(build_strata(&env, empty), Err(SisError::NoStrata));
        let mut one = [Stratum::default()];
        let short =
            SisBuffers { dirs: &mut d[..3], intensity: &mut i, nearest: &mut c, labels: &mut l, strata: &mut one };
        assert_eq!(build_strata(&env, short), Err(SisError::BufferTooSmall));
    }
}
