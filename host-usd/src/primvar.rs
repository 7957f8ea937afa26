//! Primvars: a value array, optional `:indices`, and an interpolation, expanded to one value
//! per face-vertex (corner) of a mesh.

use crate::stage::{PrimPath, Stage, Value};

/// How a primvar's elements map onto a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// One value for the whole prim.
    Constant,
    /// One value per face.
    Uniform,
    /// One value per point, interpolated over the faces.
    Vertex,
    /// One value per point, linearly interpolated.
    Varying,
    /// One value per face-vertex (corner).
    FaceVarying,
}

impl Interpolation {
    /// The interpolation named by a USD token (`faceVarying`, …), if it is one.
    pub fn from_token(t: &str) -> Option<Self> {
        Some(match t {
            "constant" => Self::Constant,
            "uniform" => Self::Uniform,
            "vertex" => Self::Vertex,
            "varying" => Self::Varying,
            "faceVarying" => Self::FaceVarying,
            _ => return None,
        })
    }
}

/// A primvar read from a prim.
#[derive(Clone, Debug, PartialEq)]
pub struct Primvar {
    /// The elements' components, flattened.
    pub values: Vec<f64>,
    /// Components per element (3 for normals).
    pub width: usize,
    /// The `:indices` into the elements, when authored.
    pub indices: Option<Vec<i64>>,
    /// How the elements map onto the mesh.
    pub interpolation: Interpolation,
}

impl Primvar {
    /// Reads `primvars:<name>` (with `primvars:<name>:indices`), or, when `fallback_attr` is
    /// given and the primvar is not authored, that plain attribute (e.g. `normals`, whose
    /// interpolation defaults to `vertex`).
    pub fn read(
        stage: &Stage,
        prim: &PrimPath,
        name: &str,
        fallback_attr: Option<&str>,
    ) -> Result<Option<Self>, String> {
        let pv = format!("primvars:{name}");
        let (attr_name, value, interp_default) = match stage.value(prim, &pv)? {
            Some(v) => (pv, v, Interpolation::Constant),
            None => match fallback_attr {
                Some(a) => match stage.value(prim, a)? {
                    Some(v) => (a.to_string(), v, Interpolation::Vertex),
                    None => return Ok(None),
                },
                None => return Ok(None),
            },
        };
        let Value::Numbers { values, shape, .. } = value else {
            return Err(format!("{attr_name} is not numeric"));
        };
        let interpolation = match stage.attr_metadata(prim, &attr_name, "interpolation")? {
            Some(Value::Token(t)) => {
                Interpolation::from_token(&t).ok_or_else(|| format!("{attr_name}: unknown interpolation {t:?}"))?
            }
            _ => interp_default,
        };
        let indices = if attr_name.starts_with("primvars:") {
            stage.value(prim, &format!("{attr_name}:indices"))?.and_then(|v| match v {
                Value::Numbers { values, .. } => Some(values.iter().map(|&x| x as i64).collect()),
                _ => None,
            })
        } else {
            None
        };
        Ok(Some(Self { values, width: shape, indices, interpolation }))
    }

    /// Number of elements the primvar holds (after indexing).
    pub fn len(&self) -> usize {
        match &self.indices {
            Some(i) => i.len(),
            None => self.values.len() / self.width.max(1),
        }
    }

    /// True when the primvar has no elements.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Element `i` (after indexing), or `None` when out of range.
    pub fn element(&self, i: usize) -> Option<&[f64]> {
        let j = match &self.indices {
            Some(idx) => usize::try_from(*idx.get(i)?).ok()?,
            None => i,
        };
        self.values.get(j * self.width..(j + 1) * self.width)
    }

    /// The element index for face `face`, corner `fv` (global face-vertex index) on point
    /// `point`.
    pub fn element_for(&self, face: usize, fv: usize, point: usize) -> usize {
        match self.interpolation {
            Interpolation::Constant => 0,
            Interpolation::Uniform => face,
            Interpolation::Vertex | Interpolation::Varying => point,
            Interpolation::FaceVarying => fv,
        }
    }

    /// How many elements a mesh with these counts needs.
    pub fn expected_len(&self, faces: usize, face_vertices: usize, points: usize) -> usize {
        match self.interpolation {
            Interpolation::Constant => 1,
            Interpolation::Uniform => faces,
            Interpolation::Vertex | Interpolation::Varying => points,
            Interpolation::FaceVarying => face_vertices,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indexing_and_interpolation() {
        let p = Primvar {
            values: vec![0.0, 0.0, 1.0, 1.0, 0.0, 0.0],
            width: 3,
            indices: Some(vec![1, 0, 1]),
            interpolation: Interpolation::FaceVarying,
        };
        assert_eq!(p.len(), 3);
        assert_eq!(p.element(0), Some(&[1.0, 0.0, 0.0][..]));
        assert_eq!(p.element(1), Some(&[0.0, 0.0, 1.0][..]));
        assert_eq!(p.element(3), None);
        assert_eq!(p.element_for(4, 7, 2), 7);
        let bad = Primvar { indices: Some(vec![-1, 5]), ..p.clone() };
        assert_eq!(bad.element(0), None);
        assert_eq!(bad.element(1), None);
    }
}
