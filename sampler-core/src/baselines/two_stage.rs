//! Two-stage importance sampling (after Cline, Egbert, Talbot & Cardon 2006), the paper's main
//! comparison. Only the published abstract was available to us; this is a reconstruction:
//!
//! * a summed-area table (SAT) of the environment's importance at the finest level gives the
//!   integral of L over any texel-aligned rectangle of the equal-area square in O(1);
//! * per shading point the square is partitioned into at most `R` rectangles driven by the
//!   BRDF: first split at the texel of the BRDF's peak (the mirror direction, or the normal for
//!   a diffuse BRDF), then repeatedly split the rectangle with the largest weight × BRDF
//!   variation across its longer side;
//! * each rectangle's B̃ is the mean of B·cos at its centre and four corners (piecewise
//!   constant; Cline et al. use a piecewise-linear approximation), floored at 1e-3 of the
//!   largest so that every rectangle where L > 0 keeps a positive weight (unbiasedness);
//! * stage 1 picks a rectangle ∝ B̃ × ∫L; stage 2 picks a texel inside it ∝ L — a column by
//!   bisection on the SAT's column sums, then a row — and a point uniformly in the texel.
//!
//! The density of a direction is (w_r / Σw) · L_texel / ∫_r L per texel. The SAT is a
//! caller-owned `f64` buffer of (N+1)² values (8 bytes per texel: built only when a render uses
//! this method).

use crate::brdf::Brdf;
use crate::cell::Cell;
use crate::env::{EnvHierarchy, luminance};
use crate::frame::Frame;
use crate::mapping::SPHERE_AREA;
use crate::sampler::DirectionSample;
use crate::warp::ONE_MINUS_EPSILON;
use glam::{DVec2, Vec2, Vec3};
use heapless::Vec;

/// Values in the SAT of a `2^level` map.
#[must_use]
pub const fn sat_len(level: u32) -> usize {
    let n = (1usize << level) + 1;
    n * n
}

/// Fills `sat` ((N+1)², row-major, zero first row and column) with the summed importance of
/// the map's finest level: `sat[y][x]` = Σ over texels (i < x, j < y).
pub fn build_sat(env: &EnvHierarchy<'_>, sat: &mut [f64]) -> bool {
    let level = env.finest_level();
    let n = 1usize << level;
    if sat.len() != sat_len(level) {
        return false;
    }
    let stride = n + 1;
    sat[..stride].fill(0.0);
    for y in 0..n {
        let mut row = 0.0f64;
        sat[(y + 1) * stride] = 0.0;
        for x in 0..n {
            row += env.node_relative(Cell::new(level, x as u32, y as u32)) as f64;
            sat[(y + 1) * stride + x + 1] = sat[y * stride + x + 1] + row;
        }
    }
    true
}

/// A texel-aligned rectangle [x0, x1) × [y0, y1) with its B̃ and ∫L.
#[derive(Clone, Copy, Debug, Default)]
struct Rect {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
    btilde: f32,
    variation: f32,
    integral: f64,
}

/// The two-stage sampler of one shading point (at most `R` rectangles).
pub struct TwoStageSampler<'a, 'e, const R: usize = 32> {
    env: &'a EnvHierarchy<'e>,
    sat: &'a [f64],
    rects: Vec<Rect, R>,
    /// Cumulative weights (B̃ × ∫L) of the rectangles.
    cumulative: Vec<f64, R>,
}

impl<'a, 'e, const R: usize> TwoStageSampler<'a, 'e, R> {
    /// Builds the partition for a shading point. `sat` comes from [`build_sat`].
    pub fn new<B: Brdf + ?Sized>(env: &'a EnvHierarchy<'e>, sat: &'a [f64], brdf: &B, frame: &Frame, wo: Vec3) -> Self {
        let mut s = Self { env, sat, rects: Vec::new(), cumulative: Vec::new() };
        if env.is_black() || sat.len() != sat_len(env.finest_level()) {
            return s;
        }
        let n = env.resolution();
        let wo_local = frame.to_local(wo);
        let eval = |uv: Vec2| luminance(brdf.eval(wo_local, frame.to_local(env.dir_of(uv))));
        // Initial split at the BRDF's peak: the mirror direction (diffuse: the normal).
        let peak_local = if brdf.is_diffuse() { Vec3::Z } else { Vec3::new(-wo_local.x, -wo_local.y, wo_local.z) };
        let (px, py) = env.texel_at(env.square_of(frame.to_world(peak_local)));
        let xs = [0, px, n];
        let ys = [0, py, n];
        for j in 0..2 {
            for i in 0..2 {
                if xs[i] < xs[i + 1] && ys[j] < ys[j + 1] {
                    let r = s.rect(xs[i], ys[j], xs[i + 1], ys[j + 1], &eval);
                    let _ = s.rects.push(r);
                }
            }
        }
        // Refine: split the rectangle with the largest weight × variation along its longer side.
        while s.rects.len() < R {
            let Some((k, _)) = s
                .rects
                .iter()
                .enumerate()
                .filter(|(_, r)| r.x1 - r.x0 > 1 || r.y1 - r.y0 > 1)
                .map(|(k, r)| (k, r.btilde as f64 * r.integral * r.variation as f64))
                .max_by(|a, b| a.1.total_cmp(&b.1))
            else {
                break;
            };
            let r = s.rects[k];
            let (a, b) = if r.x1 - r.x0 >= r.y1 - r.y0 {
                let m = (r.x0 + r.x1) / 2;
                (s.rect(r.x0, r.y0, m, r.y1, &eval), s.rect(m, r.y0, r.x1, r.y1, &eval))
            } else {
                let m = (r.y0 + r.y1) / 2;
                (s.rect(r.x0, r.y0, r.x1, m, &eval), s.rect(r.x0, m, r.x1, r.y1, &eval))
            };
            s.rects[k] = a;
            let _ = s.rects.push(b);
        }
        // Floor B̃ so that every rectangle with light keeps a positive weight.
        let max_b = s.rects.iter().map(|r| r.btilde).fold(0.0f32, f32::max);
        let floor = if max_b > 0.0 { 1e-3 * max_b } else { 1.0 };
        let mut total = 0.0f64;
        for r in s.rects.iter_mut() {
            r.btilde = r.btilde.max(floor);
            total += r.btilde as f64 * r.integral;
            let _ = s.cumulative.push(total);
        }
        s
    }

    fn rect(&self, x0: u32, y0: u32, x1: u32, y1: u32, eval: &impl Fn(Vec2) -> f32) -> Rect {
        let n = self.env.resolution() as f32;
        let at = |fx: f32, fy: f32| {
            Vec2::new((x0 as f32 + fx * (x1 - x0) as f32) / n, (y0 as f32 + fy * (y1 - y0) as f32) / n)
        };
        // The corners exactly, not inset: the first split runs through the BRDF's peak, so a
        // corner of each of the first four rectangles lies within a texel of it. Inset corners
        // can miss a needle lobe (α = 0.01) entirely: every rectangle's B̃ then comes from the
        // tails and the lobe's rectangle is drawn far less often than it should (a heavy tail).
        let v = [at(0.5, 0.5), at(0.0, 0.0), at(1.0, 0.0), at(0.0, 1.0), at(1.0, 1.0)].map(|p| eval(p).max(0.0));
        let mean = v.iter().sum::<f32>() / 5.0;
        let (lo, hi) = v.iter().fold((f32::INFINITY, 0.0f32), |(lo, hi), &x| (lo.min(x), hi.max(x)));
        Rect {
            x0,
            y0,
            x1,
            y1,
            btilde: mean,
            variation: (hi - lo) / mean.max(1e-30) + 1e-3,
            integral: self.sum(x0, y0, x1, y1),
        }
    }

    /// Σ importance over [x0, x1) × [y0, y1) from the SAT.
    #[inline]
    fn sum(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> f64 {
        let stride = self.env.resolution() as usize + 1;
        let at = |x: u32, y: u32| self.sat[y as usize * stride + x as usize];
        (at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0)).max(0.0)
    }

    /// The environment it samples.
    #[must_use]
    pub fn env(&self) -> &EnvHierarchy<'e> {
        self.env
    }

    /// Rectangles in the partition.
    #[must_use]
    pub fn rect_count(&self) -> usize {
        self.rects.len()
    }

    /// Draws a direction; `None` when no rectangle has light.
    pub fn sample(&self, u: DVec2) -> Option<DirectionSample> {
        let total = *self.cumulative.last()?;
        if total <= 0.0 {
            return None;
        }
        let mut xi = u.clamp(DVec2::ZERO, DVec2::splat(ONE_MINUS_EPSILON));
        // Stage 1: a rectangle ∝ weight (ξ.x rescaled into it).
        let t = xi.x * total;
        let k = self.cumulative.iter().position(|&c| t < c).unwrap_or(self.rects.len() - 1);
        let lo = if k == 0 { 0.0 } else { self.cumulative[k - 1] };
        let width = self.cumulative[k] - lo;
        if width <= 0.0 {
            return None;
        }
        xi.x = ((t - lo) / width).clamp(0.0, ONE_MINUS_EPSILON);
        let r = self.rects[k];
        // Stage 2: a column ∝ its sum (bisection), then a row within it.
        let target = xi.x * r.integral;
        let (mut a, mut b) = (r.x0, r.x1);
        while b - a > 1 {
            let m = (a + b) / 2;
            if self.sum(r.x0, r.y0, m, r.y1) <= target { a = m } else { b = m }
        }
        let x = a;
        let before = self.sum(r.x0, r.y0, x, r.y1);
        let column = self.sum(x, r.y0, x + 1, r.y1);
        xi.x = if column > 0.0 { ((target - before) / column).clamp(0.0, ONE_MINUS_EPSILON) } else { 0.5 };
        let target_y = xi.y * column;
        let (mut a, mut b) = (r.y0, r.y1);
        while b - a > 1 {
            let m = (a + b) / 2;
            if self.sum(x, r.y0, x + 1, m) <= target_y { a = m } else { b = m }
        }
        let y = a;
        let below = self.sum(x, r.y0, x + 1, y);
        let cell = self.sum(x, y, x + 1, y + 1);
        xi.y = if cell > 0.0 { ((target_y - below) / cell).clamp(0.0, ONE_MINUS_EPSILON) } else { 0.5 };
        let uv = Cell::new(self.env.finest_level(), x, y).point(xi);
        let pdf = self.pdf_texel(k, x, y) / SPHERE_AREA;
        (pdf > 0.0).then(|| DirectionSample { dir: self.env.dir_of(uv), uv, pdf })
    }

    /// Density per unit square area of texel (x, y) inside rectangle k.
    fn pdf_texel(&self, k: usize, x: u32, y: u32) -> f32 {
        let total = self.cumulative.last().copied().unwrap_or(0.0);
        let r = self.rects[k];
        if total <= 0.0 || r.integral <= 0.0 {
            return 0.0;
        }
        let weight = r.btilde as f64 * r.integral / total;
        let n = self.env.resolution() as f64;
        (weight * self.env.node_relative(Cell::new(self.env.finest_level(), x, y)) as f64 / r.integral * n * n) as f32
    }

    /// Density per unit area of the square at `uv`.
    #[must_use]
    pub fn pdf_square(&self, uv: Vec2) -> f32 {
        let (x, y) = self.env.texel_at(uv);
        match self.rects.iter().position(|r| x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1) {
            Some(k) => self.pdf_texel(k, x, y),
            None => 0.0,
        }
    }

    /// Density with respect to solid angle of world direction `dir`.
    #[must_use]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        self.pdf_square(self.env.square_of(dir)) / SPHERE_AREA
    }
}
