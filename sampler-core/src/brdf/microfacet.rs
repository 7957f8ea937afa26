//! Isotropic GGX (Trowbridge–Reitz) microfacet distribution: Walter et al. 2007 D, separable
//! Smith G1, and visible-normal sampling (spherical caps, Dupuy & Benyoub 2023), in local
//! coordinates (normal = +z). Written to stay accurate for α down to 1e-4.

use crate::cone::Cone;
use crate::sampling::sin_cos_2pi;
use core::f32::consts::{FRAC_PI_2, PI};
use glam::{Vec2, Vec3};

/// Smallest roughness accepted (the scene format's clamp).
pub const MIN_ALPHA: f32 = 1e-4;

/// An isotropic GGX distribution of roughness α (not squared).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    alpha: f32,
}

impl Ggx {
    /// α is clamped to [`MIN_ALPHA`, 1e3]; NaN becomes [`MIN_ALPHA`].
    #[must_use]
    pub fn new(alpha: f32) -> Self {
        let alpha = if alpha.is_nan() { MIN_ALPHA } else { alpha.clamp(MIN_ALPHA, 1e3) };
        Self { alpha }
    }

    /// The (clamped) roughness α.
    #[inline]
    #[must_use]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// D(m) for a unit microfacet normal m: α² / (π (α² m_z² + m_x² + m_y²)²), which equals
    /// 1/(π α² cos⁴θ (1 + tan²θ/α²)²) without forming 1 − cos² (exact for tiny α).
    #[inline]
    #[must_use]
    pub fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let k = a2 * m.z * m.z + (m.x * m.x + m.y * m.y);
        if k <= 0.0 {
            return 0.0;
        }
        a2 / (PI * k * k)
    }

    /// Smith G1(v) = 2 / (1 + √(1 + α² tan²θ_v)); 0 below the surface.
    #[inline]
    #[must_use]
    pub fn g1(&self, v: Vec3) -> f32 {
        if v.z <= 0.0 {
            return 0.0;
        }
        let tan2 = (v.x * v.x + v.y * v.y) / (v.z * v.z);
        2.0 / (1.0 + libm::sqrtf(1.0 + self.alpha * self.alpha * tan2))
    }

    /// Samples a visible microfacet normal for the view `wo` (wo.z > 0).
    #[inline]
    #[must_use]
    pub fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        self.sample_visible_stretched(self.stretch(wo), u)
    }

    /// The view in the stretched (α = 1) configuration; depends on `wo` only, so batch samplers
    /// compute it once.
    #[inline]
    #[must_use]
    pub fn stretch(&self, wo: Vec3) -> Vec3 {
        Vec3::new(wo.x * self.alpha, wo.y * self.alpha, wo.z).normalize()
    }

    /// [`Self::sample_visible`] given `w = self.stretch(wo)`.
    #[inline]
    #[must_use]
    pub fn sample_visible_stretched(&self, w: Vec3, u: Vec2) -> Vec3 {
        let a = self.alpha;
        let (sin_phi, cos_phi) = sin_cos_2pi(u.x);
        let z = (1.0 - u.y) * (1.0 + w.z) - w.z;
        let sin_theta = libm::sqrtf((1.0 - z * z).clamp(0.0, 1.0));
        let c = Vec3::new(sin_theta * cos_phi, sin_theta * sin_phi, z);
        let h = c + w;
        let m = Vec3::new(h.x * a, h.y * a, h.z.max(0.0));
        let len2 = m.length_squared();
        if len2 > 0.0 && len2.is_finite() { m / libm::sqrtf(len2) } else { Vec3::Z }
    }

    /// Density of the reflected direction `wi = reflect(wo, m)` when m is drawn by
    /// [`Self::sample_visible`]: G1(wo)·D(m) / (4 wo_z), with respect to solid angle of wi
    /// over the whole sphere (directions below the surface included).
    #[inline]
    #[must_use]
    pub fn pdf_reflected(&self, wo: Vec3, m: Vec3) -> f32 {
        if wo.z <= 0.0 || wo.dot(m) <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * self.d(m) / (4.0 * wo.z)
    }
}

/// Where the half vectors of a view and a cone of incident directions lie
/// ([`HalfVectorCone::new`]): what bounds every microfacet lobe over the cone, whatever its α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfVectorCone {
    /// A lower bound of sinθh, the half vectors' angle from the normal (0: the normal may be
    /// among them).
    pub sin_normal: f32,
    /// A lower bound of ωo·h, in [0, 1] (Schlick's Fresnel falls as it grows).
    pub cos_oh: f32,
}

impl HalfVectorCone {
    /// Nothing known: any half vector.
    pub const ANY: Self = Self { sin_normal: 0.0, cos_oh: 0.0 };

    /// Bounds the half vectors h of `wo` and every direction ωi of `cone` (local frame).
    ///
    /// h moves at most 1/|ωo + ωi| = 1/(2 cos(θ/2)) radians per radian of ωi, θ the angle
    /// between ωo and ωi; every ωi of the cone is reached from its axis by an arc of at most
    /// θc inside it, so h stays within ρ = θc / (2 cos(θmax/2)) of the half vector of the axis.
    /// With cos ρ ≥ 1 − ρ²/2 and sin ρ ≤ ρ, the angle addition formulas bound the normal's
    /// nearest approach and the view's farthest without a trigonometric call.
    #[must_use]
    pub fn new(wo: Vec3, cone: &Cone) -> Self {
        let (c_oa, s_oa) = cone.cos_sin_to(wo);
        if c_oa <= -cone.cos {
            return Self::ANY;
        }
        let cos_widest = c_oa * cone.cos - s_oa * cone.sin;
        let rho = cone.angle / (2.0 * libm::sqrtf((0.5 * (1.0 + cos_widest)).max(0.0)));
        if rho.is_nan() || rho >= FRAC_PI_2 {
            return Self::ANY;
        }
        let Some(h) = half_vector(wo, cone.axis) else { return Self::ANY };
        let cos_rho = 1.0 - 0.5 * rho * rho;
        let sin_normal = (libm::sqrtf(h.x * h.x + h.y * h.y) * cos_rho - h.z.max(0.0) * rho).max(0.0);
        let (c_oh, s_oh) = (wo.dot(h), wo.cross(h).length());
        let cos_oh = if c_oh >= 0.0 { c_oh * cos_rho } else { c_oh } - s_oh * rho;
        Self { sin_normal, cos_oh: cos_oh.clamp(0.0, 1.0) }
    }
}

impl Ggx {
    /// The largest value D takes anywhere: at the normal for α < 1, at grazing half vectors
    /// above.
    #[inline]
    #[must_use]
    pub fn d_max(&self) -> f32 {
        let a2 = self.alpha * self.alpha;
        if self.alpha < 1.0 { 1.0 / (PI * a2) } else { a2 / PI }
    }

    /// An upper bound of D over half vectors at least `cone.sin_normal` from the normal: D
    /// falls with sinθh for α < 1.
    #[inline]
    #[must_use]
    pub fn d_bound(&self, cone: &HalfVectorCone) -> f32 {
        if self.alpha >= 1.0 {
            return self.d_max();
        }
        let a2 = self.alpha * self.alpha;
        let s2 = cone.sin_normal * cone.sin_normal;
        let k = a2 + (1.0 - a2) * s2;
        a2 / (PI * k * k)
    }
}

/// Normalised half vector of two unit directions, or `None` when they are opposite.
#[inline]
#[must_use]
pub fn half_vector(wo: Vec3, wi: Vec3) -> Option<Vec3> {
    let h = wo + wi;
    let len2 = h.length_squared();
    if len2 > 1e-24 && len2.is_finite() { Some(h / libm::sqrtf(len2)) } else { None }
}

/// Schlick's Fresnel approximation.
#[inline]
#[must_use]
pub fn fresnel_schlick(f0: f32, cos_theta: f32) -> f32 {
    let c = (1.0 - cos_theta.clamp(0.0, 1.0)).max(0.0);
    let c2 = c * c;
    f0 + (1.0 - f0) * c2 * c2 * c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn d_is_normalised_projected_area() {
        // ∫ D(m) cosθ_m dm = 1, by midpoint rule in θ with an α-adapted grid.
        for alpha in [1e-3f32, 0.1, 0.5, 1.0] {
            let g = Ggx::new(alpha);
            let n = 20_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                // θ = atan(α·tan(ψ)), ψ uniform in [0, π/2): dense where D is.
                let psi = (i as f64 + 0.5) / n as f64 * core::f64::consts::FRAC_PI_2;
                let dpsi = core::f64::consts::FRAC_PI_2 / n as f64;
                let theta = (alpha as f64 * psi.tan()).atan();
                let dtheta = alpha as f64 / (psi.cos().powi(2) + (alpha as f64 * psi.sin()).powi(2)) * dpsi;
                let m = Vec3::new(theta.sin() as f32, 0.0, theta.cos() as f32);
                sum += g.d(m) as f64 * theta.cos() * theta.sin() * dtheta * 2.0 * core::f64::consts::PI;
            }
            assert!((sum - 1.0).abs() < 1e-3, "alpha {alpha}: {sum}");
        }
    }
}
