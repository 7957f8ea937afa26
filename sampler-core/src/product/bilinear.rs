//! Bilinear densities on a cell: B̃ interpolated between the BRDF's values at a leaf's corners
//! ([`Leaves::Bilinear`](super::quadtree::Leaves::Bilinear)), sampled exactly by inverting its marginal and conditional,
//! both linear.
//!
//! Corner values are in child order (see `warp::child_offset`): (0,0), (1,0), (0,1), (1,1), in
//! the cell's own coordinates s, t ∈ [0, 1].

use crate::cell::Cell;
use crate::warp::{ONE_MINUS_EPSILON, child_offset};
use glam::{DVec2, Vec2};

/// The values at a cell's four corners.
pub type Corners = [f32; 4];

/// The interpolated value at (s, t) of the cell.
#[inline(always)]
#[must_use]
pub fn bilinear(w: &Corners, s: f32, t: f32) -> f32 {
    let bottom = w[0] + s * (w[1] - w[0]);
    let top = w[2] + s * (w[3] - w[2]);
    bottom + t * (top - bottom)
}

/// Mean over the cell (also the value at its centre).
#[inline(always)]
#[must_use]
pub fn mean(w: &Corners) -> f32 {
    0.25 * ((w[0] + w[1]) + (w[2] + w[3]))
}

/// The corner values of the sub-cell with lower corner (s, t) and side `size` (cell units).
#[inline]
#[must_use]
pub fn sub_corners(w: &Corners, s: f32, t: f32, size: f32) -> Corners {
    [bilinear(w, s, t), bilinear(w, s + size, t), bilinear(w, s, t + size), bilinear(w, s + size, t + size)]
}

/// Density of the bilinear distribution at `p` of the cell (relative to the uniform density:
/// value / mean); uniform (1) when the cell's mean is not positive.
#[inline]
#[must_use]
pub fn pdf(w: &Corners, p: DVec2) -> f64 {
    let m = mean(w) as f64;
    if m.is_nan() || m <= 0.0 {
        return 1.0;
    }
    bilinear(w, p.x as f32, p.y as f32) as f64 / m
}

/// Warps a uniform point of [0, 1)² to the bilinear distribution (uniform when the mean is
/// not positive): t from the marginal, then s given t. Continuous and monotone in each
/// coordinate, so stratification survives.
#[inline]
#[must_use]
pub fn sample(w: &Corners, xi: DVec2) -> DVec2 {
    let w = w.map(f64::from);
    let t = sample_linear(xi.y, w[0] + w[1], w[2] + w[3]);
    let s = sample_linear(xi.x, w[0] + t * (w[2] - w[0]), w[1] + t * (w[3] - w[1]));
    DVec2::new(s, t)
}

/// Inverts the CDF of the density ∝ (1 − x)·a + x·b on [0, 1), a, b ≥ 0:
/// x = u(a + b) / (a + √((1 − u)a² + u b²)), the root that stays accurate when a ≈ b.
#[inline]
fn sample_linear(u: f64, a: f64, b: f64) -> f64 {
    let a = a.max(0.0);
    let b = b.max(0.0);
    let denom = a + libm::sqrt((1.0 - u) * a * a + u * b * b);
    if denom.is_nan() || denom <= 0.0 {
        return u;
    }
    (u * (a + b) / denom).min(ONE_MINUS_EPSILON)
}

/// The masses a step of the bilinear walk chooses from.
pub(crate) enum Masses<'m> {
    /// The 16 grandchildren, Morton order.
    Sixteen(&'m [f32; 16]),
    /// The four children.
    Four([f32; 4]),
}

/// A cell of the environment's levels inside a bilinear leaf: its place in the pyramid and its
/// lower corner (s, t) and side in the leaf's own coordinates.
pub(crate) struct BilinearCell {
    pub cell: Cell,
    pub s: f32,
    pub t: f32,
    pub size: f32,
}

impl BilinearCell {
    /// To grandchild (gx, gy) ∈ [0, 4)².
    #[inline(always)]
    pub fn descend_two(&mut self, gx: u32, gy: u32) {
        self.size *= 0.25;
        self.s += gx as f32 * self.size;
        self.t += gy as f32 * self.size;
        self.cell = self.cell.grandchild(gx, gy);
    }

    /// To child `child` (numbered `dx + 2·dy`).
    #[inline(always)]
    pub fn descend(&mut self, child: usize) {
        let (dx, dy) = child_offset(child);
        self.size *= 0.5;
        self.s += dx as f32 * self.size;
        self.t += dy as f32 * self.size;
        self.cell = self.cell.child(child);
    }

    /// Density per unit square area at `uv` in this final cell (reached with probability
    /// `path`, B̃ bilinear between `corners` inside it).
    #[inline]
    pub fn density(&self, path: f64, corners: &Corners, uv: Vec2) -> f64 {
        let Cell { level, x, y } = self.cell;
        let scale = (1u64 << level) as f64;
        let p = DVec2::new(uv.x as f64 * scale - x as f64, uv.y as f64 * scale - y as f64);
        path * self.cell.inverse_area() * pdf(corners, p.clamp(DVec2::ZERO, DVec2::ONE))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_inversion_matches_its_cdf() {
        for (a, b) in [(1.0, 1.0), (0.0, 2.0), (3.0, 0.0), (0.2, 5.0)] {
            for k in 1..10 {
                let u = k as f64 / 10.0;
                let x = sample_linear(u, a, b);
                let cdf = (2.0 * a * x + (b - a) * x * x) / (a + b);
                assert!((cdf - u).abs() < 1e-12, "a {a} b {b} u {u}: cdf {cdf}");
            }
        }
        assert_eq!(sample_linear(0.3, 0.0, 0.0), 0.3);
    }

    #[test]
    fn bilinear_sampling_matches_its_pdf_on_a_grid() {
        // Monte Carlo histogram against the integrated pdf, 8×8 bins.
        let w: Corners = [0.1, 2.0, 0.7, 0.0];
        let n = 1 << 18;
        let mut bins = [0u32; 64];
        let mut rng = crate::rng::Pcg32::new(3, 7);
        for _ in 0..n {
            let p = sample(&w, DVec2::new(rng.next_f64(), rng.next_f64()));
            assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
            bins[(p.y * 8.0) as usize * 8 + (p.x * 8.0) as usize] += 1;
        }
        for (k, &count) in bins.iter().enumerate() {
            // The bilinear's mean over a bin is its value at the bin's centre.
            let c = DVec2::new((k % 8) as f64 + 0.5, (k / 8) as f64 + 0.5) / 8.0;
            let expected = pdf(&w, c) / 64.0 * n as f64;
            let sigma = expected.sqrt().max(1.0);
            assert!((count as f64 - expected).abs() < 5.0 * sigma, "bin {k}: {count} vs {expected}");
        }
    }

    #[test]
    fn sub_cells_and_means_agree() {
        let w: Corners = [1.0, 3.0, 2.0, 6.0];
        assert_eq!(mean(&w), bilinear(&w, 0.5, 0.5));
        let q = sub_corners(&w, 0.5, 0.25, 0.25);
        assert_eq!(q[0], bilinear(&w, 0.5, 0.25));
        assert_eq!(q[3], bilinear(&w, 0.75, 0.5));
        assert_eq!(pdf(&[0.0; 4], DVec2::splat(0.3)), 1.0);
    }
}
