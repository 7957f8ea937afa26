//! UsdGeomPointInstancer: per instance, scale · orient · translate (row-vector order), then
//! the instancer's world; each prototype's own subtree transform (root included) applies
//! first. `invisibleIds` hide instances; prototypes are not rendered in place.

use crate::stage::{PrimPath, Stage, Value};
use glam::{DMat4, DQuat, DVec3};

/// One instance: which prototype, and its transform relative to the instancer.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// The instance's index among the instancer's `protoIndices`.
    pub index: usize,
    /// Which of the instancer's `prototypes` it instantiates.
    pub prototype: usize,
    /// Its transform relative to the instancer (scale · orient · translate).
    pub transform: DMat4,
}

fn numbers(v: Option<Value>) -> Vec<f64> {
    match v {
        Some(Value::Numbers { values, .. }) => values,
        _ => Vec::new(),
    }
}

/// The prototypes (paths) and the visible instances of a PointInstancer.
pub fn read(stage: &Stage, prim: &PrimPath) -> Result<(Vec<PrimPath>, Vec<Instance>), String> {
    let prototypes = stage.targets(prim, "prototypes")?;
    let proto_indices = numbers(stage.value(prim, "protoIndices")?);
    let positions = numbers(stage.value(prim, "positions")?);
    let mut orientations = numbers(stage.value(prim, "orientations")?);
    if orientations.is_empty() {
        orientations = numbers(stage.value(prim, "orientationsf")?);
    }
    let scales = numbers(stage.value(prim, "scales")?);
    let ids = numbers(stage.value(prim, "ids")?);
    // Sorted and searched: a hash of every instance's id costs more than the search.
    let mut invisible: Vec<i64> = numbers(stage.value(prim, "invisibleIds")?).iter().map(|&x| x as i64).collect();
    invisible.sort_unstable();
    let n = proto_indices.len();
    if positions.len() < 3 * n {
        return Err(format!("{n} protoIndices but {} positions", positions.len() / 3));
    }
    let mut out = Vec::with_capacity(n);
    for (i, &p) in proto_indices.iter().enumerate() {
        let id = ids.get(i).map_or(i as i64, |&x| x as i64);
        if invisible.binary_search(&id).is_ok() {
            continue;
        }
        let proto = p as i64;
        if proto < 0 || proto as usize >= prototypes.len() {
            return Err(format!("instance {i} uses prototype {proto} of {}", prototypes.len()));
        }
        let t = DVec3::new(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
        // Quaternions arrive as (w, x, y, z). Like Pixar, the rotation matrix is built from
        // the authored (half-precision, not quite unit) quaternion as it is.
        let r = match orientations.get(4 * i..4 * i + 4) {
            Some(q) => DQuat::from_xyzw(q[1], q[2], q[3], q[0]),
            None => DQuat::IDENTITY,
        };
        if !r.is_finite() {
            return Err(format!("instance {i} has a non-finite orientation"));
        }
        let s = match scales.get(3 * i..3 * i + 3) {
            Some(s) => DVec3::new(s[0], s[1], s[2]),
            None => DVec3::ONE,
        };
        out.push(Instance {
            index: i,
            prototype: proto as usize,
            transform: DMat4::from_scale_rotation_translation(s, r, t),
        });
    }
    Ok((prototypes, out))
}
