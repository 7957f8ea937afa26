//! One copy of each distinct field list of a layer (ppis patch, see PATCHED.md).
//!
//! A reader hands every spec's finished [`Fields`] to the layer's [`FieldTable`]; a list
//! equal to one an earlier spec holds is replaced by that spec's, so a layer of many
//! similar prims holds each prim's common fields once, as a usdc file stores its field
//! sets once. Lists are equal when their names are and their values are bit for bit:
//! `0.0` and `-0.0` are kept apart, as every NaN is from every other. Only lists of plain
//! values (numbers, vectors, matrices, tokens, strings, their arrays, the spec enums, and
//! token and path list ops: a prim's `apiSchemas`, a relationship's `targetPaths`, an
//! attribute's `connectionPaths`) are shared; a list holding anything else (a dictionary,
//! a reference or payload list op, time samples) is left as it is.

use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::mem::Discriminant;
use std::sync::Arc;

use bytemuck::{bytes_of, cast_slice};

use super::fields::{take_field, Field, Fields, List, Split};
use crate::sdf::{ListOp, Value};
use crate::tf::Token;

/// The distinct field lists a reader has finished so far, and the heads (every field but
/// the last) of those lists. It lives while its layer is read: a list held only by the
/// table afterwards would be held for nothing.
/// Its hash is aHash, keyed at random per table as the standard map's SipHash is (a
/// file cannot be made of lists that collide), at a fraction of SipHash's cost for the
/// many short writes a list makes.
#[derive(Default)]
pub struct FieldTable {
    lists: HashMap<Key, (), ahash::RandomState>,
    /// Heads by their hash (under `lists`' hasher), each equal head once.
    heads: HashMap<u64, Vec<Arc<[Field]>>>,
}

impl FieldTable {
    /// Replaces `fields` by the equal list the table holds, or makes the table hold it.
    /// A list the table does not hold whose head an earlier list had keeps only its
    /// last field and shares that head (a list of a value seen once then costs the
    /// value's field, not its whole list).
    pub fn share(&mut self, fields: &mut Fields) {
        let List::Whole(list) = &fields.0 else { return };
        if list.is_empty() || !list.iter().all(|field| bits(&field.value).is_some()) {
            return;
        }
        let key = Key(fields.0.clone());
        if let Some((held, ())) = self.lists.get_key_value(&key) {
            fields.0 = held.0.clone();
            return;
        }
        drop(key);
        if let Some(head) = self.head(list) {
            let List::Whole(mut list) = std::mem::take(fields).0 else { unreachable!("a whole list") };
            let last = match Arc::get_mut(&mut list) {
                Some(own) => own.last_mut().map(take_field),
                None => list.last().cloned(),
            };
            fields.0 = List::Split(Arc::new(Split { head, last: last.expect("a list of two or more") }));
        }
        self.lists.insert(Key(fields.0.clone()), ());
    }

    /// The held head equal to `list`'s, if an earlier list had it; else the table holds
    /// a copy of it for later lists. A list of one field has no head.
    fn head(&mut self, list: &[Field]) -> Option<Arc<[Field]>> {
        let (_, head) = list.split_last()?;
        if head.is_empty() {
            return None;
        }
        let hash = self.lists.hasher().hash_one(HashFields(head.iter()));
        let bucket = self.heads.entry(hash).or_default();
        if let Some(held) = bucket.iter().find(|held| equal(held.iter(), head.iter())) {
            return Some(held.clone());
        }
        bucket.push(head.into());
        None
    }

    /// The number of distinct lists held.
    pub fn len(&self) -> usize {
        self.lists.len()
    }

    /// Whether it holds none.
    pub fn is_empty(&self) -> bool {
        self.lists.is_empty()
    }
}

/// A field list whose every value has [`bits`].
struct Key(List);

/// Fields hashed by their names and bits, in order.
struct HashFields<I>(I);

impl<'a, I: Iterator<Item = &'a Field> + Clone> Hash for HashFields<I> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        state.write_usize(self.0.clone().count());
        for field in self.0.clone() {
            field.name.as_str().hash(state);
            bits(&field.value).hash(state);
        }
    }
}

/// Whether two field sequences have the same names and bits, in order.
fn equal<'a>(a: impl ExactSizeIterator<Item = &'a Field>, b: impl ExactSizeIterator<Item = &'a Field>) -> bool {
    a.len() == b.len() && a.zip(b).all(|(a, b)| a.name.as_str() == b.name.as_str() && bits(&a.value) == bits(&b.value))
}

impl Hash for Key {
    fn hash<H: Hasher>(&self, state: &mut H) {
        HashFields(self.0.iter()).hash(state);
    }
}

impl PartialEq for Key {
    fn eq(&self, other: &Self) -> bool {
        equal(self.0.iter(), other.0.iter())
    }
}

impl Eq for Key {}

/// A value as its variant and the bits it holds, compared exactly.
type Bits<'a> = (Discriminant<Value>, Content<'a>);

#[derive(Hash, PartialEq, Eq)]
enum Content<'a> {
    Bytes(&'a [u8]),
    Bools(&'a [bool]),
    Small(u64),
    Text(&'a str),
    Tokens(&'a [Token]),
    Strings(&'a [String]),
    TokenOp(Op<'a, Token>),
    PathOp(Op<'a, crate::sdf::Path>),
}

/// A list op compared item by item, its explicit flag included. Tokens and paths are
/// equal exactly when their texts are.
struct Op<'a, T: Default + Clone + PartialEq>(&'a ListOp<T>);

impl<T: Default + Clone + PartialEq> Op<'_, T> {
    fn lists(&self) -> [&[T]; 6] {
        let op = self.0;
        [
            &op.explicit_items,
            &op.added_items,
            &op.prepended_items,
            &op.appended_items,
            &op.deleted_items,
            &op.ordered_items,
        ]
    }
}

impl<T: Default + Clone + PartialEq + Hash> Hash for Op<'_, T> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.0.explicit.hash(state);
        for list in self.lists() {
            list.hash(state);
        }
    }
}

impl<T: Default + Clone + PartialEq> PartialEq for Op<'_, T> {
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0
    }
}

impl<T: Default + Clone + Eq> Eq for Op<'_, T> {}

/// The bits of a plain value; `None` for values the table does not share.
fn bits(value: &Value) -> Option<Bits<'_>> {
    use Content::{Bools, Bytes, Small, Strings, Text, Tokens};
    let content = match value {
        Value::Bool(v) => Bools(std::slice::from_ref(v)),
        Value::BoolVec(v) => Bools(v),
        Value::Uchar(v) => Bytes(bytes_of(v)),
        Value::UcharVec(v) => Bytes(v),
        Value::Int(v) => Bytes(bytes_of(v)),
        Value::IntVec(v) => Bytes(cast_slice(v)),
        Value::Uint(v) => Bytes(bytes_of(v)),
        Value::UintVec(v) => Bytes(cast_slice(v)),
        Value::Int64(v) => Bytes(bytes_of(v)),
        Value::Int64Vec(v) => Bytes(cast_slice(v)),
        Value::Uint64(v) => Bytes(bytes_of(v)),
        Value::Uint64Vec(v) => Bytes(cast_slice(v)),
        Value::Half(v) => Bytes(bytes_of(v)),
        Value::HalfVec(v) => Bytes(cast_slice(v)),
        Value::Float(v) => Bytes(bytes_of(v)),
        Value::FloatVec(v) => Bytes(cast_slice(v)),
        Value::Double(v) => Bytes(bytes_of(v)),
        Value::DoubleVec(v) => Bytes(cast_slice(v)),
        Value::String(v) => Text(v),
        Value::StringVec(v) => Strings(v),
        Value::Token(v) => Text(v.as_str()),
        Value::TokenVec(v) => Tokens(v),
        Value::Specifier(v) => Small(*v as u64),
        Value::Permission(v) => Small(*v as u64),
        Value::Variability(v) => Small(*v as u64),
        Value::TokenListOp(v) => Content::TokenOp(Op(v)),
        Value::PathListOp(v) => Content::PathOp(Op(v)),
        _ => Bytes(vector_bits(value)?),
    };
    Some((std::mem::discriminant(value), content))
}

/// The bits of a vector, quaternion or matrix value, or of an array of them.
fn vector_bits(value: &Value) -> Option<&[u8]> {
    Some(match value {
        Value::Quath(v) => bytes_of(v),
        Value::Quatf(v) => bytes_of(v),
        Value::Quatd(v) => bytes_of(&**v),
        Value::QuathVec(v) => cast_slice(v),
        Value::QuatfVec(v) => cast_slice(v),
        Value::QuatdVec(v) => cast_slice(v),
        Value::Vec2h(v) => bytes_of(v),
        Value::Vec2f(v) => bytes_of(v),
        Value::Vec2d(v) => bytes_of(v),
        Value::Vec2i(v) => bytes_of(v),
        Value::Vec2hVec(v) => cast_slice(v),
        Value::Vec2fVec(v) => cast_slice(v),
        Value::Vec2dVec(v) => cast_slice(v),
        Value::Vec2iVec(v) => cast_slice(v),
        Value::Vec3h(v) => bytes_of(v),
        Value::Vec3f(v) => bytes_of(v),
        Value::Vec3d(v) => bytes_of(v),
        Value::Vec3i(v) => bytes_of(v),
        Value::Vec3hVec(v) => cast_slice(v),
        Value::Vec3fVec(v) => cast_slice(v),
        Value::Vec3dVec(v) => cast_slice(v),
        Value::Vec3iVec(v) => cast_slice(v),
        Value::Vec4h(v) => bytes_of(v),
        Value::Vec4f(v) => bytes_of(v),
        Value::Vec4d(v) => bytes_of(&**v),
        Value::Vec4i(v) => bytes_of(v),
        Value::Vec4hVec(v) => cast_slice(v),
        Value::Vec4fVec(v) => cast_slice(v),
        Value::Vec4dVec(v) => cast_slice(v),
        Value::Vec4iVec(v) => cast_slice(v),
        Value::Matrix2d(v) => bytes_of(&**v),
        Value::Matrix3d(v) => bytes_of(&**v),
        Value::Matrix4d(v) => bytes_of(&**v),
        Value::Matrix2dVec(v) => cast_slice(v),
        Value::Matrix3dVec(v) => cast_slice(v),
        Value::Matrix4dVec(v) => cast_slice(v),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sdf::{Specifier, Variability};

    fn fields(pairs: &[(&str, Value)]) -> Fields {
        let mut fields = Fields::default();
        for (name, value) in pairs {
            fields.set(name, value.clone());
        }
        fields
    }

    #[test]
    fn equal_lists_are_one_list() {
        let mut table = FieldTable::default();
        let make = || {
            fields(&[
                ("specifier", Value::Specifier(Specifier::Def)),
                ("typeName", Value::Token(Token::new("Sphere"))),
                ("properties", Value::TokenVec(vec![Token::from("radius"), Token::new("xformOpOrder")])),
                ("variability", Value::Variability(Variability::Uniform)),
                ("default", Value::Vec3fVec(vec![crate::gf::vec3f(1.0, 2.0, 3.0)])),
            ])
        };
        let (mut a, mut b) = (make(), make());
        table.share(&mut a);
        table.share(&mut b);
        assert!(a.is_shared_with(&b));
        assert_eq!(table.len(), 1);
    }

    #[test]
    fn lists_that_differ_in_a_bit_a_variant_or_a_name_stay_apart() {
        let mut table = FieldTable::default();
        let mut lists = [
            fields(&[("default", Value::Double(0.0))]),
            fields(&[("default", Value::Double(-0.0))]),
            fields(&[("default", Value::Float(0.0))]),
            fields(&[("default", Value::Int64(0))]),
            fields(&[("default", Value::Uint64(0))]),
            fields(&[("comment", Value::Double(0.0))]),
            fields(&[("default", Value::Token(Token::new("a")))]),
            fields(&[("default", Value::String("a".into()))]),
            fields(&[("default", Value::Double(0.0)), ("custom", Value::Bool(false))]),
        ];
        for list in &mut lists {
            table.share(list);
        }
        assert_eq!(table.len(), lists.len());
    }

    #[test]
    fn lists_of_other_values_are_not_shared_and_edits_copy() {
        let mut table = FieldTable::default();
        let dictionary = || fields(&[("customData", Value::Dictionary(Default::default()))]);
        let (mut a, mut b) = (dictionary(), dictionary());
        table.share(&mut a);
        table.share(&mut b);
        assert!(!a.is_shared_with(&b) && table.is_empty());

        let (mut c, mut d) = (fields(&[("default", Value::Int(1))]), fields(&[("default", Value::Int(1))]));
        table.share(&mut c);
        table.share(&mut d);
        d.set("default", Value::Int(2));
        d.set("custom", Value::Bool(true));
        assert_eq!(c.get("default"), Some(&Value::Int(1)));
        assert_eq!(c.len(), 1);
        assert_eq!(d.get("default"), Some(&Value::Int(2)));
        assert_eq!(d.remove("default"), Some(Value::Int(2)));
        assert_eq!(c.get("default"), Some(&Value::Int(1)));
    }

    #[test]
    fn equal_token_and_path_list_ops_are_one_list() {
        use crate::sdf::{path, ListOp};
        let mut table = FieldTable::default();
        let prim = |op: ListOp<Token>| fields(&[("typeName", Value::Token(Token::new("Sphere"))), ("apiSchemas", op.into())]);
        let binding = ListOp::prepended([Token::new("MaterialBindingAPI")]);
        let mut lists = [
            prim(binding.clone()),
            prim(binding.clone()),
            prim(ListOp::appended([Token::new("MaterialBindingAPI")])),
            prim(ListOp::explicit([Token::new("MaterialBindingAPI")])),
            prim(ListOp::prepended([Token::new("MaterialBindingAPI"), Token::new("LightAPI")])),
        ];
        for list in &mut lists {
            table.share(list);
        }
        assert!(lists[0].is_shared_with(&lists[1]));
        assert_eq!(table.len(), 4, "a different operation or item is a different list");

        let rel = |target: &str| fields(&[("targetPaths", ListOp::explicit([path(target).unwrap()]).into())]);
        let (mut a, mut b, mut c) = (rel("/Looks/M0"), rel("/Looks/M0"), rel("/Looks/M1"));
        for list in [&mut a, &mut b, &mut c] {
            table.share(list);
        }
        assert!(a.is_shared_with(&b) && !a.is_shared_with(&c));
        // An edit copies the shared list.
        b.set("targetPaths", ListOp::explicit([path("/Looks/M2").unwrap()]).into());
        assert_eq!(a.get("targetPaths"), Some(&ListOp::explicit([path("/Looks/M0").unwrap()]).into()));
    }

    #[test]
    fn lists_of_distinct_values_share_their_heads() {
        let mut table = FieldTable::default();
        let points = |x: f32| {
            fields(&[
                ("typeName", Value::Token(Token::new("point3f[]"))),
                ("variability", Value::Variability(Variability::Varying)),
                ("default", Value::Vec3fVec(vec![crate::gf::vec3f(x, 0.0, 0.0)])),
            ])
        };
        let (mut a, mut b, mut c, mut d) = (points(1.0), points(2.0), points(3.0), points(3.0));
        for list in [&mut a, &mut b, &mut c, &mut d] {
            table.share(list);
        }
        assert!(b.shares_head_with(&c) && !a.shares_head_with(&b), "the first keeps its whole list");
        assert!(c.is_shared_with(&d), "an equal split list is one list");
        assert_eq!(table.len(), 3);
        let names: Vec<&str> = c.iter().map(|(name, _)| name).collect();
        assert_eq!(names, ["typeName", "variability", "default"]);
        assert_eq!(c.len(), 3);
        assert_eq!(c.get("default"), Some(&Value::Vec3fVec(vec![crate::gf::vec3f(3.0, 0.0, 0.0)])));
        assert_eq!(c.get("variability"), Some(&Value::Variability(Variability::Varying)));

        // Editing a split list copies it: neither its head's other lists nor its equals see it.
        c.set("default", Value::Vec3fVec(Vec::new()));
        c.set("custom", Value::Bool(true));
        assert_eq!(d.get("default"), Some(&Value::Vec3fVec(vec![crate::gf::vec3f(3.0, 0.0, 0.0)])));
        assert_eq!(b.get("default"), Some(&Value::Vec3fVec(vec![crate::gf::vec3f(2.0, 0.0, 0.0)])));
        assert_eq!(c.len(), 4);
        assert_eq!(d.remove("variability"), Some(Value::Variability(Variability::Varying)));
        assert_eq!(b.get("variability"), Some(&Value::Variability(Variability::Varying)));
        let taken: Vec<String> = b.into_iter().map(|(name, _)| name.to_string()).collect();
        assert_eq!(taken, ["typeName", "variability", "default"]);
    }
}
