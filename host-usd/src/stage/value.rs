//! Composed values as plain numbers, tokens and asset paths.

use openusd::sdf;

/// A composed value, reduced to what the importer needs.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// Every numeric scalar, vector, quaternion (w, x, y, z) and matrix, flattened, of any
    /// precision; `shape` is the number of components per element (1 for scalars).
    Numbers {
        /// The components, flattened.
        values: Vec<f64>,
        /// Components per element.
        shape: usize,
        /// True for an array value (even of one element).
        array: bool,
    },
    /// A token.
    Token(String),
    /// A token array.
    Tokens(Vec<String>),
    /// A bool.
    Bool(bool),
    /// An asset path as authored, and resolved against the layer that authored it.
    Asset {
        /// The path as authored.
        authored: String,
        /// The resolved path, when the asset resolves.
        resolved: Option<String>,
    },
    /// Any other type, by its name.
    Other(String),
}

impl Value {
    /// The components of a numeric value.
    pub fn numbers(&self) -> Option<&[f64]> {
        match self {
            Value::Numbers { values, .. } => Some(values),
            _ => None,
        }
    }

    /// A numeric scalar (a bool as 0 or 1).
    pub fn scalar(&self) -> Option<f64> {
        match self {
            Value::Numbers { values, shape: 1, array: false } => values.first().copied(),
            Value::Bool(b) => Some(f64::from(u8::from(*b))),
            _ => None,
        }
    }

    /// A token's text.
    pub fn token(&self) -> Option<&str> {
        match self {
            Value::Token(t) => Some(t),
            _ => None,
        }
    }
}

/// openusd's value → ours.
pub(super) fn convert(v: sdf::Value) -> Value {
    use sdf::Value as V;
    fn nums(values: Vec<f64>, shape: usize, array: bool) -> Value {
        Value::Numbers { values, shape, array }
    }
    macro_rules! flat {
        ($v:expr, $($f:ident),+) => { $v.iter().flat_map(|e| [$(e.$f as f64),+]).collect::<Vec<f64>>() };
    }
    macro_rules! flath {
        ($v:expr, $($f:ident),+) => { $v.iter().flat_map(|e| [$(e.$f.to_f64()),+]).collect::<Vec<f64>>() };
    }
    match v {
        V::Bool(b) => Value::Bool(b),
        V::Uchar(x) => nums(vec![x.into()], 1, false),
        V::Int(x) => nums(vec![x.into()], 1, false),
        V::Uint(x) => nums(vec![x.into()], 1, false),
        V::Int64(x) => nums(vec![x as f64], 1, false),
        V::Uint64(x) => nums(vec![x as f64], 1, false),
        V::Half(x) => nums(vec![x.to_f64()], 1, false),
        V::Float(x) => nums(vec![x.into()], 1, false),
        V::Double(x) => nums(vec![x], 1, false),
        V::UcharVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::IntVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::UintVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::Int64Vec(x) => nums(x.into_iter().map(|e| e as f64).collect(), 1, true),
        V::Uint64Vec(x) => nums(x.into_iter().map(|e| e as f64).collect(), 1, true),
        V::HalfVec(x) => nums(x.into_iter().map(|e| e.to_f64()).collect(), 1, true),
        V::FloatVec(x) => nums(x.into_iter().map(f64::from).collect(), 1, true),
        V::DoubleVec(x) => nums(x, 1, true),
        V::Vec2f(e) => nums(flat!([e], x, y), 2, false),
        V::Vec2d(e) => nums(flat!([e], x, y), 2, false),
        V::Vec2h(e) => nums(flath!([e], x, y), 2, false),
        V::Vec2i(e) => nums(flat!([e], x, y), 2, false),
        V::Vec2fVec(v) => nums(flat!(v, x, y), 2, true),
        V::Vec2dVec(v) => nums(flat!(v, x, y), 2, true),
        V::Vec2hVec(v) => nums(flath!(v, x, y), 2, true),
        V::Vec2iVec(v) => nums(flat!(v, x, y), 2, true),
        V::Vec3f(e) => nums(flat!([e], x, y, z), 3, false),
        V::Vec3d(e) => nums(flat!([e], x, y, z), 3, false),
        V::Vec3h(e) => nums(flath!([e], x, y, z), 3, false),
        V::Vec3i(e) => nums(flat!([e], x, y, z), 3, false),
        V::Vec3fVec(v) => nums(flat!(v, x, y, z), 3, true),
        V::Vec3dVec(v) => nums(flat!(v, x, y, z), 3, true),
        V::Vec3hVec(v) => nums(flath!(v, x, y, z), 3, true),
        V::Vec3iVec(v) => nums(flat!(v, x, y, z), 3, true),
        V::Vec4f(e) => nums(flat!([e], x, y, z, w), 4, false),
        V::Vec4d(e) => nums(flat!([e], x, y, z, w), 4, false),
        V::Vec4h(e) => nums(flath!([e], x, y, z, w), 4, false),
        V::Vec4i(e) => nums(flat!([e], x, y, z, w), 4, false),
        V::Vec4fVec(v) => nums(flat!(v, x, y, z, w), 4, true),
        V::Vec4dVec(v) => nums(flat!(v, x, y, z, w), 4, true),
        V::Vec4hVec(v) => nums(flath!(v, x, y, z, w), 4, true),
        V::Vec4iVec(v) => nums(flat!(v, x, y, z, w), 4, true),
        V::Quatf(e) => nums(flat!([e], w, x, y, z), 4, false),
        V::Quatd(e) => nums(flat!([e], w, x, y, z), 4, false),
        V::Quath(e) => nums(flath!([e], w, x, y, z), 4, false),
        V::QuatfVec(v) => nums(flat!(v, w, x, y, z), 4, true),
        V::QuatdVec(v) => nums(flat!(v, w, x, y, z), 4, true),
        V::QuathVec(v) => nums(flath!(v, w, x, y, z), 4, true),
        V::Matrix4d(m) => nums(m.0.to_vec(), 16, false),
        V::Matrix3d(m) => nums(m.0.to_vec(), 9, false),
        V::Matrix4dVec(v) => nums(v.iter().flat_map(|m| m.0).collect(), 16, true),
        V::Token(t) => Value::Token(t.as_str().to_string()),
        V::String(s) => Value::Token(s),
        V::TokenVec(v) => Value::Tokens(v.iter().map(|t| t.as_str().to_string()).collect()),
        V::StringVec(v) => Value::Tokens(v),
        V::AssetPath(a) => Value::Asset {
            authored: a.evaluated_path().unwrap_or(a.as_str()).to_string(),
            resolved: a.resolved_path().map(str::to_string),
        },
        other => Value::Other(format!("{other:?}").chars().take(80).collect()),
    }
}
