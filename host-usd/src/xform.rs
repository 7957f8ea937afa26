//! World transforms: each prim's local transform composed with its parent's, up to the root
//! or a `!resetXformStack!`, memoised per path and resolved top-down (`inherit.rs`).
//! Matrices are glam's column-vector form (the transpose of USD's row-vector matrices), so
//! `world = parent · local`.

use crate::stage::{PrimMap, PrimPath, Stage};
use glam::{DMat3, DMat4, DVec3};

/// Each prim's world transform, memoised by path.
#[derive(Default)]
pub struct WorldTransforms {
    cache: PrimMap<DMat4>,
}

impl WorldTransforms {
    /// Local-to-world of `prim` in the stage's own frame (before any up-axis conversion).
    pub fn world(&mut self, stage: &Stage, prim: &PrimPath) -> Result<DMat4, String> {
        crate::inherit::resolve_down(&mut self.cache, prim, DMat4::IDENTITY, |p, parent| {
            let (local, resets) = crate::xform_ops::local_transform(stage, p)?;
            Ok(if resets { local } else { *parent * local })
        })
    }

    /// The transform of `prim` relative to `root`'s parent: the locals from `prim` up to and
    /// including `root` (a PointInstancer prototype's own transform is part of each
    /// instance).
    pub fn relative_to(&mut self, stage: &Stage, prim: &PrimPath, root: &PrimPath) -> Result<DMat4, String> {
        let mut m = DMat4::IDENTITY;
        let mut p = prim.clone();
        loop {
            let (local, resets) = crate::xform_ops::local_transform(stage, &p)?;
            m = local * m;
            if p == *root || resets {
                return Ok(m);
            }
            p = p.parent().filter(|up| !up.is_root()).ok_or_else(|| format!("{prim} is not under {root}"))?;
        }
    }
}

/// The rotation that brings a stage with `up_axis` into the renderer's Y-up frame.
pub fn up_axis_conversion(z_up: bool) -> DMat4 {
    if z_up { DMat4::from_rotation_x(-std::f64::consts::FRAC_PI_2) } else { DMat4::IDENTITY }
}

/// The rotation part of an affine transform, scale and shear removed (Gram–Schmidt).
pub fn rotation_part(m: &DMat4) -> DMat3 {
    let x = m.x_axis.truncate().normalize_or_zero();
    let y = (m.y_axis.truncate() - x * x.dot(m.y_axis.truncate())).normalize_or_zero();
    let mut z = x.cross(y);
    if z.dot(m.z_axis.truncate()) < 0.0 {
        z = -z;
    }
    if x == DVec3::ZERO || y == DVec3::ZERO {
        return DMat3::IDENTITY;
    }
    DMat3::from_cols(x, y, z)
}

/// Whether the transform is a similarity (rotation, uniform scale, translation), and its
/// scale.
pub fn uniform_scale(m: &DMat4) -> Option<f64> {
    let m3 = DMat3::from_mat4(*m);
    let (a, b, c) = (m3.x_axis, m3.y_axis, m3.z_axis);
    let s = a.length();
    let tol = 1e-6 * s.max(1e-300);
    let ok = (b.length() - s).abs() <= tol
        && (c.length() - s).abs() <= tol
        && a.dot(b).abs() <= tol * s
        && a.dot(c).abs() <= tol * s
        && b.dot(c).abs() <= tol * s;
    ok.then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_up_becomes_y_up() {
        let c = up_axis_conversion(true);
        let z = c.transform_vector3(DVec3::Z);
        assert!((z - DVec3::Y).length() < 1e-15);
        let y = c.transform_vector3(DVec3::Y);
        assert!((y + DVec3::Z).length() < 1e-15);
    }

    #[test]
    fn similarity_detection() {
        let m = DMat4::from_scale_rotation_translation(DVec3::splat(2.5), glam::DQuat::from_rotation_y(0.3), DVec3::X);
        assert!((uniform_scale(&m).unwrap() - 2.5).abs() < 1e-12);
        let n = DMat4::from_scale(DVec3::new(1.0, 2.0, 1.0));
        assert!(uniform_scale(&n).is_none());
        let r = rotation_part(&m);
        assert!((r * DVec3::Z - glam::DQuat::from_rotation_y(0.3) * DVec3::Z).length() < 1e-12);
    }
}
