//! A prim's local transform from its `xformOpOrder`: the first listed op is outermost, the
//! last is applied to points first; `!invert!` inverts an op, a leading `!resetXformStack!`
//! cuts the parent's transform. Evaluated in f64 as Pixar does, `orient` included (through
//! an axis and an angle, which matters at 1e-8 for an authored `quatf`). Matrices are
//! glam's column-vector form, the transpose of USD's row-vector matrices.

use crate::stage::{PrimPath, Stage, Value};
use glam::{DMat4, DQuat, DVec3};

const INVERT: &str = "!invert!";
const RESET: &str = "!resetXformStack!";

/// The 4×4 matrix of one op (column-vector form); `kind` is the part after `xformOp:`
/// without the suffix.
fn op_matrix(kind: &str, v: &Value) -> Result<DMat4, String> {
    let nums = v.numbers().unwrap_or(&[]);
    let n = |i: usize, d: f64| nums.get(i).copied().unwrap_or(d);
    let vec3 = |d: f64| DVec3::new(n(0, d), n(1, d), n(2, d));
    let axis = |a: char, deg: f64| match a {
        'X' => DMat4::from_rotation_x(deg.to_radians()),
        'Y' => DMat4::from_rotation_y(deg.to_radians()),
        _ => DMat4::from_rotation_z(deg.to_radians()),
    };
    Ok(match kind {
        "translate" => DMat4::from_translation(vec3(0.0)),
        "translateX" => DMat4::from_translation(DVec3::new(n(0, 0.0), 0.0, 0.0)),
        "translateY" => DMat4::from_translation(DVec3::new(0.0, n(0, 0.0), 0.0)),
        "translateZ" => DMat4::from_translation(DVec3::new(0.0, 0.0, n(0, 0.0))),
        "scale" => DMat4::from_scale(vec3(1.0)),
        "scaleX" => DMat4::from_scale(DVec3::new(n(0, 1.0), 1.0, 1.0)),
        "scaleY" => DMat4::from_scale(DVec3::new(1.0, n(0, 1.0), 1.0)),
        "scaleZ" => DMat4::from_scale(DVec3::new(1.0, 1.0, n(0, 1.0))),
        "rotateX" | "rotateY" | "rotateZ" => axis(kind.chars().last().unwrap_or('Z'), n(0, 0.0)),
        "rotateXYZ" | "rotateXZY" | "rotateYXZ" | "rotateYZX" | "rotateZXY" | "rotateZYX" => {
            // The first letter's axis applies first: M = R_last · … · R_first (columns).
            let order: Vec<char> = kind[6..].chars().collect();
            let angle = |a: char| n((a as u8 - b'X') as usize, 0.0);
            order.iter().fold(DMat4::IDENTITY, |m, &a| axis(a, angle(a)) * m)
        }
        "orient" => {
            // Quaternions arrive as (w, x, y, z). Pixar goes through an axis and an angle
            // (GfRotation): w is kept and the axis rescaled to unit length with it.
            let (w, axis) = (n(0, 1.0), DVec3::new(n(1, 0.0), n(2, 0.0), n(3, 0.0)));
            if !(w.is_finite() && axis.is_finite()) {
                return Err("xformOp:orient is not finite".into());
            }
            let len = axis.length();
            if len <= 1e-10 {
                DMat4::IDENTITY
            } else {
                let half = (2.0 * w.clamp(-1.0, 1.0).acos()).to_degrees().to_radians() / 2.0;
                let v = axis / len * half.sin();
                DMat4::from_quat(DQuat::from_xyzw(v.x, v.y, v.z, half.cos()))
            }
        }
        "transform" => {
            if nums.len() != 16 {
                return Err("xformOp:transform is not a matrix4d".into());
            }
            DMat4::from_cols_array(&std::array::from_fn(|i| nums[i]))
        }
        other => return Err(format!("unknown xformOp kind {other:?}")),
    })
}

/// The local-to-parent transform of `prim` and whether it resets the parent's transform.
pub fn local_transform(stage: &Stage, prim: &PrimPath) -> Result<(DMat4, bool), String> {
    let Some(order) = stage.xform_op_order(prim)? else {
        return Ok((DMat4::IDENTITY, false));
    };
    let mut m = DMat4::IDENTITY;
    let mut resets = false;
    for (i, op) in order.iter().enumerate() {
        if op == RESET {
            if i != 0 {
                return Err(format!("{RESET} at position {i} of xformOpOrder (only the first is valid)"));
            }
            resets = true;
            continue;
        }
        let (inverted, name) = match op.strip_prefix(INVERT) {
            Some(rest) => (true, rest),
            None => (false, op.as_str()),
        };
        let kind = name.strip_prefix("xformOp:").and_then(|k| k.split(':').next());
        let kind = kind.ok_or_else(|| format!("xformOpOrder entry {op:?} is not an xformOp"))?;
        let op_m = match stage.value(prim, name)? {
            Some(v) => op_matrix(kind, &v)?,
            // Pixar's op transform is the identity where the op has no value: an inverted op
            // whose attribute is absent, or a time-sampled op read at the default time code.
            None if inverted || stage.is_time_sampled(prim, name)? => DMat4::IDENTITY,
            None => return Err(format!("{name} is listed in xformOpOrder but has no value")),
        };
        let op_m = if inverted {
            let det = op_m.determinant();
            if det.is_nan() || det.abs() <= 1e-300 {
                return Err(format!("{op}: the op is singular and cannot be inverted"));
            }
            op_m.inverse()
        } else {
            op_m
        };
        m *= op_m;
    }
    Ok((m, resets))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nums(v: &[f64]) -> Value {
        Value::Numbers { values: v.to_vec(), shape: v.len(), array: false }
    }

    #[test]
    fn euler_orders_apply_the_first_axis_first() {
        let m = op_matrix("rotateXYZ", &nums(&[90.0, 0.0, 90.0])).unwrap();
        // X first: +Y → +Z; then Z: +Z stays.
        let p = m.transform_vector3(DVec3::Y);
        assert!((p - DVec3::Z).length() < 1e-12, "{p}");
        let m = op_matrix("rotateZYX", &nums(&[90.0, 0.0, 90.0])).unwrap();
        // Z first: +Y → −X; then X: −X stays.
        let p = m.transform_vector3(DVec3::Y);
        assert!((p + DVec3::X).length() < 1e-12, "{p}");
    }

    #[test]
    fn orient_is_normalised_and_bad_ops_fail() {
        let m = op_matrix("orient", &nums(&[0.5, 0.5, 0.5, 0.5001])).unwrap();
        assert!((m.determinant() - 1.0).abs() < 1e-15);
        assert_eq!(op_matrix("orient", &nums(&[0.0; 4])).unwrap(), DMat4::IDENTITY);
        assert!(op_matrix("orient", &nums(&[f64::NAN, 0.0, 0.0, 1.0])).is_err());
        assert!(op_matrix("transform", &nums(&[1.0; 3])).is_err());
        assert!(op_matrix("shear", &nums(&[1.0])).is_err());
    }
}
