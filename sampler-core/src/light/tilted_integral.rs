//! The power of a flat emitter whose shaping axis is not its normal (a face of a shaped mesh
//! light or CylinderLight, whose axis is the light's −Z): ∫ factor(ω) max(0, ω·n) dω over the
//! sphere, and the same with |ω·n| for a two-sided one. For a cone and focus, which depend on
//! the angle θ from the axis only, the integral over the angle φ about the axis of the clipped
//! cosine has a closed form (with A = cos θ cos α, B = sin θ sin α, α the tilt of the normal:
//! 2πA where A ≥ B, 0 where A ≤ −B, else 2(Aφ₀ + B sin φ₀) with φ₀ = acos(−A/B)), leaving one
//! integral in θ, by Simpson's rule between its kinks; with an IES profile, which depends on φ
//! too, a midpoint rule over the sphere.

use super::Shaping;
use core::f32::consts::{FRAC_PI_2, PI};
use glam::Vec3;

/// Simpson intervals per smooth piece in θ.
const STEPS: usize = 64;
/// The midpoint grid over the sphere for a profiled emitter: θ rows (twice as many in φ).
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

    /// The midpoint rule over the sphere for a profiled emitter tilted from its axis.
    fn profiled_integral_about(&self, normal: Vec3, two_sided: bool) -> Vec3 {
        let (rows, cols) = (PROFILE_ROWS, 2 * PROFILE_ROWS);
        let mut total = Vec3::ZERO;
        for i in 0..rows {
            let theta = PI * (i as f32 + 0.5) / rows as f32;
            let (st, ct) = (libm::sinf(theta), libm::cosf(theta));
            for j in 0..cols {
                let phi = 2.0 * PI * (j as f32 + 0.5) / cols as f32;
                let w = Vec3::new(st * libm::cosf(phi), st * libm::sinf(phi), ct);
                let c = w.dot(normal);
                let cos = if two_sided { c.abs() } else { c.max(0.0) };
                if cos > 0.0 {
                    total += self.factor(w) * (cos * st);
                }
            }
        }
        total * (PI / rows as f32) * (2.0 * PI / cols as f32)
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
