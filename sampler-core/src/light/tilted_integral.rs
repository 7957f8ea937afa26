//! The power of a flat emitter whose shaping axis is not its normal (a face of a shaped mesh
//! light or CylinderLight, whose axis is the light's −Z): ∫ factor(ω) max(0, ω·n) dω over the
//! sphere, and the same with |ω·n| for a two-sided one. For a cone and focus, which depend on
//! the angle θ from the axis only, the integral over the angle φ about the axis of the clipped
//! cosine has a closed form (with A = cos θ cos α, B = sin θ sin α, α the tilt of the normal:
//! 2πA where A ≥ B, 0 where A ≤ −B, else 2(Aφ₀ + B sin φ₀) with φ₀ = acos(−A/B)), leaving one
//! integral in θ, by Simpson's rule between its kinks; with an IES profile, which depends on φ
//! too, a midpoint rule over the cap of directions that emit, in the axis's frame (so that a
//! narrow beam still spans every row). A mesh light's faces share one shaping: a host computes
//! that grid once ([`TiltedGrid`]) and each face's integral is then a sum of products.

use super::Shaping;
use core::cell::Cell;
use core::f32::consts::{FRAC_PI_2, PI};
use glam::Vec3;

/// Simpson intervals per smooth piece in θ.
const STEPS: usize = 64;
/// The midpoint grid over the emitting cap for a profiled emitter: θ rows (twice as many in φ).
const PROFILE_ROWS: usize = 128;

/// ∫ max(0, A + B cos φ) dφ over [0, 2π], for B ≥ 0.
fn clipped_cosine(a: f32, b: f32) -> f32 {
    if a >= b {
        2.0 * PI * a
    } else if a <= -b {
        0.0
    } else {
        let phi0 = libm::acosf((-a / b).clamp(-1.0, 1.0));
        2.0 * (a * phi0 + b * libm::sinf(phi0))
    }
}

impl Shaping {
    /// ∫ factor(ω) max(0, ω·n) dω over the sphere for the unit `normal` (with |ω·n| when
    /// `two_sided`): a flat emitter's power over its radiance times its area. Equal to
    /// [`Shaping::integral`]`(true, two_sided)` when the normal is the axis.
    #[must_use]
    pub fn integral_about(&self, normal: Vec3, two_sided: bool) -> Vec3 {
        let sides = if two_sided { 2.0 } else { 1.0 };
        if self.is_none() {
            return Vec3::splat(sides * PI);
        }
        let cos_a = self.axis().dot(normal).clamp(-1.0, 1.0);
        if cos_a >= 1.0 - 1e-7 {
            return self.integral(true, two_sided);
        }
        if self.profile().is_some() {
            return self.profiled_integral_about(normal, two_sided);
        }
        let alpha = libm::acosf(cos_a);
        let sin_a = libm::sinf(alpha);
        let end = self.cutoff();
        let mut cuts = [self.soft_start(), (FRAC_PI_2 - alpha).abs(), FRAC_PI_2 + alpha, end];
        cuts.sort_unstable_by(f32::total_cmp);
        let weight = |theta: f32| {
            let (s, c) = (libm::sinf(theta), libm::cosf(theta));
            let (a, b) = (c * cos_a, s * sin_a);
            let k = clipped_cosine(a, b) + if two_sided { clipped_cosine(-a, b) } else { 0.0 };
            self.factor_at_angle(theta, c) * (k * s)
        };
        let mut total = Vec3::ZERO;
        let mut lo = 0.0f32;
        for hi in cuts {
            let hi = hi.min(end);
            if hi <= lo {
                continue;
            }
            let h = (hi - lo) / STEPS as f32;
            let mut sum = weight(lo) + weight(hi);
            for k in 1..STEPS {
                sum += weight(lo + k as f32 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
            }
            total += sum * (h / 3.0);
            lo = hi;
        }
        total
    }

    /// The midpoint rule over the cap within [`Shaping::emission_extent`] of the axis (all the
    /// sphere that emits) for a profiled emitter tilted from its axis.
    fn profiled_integral_about(&self, normal: Vec3, two_sided: bool) -> Vec3 {
        let mut total = Vec3::ZERO;
        for k in 0..TILTED_GRID_CELLS {
            let (w, weight) = self.tilted_grid_cell(k);
            total += weight * clipped(w.dot(normal), two_sided);
        }
        total
    }

    /// Cell `k` of the midpoint grid over the emitting cap that [`Shaping::integral_about`]
    /// sums for a profiled emitter: its direction, and the factor there times its solid angle.
    #[must_use]
    pub fn tilted_grid_cell(&self, k: usize) -> (Vec3, Vec3) {
        let (rows, cols) = (PROFILE_ROWS, 2 * PROFILE_ROWS);
        let (i, j) = (k / cols, k % cols);
        let extent = self.emission_extent();
        let d_theta = extent / rows as f32;
        let theta = d_theta * (i as f32 + 0.5);
        let (st, ct) = (libm::sinf(theta), libm::cosf(theta));
        let phi = 2.0 * PI * (j as f32 + 0.5) / cols as f32;
        let local = Vec3::new(st * libm::cosf(phi), st * libm::sinf(phi), ct);
        let w = self.axis_frame_to_world(local);
        (w, self.factor(w) * (st * d_theta * (2.0 * PI / cols as f32)))
    }

    /// The world direction of `local`, given in a frame whose +Z is the axis.
    fn axis_frame_to_world(&self, local: Vec3) -> Vec3 {
        let a = self.axis();
        // Duff et al.'s branchless orthonormal basis about the axis.
        let sign = if a.z >= 0.0 { 1.0 } else { -1.0 };
        let p = -1.0 / (sign + a.z);
        let q = a.x * a.y * p;
        let t = Vec3::new(1.0 + sign * a.x * a.x * p, sign * q, -sign * a.x);
        let b = Vec3::new(q, sign + a.y * a.y * p, -a.y);
        t * local.x + b * local.y + a * local.z
    }
}

/// The cells of the grid [`Shaping::tilted_grid_cell`] numbers.
pub const TILTED_GRID_CELLS: usize = 2 * PROFILE_ROWS * PROFILE_ROWS;

/// The cosine weight of a direction whose cosine with a face's normal is `cos`.
#[inline]
fn clipped(cos: f32, two_sided: bool) -> f32 {
    if two_sided { cos.abs() } else { cos.max(0.0) }
}

/// The grid of [`Shaping::tilted_grid_cell`] computed once for the many faces of one light (a
/// host keeps it): the cells where the emission is not zero, and the last face's sum, which
/// the next face reuses when it has the same normal and sides (a quad's two triangles, the
/// faces of a flat panel, a row of like tiles).
#[derive(Clone, Debug)]
pub struct TiltedGrid<'a> {
    cells: &'a [(Vec3, Vec3)],
    last: Cell<Option<(Vec3, bool, Vec3)>>,
}

impl<'a> TiltedGrid<'a> {
    /// Fills `cells` (at least [`TILTED_GRID_CELLS`] long) with the grid of `shaping`, keeping
    /// the cells that emit; the grid over them.
    pub fn build(shaping: &Shaping, cells: &'a mut [(Vec3, Vec3)]) -> Self {
        let mut used = 0;
        for k in 0..TILTED_GRID_CELLS.min(cells.len()) {
            let cell = shaping.tilted_grid_cell(k);
            if cell.1 != Vec3::ZERO {
                cells[used] = cell;
                used += 1;
            }
        }
        Self { cells: &cells[..used], last: Cell::new(None) }
    }

    /// [`Shaping::integral_about`] for a profiled shaping whose axis is not `normal`, from the
    /// grid: the same midpoint sum, without evaluating the profile again (nor the sum, for the
    /// normal and sides of the face before).
    #[must_use]
    pub fn integral_about(&self, normal: Vec3, two_sided: bool) -> Vec3 {
        if let Some((n, sides, total)) = self.last.get()
            && n.to_array().map(f32::to_bits) == normal.to_array().map(f32::to_bits)
            && sides == two_sided
        {
            return total;
        }
        let total = self
            .cells
            .iter()
            .fold(Vec3::ZERO, |total, (w, weight)| total + *weight * clipped(w.dot(normal), two_sided));
        self.last.set(Some((normal, two_sided, total)));
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_clipped_cosine_matches_a_sum() {
        for (a, b) in [(0.3f32, 0.5f32), (-0.2, 0.6), (0.9, 0.1), (-0.7, 0.2), (0.0, 1.0)] {
            let n = 20_000;
            let sum: f32 =
                (0..n).map(|i| (a + b * libm::cosf(2.0 * PI * (i as f32 + 0.5) / n as f32)).max(0.0)).sum::<f32>()
                    * (2.0 * PI / n as f32);
            assert!((clipped_cosine(a, b) - sum).abs() < 1e-3, "{a} {b}: {} against {sum}", clipped_cosine(a, b));
        }
    }
}
