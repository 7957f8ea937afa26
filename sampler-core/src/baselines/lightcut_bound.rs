//! A Lightcuts cluster's error bound at a shading point (Walter et al. 2005, section 4.1),
//! with visibility bounded by 1: the node's intensity × an upper bound of the geometric term
//! over its lights (1 for directional lights, 1/d²min for point lights, d_min the distance to
//! the node's box) × an upper bound of BRDF × cosine over the node's directions
//! ([`Brdf::cone_bounds`] over the cone of its directions, or the cone the box's bounding
//! sphere subtends).

use super::lightcut_tree::{CutLightKind, CutNode};
use crate::brdf::Brdf;
use crate::cone::Cone;
use crate::estimator::ShadingPoint;
use glam::Vec3;

/// The node's error bound at `p` (luminance): an upper bound of BRDF × cosine over its
/// directions × of the geometric term over its lights × its intensity's largest channel
/// (luminance of a product of colours is at most the largest channel of one times the
/// luminance of the other).
pub(super) fn error_bound<B: Brdf + ?Sized>(n: &CutNode, p: Vec3, sp: &ShadingPoint<'_, B>, wo_local: Vec3) -> f32 {
    let (cone, g) = if n.kind == CutLightKind::Directional {
        (n.cone, 1.0)
    } else {
        let closest = p.clamp(n.min, n.max);
        let d2 = (closest - p).length_squared();
        if d2.is_nan() || d2 <= 0.0 {
            return f32::INFINITY;
        }
        (sphere_cone(n, p), 1.0 / d2)
    };
    let local = Cone { axis: sp.frame.to_local(cone.axis), ..cone };
    let mut m = [0.0f32];
    sp.brdf.cone_bounds(wo_local, &[local], &mut m);
    let bound = m[0].max(0.0) * g * n.intensity.max_element();
    if bound.is_nan() { f32::INFINITY } else { bound }
}

/// The cone of directions from `p` to the bounding sphere of the node's box; every direction
/// where `p` is inside it.
fn sphere_cone(n: &CutNode, p: Vec3) -> Cone {
    let (centre, radius) = (0.5 * (n.min + n.max), 0.5 * (n.max - n.min).length());
    let v = centre - p;
    let d = v.length();
    if d <= radius * 1.0001 || d == 0.0 {
        return Cone::default();
    }
    Cone::new(v / d, libm::asinf((radius / d).min(1.0)) * 1.0001 + 1e-6)
}
